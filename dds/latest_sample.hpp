// The latest sample of one topic from one cell, as a reader's listener keeps it (robodamp monitor, the
// dashboard's tests): the cell named, else the first heard. Off the real-time path.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

namespace robodamp::dds {

// The latest sample of one cell: the one named, else the first seen.
template <typename T>
class Latest : public eprosima::fastdds::dds::DataReaderListener {
 public:
  explicit Latest(std::shared_ptr<std::string> cell) : cell_(std::move(cell)) {}
  void on_data_available(eprosima::fastdds::dds::DataReader* r) override {
    T v;
    eprosima::fastdds::dds::SampleInfo info;
    while (r->take_next_sample(&v, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
      if (info.valid_data) {
        std::lock_guard<std::mutex> cell_lock(cell_mutex());
        if (cell_->empty()) *cell_ = v.cell();
        if (v.cell() != *cell_) continue;
        std::lock_guard<std::mutex> lock(m_);
        value_ = v;
        ++count_;
      }
  }
  std::pair<T, std::uint64_t> get() {
    std::lock_guard<std::mutex> lock(m_);
    return {value_, count_};
  }
  static std::mutex& cell_mutex() {
    static std::mutex m;
    return m;
  }

 private:
  std::shared_ptr<std::string> cell_;
  std::mutex m_;
  T value_{};
  std::uint64_t count_{0};
};

}  // namespace robodamp::dds
