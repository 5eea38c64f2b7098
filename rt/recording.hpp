// Recordings of the loop's telemetry (format: docs/recording_format.md): an 8-byte magic, the format
// version, a JSON header (versions, configuration text, the controller's and supervisor's exact
// parameters, the frame layout) and one fixed-size frame per tick. Written by a telemetry consumer off
// the real-time thread. Replay runs the recorded supervisor inputs through the same Supervisor and
// controller and must reproduce every recorded command bit for bit.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/controller_params.hpp"
#include "rt/supervisor.hpp"
#include "rt/telemetry_frame.hpp"

namespace robodamp::rt {

inline constexpr char kRecordingMagic[8] = {'R', 'D', 'A', 'M', 'P', 'R', 'E', 'C'};
inline constexpr std::uint32_t kRecordingFormatVersion = 1;

class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The header for a run: what replay needs (settings, parameters) and what a reader needs to know.
[[nodiscard]] nlohmann::json recording_header(const config::Config& cfg, const Supervisor& supervisor,
                                              config::ClockKind clock);

[[nodiscard]] nlohmann::json to_json(const control::ControllerParams& p);
[[nodiscard]] control::ControllerParams controller_params_from(const nlohmann::json& j);
[[nodiscard]] nlohmann::json to_json(const SupervisorSettings& s);
[[nodiscard]] SupervisorSettings supervisor_settings_from(const nlohmann::json& j);

// Writes as frames arrive (a TelemetryDrain consumer); large stdio buffer, flushed on close.
class Recorder {
 public:
  Recorder(const std::string& path, const nlohmann::json& header);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
  void write(const TelemetryFrame& f);
  void close();
  [[nodiscard]] std::uint64_t frames() const { return frames_; }
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* f_{nullptr};
  std::vector<char> buffer_;
  std::uint64_t frames_{0};
  std::uint64_t write_errors_{0};
};

struct Recording {
  nlohmann::json header;
  std::vector<TelemetryFrame> frames;
  std::size_t trailing_bytes{0};  // a partial last frame (the writer stopped mid-frame)
};

[[nodiscard]] Recording read_recording(const std::string& path);

// CSV with one column per frame field (doubles to 17 significant digits) plus the state and trip names.
void write_csv(const Recording& r, std::FILE* out);

struct ReplayResult {
  std::uint64_t frames{0};
  std::uint64_t mismatches{0};            // frames whose command, state or trip differ in any bit
  std::uint64_t first_mismatch_tick{0};
  double first_recorded_v{0.0}, first_replayed_v{0.0};
  std::string final_state, final_trip;
};

[[nodiscard]] ReplayResult replay(const Recording& r);

}  // namespace robodamp::rt
