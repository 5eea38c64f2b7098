// The loop on DDS: decimated telemetry and status from the telemetry drain's frames (the real-time
// thread never touches DDS: it only fills the ring; the drain thread calls on_frame), and parameter
// requests answered with a reply. A request is refused with a reason unless dds.parameter_writes is on;
// when on, the handler validates it exactly as the configuration would (key, value, unit, allowed range)
// and queues it for the loop's next tick boundary.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <iterator>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <stop_token>
#include <vector>

#include "config/supervisory_config.hpp"
#include "fields/fields.hpp"
#include "rt/availability.hpp"
#include "rt/telemetry_frame.hpp"
#include "rt/timing_histogram.hpp"
#include "threads/worker.hpp"

namespace eprosima::fastdds::dds {
class DataWriter;
}

namespace robodamp::dds {

class Participant;

enum class RequestKind : std::uint8_t { kSetGain, kSelectParameterSet, kEnable, kSetSpindleRpm, kResetFault };

// The bins of the status topic's timing histograms: [0, 1), [1, 2), [2, 5) ... [5000, 10000) us and the last
// one from 10000 us up (14 bins).
inline constexpr double kHistogramEdgesUs[] = {0, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000};
inline constexpr std::size_t kHistogramBins = std::size(kHistogramEdgesUs);

struct Decision {
  bool accepted{false};
  std::string reason;
};

// What the Machining_ topic carries (dds/robodamp.idl), filled by the cell's machining monitor.
struct MachiningSample {
  std::uint64_t tick{0};
  double time_s{0.0};
  double spindle_rpm{0.0}, tooth_passing_hz{0.0}, depth_mm{0.0};
  bool depth_measured{false};  // depth_mm is the robot's; else the job's planned depth
  bool limits_ready{false};
  double open_limit_mm{0.0}, damped_limit_mm{0.0};
  std::string limit_method;  // which method made damped_limit_mm (milling::LiveLimits::method)
  bool loop_active{false};
  double limit_mm{0.0};
  bool depth_warning{false};
  bool indicator_valid{false};
  double once_per_rev_ratio{0.0}, nonharmonic_share{0.0}, chatter_hz{0.0};
  bool chatter{false};
  std::uint8_t cutting{0};              // kCuttingUnknown, kCutting, kNotCutting
  std::string cutting_reason;           // what says so
  std::vector<double> pose_deg;         // a pose-scheduled cell: the robot's joints now (empty: not known)
  std::vector<double> limits_pose_deg;  // the pose the limits are for (on the live stability's grid)
  // A measured map (pose modes): the largest one-sigma frequency spread of the modes at limits_pose_deg, %, and
  // how far that pose is from the nearest measured one; -1 each: the model alone (no measured modes).
  double mode_spread_pct{-1.0}, nearest_measured_deg{-1.0};
};
inline constexpr std::uint8_t kCuttingUnknown = 0, kCutting = 1, kNotCutting = 2;
[[nodiscard]] inline const char* cutting_name(std::uint8_t c) {
  return c == kCutting ? "cutting" : c == kNotCutting ? "not cutting" : "not known yet";
}

// One point of a robot program's trajectory (dds.path_ahead), as the message carries it.
struct TrajectoryPoint {
  std::vector<double> position_rad;
  double time_from_start_s{0.0};
};

// What the Advice_ topic carries (dds/robodamp.idl), filled from the cell's speed advisor.
struct AdviceSample {
  std::uint64_t seq{0};
  double time_s{0.0};
  std::string trigger;
  double spindle_rpm{0.0}, depth_mm{0.0};
  bool damped{false};
  double chatter_hz{0.0}, limit_now_mm{0.0};
  std::string method;
  bool found{false};
  double advised_rpm{0.0}, advised_limit_mm{0.0}, margin{0.0};
  std::vector<double> option_rpm, option_limit_mm;  // nearest first (at most 8 go on the wire)
  double best_rpm{0.0}, best_limit_mm{0.0};
  std::string reason;
  double rpm_min{0.0}, rpm_max{0.0};
  std::vector<double> pose_deg;           // the pose the candidates were checked at (empty: none)
  std::uint32_t poses_ahead{0};           // ... and this many poses of the path ahead
  std::vector<double> limiting_pose_deg;  // where the advised (else the best) speed's limit is lowest
  std::string status{"current"};          // "current", "followed" or "expired" (runtime::AdviceStatus)
  std::string status_reason;
};

// What the Spectrum_ topic carries (dds/robodamp.idl), from the cell's spectrum monitor.
struct SpectrumSample {
  std::uint64_t tick{0};
  double time_s{0.0};
  double bin_hz{0.0}, record_s{0.0};
  std::vector<float> accel_asd;  // (m/s^2)/sqrt(Hz), at most 1024 go on the wire
  std::vector<float> mode_hz;    // at most 16
  double tooth_passing_hz{0.0};
};

// What the Lobes_ topic carries (dds/robodamp.idl): the accurate limits the cell knows at its set and gain.
struct LobesSample {
  double time_s{0.0};
  std::size_t parameter_set{0};
  double gain_ns_per_m{0.0};
  std::string method;
  double depth_mm{0.0};
  std::vector<double> rpm, open_limit_mm, damped_limit_mm;  // by speed, at most 256
  bool speed_scheduled{false};   // each speed with its band's controller and K (parameter_set, gain not one)
  std::vector<double> pose_deg;  // the pose the limits are for (empty: none)
};

struct BridgeSources {
  std::string cell;                             // cell.name: on every topic; requests for other cells are ignored
  std::string backend;                          // for the status
  std::function<std::size_t()> parameter_set;   // the active set (any thread)
  std::function<double()> gain_limit_ns_per_m;  // what a gain request may ask for now
  std::function<Decision(RequestKind, double)> handle;        // validate and queue (parameter writes on)
  std::function<MachiningSample()> machining;                 // empty: no machining topic (no spindle.job)
  std::function<std::optional<AdviceSample>()> advice{};      // the latest speed advice; empty: no advice topic
  std::function<std::optional<SpectrumSample>()> spectrum{};  // a new spectrum, if one is due; empty: no topic
  std::function<std::optional<LobesSample>()> lobes{};        // the lobes, if they changed; empty: no topic
  double gain_ramp_s{0.0};                                    // controller.gain_ramp_s: when the loop is at full gain
  std::function<std::size_t()> parameter_sets{};  // how many sets a select request may choose from (any thread)
  double spindle_rpm_max{0.0};                    // spindle.rpm_max: what a spindle request may ask for
  // dds.joint_states: each message's names and positions (rad), on the reader's thread; the silence check,
  // on the status thread. Empty: no joint-state reader.
  std::function<void(const std::vector<std::string>&, const std::vector<double>&)> joint_state{};
  std::function<void()> joint_state_check{};
  // dds.path_ahead: each trajectory's joint names and points, on the reader's thread. Empty: no reader.
  std::function<void(const std::vector<std::string>&, const std::vector<TrajectoryPoint>&)> trajectory{};
};

struct BridgeCounters {
  std::uint64_t telemetry{0}, status{0}, requests{0}, refused{0}, machining{0}, advice{0}, spectrum{0}, lobes{0};
  std::uint64_t other_cells{0};  // requests for another cell, ignored
};

// BridgeCounters' JSON keys (the run summary's "dds") and their words in its text line.
[[nodiscard]] constexpr auto field_list(fields::Tag<BridgeCounters>) {
  using B = BridgeCounters;
  using F = fields::Field<B, std::uint64_t>;
  return std::tuple{F{"telemetry", &B::telemetry, "telemetry samples published"},
                    F{"status", &B::status, "status samples"},
                    F{"requests", &B::requests, "parameter requests"},
                    F{"refused", &B::refused, "refused"},
                    F{"machining", &B::machining, "machining samples"},
                    F{"advice", &B::advice, "speed advices"},
                    F{"spectrum", &B::spectrum, "spectra"},
                    F{"lobes", &B::lobes, "lobe diagrams"},
                    F{"other_cells", &B::other_cells, "requests for other cells ignored"}};
}
static_assert(fields::lists_every_member<BridgeCounters>(), "each counter in BridgeCounters' field list");

class Bridge {
 public:
  Bridge(const config::DdsConfig& cfg, double loop_rate_hz, const std::string& config_source, BridgeSources sources);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  // The telemetry drain's consumer (non-real-time thread).
  void on_frame(const rt::TelemetryFrame& f);
  // Status (and machining) at dds.status_rate_hz on a thread of its own; stop() publishes a last one.
  void start();
  void stop();
  [[nodiscard]] BridgeCounters counters() const;

 private:
  class RequestListener;
  class JointStateListener;
  class TrajectoryListener;
  void publish_status();
  void publish_machining();
  void publish_advice();  // a new advice (its seq), and each change of its status, once
  void publish_spectrum();
  void publish_lobes();
  Decision decide(RequestKind kind, double value);
  Decision refuse(std::string reason);

  config::DdsConfig cfg_;
  std::string source_;
  BridgeSources src_;
  std::unique_ptr<Participant> participant_;
  eprosima::fastdds::dds::DataWriter* telemetry_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* status_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* reply_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* machining_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* advice_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* spectrum_writer_{nullptr};
  eprosima::fastdds::dds::DataWriter* lobes_writer_{nullptr};
  std::uint64_t published_advice_{0};  // status thread
  std::string published_advice_status_;
  std::unique_ptr<RequestListener> listener_;
  std::unique_ptr<JointStateListener> joint_state_listener_;
  std::unique_ptr<TrajectoryListener> trajectory_listener_;
  rt::AvailabilityMeter availability_;  // under m_

  // Decimation window (drain thread).
  std::uint64_t window_ticks_{1}, in_window_{0};
  double sum_sq_{0.0}, peak_v_{0.0};
  std::uint64_t saturated_in_window_{0};
  float wake_max_us_{0.0F};
  std::uint32_t last_saturated_total_{0};

  mutable std::mutex m_;  // the status snapshot
  rt::TelemetryFrame last_{};
  bool have_frame_{false};
  rt::TimingHistogram wake_, compute_;
  std::uint8_t published_state_{255}, published_trip_{255};
  bool running_{false};  // guarded by m_: between start() and stop()
  std::atomic<std::uint64_t> n_telemetry_{0}, n_status_{0}, n_requests_{0}, n_refused_{0}, n_machining_{0},
      n_advice_{0}, n_spectrum_{0}, n_lobes_{0}, n_other_cells_{0};
  threads::Worker status_;  // status, machining, advice, spectrum and lobes at status_rate_hz (last: stopped first)
};

}  // namespace robodamp::dds
