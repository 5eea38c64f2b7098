// Finding the robot's stops along its path from the joints it reports (commission/path_measurement.hpp,
// docs/pose_dynamics.md "Measuring along the path"): when the joints have stood within still_deg for
// commissioning.settle_s and the cell is at rest, the loop's chirp starts. Fed one telemetry frame at a time
// on the drain thread; the cell it reads and commands is behind DwellCell, so a test can drive it with frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/modal_test.hpp"
#include "commission/path_measurement.hpp"
#include "config/config.hpp"
#include "rt/supervisor.hpp"
#include "rt/telemetry_frame.hpp"

namespace robodamp::commission {

// What the watch needs of the running cell (runtime::Cell in the product).
class DwellCell {
 public:
  virtual ~DwellCell() = default;
  [[nodiscard]] virtual std::vector<double> robot_pose_deg() const = 0;  // empty: not known
  [[nodiscard]] virtual bool post(const rt::OperatorCommand& c) = 0;     // false: the queue is full
  virtual void request_stop() noexcept = 0;
};

[[nodiscard]] int measured_stops(const std::vector<DwellMeasurement>& dwells);

// Finds the robot's stops, starts the chirp at each, watches it, and stops the run once enough dwells are
// measured or the chirp saturates. A stillness shorter than settle_s that ends with a move is a pause, not a
// stop: it takes no dwell number (the plant side numbers only stops that last a whole plan).
class DwellWatch {
 public:
  DwellWatch(const config::Config& cfg, const analysis::CommissioningPlan& plan, const PathMeasureOptions& o);
  void attach(DwellCell* cell) { cell_ = cell; }
  [[nodiscard]] const std::optional<std::pair<MeasureStatus, std::string>>& stopped() const { return stopped_; }
  [[nodiscard]] const std::vector<DwellMeasurement>& dwells() const { return dwells_; }
  [[nodiscard]] int pauses() const { return pauses_; }
  void on_frame(const rt::TelemetryFrame& f);

 private:
  enum class Phase { kMoving, kStill, kStartPosted, kChirping, kHolding, kDone };

  void stop(MeasureStatus s, std::string why);
  void watch_rest(const rt::TelemetryFrame& f);
  [[nodiscard]] double rest_rms_mps2() const;
  void watch_chirp(const rt::TelemetryFrame& f);
  [[nodiscard]] bool moved(const std::vector<double>& q) const;
  void skip(const std::string& why);
  void on_move(double t_s);
  void step(const rt::TelemetryFrame& f);
  void start_chirp(const rt::TelemetryFrame& f);
  void accumulate_pose();

  analysis::CommissioningPlan plan_;
  PathMeasureOptions o_;
  double settle_s_, rest_limit_, chirp_s_, fs_hz_;
  DwellCell* cell_{nullptr};
  std::optional<std::pair<MeasureStatus, std::string>> stopped_;
  std::vector<DwellMeasurement> dwells_;
  Phase phase_{Phase::kMoving};
  std::vector<double> ref_;
  double still_since_s_{0.0}, next_poll_s_{0.0};
  std::uint32_t saturated0_{0};
  std::vector<double> rest_sq_;
  std::size_t rest_at_{0}, rest_n_{0}, pose_n_{0};
  double rest_sum_{0.0};
  int pauses_{0};
};

}  // namespace robodamp::commission
