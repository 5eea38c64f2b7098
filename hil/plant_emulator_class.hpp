// The plant emulator behind run_emulator (hil/plant_emulator.hpp): a class internal to robodamp_hil.
#pragma once

#include <linux/can.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "analysis/bench_run.hpp"
#include "analysis/modal_test.hpp"
#include "drivers/can_channel.hpp"
#include "hil/cutting_load.hpp"
#include "hil/emulator_registers.hpp"
#include "hil/plant_emulator.hpp"
#include "hil/pose_trajectory.hpp"
#include "hil/regenerative_cut.hpp"
#include "rt/realtime.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"

namespace robodamp::hil::detail {

using Clock = std::chrono::steady_clock;

const config::CanConfig& can_section(const config::Config& cfg);
// The emulated plant with the configuration's drive vibration (the closed loop's and the open-loop reference's).
sim::Plant make_plant(const config::Config& cfg, const sim::PlantModel& model);

// The simulated plant as the DAQ node and the amplifier on CAN, the amplifier and the robot on Modbus:
// built from the configuration and the options (the plant, the cut, the registers), connected to one
// controller, stepped once per received command (lockstep) or per period of the wall clock (realtime),
// then reported. Not copyable: the cut and the campaigns hold references to the plant.
class PlantEmulator {
 public:
  PlantEmulator(const config::Config& cfg, const EmulatorOptions& o);
  PlantEmulator(const PlantEmulator&) = delete;
  PlantEmulator& operator=(const PlantEmulator&) = delete;

  void connect();
  void run();
  EmulatorReport finish();

 private:
  void setup_cut();
  void setup_campaigns();
  void run_lockstep();
  void run_realtime();
  [[nodiscard]] bool stopping() const { return o_.stop_flag != nullptr && o_.stop_flag->load() != 0; }
  // The controller's side of the bus.
  void send_sensor();
  bool receive_commands(bool& got);  // drains the frames waiting; false when the controller has gone
  // Fault injection (plant time): the bus off for a while, the Modbus device hanging.
  void faults_at(double t);
  void inject(const char* kind, double t);
  void send_error_frame(canid_t flags);
  // One plant period with the amplifier's output, then the amplifier and robot registers.
  void step_plant();
  void move_robot(double t);
  double turn_spindle(double t);
  void read_advice(double t);
  void after_step(std::size_t k, double t);
  void amplifier(std::size_t k, double t);
  void robot_reports(double t);
  void open_loop_reference();
  void check_measure_dwells() const;

  const config::Config& cfg_;
  const EmulatorOptions& o_;
  const config::CanConfig& can_;
  EmulatorReport rep_;
  const config::HilPacing pacing_;
  const double fs_, dt_;
  std::optional<PoseTrajectory> trajectory_;
  const sim::PlantModel model_;
  sim::Plant plant_;
  const int impact_id_;
  const std::size_t impact_index_;
  const analysis::ImpactTest test_;
  std::vector<SpindleChange> changes_;
  std::optional<RegenerativeCut> regenerative_;
  std::optional<CuttingLoad> cutting_;
  EmulatorRegisters regs_;
  std::vector<std::pair<double, sim::PlantModel>> retunes_;  // the structure along the trajectory, built now
  std::size_t next_retune_{0};
  double pose_published_s_{0.0};
  std::optional<drivers::CanListener> listener_;
  std::optional<drivers::CanChannel> channel_;
  rt::RealtimeStatus rts_;
  std::optional<rt::RealtimeProcess> rt_process_;
  std::optional<analysis::ImpactCampaign> campaign_;
  // --measure-out: one commissioning test, or one per dwell of the trajectory (into measure_out/dwell_<k>).
  std::vector<std::pair<std::string, std::unique_ptr<analysis::ModalTest>>> modal_tests_;
  std::optional<DwellCampaigns> dwell_campaigns_;
  // The run.
  double published_rpm_{-1.0}, published_at_s_{-1.0};
  std::uint32_t sensor_counter_{0}, last_cmd_counter_{0};
  bool have_cmd_counter_{false};
  double command_v_{0.0};  // newest command received
  double applied_v_{0.0};  // what the amplifier drives this period with
  bool enabled_{false}, ready_{false};
  double enabled_at_s_{0.0}, ms_v_{0.0}, temperature_c_;
  std::size_t next_mounting_{0}, next_spindle_{0};
  std::uint64_t max_ticks_{UINT64_MAX};
  Clock::time_point wall0_{};
  double bus_off_until_s_{-1.0};
  bool bus_off_done_{false}, hang_done_{false};
  double published_depth_mm_{-1.0}, advice_polled_s_{-1.0};
  bool cut_end_logged_{false};
  unsigned advice_seq_{0};
};

}  // namespace robodamp::hil::detail
