// Latency histogram in whole microseconds (as cyclictest's -h, so the two compare bin for bin) with an
// exact maximum and mean. record() is RT-safe (fixed storage, no allocation); a single writer.
#pragma once

#include <array>
#include <cstdint>

namespace robodamp::rt {

class TimingHistogram {
 public:
  static constexpr std::size_t kBins = 10000;  // 0 .. 9999 us; beyond goes to overflow (max stays exact)

  void record(std::int64_t ns) noexcept {
    if (ns < 0) ns = 0;
    const auto us = static_cast<std::uint64_t>(ns / 1000);
    if (us < kBins)
      ++bins_[us];
    else
      ++overflow_;
    ++count_;
    sum_ns_ += static_cast<double>(ns);
    if (ns > max_ns_) max_ns_ = ns;
  }
  void add_bin(std::size_t us, std::uint64_t n) noexcept {  // for histograms read from elsewhere
    if (us < kBins)
      bins_[us] += n;
    else
      overflow_ += n;
    count_ += n;
    sum_ns_ += static_cast<double>(n) * (static_cast<double>(us) * 1000.0 + 500.0);
    if (n > 0 && static_cast<std::int64_t>(us) * 1000 > max_ns_) max_ns_ = static_cast<std::int64_t>(us) * 1000;
  }
  void clear() noexcept { *this = TimingHistogram{}; }

  // Smallest whole-microsecond bin at or below which a fraction q of the samples lies (q in (0, 1]).
  [[nodiscard]] double percentile_us(double q) const noexcept {
    if (count_ == 0) return 0.0;
    const double target = q * static_cast<double>(count_);
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += bins_[i];
      if (static_cast<double>(seen) >= target) return static_cast<double>(i);
    }
    return max_us();
  }
  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  [[nodiscard]] std::uint64_t overflow() const noexcept { return overflow_; }
  [[nodiscard]] double max_us() const noexcept { return static_cast<double>(max_ns_) * 1e-3; }
  [[nodiscard]] double mean_us() const noexcept { return count_ ? sum_ns_ * 1e-3 / static_cast<double>(count_) : 0.0; }
  [[nodiscard]] std::uint64_t bin(std::size_t us) const noexcept { return us < kBins ? bins_[us] : 0; }

 private:
  std::array<std::uint64_t, kBins> bins_{};
  std::uint64_t overflow_{0};
  std::uint64_t count_{0};
  double sum_ns_{0.0};
  std::int64_t max_ns_{0};
};

}  // namespace robodamp::rt
