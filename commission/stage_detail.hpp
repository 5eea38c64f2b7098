// What the commissioning runs share (commission.cpp, path_commission.cpp and their reports): a stop with its
// stage and reason, a measurement's status as that stop, the time since, printf-style text, HTML escaping.
// Internal to the commission library. Off the real-time path.
#pragma once

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "commission/commission.hpp"
#include "commission/measurement.hpp"
#include "config/config.hpp"

namespace robodamp::commission::detail {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

template <class... A>
std::string fmt(const char* f, A... a) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

// A stop: the stage, the outcome, the reason.
struct Stop {
  Stage stage;
  Outcome outcome;
  std::string reason;
};

// Nothing when the measurement ran; else the stop its status is at `stage`.
inline void throw_unless_measured(const MeasureOutcome& o, Stage stage) {
  switch (o.status) {
    case MeasureStatus::kOk:
      return;
    case MeasureStatus::kTripped:
      throw Stop{stage, Outcome::kTripped, o.message};
    case MeasureStatus::kConfigError:
      throw Stop{stage, Outcome::kBadInput, o.message};
    case MeasureStatus::kNotReady:
    case MeasureStatus::kSaturated:
      throw Stop{stage, Outcome::kRefused, o.message};
    case MeasureStatus::kAborted:
      throw Stop{stage, Outcome::kAborted, o.message};
    default:
      throw Stop{stage, Outcome::kFailed, o.message};
  }
}

// Runs a commissioning to its outcome: verified when it returns, else the stop's stage and reason, or what was
// thrown (bad input: a configuration or an argument refused; failed: anything else). Never throws.
template <class Result, class Run>
void run_to_outcome(Result& r, Run&& run) {
  try {
    run();
    r.outcome = Outcome::kVerified;
  } catch (const Stop& stop) {
    r.stage = stop.stage, r.outcome = stop.outcome, r.reason = stop.reason;
  } catch (const config::ConfigError& e) {
    r.outcome = Outcome::kBadInput, r.reason = e.what();
  } catch (const std::invalid_argument& e) {
    r.outcome = Outcome::kBadInput, r.reason = e.what();
  } catch (const std::exception& e) {
    r.outcome = Outcome::kFailed, r.reason = e.what();
  }
}

// Runs the stages in turn: each said, timed and recorded; a stage before `from` reuses the directory's files
// (reuse set while it runs), but identify, which is quick and deterministic, always runs again.
class StageRunner {
 public:
  StageRunner(Stage from, std::string dir, const std::function<void(const std::string&)>& say, Stage& current,
              std::vector<StageTime>& times)
      : from_(from), dir_(std::move(dir)), say_(say), current_(current), times_(times) {}
  template <class F>
  void operator()(Stage st, F&& f) {
    current_ = st;
    const auto t0 = Clock::now();
    reuse_ = st < from_ && st != Stage::kIdentify;
    say_(std::string("commission: stage ") + std::to_string(static_cast<int>(st)) + "/5 " + to_string(st) +
         (reuse_ ? " (reusing " + dir_ + ")" : ""));
    f();
    times_.push_back({st, seconds_since(t0), reuse_});
    say_(fmt("commission: %s done in %.1f s", to_string(st), seconds_since(t0)));
  }
  [[nodiscard]] bool reuse() const { return reuse_; }

 private:
  Stage from_;
  std::string dir_;
  const std::function<void(const std::string&)>& say_;
  Stage& current_;
  std::vector<StageTime>& times_;
  bool reuse_{false};
};

// DIR/configuration.yaml: the header, then the file the tune wrote (DIR/from), read back as a configuration
// first and renamed into place whole (nothing half-written stands there). Returns its path.
inline std::string write_configuration(const std::filesystem::path& dir, const std::string& from,
                                       const std::string& header) {
  std::ifstream in(dir / from);
  const std::string tuned((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string text = header + tuned;
  (void)config::parse_config(text, (dir / "configuration.yaml").string());
  const std::filesystem::path tmp = dir / "configuration.yaml.partial";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw Stop{Stage::kWrite, Outcome::kFailed, "cannot write " + tmp.string()};
  }
  std::filesystem::rename(tmp, dir / "configuration.yaml");
  return (dir / "configuration.yaml").string();
}

inline std::string esc(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

}  // namespace robodamp::commission::detail
