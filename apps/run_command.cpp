#include "apps/run_command.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>

#include <spdlog/spdlog.h>

#include "apps/session.hpp"
#include "rt/recording.hpp"
#include "rt/signals.hpp"

namespace robodamp::apps {

std::optional<config::Config> load_config_or_report(const std::string& path) {
  try {
    return config::load_config_file(path);
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return std::nullopt;
  }
}

int run_loop(const RunOptions& o) {
  const auto loaded = load_config_or_report(o.config_path);
  if (!loaded) return 2;
  const config::Config& cfg = *loaded;
  if (!(o.duration_s > 0.0 && o.duration_s <= 7.0 * 24 * 3600)) {
    std::cerr << "--duration " << o.duration_s << " s: allowed 0 < value <= 604800 s (one week)\n";
    return 2;
  }
  try {
    SessionOptions so;
    so.clock = o.clock;
    so.impact_every_s = o.impact_every_s;
    so.record_path = o.record_path;
    Session session(cfg, so);
    rt::install_shutdown_handlers();
    spdlog::info("robodamp run: {} at {} Hz on the {} clock for {} s against {} (Ctrl-C ends it through the safe state)",
                 o.config_path, cfg.loop.rate_hz, config::to_string(session.config().loop.clock), o.duration_s,
                 session.hardware() ? "the hardware" : "the simulated plant");
    const RunSummary s = session.run(o.duration_s);
    std::cout << summary_text(s);
    if (!o.json_path.empty()) {
      std::ofstream out(o.json_path);
      out << summary_json(s).dump(2) << '\n';
      if (!out) {
        std::cerr << "--json " << o.json_path << ": cannot write\n";
        return 1;
      }
    }
    if (!o.histogram_path.empty()) {
      // The layout of cyclictest's --histfile (whole-microsecond bins), so one script reads both.
      std::ofstream out(o.histogram_path);
      const auto& h = s.loop.wake_latency;
      out << "# robodamp run wake-up latency histogram (us)\n";
      std::size_t last = 0;
      for (std::size_t us = 0; us < rt::TimingHistogram::kBins; ++us)
        if (h.bin(us) > 0) last = us;
      char line[64];
      for (std::size_t us = 0; us <= last; ++us) {
        std::snprintf(line, sizeof line, "%06zu %06llu\n", us, static_cast<unsigned long long>(h.bin(us)));
        out << line;
      }
      out << "# Total: " << h.count() << "\n# Max Latencies: " << h.max_us() << "\n# Histogram Overflows: "
          << h.overflow() << "\n# Loop overruns: " << s.loop.overruns << "\n# Missed ticks: " << s.loop.missed_ticks
          << '\n';
      if (!out) {
        std::cerr << "--histogram " << o.histogram_path << ": cannot write\n";
        return 1;
      }
    }
    if (s.record_errors > 0) return 1;
    return s.trip == "none" || s.trip == "signal" ? 0 : 4;
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 2;
  } catch (const rt::RecordingError& e) {
    std::cerr << "--record: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {  // a CAN transport or interface that cannot be opened
    std::cerr << "robodamp run: " << e.what() << '\n';
    return 1;
  }
}

int run_replay(const std::string& path) {
  try {
    const rt::Recording r = rt::read_recording(path);
    const rt::ReplayResult res = rt::replay(r);
    std::cout << path << ": " << res.frames << " frames (" << r.header.value("clock", "?") << " clock, "
              << r.header.value("rate_hz", 0.0) << " Hz, robodamp " << r.header.value("robodamp_version", "?") << " "
              << r.header.value("git_commit", "?") << ")\n";
    if (r.trailing_bytes > 0)
      std::cout << "  note: " << r.trailing_bytes << " trailing bytes of a partial frame ignored\n";
    std::cout << "  replayed through the same supervisor and controller: final state " << res.final_state
              << ", trip " << res.final_trip << '\n';
    if (res.mismatches == 0) {
      std::cout << "  commands reproduced bit for bit\n";
      return 0;
    }
    char b[200];
    std::snprintf(b, sizeof b, "  %llu frames differ; first at tick %llu: recorded %.17g V, replayed %.17g V\n",
                  static_cast<unsigned long long>(res.mismatches),
                  static_cast<unsigned long long>(res.first_mismatch_tick), res.first_recorded_v, res.first_replayed_v);
    std::cout << b;
    return 1;
  } catch (const std::exception& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

int run_csv(const std::string& path, const std::string& out_path) {
  try {
    const rt::Recording r = rt::read_recording(path);
    std::FILE* out = out_path.empty() || out_path == "-" ? stdout : std::fopen(out_path.c_str(), "w");
    if (out == nullptr) {
      std::cerr << "-o " << out_path << ": cannot open for writing\n";
      return 1;
    }
    rt::write_csv(r, out);
    const bool ok = std::ferror(out) == 0;
    if (out != stdout) std::fclose(out);
    if (!ok) {
      std::cerr << "-o " << out_path << ": write failed\n";
      return 1;
    }
    if (out != stdout) std::cout << "wrote " << r.frames.size() << " frames to " << out_path << '\n';
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

}  // namespace robodamp::apps
