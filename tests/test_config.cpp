// Configuration: presets load, and every error path names file, line, key, value, unit and range.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "modal/receptance.hpp"
#include "config/config.hpp"
#include "config/yaml_edit.hpp"
#include "analysis/chain_design.hpp"
#include "test_util.hpp"

namespace robodamp::config {
namespace {

const char* kValid = R"(loop:
  rate_hz: 5000
actuator:
  mounting: horizontal
  constant_n_per_v: 4.8
  natural_freq_hz: 9.0
  damping_ratio: 0.15
  delay_s: 0.0006
  force_limit_n: 36
amplifier:
  voltage_limit_v: 10
  slew_rate_v_per_s: 20000
controller:
  gain_ns_per_m: 2000
  polarity: 1
  match_freq_hz: 9.2
  chain:
    - {kind: lowpass2, cutoff_hz: 50, damping_ratio: 0.707}
    - {kind: integrator}
    - {kind: highpass2, cutoff_hz: 4}
    - {kind: notch, center_hz: 3, bandwidth_hz: 4}
    - {kind: compensator, model: c2}
)";

// Replaces the first occurrence of `from` in the valid file.
std::string edited(const std::string& from, const std::string& to) {
  std::string s = kValid;
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

std::vector<Problem> problems_of(const std::string& yaml) {
  try {
    (void)analysis::design_chain(parse_config(yaml, "bad.yaml"));
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

std::string only_problem(const std::string& yaml) {
  const auto p = problems_of(yaml);
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  EXPECT_EQ(p.size(), 1U) << all;
  return all;
}

TEST(Config, AllPresetsLoadAndDesign) {
  for (const char* name : {"horizontal_c2", "horizontal_c1", "horizontal_c3", "vertical_c1"}) {
    SCOPED_TRACE(name);
    const Config c = load_config_file(test::preset(name));
    EXPECT_EQ(c.loop.rate_hz, 5000.0);
    EXPECT_EQ(c.controller.gain_ns_per_m, 2000.0);
    EXPECT_EQ(c.actuator.force_limit_n, 36.0);
    EXPECT_EQ(c.actuator.constant_n_per_v, 4.8);
    ASSERT_EQ(c.robot.frfs.size(), 3U);
    EXPECT_EQ(c.robot.frfs[0].modes.size(), 3U);
    EXPECT_DOUBLE_EQ(c.robot.frfs[0].modes[0].residue_im_m_per_n, -3.63e-5);
    EXPECT_DOUBLE_EQ(c.robot.frfs[2].modes[0].residue_im_m_per_n, 4.06e-5);  // H22 = H21 (Table 1)
    EXPECT_NEAR(*modal::dominant_mode_hz(c.robot), 9.2, 1e-12);
    const auto d = analysis::design_chain(c);
    EXPECT_EQ(d.match_freq_hz, 9.2);
  }
  EXPECT_EQ(load_config_file(test::preset("vertical_c1")).actuator.natural_freq_hz, 14.0);
  EXPECT_EQ(load_config_file(test::preset("horizontal_c1")).controller.polarity, -1);
}

TEST(Config, ValidMinimalFileParses) {
  EXPECT_TRUE(problems_of(kValid).empty());
  const Config c = parse_config(kValid, "x.yaml");
  EXPECT_EQ(c.controller.chain.size(), 5U);
  EXPECT_EQ(c.controller.chain[2].damping_ratio, 0.707);  // documented default
  EXPECT_EQ(c.controller.gain_ramp_s, 0.5);
  EXPECT_EQ(c.controller.chain[4].name, "compensator");
}

TEST(Config, OutOfRangeNamesFileLineKeyValueUnitAndRange) {
  const std::string m = only_problem(edited("cutoff_hz: 50", "cutoff_hz: 3000"));
  EXPECT_NE(m.find("bad.yaml:18:"), std::string::npos) << m;
  EXPECT_NE(m.find("controller.chain[0].cutoff_hz"), std::string::npos) << m;
  EXPECT_NE(m.find("= 3000 Hz"), std::string::npos) << m;
  EXPECT_NE(m.find("allowed 0 < value < 2500 Hz"), std::string::npos) << m;
  EXPECT_NE(m.find("Nyquist"), std::string::npos) << m;
}

TEST(Config, CutoffExactlyAtNyquistIsRejected) {
  EXPECT_NE(only_problem(edited("cutoff_hz: 50", "cutoff_hz: 2500")).find("out of range"), std::string::npos);
}

TEST(Config, EveryNumericKeyIsRangeChecked) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"rate_hz: 5000", "rate_hz: 500"},
      {"rate_hz: 5000", "rate_hz: 25000"},
      {"constant_n_per_v: 4.8", "constant_n_per_v: 0"},
      {"natural_freq_hz: 9.0", "natural_freq_hz: -9"},
      {"damping_ratio: 0.15", "damping_ratio: 0"},
      {"delay_s: 0.0006", "delay_s: -0.001"},
      {"force_limit_n: 36", "force_limit_n: 0"},
      {"voltage_limit_v: 10", "voltage_limit_v: 0"},
      {"slew_rate_v_per_s: 20000", "slew_rate_v_per_s: -1"},
      {"gain_ns_per_m: 2000", "gain_ns_per_m: -5"},
      {"match_freq_hz: 9.2", "match_freq_hz: 2600"},
      {"damping_ratio: 0.707}", "damping_ratio: 0}"},
      {"center_hz: 3", "center_hz: 0"},
      {"bandwidth_hz: 4", "bandwidth_hz: 0"},
      {"{kind: integrator}", "{kind: integrator, leak_hz: 5}"},
  };
  for (const auto& [from, to] : cases) {
    const std::string m = only_problem(edited(from, to));
    EXPECT_NE(m.find("is out of range: allowed"), std::string::npos) << to << "\n" << m;
    EXPECT_NE(m.find("bad.yaml:"), std::string::npos) << m;
  }
}

TEST(Config, NotANumberNamesTheExpectedUnit) {
  const std::string m = only_problem(edited("gain_ns_per_m: 2000", "gain_ns_per_m: lots"));
  EXPECT_NE(m.find("controller.gain_ns_per_m"), std::string::npos) << m;
  EXPECT_NE(m.find("'lots' is not a number (N s/m"), std::string::npos) << m;
  EXPECT_NE(only_problem(edited("gain_ns_per_m: 2000", "gain_ns_per_m: .nan")).find("out of range"), std::string::npos);
  EXPECT_NE(only_problem(edited("gain_ns_per_m: 2000", "gain_ns_per_m: .inf")).find("out of range"), std::string::npos);
}

TEST(Config, UnknownKeysAreErrorsThatListTheAllowedOnes) {
  // A misspelt key next to the real one: the typo is reported, not silently ignored.
  const auto p = problems_of(edited("cutoff_hz: 4}", "cutoff_hz: 4, cutof_hz: 4}"));
  ASSERT_EQ(p.size(), 1U);
  EXPECT_EQ(p[0].key, "controller.chain[2].cutof_hz");
  EXPECT_NE(p[0].message.find("unknown key; allowed here: cutoff_hz, damping_ratio"), std::string::npos)
      << p[0].message;
  EXPECT_EQ(p[0].mark.line, 20);
  const auto top = problems_of(std::string(kValid) + "spindle_rpm: 12000\n");
  ASSERT_EQ(top.size(), 1U);
  EXPECT_EQ(top[0].key, "spindle_rpm");
}

TEST(Config, DuplicateKeysAreErrors) {
  const auto p = problems_of(edited("  rate_hz: 5000\n", "  rate_hz: 5000\n  rate_hz: 10000\n"));
  ASSERT_FALSE(p.empty());
  EXPECT_EQ(p[0].key, "loop.rate_hz");
  EXPECT_NE(p[0].message.find("duplicate"), std::string::npos);
}

TEST(Config, MissingRequiredKeysSayWhatIsExpected) {
  const std::string m = only_problem(edited("  force_limit_n: 36\n", ""));
  EXPECT_NE(m.find("actuator.force_limit_n: missing (required: a number in N"), std::string::npos) << m;
  const auto no_controller = problems_of(std::string(kValid).substr(0, std::string(kValid).find("controller:")));
  ASSERT_EQ(no_controller.size(), 1U);
  EXPECT_EQ(no_controller[0].key, "controller");
}

TEST(Config, ChoicesAndPolarity) {
  EXPECT_NE(only_problem(edited("mounting: horizontal", "mounting: sideways")).find("one of horizontal, vertical"),
            std::string::npos);
  EXPECT_NE(only_problem(edited("polarity: 1", "polarity: 2")).find("+1 or -1"), std::string::npos);
  EXPECT_NE(only_problem(edited("model: c2", "model: c9")).find("one of c1, c2, c3, rational"), std::string::npos);
  EXPECT_NE(only_problem(edited("kind: notch", "kind: comb")).find("'comb' is not allowed"), std::string::npos);
  EXPECT_TRUE(problems_of(edited("polarity: 1", "polarity: -1")).empty());
  EXPECT_TRUE(problems_of(edited("polarity: 1", "polarity: +1")).empty());
}

TEST(Config, ChainStructureIsChecked) {
  // No integrator: not DVF.
  EXPECT_NE(only_problem(edited("    - {kind: integrator}\n", "")).find("exactly one integrator"), std::string::npos);
  // Ideal integrator without a high-pass would wind up on an offset.
  const std::string m = only_problem(edited("    - {kind: highpass2, cutoff_hz: 4}\n", ""));
  EXPECT_NE(m.find("controller.chain[1].leak_hz"), std::string::npos) << m;
  EXPECT_TRUE(
      problems_of(edited("    - {kind: highpass2, cutoff_hz: 4}\n", "")
                      .replace(std::string(kValid).find("{kind: integrator}"), 18, "{kind: integrator, leak_hz: 0.1}"))
          .empty());
  EXPECT_NE(only_problem(edited("{kind: notch,", "{kind: notch, name: lowpass2,")).find("used twice"),
            std::string::npos);
  const auto renamed = problems_of(edited("  chain:\n", "  chain: {}\n  old_chain:\n"));
  ASSERT_EQ(renamed.size(), 2U);
  EXPECT_NE(renamed[0].message.find("non-empty list"), std::string::npos);
  EXPECT_EQ(renamed[1].key, "controller.old_chain");
}

TEST(Config, UnstableOrImproperCompensatorIsADesignErrorAtItsLine) {
  const std::string unstable =
      edited("{kind: compensator, model: c2}",
             "{kind: compensator, model: rational, numerator: [1, 2], denominator: [1, -3, 2]}");
  const std::string m = only_problem(unstable);
  EXPECT_NE(m.find("bad.yaml:22:"), std::string::npos) << m;
  EXPECT_NE(m.find("controller.chain[4]"), std::string::npos) << m;
  EXPECT_NE(m.find("unstable or marginally stable: pole at s = 2"), std::string::npos) << m;
  const std::string improper =
      edited("{kind: compensator, model: c2}",
             "{kind: compensator, model: rational, numerator: [1, 0, 0], denominator: [1, 3]}");
  EXPECT_NE(only_problem(improper).find("improper"), std::string::npos);
  const std::string bad_list = edited("{kind: compensator, model: c2}",
                                      "{kind: compensator, model: rational, numerator: [1, x], denominator: [0, 3]}");
  EXPECT_EQ(problems_of(bad_list).size(), 2U);
}

TEST(Config, CompensatorWithoutMatchFrequencyOrModalData) {
  const std::string m = only_problem(edited("  match_freq_hz: 9.2\n", ""));
  EXPECT_NE(m.find("controller.match_freq_hz"), std::string::npos) << m;
}

TEST(Config, PrewarpAtOrAboveNyquistIsRejected) {
  EXPECT_NE(only_problem(edited("{kind: notch,", "{kind: notch, prewarp_hz: 2500,")).find("prewarp_hz"),
            std::string::npos);
}

TEST(Config, WrongShapesAreReported) {
  EXPECT_NE(only_problem(edited("loop:\n  rate_hz: 5000\n", "loop: [5000]\n")).find("expected a map"),
            std::string::npos);
  const auto syntax = problems_of("loop:\n  rate_hz: [5000\n");
  ASSERT_EQ(syntax.size(), 1U);
  EXPECT_NE(syntax[0].message.find("syntax error"), std::string::npos);
  EXPECT_GT(syntax[0].mark.line, 0);
  EXPECT_NE(problems_of("- just\n- a list\n")[0].message.find("expected a map"), std::string::npos);
}

TEST(Config, AllProblemsAreReportedAtOnce) {
  std::string s = edited("rate_hz: 5000", "rate_hz: 50");
  s.replace(s.find("gain_ns_per_m: 2000"), 19, "gain_ns_per_m: -1");
  s.replace(s.find("mounting: horizontal"), 20, "mounting: upside");
  s += "extra: 1\n";
  const auto p = problems_of(s);
  EXPECT_EQ(p.size(), 4U);
  try {
    (void)parse_config(s, "bad.yaml");
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("4 configuration problem(s)"), std::string::npos);
  }
}

TEST(Config, UnreadableFile) {
  try {
    (void)load_config_file("/nonexistent/robodamp.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robodamp.yaml"), std::string::npos);
  }
}

TEST(Config, RobotModalDataIsValidated) {
  const std::string base = std::string(kValid) + R"(robot:
  frfs:
    - name: H11yy
      response_location: 1
      excitation_location: 1
      modes:
        - {natural_freq_hz: 9.2, damping_ratio: 0.02, residue_re_m_per_n: -2.92e-6, residue_im_m_per_n: -3.63e-5}
    - name: H22yy
      response_location: 2
      excitation_location: 2
      modes:
        - {natural_freq_hz: 9.2, damping_ratio: 0.02, stiffness_n_per_m: 2.0e6}
)";
  EXPECT_TRUE(problems_of(base).empty()) << (problems_of(base).empty() ? "" : problems_of(base).front().to_string());
  auto bad = base;
  bad.replace(bad.find("damping_ratio: 0.02"), 19, "damping_ratio: 1.5");
  const std::string m = only_problem(bad);
  EXPECT_NE(m.find("robot.frfs[0].modes[0].damping_ratio = 1.5"), std::string::npos) << m;
}

TEST(Config, PlantSectionsAreValidated) {
  const std::string preset = test::read_file(test::preset("horizontal_c2"));
  auto with = [&](const std::string& from, const std::string& to) {
    std::string y = preset;
    y.replace(y.find(from), from.size(), to);
    return y;
  };
  auto one = [&](const std::string& yaml) {
    const auto p = problems_of(yaml);
    EXPECT_EQ(p.size(), 1u);
    return p.empty() ? std::string() : p.front().to_string();
  };
  std::string m = one(with("  location: 2\n  sensitivity_mv_per_g", "  location: 7\n  sensitivity_mv_per_g"));
  EXPECT_NE(m.find("sensor.location = 7 is not a robot location (known: 1, 2)"), std::string::npos) << m;
  m = one(with("axis_sign: -1", "axis_sign: 2"));
  EXPECT_NE(m.find("robot.locations[1].axis_sign = '2' is not allowed: +1 or -1"), std::string::npos) << m;
  m = one(with("noise_density_ug_per_rthz: 3 ", "noise_density_ug_per_rthz: -3 "));
  EXPECT_NE(m.find("sensor.noise_density_ug_per_rthz = -3 ug/sqrt(Hz) is out of range"), std::string::npos) << m;
  m = one(with("sweep_gain_factors: [0.5, 0.9, 1.1, 1.5]", "sweep_gain_factors: [0.5, -1]"));
  EXPECT_NE(m.find("bench.sweep_gain_factors[1] = -1 is out of range"), std::string::npos) << m;
  m = one(with("oversampling: 1 ", "oversampling: 2.5 "));
  EXPECT_NE(m.find("plant.oversampling = 2.5 must be a whole number"), std::string::npos) << m;
  m = one(with("band_max_hz: 100", "band_max_hz: 3"));
  EXPECT_NE(m.find("analysis.band_max_hz = 3 Hz must be above analysis.band_min_hz = 5 Hz"), std::string::npos) << m;
  m = one(
      with("{natural_freq_hz: 21.0, damping_ratio: 0.025, residue_re_m_per_n: 2.01e-6, residue_im_m_per_n: -7.85e-6}",
           "{natural_freq_hz: 21.0, damping_ratio: 0.025, residue_re_m_per_n: 2.01e-6, stiffness_n_per_m: 1e6}"));
  EXPECT_NE(m.find("robot.frfs[0].modes[1].residue_re_m_per_n: given together with stiffness_n_per_m"),
            std::string::npos)
      << m;
}

TEST(Config, LoopSupervisionRealtimeAndTelemetryAreValidated) {
  const Config defaults = parse_config(kValid, "ok.yaml");
  EXPECT_EQ(defaults.loop.clock, ClockKind::kWall);
  EXPECT_EQ(defaults.realtime.priority, 80);
  EXPECT_EQ(defaults.supervision.stale_sensor_cycles, 5);
  EXPECT_EQ(defaults.telemetry.ring_frames, 65536);
  EXPECT_NE(defaults.yaml_text.find("rate_hz: 5000"), std::string::npos);

  const Config v = parse_config(edited("  rate_hz: 5000\n", "  rate_hz: 5000\n  clock: virtual\n") +
                                    "realtime: {priority: 0, cpu: 1, lock_memory: false}\n"
                                    "supervision: {trip_ramp_s: 0.02, instability_blocks: 6}\n"
                                    "telemetry: {ring_frames: 4096}\n",
                                "ok.yaml");
  EXPECT_EQ(v.loop.clock, ClockKind::kVirtual);
  EXPECT_EQ(v.realtime.priority, 0);
  EXPECT_EQ(v.realtime.cpu, 1);
  EXPECT_FALSE(v.realtime.lock_memory);
  EXPECT_DOUBLE_EQ(v.supervision.trip_ramp_s, 0.02);
  EXPECT_EQ(v.supervision.instability_blocks, 6);
  EXPECT_EQ(v.telemetry.ring_frames, 4096);

  const auto p = problems_of(edited("  rate_hz: 5000\n", "  rate_hz: 5000\n  clock: sundial\n") +
                             "realtime: {priority: 120, cpu: -2}\n"
                             "supervision: {saturation_duty_max: 0, trip_ramp_s: 2, stale_sensor_cycles: 0.5,"
                             " max_gain_fraction: 1.5}\n"
                             "telemetry: {ring_frames: 5000}\n");
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  EXPECT_EQ(p.size(), 8U) << all;
  for (const char* expected :
       {"loop.clock = 'sundial' is not allowed: one of wall, virtual", "realtime.priority = 120", "realtime.cpu = -2",
        "supervision.saturation_duty_max = 0 (fraction of the window) is out of range",
        "supervision.trip_ramp_s = 2 s is out of range", "supervision.stale_sensor_cycles = 0.5",
        "supervision.max_gain_fraction = 1.5", "telemetry.ring_frames = 5000 must be a power of two"})
    EXPECT_NE(all.find(expected), std::string::npos) << expected << "\n" << all;
}

TEST(Config, RecoveryIsValidatedByKeyWithItsUnitAndRange) {
  const Config defaults = parse_config(kValid, "ok.yaml");
  const auto& d = defaults.supervision.recovery;
  EXPECT_EQ(d.recoverable, (std::vector<rt::Trip>{rt::Trip::kOverruns, rt::Trip::kSensorStale, rt::Trip::kSampleInvalid,
                                                  rt::Trip::kSensorDriver, rt::Trip::kActuatorDriver}));
  EXPECT_EQ(d.max_recoveries, 3);
  const Config v = parse_config(kValid + std::string("supervision:\n  recovery:\n    recoverable: [overruns]\n"
                                                     "    cool_down_s: 0.5\n    max_recoveries: 5\n"),
                                "ok.yaml");
  EXPECT_EQ(v.supervision.recovery.recoverable, std::vector<rt::Trip>{rt::Trip::kOverruns});
  EXPECT_DOUBLE_EQ(v.supervision.recovery.cool_down_s, 0.5);
  EXPECT_EQ(v.supervision.recovery.max_recoveries, 5);
  EXPECT_TRUE(parse_config(kValid + std::string("supervision: {recovery: {recoverable: []}}\n"), "ok.yaml")
                  .supervision.recovery.recoverable.empty());
  const auto p = problems_of(
      kValid + std::string("supervision: {recovery: {recoverable: [instability, overruns, overruns, "
                           "sundial], cool_down_s: -1, max_recoveries: 2.5, window_s: 0, probaton_s: 3}}\n"));
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  EXPECT_EQ(p.size(), 7U) << all;
  for (const char* expected :
       {"supervision.recovery.recoverable[0] = 'instability' cannot recover by itself",
        "recoverable[2] = 'overruns' is listed twice", "recoverable[3] = 'sundial' cannot recover",
        "supervision.recovery.cool_down_s = -1 s is out of range", "supervision.recovery.max_recoveries = 2.5",
        "supervision.recovery.window_s = 0 s is out of range", "supervision.recovery.probaton_s: unknown key"})
    EXPECT_NE(all.find(expected), std::string::npos) << expected << "\n" << all;
  // The overrun trip's ride-through: a share of the delay margin, 0..1.
  EXPECT_DOUBLE_EQ(defaults.supervision.overrun_delay_margin_share, 1.0);
  const auto share = problems_of(kValid + std::string("supervision: {overrun_delay_margin_share: 1.5}\n"));
  ASSERT_EQ(share.size(), 1U);
  EXPECT_NE(
      share.front().to_string().find("supervision.overrun_delay_margin_share = 1.5 (share of the delay margin) is out "
                                     "of range: allowed 0 <= value <= 1"),
      std::string::npos)
      << share.front().to_string();
}

}  // namespace
TEST(Config, TheHilConfigurationLoadsWithEveryHardwareSection) {
  const Config c = load_config_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/hil_horizontal_c2.yaml");
  ASSERT_TRUE(c.can && c.modbus && c.dds);
  EXPECT_EQ(c.can->interface, "unix:/tmp/robodamp-hil.sock");
  EXPECT_EQ(c.modbus->amplifier_link.port, 1502);
  ASSERT_TRUE(c.modbus->robot_link);
  EXPECT_EQ(c.modbus->robot_link->unit_id, 2);
  ASSERT_EQ(c.parameter_sets.size(), 1U);
  EXPECT_EQ(c.parameter_sets[0].mounting, "vertical");
  EXPECT_NE(c.parameter_sets[0].resolved_path.find("config/presets/vertical_c1.yaml"), std::string::npos);
  EXPECT_FALSE(c.dds->parameter_writes);
  EXPECT_EQ(c.hil.pacing, HilPacing::kRealtime);
}

TEST(Config, ModbusDdsAndHilSectionsAreValidated) {
  const Config rtu =
      parse_config(std::string(kValid) +
                       "modbus:\n  amplifier: {transport: rtu, device: /dev/ttyS1, baud: 38400, parity: even,"
                       " unit_id: 5}\n",
                   "ok.yaml");
  ASSERT_TRUE(rtu.modbus);
  EXPECT_EQ(rtu.modbus->amplifier_link.transport, ModbusTransport::kRtu);
  EXPECT_EQ(describe(rtu.modbus->amplifier_link), "rtu /dev/ttyS1 38400 8E1 unit 5");

  const auto p = problems_of(std::string(kValid) +
                             "modbus:\n  poll_period_s: 0.05\n  link_timeout_s: 0.01\n"
                             "  amplifier: {host: 127.0.0.1, port: 70000, ready_input: 3, fault_input: 3}\n"
                             "  robot: {port: 502, horizontal_value: 1, vertical_value: 1, depth_register: 0,"
                             " depth_mm_per_count: -1}\n"
                             "parameter_sets: {vertical: no_such_file.yaml}\n"
                             "dds: {domain_id: 300, transport: carrier_pigeon}\n"
                             "hil: {pacing: sometimes}\n");
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  for (const char* expected :
       {"modbus.link_timeout_s = 0.01 s is shorter than modbus.poll_period_s = 0.05 s",
        "modbus.amplifier.port = 70000 (TCP port) is out of range",
        "modbus.amplifier.fault_input = 3 is the ready input's address too",
        "modbus.robot.vertical_value = 1 is the horizontal value too",
        "parameter_sets.vertical = 'no_such_file.yaml': no such file", "dds.domain_id = 300",
        "dds.transport = 'carrier_pigeon' is not allowed", "hil.pacing = 'sometimes' is not allowed",
        "modbus.robot.depth_mm_per_count = -1 mm per count is out of range",
        "modbus.robot.depth_register = 0 is modbus.robot.mounting_register too"})
    EXPECT_NE(all.find(expected), std::string::npos) << expected << "\nin:\n" << all;
  EXPECT_EQ(p.size(), 10U) << all;
}

TEST(Config, CommissioningSectionIsValidated) {
  const Config ok = parse_config(std::string(kValid) + "commissioning: {chirp_periods: 3, record_s: 6}\n", "ok.yaml");
  EXPECT_EQ(ok.commissioning.chirp_periods, 3);
  EXPECT_EQ(ok.commissioning.record_s, 6.0);
  EXPECT_EQ(ok.commissioning.chirp_f1_hz, 100.0);  // defaults for the rest
  const auto p =
      problems_of(std::string(kValid) +
                  "commissioning: {chirp_f0_hz: 50, chirp_f1_hz: 20, chirp_periods: 1, chirp_force_fraction: 1.5,"
                  " impacts_per_location: 0, settle_s: .nan}\n");
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  for (const char* expected :
       {"commissioning.chirp_f1_hz = 20 Hz must be above chirp_f0_hz = 50 Hz", "commissioning.chirp_periods = 1",
        "commissioning.chirp_force_fraction = 1.5 (x actuator.force_limit_n) is out of range",
        "commissioning.impacts_per_location = 0", "commissioning.settle_s"})
    EXPECT_NE(all.find(expected), std::string::npos) << expected << "\nin:\n" << all;
  EXPECT_EQ(p.size(), 5U) << all;
}

TEST(Config, HarmonicNotchAndSpindleAreValidated) {
  std::string text = std::string(kValid);
  const auto at = text.find("controller:\n");
  ASSERT_NE(at, std::string::npos);
  std::string ok = text;
  ok.insert(at + 12, "  harmonic_notch: {harmonics: 4, bandwidth_hz: 20, depth_db: 40}\n");
  const Config c =
      parse_config(ok + "spindle: {teeth: 2, rpm_max: 24000, apply_advice: true, advice_grid_points: 0}\n", "ok.yaml");
  EXPECT_TRUE(c.spindle.apply_advice);
  EXPECT_EQ(c.spindle.advice_grid_points, 0);
  ASSERT_TRUE(c.controller.harmonic_notch);
  EXPECT_EQ(c.controller.harmonic_notch->harmonics, 4);
  EXPECT_EQ(c.controller.harmonic_notch->slew_fraction, 0.05);  // default
  EXPECT_EQ(c.spindle.teeth, 2);
  std::string bad = text;
  bad.insert(at + 12, "  harmonic_notch: {harmonics: 9, depth_db: 0, slew_fraction: 2, update_hz: .nan}\n");
  const auto p =
      problems_of(bad + "spindle: {teeth: 0, rpm_max: -5, apply_advice: sometimes, advice_grid_points: 401}\n");
  std::string all;
  for (const auto& q : p) all += q.to_string() + "\n";
  for (const char* expected :
       {"controller.harmonic_notch.harmonics = 9", "controller.harmonic_notch.depth_db = 0 dB is out of range",
        "controller.harmonic_notch.slew_fraction = 2", "controller.harmonic_notch.update_hz", "spindle.teeth = 0",
        "spindle.rpm_max = -5 rpm is out of range", "spindle.apply_advice",
        "spindle.advice_grid_points = 401 (speeds) is out of range: allowed 0 <= value <= 400"})
    EXPECT_NE(all.find(expected), std::string::npos) << expected << "\nin:\n" << all;
  EXPECT_EQ(p.size(), 8U) << all;
}

TEST(Config, AParameterRequestsGainIsWordedLikeTheConfiguration) {
  EXPECT_FALSE(gain_request_problem(2000.0, 4324.0, "0.9 x K_max"));
  const auto p = gain_request_problem(5000.0, 4324.0, "0.9 x K_max");
  ASSERT_TRUE(p);
  EXPECT_EQ(*p,
            "controller.gain_ns_per_m = 5000 N s/m is out of range: allowed 0 <= value <= 4324 N s/m (0.9 x K_max)");
  EXPECT_TRUE(gain_request_problem(std::nan(""), 4324.0, ""));
}

}  // namespace robodamp::config

// config::edit_yaml: values set as data in any YAML style, the rest of the text kept.
namespace {
std::string edited(const std::string& text, const std::vector<robodamp::config::YamlEdit>& edits, bool* kept) {
  const auto r = robodamp::config::edit_yaml(text, edits);
  *kept = r.comments_kept;
  return r.text;
}
}  // namespace

TEST(YamlEdit, SetsValuesInBlockAndFlowStyleAndKeepsComments) {
  using robodamp::config::YamlEdit;
  const std::string text =
      "# header\n"
      "controller:\n"
      "  gain_ns_per_m: 2000   # the gain\n"
      "  polarity: \"+1\"       # quoted\n"
      "  chain:\n"
      "    - kind: lowpass2    # block entry\n"
      "      cutoff_hz: 50\n"
      "    - {kind: compensator, model: c1}   # flow entry\n"
      "    -\n"
      "      kind: compensator\n"
      "      model: c2\n"
      "other: {a: [1, 2], b: {}}\n";
  YAML::Node entry;
  entry["kind"] = "compensator";
  entry["model"] = "rational";
  entry["numerator"] = std::vector<double>{1.0, 2.0};
  bool kept = false;
  const std::string out = edited(text,
                                 {{{"controller", "gain_ns_per_m"}, YAML::Node("288.5")},
                                  {{"controller", "polarity"}, YAML::Node("-1")},
                                  {{"controller", "chain", std::size_t{0}}, entry},
                                  {{"controller", "chain", std::size_t{1}}, entry},
                                  {{"controller", "chain", std::size_t{2}}, entry},
                                  {{"controller", "match_freq_hz"}, YAML::Node("9.2")},
                                  {{"other", "b", "c"}, YAML::Node("3")},
                                  {{"other", "a", std::size_t{1}}, YAML::Node("5")}},
                                 &kept);
  EXPECT_TRUE(kept) << out;
  // Comments outside the replaced values are kept ("# block entry" was inside one).
  for (const char* comment : {"# header", "# the gain", "# quoted", "# flow entry"})
    EXPECT_NE(out.find(comment), std::string::npos) << comment << "\n" << out;
  const YAML::Node r = YAML::Load(out);
  EXPECT_EQ(r["controller"]["gain_ns_per_m"].as<double>(), 288.5);
  EXPECT_EQ(r["controller"]["polarity"].as<int>(), -1);
  EXPECT_EQ(r["controller"]["match_freq_hz"].as<double>(), 9.2);
  ASSERT_EQ(r["controller"]["chain"].size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(r["controller"]["chain"][i]["model"].as<std::string>(), "rational") << out;
    EXPECT_FALSE(r["controller"]["chain"][i]["cutoff_hz"]) << out;
    EXPECT_EQ(r["controller"]["chain"][i]["numerator"][1].as<double>(), 2.0) << out;
  }
  EXPECT_EQ(r["other"]["a"][1].as<int>(), 5);
  EXPECT_EQ(r["other"]["b"]["c"].as<int>(), 3);
}

TEST(YamlEdit, WhatCannotBeSplicedIsWrittenAgainFromTheDataAndBadPathsAreRefused) {
  using robodamp::config::YamlEdit;
  // A block scalar cannot be replaced in place: the document is emitted again (comments lost), correctly.
  const std::string text = "# comment\nnote: |\n  two\n  lines\nk: 1\n";
  bool kept = true;
  const std::string out = edited(text, {{{"note"}, YAML::Node("one")}, {{"k"}, YAML::Node("2")}}, &kept);
  EXPECT_FALSE(kept);
  const YAML::Node r = YAML::Load(out);
  EXPECT_EQ(r["note"].as<std::string>(), "one");
  EXPECT_EQ(r["k"].as<int>(), 2);
  EXPECT_THROW((void)robodamp::config::edit_yaml("a: [1, 2]\n", {{{"a", std::size_t{2}}, YAML::Node("3")}}),
               std::invalid_argument);
  EXPECT_THROW((void)robodamp::config::edit_yaml("a: 1\n", {{{"a", "b"}, YAML::Node("3")}}), std::invalid_argument);
  EXPECT_THROW((void)robodamp::config::edit_yaml("a: [1, 2\n", {{{"a"}, YAML::Node("3")}}), YAML::Exception);
}
