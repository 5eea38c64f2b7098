// The supervisor and the controller together: one deterministic step per loop tick from that tick's
// inputs (sensor sample, driver and amplifier status, timing flags, an operator command) to the
// amplifier command and enable. Everything it does depends on those inputs only, so a recording of them
// replays bit for bit (rt/recording.hpp). Construction allocates (the saturation window); step() is
// RT-safe: no allocation, locking, I/O, exceptions or logging.
//
// States:  Disabled --arm--> Arming --amplifier ready--> Active --disarm--> Stopping --ramped--> Disabled
//          any --trip--> Fault (command ramps to zero within trip_ramp_s, then the amplifier is disabled;
//          latched until reset_fault, which returns to Disabled once the ramp is over).
// Arming is refused unless the sensor is live (arming_live_cycles fresh valid samples in a row), the
// actuator path is healthy (drivers ok, amplifier without fault), the analysis found the configured
// loop stable and, with a pose schedule, the pose is in a region whose set is in place (handed over). Activation and disarming fade the command in and out over controller.gain_ramp_s; gain
// requests are validated (0 <= K <= max_gain_fraction x the analysed maximum stable K) and ramped by the
// controller; a parameter-set selection is validated the same way (the set's own analysis) and handed
// over by the controller (fade out, swap, fade in); everything is applied at the tick boundary.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "control/controller.hpp"
#include "fields/fields.hpp"
#include "rt_settings/rt_settings.hpp"

namespace robodamp::rt {

enum class State : std::uint8_t { kDisabled, kArming, kActive, kStopping, kFault };

// Trip, its names and kTripCount: rt_settings/rt_settings.hpp.

enum class ArmRefusal : std::uint8_t {
  kNone,
  kNotDisabled,
  kSensorNotLive,
  kActuatorPath,
  kAnalysisUnstable,
  kPoseUnknown
};

enum class CommandKind : std::uint8_t {
  kNone,
  kArm,
  kDisarm,
  kResetFault,
  kSetGain,
  kSelectParams,
  kSetSpindle,
  kSetPoseRegion,
  kStartExcitation,  // the loop's: its on-command chirp starts at the next tick (rt/excitation.hpp); not the supervisor's
};
inline constexpr CommandKind kLastCommandKind = CommandKind::kStartExcitation;

struct OperatorCommand {
  CommandKind kind{CommandKind::kNone};
  // set_gain: K in N s/m; select_params: index of the parameter set; set_spindle: rpm;
  // set_pose_region: the parameter set of the region the pose is in, or -1 when it is out of the map.
  double value{0.0};
};

[[nodiscard]] const char* to_string(State s);
[[nodiscard]] const char* to_string(Trip t);
[[nodiscard]] const char* describe(Trip t);  // what it means and what the operator should look at
[[nodiscard]] const char* to_string(ArmRefusal r);
[[nodiscard]] const char* to_string(CommandKind k);

// Everything one tick's decision depends on (and what a recording stores to replay it).
struct TickInput {
  double dt_s{0.0};  // measured time since the previous tick: drives the ramps and timeouts
  double accel_mps2{0.0};
  bool fresh{false};
  bool sensor_ok{true};
  bool actuator_ok{true};
  bool actuator_saturated{false};
  bool amplifier_ready{false};
  bool amplifier_fault{false};
  bool overrun{false};       // the previous tick ran past its deadline, or ticks were missed
  double excitation_v{0.0};  // the loop's command source beside the controller (rt/excitation.hpp), V
  bool shutdown{false};      // SIGINT / SIGTERM seen
  OperatorCommand command{};
};

struct TickOutput {
  double command_v{0.0};
  double controller_v{0.0};  // the controller's output before the supervisor's fade / trip ramp
  double filtered_mps{0.0};  // chain output
  bool amplifier_enable{false};
  State state{State::kDisabled};
  Trip trip{Trip::kNone};
  bool saturated{false};  // this tick counted as saturated
  bool derated{false};    // the controller's command derated this tick (supervision.derate)
};

struct SupervisorCounters {
  std::array<std::uint64_t, kTripCount> trips{};  // per reason
  std::uint64_t ticks{0};
  std::uint64_t stale_ticks{0};
  std::uint64_t invalid_samples{0};
  std::uint64_t overruns{0};
  // Runs of overrun_cycles or more consecutive overruns that ended within the active set's delay margin
  // (supervision.overrun_delay_margin_share): ridden through, not tripped.
  std::uint64_t overrun_runs_ridden{0};
  // Ticks active or stopping on a stale or invalid sample: the controller's part of the
  // command was zero (supervision.zero_command_while_stale). Runs of them, and the longest run in ticks.
  std::uint64_t sensor_hold_ticks{0};
  std::uint64_t sensor_holds{0};
  std::uint64_t longest_sensor_hold_ticks{0};
  std::uint64_t saturated_ticks{0};
  std::uint64_t arm_refused{0};
  std::uint64_t gain_refused{0};
  std::uint64_t params_refused{0};
  std::uint64_t params_selected{0};
  std::uint64_t spindle_refused{0};  // set_spindle commands refused (the notches parked)
  std::uint64_t pose_out_of_map{0};  // set_pose_region -1: the pose outside every region, or unknown
  std::uint64_t pose_regions{0};     // set_pose_region with a region's set
  // controller.speed_schedule: hand-overs to another band's set as the spindle moved, and those refused (K
  // then held at 0 there).
  std::uint64_t speed_handovers{0};
  std::uint64_t speed_handovers_refused{0};
  std::uint64_t commands{0};
  // Recovery (supervision.recovery): re-armed after a recoverable trip; latched because the budget of
  // max_recoveries within window_s was spent, or because a recovery tripped again within probation_s.
  std::uint64_t recoveries{0};
  std::uint64_t budget_latches{0};
  std::uint64_t probation_latches{0};
  // Keeping damping through chatter (supervision.derate, the spindle turning): growth probes (the gain lowered
  // to probe_factor), their verdicts (the process's growth: full gain again; fed by the gain: held lowered;
  // the same speed's gain feeding a growth twice trips instability), saturation derates (instead of the
  // saturation trip), restores to full gain once quiet, and the ticks active with the command derated.
  std::uint64_t derate_probes{0};
  std::uint64_t growth_process{0};
  std::uint64_t growth_gain_fed{0};
  std::uint64_t saturation_derates{0};
  std::uint64_t derate_restores{0};
  std::uint64_t derated_ticks{0};
};

// SupervisorCounters' JSON keys (the run summary's "supervisor" object) and their words in text.
[[nodiscard]] constexpr auto field_list(fields::Tag<SupervisorCounters>) {
  using S = SupervisorCounters;
  using fields::Field;
  return std::tuple{
      fields::NamedCounts<S, kTripCount>{"trips", &S::trips,
                                         +[](std::size_t i) { return trip_name(static_cast<Trip>(i)); }},
      Field<S, std::uint64_t>{"ticks", &S::ticks, "ticks"},
      Field<S, std::uint64_t>{"stale_ticks", &S::stale_ticks, "stale ticks"},
      Field<S, std::uint64_t>{"invalid_samples", &S::invalid_samples, "invalid samples"},
      Field<S, std::uint64_t>{"overruns", &S::overruns, "overruns"},
      Field<S, std::uint64_t>{"overrun_runs_ridden", &S::overrun_runs_ridden, "overrun runs ridden through"},
      Field<S, std::uint64_t>{"sensor_hold_ticks", &S::sensor_hold_ticks, "ticks on a held sample"},
      Field<S, std::uint64_t>{"sensor_holds", &S::sensor_holds, "runs on a held sample"},
      Field<S, std::uint64_t>{"longest_sensor_hold_ticks", &S::longest_sensor_hold_ticks, "ticks the longest"},
      Field<S, std::uint64_t>{"saturated_ticks", &S::saturated_ticks, "saturated ticks"},
      Field<S, std::uint64_t>{"arm_refused", &S::arm_refused, "arms refused"},
      Field<S, std::uint64_t>{"gain_refused", &S::gain_refused, "gains refused"},
      Field<S, std::uint64_t>{"params_refused", &S::params_refused, "parameter sets refused"},
      Field<S, std::uint64_t>{"params_selected", &S::params_selected, "parameter sets selected"},
      Field<S, std::uint64_t>{"spindle_refused", &S::spindle_refused, "spindle speeds refused"},
      Field<S, std::uint64_t>{"pose_out_of_map", &S::pose_out_of_map, "poses out of the map"},
      Field<S, std::uint64_t>{"pose_regions", &S::pose_regions, "pose regions"},
      Field<S, std::uint64_t>{"speed_handovers", &S::speed_handovers, "speed hand-overs"},
      Field<S, std::uint64_t>{"speed_handovers_refused", &S::speed_handovers_refused, "speed hand-overs refused"},
      Field<S, std::uint64_t>{"commands", &S::commands, "operator commands"},
      Field<S, std::uint64_t>{"recoveries", &S::recoveries, "recoveries"},
      Field<S, std::uint64_t>{"budget_latches", &S::budget_latches, "latched by the budget"},
      Field<S, std::uint64_t>{"probation_latches", &S::probation_latches, "latched by the probation"},
      Field<S, std::uint64_t>{"derate/probes", &S::derate_probes, "growth probes"},
      Field<S, std::uint64_t>{"derate/growth_process", &S::growth_process, "the process's growth"},
      Field<S, std::uint64_t>{"derate/growth_gain_fed", &S::growth_gain_fed, "fed by the gain"},
      Field<S, std::uint64_t>{"derate/saturation_derates", &S::saturation_derates, "saturation derates"},
      Field<S, std::uint64_t>{"derate/restores", &S::derate_restores, "back to full gain"},
      Field<S, std::uint64_t>{"derate/derated_ticks", &S::derated_ticks, "ticks derated"}};
}
static_assert(fields::lists_every_member<SupervisorCounters>(), "each counter in SupervisorCounters' field list");

// What the supervisor did about faults, with its time (the supervisor's clock: the sum of the measured
// dt since the start), in a fixed log of the first kEventLogSize events.
// kProbe .. kRestored: the derating (supervision.derate); their trip is the one they stand in for.
enum class EventKind : std::uint8_t {
  kTrip,
  kRecovered,
  kLatched,
  kProbe,
  kProcessGrowth,
  kGainFedGrowth,
  kSaturationDerate,
  kRestored
};
struct SupervisorEvent {
  double time_s{0.0};
  EventKind kind{EventKind::kTrip};
  Trip trip{Trip::kNone};  // the trip, or the trip recovered from or latched
};
inline constexpr std::size_t kEventLogSize = 64;
[[nodiscard]] const char* to_string(EventKind k);

// SupervisorSettings (what the supervisor needs beyond the controller's parameters; a recording stores it):
// rt_settings/rt_settings.hpp; config::supervisor_settings fills it from a configuration.

// A controller parameter set with the analysis verdict for it (e.g. the horizontal and the vertical
// mounting's chains). Set 0 is the one the supervisor starts with.
struct ParameterSet {
  control::ControllerParams params;
  bool analysis_stable{false};
  double max_stable_gain_ns_per_m{0.0};
  double delay_margin_s{0.0};  // at its gain; 0: none known (the overrun trip is overrun_cycles alone)
};

class Supervisor {
 public:
  Supervisor(const SupervisorSettings& s, const control::ControllerParams& params);
  // Before activation (allocates): another set select_params may hand over to. Returns its index.
  std::size_t add_parameter_set(const ParameterSet& set);
  [[nodiscard]] const std::vector<ParameterSet>& parameter_sets() const noexcept { return sets_; }
  // What a gain request may ask for now: max_gain_fraction x the active set's analysed K_max (any thread).
  [[nodiscard]] double gain_limit_ns_per_m() const noexcept { return max_gain_ns_per_m(); }
  // Safe to read from any thread (relaxed atomic; DDS status and parameter requests read it).
  [[nodiscard]] std::size_t active_parameter_set() const noexcept {
    return active_set_.load(std::memory_order_relaxed);
  }
  // The set whose chain acts now: during a hand-over the outgoing one (fading out, then at K = 0 while the
  // incoming chain warms up) until the swap; the live limits are for this chain at the K it runs (any thread).
  [[nodiscard]] std::size_t running_parameter_set() const noexcept {
    return running_set_.load(std::memory_order_relaxed);
  }

  // RT-safe.
  [[nodiscard]] TickOutput step(const TickInput& in) noexcept;

  [[nodiscard]] State state() const noexcept { return state_; }
  // The state and latched trip after the last step, from any thread (relaxed atomics): for watchers such
  // as the tests, the operator's view and the run's end; the loop thread uses state().
  [[nodiscard]] State observed_state() const noexcept { return observed_state_.load(std::memory_order_relaxed); }
  [[nodiscard]] Trip observed_trip() const noexcept { return observed_trip_.load(std::memory_order_relaxed); }
  [[nodiscard]] Trip latched_trip() const noexcept { return trip_; }
  [[nodiscard]] ArmRefusal last_arm_refusal() const noexcept { return refusal_; }
  [[nodiscard]] const SupervisorCounters& counters() const noexcept { return counters_; }
  // The fault events so far (the first kEventLogSize; events_total() counts them all).
  [[nodiscard]] const SupervisorEvent* events() const noexcept { return events_.data(); }
  [[nodiscard]] std::size_t events_logged() const noexcept { return std::min(events_total_, kEventLogSize); }
  [[nodiscard]] std::uint64_t events_total() const noexcept { return events_total_; }
  // The latched trip will not recover by itself (an operator must reset it).
  [[nodiscard]] bool latched() const noexcept { return state_ == State::kFault && latched_; }
  [[nodiscard]] const control::Controller& controller() const noexcept { return controller_; }
  [[nodiscard]] const SupervisorSettings& settings() const noexcept { return s_; }
  [[nodiscard]] const control::ControllerParams& initial_params() const noexcept { return sets_.front().params; }
  // The trip ramp is over and the amplifier disabled.
  [[nodiscard]] bool safe() const noexcept {
    return state_ == State::kDisabled || (state_ == State::kFault && trip_ramp_left_s_ <= 0.0);
  }

 private:
  void handle(const OperatorCommand& c, bool live) noexcept;
  void trip(Trip t) noexcept;
  [[nodiscard]] Trip check_trips(const TickInput& in) const noexcept;
  bool record_saturation(bool saturated) noexcept;                // true: duty exceeded
  bool instability(double growth_v, double accel_mps2) noexcept;  // true: growing oscillation (trip)
  // The derating (rt/derating.cpp): the growth's verdict with the spindle turning (true: trip), the return
  // to full gain once quiet, a saturation derate (false: none left, trip), the factor to the controller.
  enum class Growth : std::uint8_t { kNone, kProbe, kGainFed };
  [[nodiscard]] bool derating_on() const noexcept;
  bool judge_growth(double rms, double accel_rms, bool grown) noexcept;
  void process_growth() noexcept;
  void restore_when_quiet() noexcept;
  bool derate_saturation() noexcept;
  bool saturated_while_turning() noexcept;
  void start_probe(double rms, double accel_rms, bool saturation) noexcept;
  void apply_derate(double ramp_s) noexcept;
  void reset_derate() noexcept;
  [[nodiscard]] double growth_signal_v(double controller_v) const noexcept;
  void reset_detectors() noexcept;
  void count_hold(bool held) noexcept;  // a tick driving on a held (zero) controller part, or not
  // step()'s stages, in order (RT-safe, noexcept, allocation-free).
  struct ControlStep {
    double controller_v{0.0};  // the controller's output this tick
    double driving_v{0.0};     // what may drive the actuator (0 while a bad sample is held)
    bool limited{false};       // the controller's force, voltage or slew limit acted this tick
    bool hold{false};          // a stale or invalid sample: the controller's part is held at zero
  };
  [[nodiscard]] bool assess_sample(const TickInput& in) noexcept;  // true: a finite sample in range
  [[nodiscard]] ControlStep run_controller(const TickInput& in, bool valid) noexcept;
  void drive(const TickInput& in, const ControlStep& c, TickOutput& out) noexcept;
  void ramp_down_fault(const TickInput& in, TickOutput& out) noexcept;

  [[nodiscard]] double max_gain_ns_per_m() const noexcept {
    return s_.limits.max_gain_fraction * sets_[active_parameter_set()].max_stable_gain_ns_per_m;
  }
  // The parameter set at index value: validated (its analysis, its gain) and handed over. False when refused.
  bool select(double value, bool fade_first = false) noexcept;
  void set_pose_region(double value) noexcept;
  [[nodiscard]] bool set_index_ok(double i) const noexcept {
    return std::isfinite(i) && i >= 0.0 && i == std::floor(i) && i < static_cast<double>(sets_.size());
  }
  [[nodiscard]] bool driving() const noexcept {
    return state_ == State::kArming || state_ == State::kActive || state_ == State::kStopping;
  }
  void follow_pose() noexcept;   // each tick: hand over to the pose's region's set once the controller can
  void follow_speed() noexcept;  // each tick: hand over to the spindle speed's band's set once the controller can
  [[nodiscard]] ArmRefusal arm_refusal(bool live) const noexcept;  // why arming would be refused now
  void recover(const TickInput& in) noexcept;                      // in Fault after the ramp: recover when allowed
  void log_event(EventKind k, Trip t) noexcept;

  SupervisorSettings s_;
  std::vector<ParameterSet> sets_;  // [0]: the set it starts with
  std::atomic<std::size_t> active_set_{0};
  std::atomic<std::size_t> running_set_{0};
  std::atomic<State> observed_state_{State::kDisabled};
  std::atomic<Trip> observed_trip_{Trip::kNone};
  control::Controller controller_;
  State state_{State::kDisabled};
  Trip trip_{Trip::kNone};
  ArmRefusal refusal_{ArmRefusal::kNone};
  SupervisorCounters counters_{};

  double last_valid_mps2_{0.0};
  // How long a run of overruns may last (measured time) before it trips: the share of the active set's
  // delay margin. Arithmetic only (RT-safe).
  [[nodiscard]] double overrun_tolerance_s() const noexcept {
    return s_.limits.overrun_delay_margin_share * sets_[active_parameter_set()].delay_margin_s;
  }
  std::uint64_t stale_run_{0}, invalid_run_{0}, live_run_{0}, overrun_run_{0};
  std::uint64_t hold_run_{0};  // consecutive ticks driving with the controller's part held at zero
  bool hold_now_{false};       // this tick's sample is stale or invalid (zero_command_while_stale)
  double overrun_run_s_{0.0};  // the measured time the current run of overruns has lasted
  bool path_ok_{true};
  double fade_{0.0};      // 0..1, activation / disarm
  double arming_s_{0.0};  // time spent arming
  double trip_from_v_{0.0}, trip_ramp_left_s_{0.0};
  double command_v_{0.0};
  double time_s_{0.0};  // sum of dt so far: the events' and the probation's clock
  control::ControllerCounters last_limits_{};
  bool pose_known_{false};
  std::size_t pose_set_{0};           // the set the pose's region wants (pose_scheduled)
  std::size_t speed_refused_set_{1};  // the speed schedule's set last refused (sets_.size(): none)

  // Recovery: which trips may recover (bit per Trip), whether this fault may, its timers, the probation
  // after the last recovery and the recoveries' times (a ring of max_recoveries, allocated at construction).
  std::uint32_t recoverable_mask_{0};
  bool latched_{true};
  double fault_safe_s_{0.0}, healthy_s_{0.0};
  double probation_until_s_{-1.0};
  std::vector<double> recovery_times_;
  std::size_t recovery_pos_{0};
  std::array<SupervisorEvent, kEventLogSize> events_{};
  std::size_t events_total_{0};

  std::vector<std::uint8_t> sat_window_;  // one entry per tick of the window
  std::size_t sat_pos_{0};
  std::uint64_t sat_count_{0};
  std::uint64_t sat_threshold_{0};

  std::uint64_t block_ticks_{0}, block_len_{1};
  double block_sum_sq_{0.0};
  double last_block_rms_{0.0}, run_start_rms_{0.0};
  double last_accel_rms_{0.0};          // the acceleration's RMS over the last block
  std::uint64_t blocks_since_jump_{0};  // blocks since the last blow or a cut's entry (spindle turning)
  int growth_run_{0};
  // The last blocks' RMS (newest at block_history_pos_ - 1), to tell a growth from a build-up or a beat
  // (instability()).
  static constexpr std::size_t kBlockHistory = 64;
  std::array<double, kBlockHistory> block_history_{};
  std::size_t block_history_pos_{0};
  [[nodiscard]] double history_back(std::size_t k) const noexcept {  // the block RMS k blocks before the newest
    return block_history_[(block_history_pos_ + kBlockHistory - 1 - k) % kBlockHistory];
  }
  [[nodiscard]] bool building_up() const noexcept;
  [[nodiscard]] bool in_scheduled_band() const noexcept;  // the spindle inside a band of a speed schedule
  [[nodiscard]] bool beating() const noexcept;

  Growth growth_{Growth::kNone};
  bool process_{false};    // a growth judged the process's since the last quiet spell
  double probe_rms_{0.0};  // the block's RMS (and the acceleration's) when the probe started
  double probe_accel_rms_{0.0};
  struct ProbeTrend {
    double slope{0.0};  // ln RMS per block
    double end{0.0};    // the line's RMS at the newest block
  };
  struct ProbeFit {  // the least-squares line through (block, ln RMS) of a probe's blocks
    double n{0.0}, sx{0.0}, sy{0.0}, sxx{0.0}, sxy{0.0};
    ProbeTrend add(double rms) noexcept;
  };
  ProbeFit probe_fit_;
  bool probe_saturation_{false};  // the probe started at a saturation, not a growth
  double block_accel_sum_sq_{0.0};
  int probe_blocks_{0};            // blocks since
  double saturation_derate_{1.0};  // the product of the saturation derates since the last restore
  std::uint64_t quiet_blocks_{0};
  double gain_fed_rpm_{-1.0};  // the speed the gain last fed a growth at (-1: none)
};

}  // namespace robodamp::rt
