// `robodamp plant`: the HIL plant emulator (hil/plant_emulator.hpp) as a process of its own: the
// simulated plant behind CAN frames and Modbus registers, for `robodamp run` to control.
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "apps/cli.hpp"
#include "hil/plant_emulator.hpp"
#include "hil/program_text.hpp"
#include "rt/signals.hpp"

namespace robodamp::apps {

namespace {

struct PlantArgs {
  std::string config_path{default_cell_config()};
  std::string pacing, cut_model{"regenerative"};
  JsonOut json;
  bool drives_off{false};
  std::optional<double> cut_at_s;
  hil::EmulatorOptions eo;
  hil::ProgramText program;
};

// 0 served a controller to the end; 2 configuration or option error; 1 could not set up or the impact
// schedule did not complete.
int run_plant(const PlantArgs& a) {
  config::Config cfg = config::load_config_file(a.config_path);
  if (a.drives_off) cfg.disturbances.drives_on = false;
  hil::EmulatorOptions eo = a.eo;
  if (!a.pacing.empty())
    eo.pacing = a.pacing == "lockstep" ? config::HilPacing::kLockstep : config::HilPacing::kRealtime;
  if (std::string e; !hil::apply_program(a.program, eo, e)) {
    std::cerr << "robodamp plant: " << e << '\n';
    return 2;
  }
  eo.cut_model =
      a.cut_model == "forced" ? hil::EmulatorOptions::CutModel::kForced : hil::EmulatorOptions::CutModel::kRegenerative;
  eo.regenerative.start_s = a.cut_at_s.value_or(-1.0);
  rt::install_shutdown_handlers();
  eo.stop_flag = &rt::shutdown_signal();
  const hil::EmulatorReport r = hil::run_emulator(cfg, eo);
  std::cout << hil::report_text(r);
  if (!emit_json(a.json, hil::report_json(r).dump(2), "plant")) return 1;
  return r.records_planned > 0 && !r.campaign_complete ? 1 : 0;
}

}  // namespace

void register_plant(Registry& r) {
  auto a = std::make_shared<PlantArgs>();
  CLI::App* sub = r.add("plant",
                        "HIL plant emulator: the simulated plant behind CAN frames and Modbus registers, "
                        "in its own process, for `robodamp run` to control",
                        [a] { return run_plant(*a); });
  sub->add_option("--config", a->config_path, "Configuration file (YAML) with can, modbus and hil sections")
      ->check(CLI::ExistingFile);
  sub->add_option("--pacing", a->pacing,
                  "Override hil.pacing: realtime (true HIL) or lockstep (one step per command frame)")
      ->check(CLI::IsMember({"realtime", "lockstep"}));
  r.number(sub, "--duration", a->eo.max_duration_s,
           {"s", 0.0, 604800.0, false, false, "0 = when the controller leaves"}, "Stop after this much plant time");
  r.json(sub, a->json, "The report (frames, timing, measured FRFs)");
  sub->add_flag("!--no-impacts", a->eo.impacts, "Do not run the impact schedule");
  sub->add_option(
      "--measure-out", a->eo.measure_out,
      "The plant side of robodamp measure: the commissioning impacts at every location, FRFs written here; with "
      "--pose-at, at each dwell from its start on a stopped measurement's times, into DIR/dwell_<k> (measure "
      "--along-path)");
  r.whole_number(sub, "--impact-location", a->eo.impact_location,
                 {"(location id)", 0, 1000, false, false, "0 = the first FRF's excitation"},
                 "Location id the hammer hits");
  r.number(sub, "--bus-off-at", a->eo.bus_off_at_s, {"s", 0.0, 604800.0},
           "Fault injection: the CAN bus goes off at this plant time (error frame, no sensor frames, then a restart)");
  r.number(sub, "--bus-off-for", a->eo.bus_off_for_s, {"s", 0.001, 3600.0}, "How long the bus stays off");
  r.number(sub, "--modbus-hang-at", a->eo.modbus_hang_at_s, {"s", 0.0, 604800.0},
           "Fault injection: the Modbus device stops answering at this plant time");
  sub->add_option("--mounting", a->program.mounting,
                  "Robot mounting register changes, TIME_S:horizontal|vertical (plant time), repeatable");
  sub->add_option("--spindle-ramp", a->program.spindle_ramps,
                  "A linear spindle ramp T0_S:T1_S:RPM (plant time; from the speed at T0 to RPM at T1), repeatable");
  sub->add_option("--depth", a->program.depth,
                  "The robot program's axial depth steps for the regenerative cut, TIME_S:MM (plant time), repeatable; "
                  "published on modbus.robot.depth_register");
  sub->add_option("--depth-ramp", a->program.depth_ramps,
                  "A linear depth ramp of the regenerative cut T0_S:T1_S:MM (plant time), repeatable");
  r.number(sub, "--spindle-register-period", a->eo.spindle_register_period_s, {"s", 0.0, 10.0},
           "How often the robot updates its spindle register during a ramp (plant time)");
  sub->add_option("--cut", a->eo.cut_job,
                  "Milling job (config/milling/*.yaml) cut against the robot at its controller part's location")
      ->check(CLI::ExistingFile);
  sub->add_option(
         "--cut-model", a->cut_model,
         "regenerative (default): the time-domain cut with surface memory, which can chatter, at --cut-rpm and "
         "--cut-axial-mm then the --spindle / --depth program (and the advice with spindle.apply_advice); "
         "forced: the rigid tool's force harmonics at the --spindle / --spindle-ramp speed")
      ->check(CLI::IsMember({"regenerative", "forced"}));
  r.number(sub, "--cut-rpm", a->eo.regenerative.rpm, {"rpm", 0.0, 200000.0, true},
           "The regenerative cut's spindle speed (default: the job's)");
  r.number(sub, "--cut-axial-mm", a->eo.regenerative.axial_mm, {"mm", 0.0, 100.0, true},
           "The regenerative cut's axial depth (default: the job's)");
  r.whole_number(sub, "--cut-revs", a->eo.regenerative.revolutions, {"(revolutions)", 2, 100000},
                 "Revolutions of the regenerative cut (default: the job's, at least 300)");
  sub->add_flag("--drives-off", a->drives_off,
                "The robot's drive vibration off for this run (disturbances.drives_on), as the in-process cut has it");
  r.number(
      sub, "--cut-until", a->eo.regenerative.until_s, {"s", 0.0, 604800.0, false, false, "0 = no bound"},
      "The regenerative cut goes on at least until this plant time (the robot's path), then until its last speed and "
      "depth have had --cut-revs revolutions");
  sub->add_flag("--cut-until-advice", a->eo.regenerative.until_advice,
                "The robot program waits for robodamp's word: the regenerative cut goes on until the robot has read a "
                "spindle-speed advice (modbus.robot.advice_register), then --cut-revs at the speed it ends at");
  r.number(sub, "--cut-at", a->cut_at_s, {"s", 0.0, 604800.0},
           "Plant time the regenerative cut starts (default: hil.settle_s + controller.gain_ramp_s after the amplifier "
           "is ready)");
  sub->add_option(
      "--pose-at", a->program.pose_at,
      "The robot's pose trajectory, a waypoint TIME_S:Q1,Q2,... (plant time, joint angles in deg; linear between "
      "waypoints; two with the same pose make a dwell, measured by impacts), repeatable; needs pose_schedule");
  r.number(sub, "--pose-register-period", a->eo.pose_register_period_s, {"s", 0.0, 10.0},
           "How often the robot updates its joint registers (plant time)");
  r.number(sub, "--pose-update", a->eo.pose_update_s, {"s", 0.0002, 10.0},
           "How often the plant's modes follow the pose (plant time)");
  sub->add_option("--spindle", a->program.spindle,
                  "Robot spindle speed changes, TIME_S:RPM (plant time; modbus.robot.spindle_rpm_register; with the "
                  "regenerative cut the cut's speed too, within spindle.rpm_max), repeatable");
}

}  // namespace robodamp::apps
