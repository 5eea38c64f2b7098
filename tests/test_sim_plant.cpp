// The simulated plant: exact discretisation, the fractional actuator delay, the physical frame, the
// sensor model, excitations, faults and reproducibility.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <string>
#include <utility>
#include <vector>

#include "modal/receptance.hpp"
#include "analysis/loop_model.hpp"
#include "sim_plant/fault_text.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/state_space.hpp"
#include "test_util.hpp"

namespace {

using namespace robodamp;

// A one-location plant: a single mode in modal-stiffness form, the actuator on it, a quiet sensor.
std::string single_mode_yaml(double fn, double zeta, double k, const std::string& extra = "") {
  return R"(
loop: {rate_hz: 5000}
actuator: {mounting: horizontal, constant_n_per_v: 4.8, natural_freq_hz: 9.0, damping_ratio: 0.15, delay_s: 0.0006,
           force_limit_n: 36, location: 1}
amplifier: {voltage_limit_v: 10, slew_rate_v_per_s: 20000}
controller:
  gain_ns_per_m: 100
  polarity: 1
  chain:
    - {kind: lowpass2, cutoff_hz: 50, damping_ratio: 0.707}
    - {kind: integrator}
    - {kind: highpass2, cutoff_hz: 4, damping_ratio: 0.707}
robot:
  frfs:
    - {name: H11, response_location: 1, excitation_location: 1,
       modes: [{natural_freq_hz: )" +
         std::to_string(fn) + ", damping_ratio: " + std::to_string(zeta) + ", stiffness_n_per_m: " + std::to_string(k) +
         R"(}]}
sensor: {location: 1, noise_density_ug_per_rthz: 0, highpass_hz: 0, adc_bits: 32}
disturbances: {drives_on: false, drive_vibration_location: 1}
)" + extra;
}

config::Config parse(const std::string& yaml) { return config::parse_config(yaml, "test.yaml"); }

TEST(StateSpace, ZohOfAModeMatchesTheAnalyticStepResponse) {
  const double fn = 12.0, zeta = 0.05, k = 2e6;
  const config::Config cfg = parse(single_mode_yaml(fn, zeta, k));
  const sim::PlantModel model = sim::build_plant_model(cfg);
  sim::Plant plant(model, cfg);
  plant.add_excitation(std::make_unique<sim::Sine>(0, 0.0, 1.0, 0.0));  // silent, exercises the path
  // A constant force held from t = 0: x(t) = F/k (1 - e^{-z wn t} (cos wd t + z / sqrt(1 - z^2) sin wd t)).
  struct Step final : sim::Excitation {
    Step() : Excitation(0) {}
    double force_n(double, double) noexcept override { return 10.0; }
  };
  plant.add_excitation(std::make_unique<Step>());
  const double wn = 2 * M_PI * fn, wd = wn * std::sqrt(1 - zeta * zeta);
  double worst = 0.0;
  for (int i = 1; i <= 5000; ++i) {
    plant.step(0.0);
    const double t = plant.time_s();
    const double x =
        10.0 / k *
        (1 - std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t)));
    worst = std::max(worst, std::abs(plant.displacement_m(0) - x));
  }
  EXPECT_LT(worst, 1e-12 * 10.0 / k * 1e3);  // relative 1e-9 of the static deflection
}

TEST(StateSpace, FractionalInputDelayIsExact) {
  // A pure integrator x' = u with the input delayed by 0.3 steps: a unit step at k = 0 contributes 0.7 h
  // in the first step and h in every later one.
  sim::Matrix a = sim::Matrix::Zero(1, 1), b = sim::Matrix::Ones(1, 1);
  const double h = 1e-3;
  const auto d = sim::discretise_zoh_delayed(a, b, h, 0.3 * h);
  EXPECT_EQ(d.steps, 0);
  EXPECT_NEAR(d.fraction, 0.3, 1e-12);
  EXPECT_NEAR(d.gamma_late(0, 0), 0.7 * h, 1e-15);
  EXPECT_NEAR(d.gamma_early(0, 0), 0.3 * h, 1e-15);
  const auto whole = sim::discretise_zoh_delayed(a, b, h, 3.0 * h);
  EXPECT_EQ(whole.steps, 3);
  EXPECT_EQ(whole.fraction, 0.0);
}

TEST(Plant, ActuatorDelayIsExactAtTheInternalRate) {
  // 0.6 ms at 5 kHz x 2 = 6 internal steps: the actuator force stays 0 for exactly 3 loop periods after
  // a voltage step, then jumps by T (Eq. 3 feedthrough).
  config::Config cfg = parse(single_mode_yaml(12.0, 0.05, 2e6, "plant: {oversampling: 2}\n"));
  sim::Plant plant(sim::build_plant_model(cfg), cfg);
  for (int i = 0; i < 3; ++i) {
    plant.step(1.0);
    EXPECT_EQ(plant.actuator_force_n(), 0.0) << i;
  }
  plant.step(1.0);
  EXPECT_NEAR(plant.actuator_force_n(), 4.8, 0.05);
}

TEST(Plant, SteadyStateSineMatchesTheReceptance) {
  const config::Config cfg = parse(single_mode_yaml(12.0, 0.05, 2e6));
  const sim::PlantModel model = sim::build_plant_model(cfg);
  sim::Plant plant(model, cfg);
  const double f = 15.0;
  plant.add_excitation(std::make_unique<sim::Sine>(0, 100.0, f, 0.0));
  double peak = 0.0;
  for (int i = 0; i < 5000 * 12; ++i) {
    plant.step(0.0);
    if (plant.time_s() > 10.0) peak = std::max(peak, std::abs(plant.displacement_m(0)));
  }
  EXPECT_NEAR(peak / 100.0, std::abs(model.receptance(0, 0, f)), 2e-3 * std::abs(model.receptance(0, 0, f)));
}

TEST(PlantModel, TableFrameBecomesPhysicalWithTheAxisSign) {
  const config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  const sim::PlantModel m = sim::build_plant_model(cfg);
  const std::size_t tcp = m.index_of(1), aml = m.index_of(2);
  // H22_phys = -H22_table, H21 likewise; H12 from H21 by reciprocity; driving points positive.
  const auto& h22_table = cfg.robot.frfs[2];
  EXPECT_NEAR(std::abs(m.receptance(aml, aml, 9.2) + modal::frf_receptance(h22_table, 9.2)), 0.0, 1e-18);
  EXPECT_GT(m.path(aml, aml)->static_compliance_m_per_n(), 0.0);
  EXPECT_GT(m.path(tcp, tcp)->static_compliance_m_per_n(), 0.0);
  EXPECT_EQ(m.receptance(tcp, aml, 21.0), m.receptance(aml, tcp, 21.0));
  ASSERT_FALSE(m.notes.empty());
  EXPECT_NE(m.notes.front().find("reciprocity"), std::string::npos);
}

TEST(PlantModel, NonPhysicalDrivingPointIsAnErrorAtItsKey) {
  std::string yaml = test::read_file(test::preset("horizontal_c2"));
  yaml.replace(yaml.find("axis_sign: -1"), 13, "axis_sign: +1");
  try {
    (void)sim::build_plant_model(config::parse_config(yaml, "flipped.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("robot.frfs[2]"), std::string::npos) << what;
    EXPECT_NE(what.find("static compliance"), std::string::npos) << what;
    EXPECT_NE(what.find("axis_sign"), std::string::npos) << what;
  }
}

TEST(PlantModel, ReciprocalPairOfOppositeSignIsAnError) {
  std::string yaml = test::read_file(test::preset("horizontal_c2"));
  // An explicit H12 copied from the table (response at location 1, sign +1) contradicts the physical H21.
  yaml += "";
  const std::string h12 = R"(
    - name: H12yy
      response_location: 1
      excitation_location: 2
      modes: *h21yy_modes
)";
  yaml.insert(yaml.find("\nsensor:"), h12);
  try {
    (void)sim::build_plant_model(config::parse_config(yaml, "h12.yaml"));
    FAIL() << "expected a ConfigError";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("reciprocity"), std::string::npos) << e.what();
  }
}

TEST(Sensor, NoiseQuantisationClippingAndCoupling) {
  config::SensorConfig s;
  s.noise_density_ug_per_rthz = 100.0;
  s.highpass_hz = 1.6;
  sim::Accelerometer a(s, 5000.0, 7);
  const double expected_rms = 100e-6 * sim::kStandardGravity * std::sqrt(2500.0);
  EXPECT_NEAR(a.noise_rms_mps2(), expected_rms, 1e-12);
  double sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) sum2 += std::pow(a.measure(0.0), 2);
  EXPECT_NEAR(std::sqrt(sum2 / n), expected_rms, 0.02 * expected_rms);
  // Readings are whole LSBs; the range clips and counts.
  const double r = a.measure(1.2345);
  EXPECT_NEAR(std::remainder(r, a.lsb_mps2()), 0.0, 1e-9 * a.lsb_mps2());
  (void)a.measure(1e9);
  EXPECT_EQ(a.clipped_count(), 1u);
  // Within 5 % above 5 Hz, as the preset's comment says.
  EXPECT_GT(std::abs(a.analog_response(5.0)), 0.95);
  EXPECT_NEAR(std::abs(a.response(5.0)), std::abs(a.analog_response(5.0)), 1e-4);
}

TEST(Excitation, HammerImpulseIsExactAtAnyStep) {
  for (double h : {1e-4, 2e-4, 7e-4, 3e-3}) {
    sim::ImpactHammer hammer(0, 1000.0, 1e-3, {0.01234});
    double impulse = 0.0;
    for (int i = 0; i < static_cast<int>(0.1 / h); ++i) impulse += hammer.force_n(i * h, h) * h;
    EXPECT_NEAR(impulse, hammer.impulse_n_s(), 1e-12) << h;
  }
}

TEST(Excitation, NoiseIsSeededAndBandLimited) {
  sim::Noise a(0, 2.0, 42), b(0, 2.0, 42), c(0, 2.0, 43);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const double x = a.force_n(0, 1e-3);
    EXPECT_EQ(x, b.force_n(0, 1e-3));
    differs = differs || x != c.force_n(0, 1e-3);
  }
  EXPECT_TRUE(differs);
  sim::Noise band(0, 2.0, 1, 5.0, 50.0, 5000.0);
  double sum2 = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) sum2 += std::pow(band.force_n(0, 2e-4), 2);
  EXPECT_NEAR(std::sqrt(sum2 / n), 2.0, 0.1);
}

TEST(Faults, SensorFaults) {
  const config::Config cfg = parse(single_mode_yaml(12.0, 0.05, 2e6));
  sim::Plant plant(sim::build_plant_model(cfg), cfg);
  plant.add_excitation(std::make_unique<sim::Sine>(0, 1000.0, 20.0, 0.0));
  plant.faults().add({sim::FaultKind::kSensorDropout, 0.1, 0.01});
  plant.faults().add({sim::FaultKind::kSensorStuck, 0.2, 0.01});
  plant.faults().add({sim::FaultKind::kSensorNan, 0.3, 0.01});
  plant.faults().add({sim::FaultKind::kSensorSpike, 0.4, 0.0102, 500.0, 0.0});
  int stale = 0, nan = 0, spikes = 0;
  double stuck_value = NAN, last = 0.0;
  bool stuck_held = true;
  for (int i = 0; i < 5000; ++i) {
    const double t = plant.time_s();
    const sim::SensorReading r = plant.sense();
    if (!r.fresh) {
      ++stale;
      EXPECT_EQ(r.accel_mps2, last);
    }
    if (std::isnan(r.accel_mps2)) ++nan;
    if (t >= 0.2 + 1e-9 && t < 0.21 - 1e-9) {
      if (std::isnan(stuck_value)) stuck_value = r.accel_mps2;
      stuck_held = stuck_held && r.accel_mps2 == stuck_value;
    }
    if (t >= 0.4 && t < 0.42 && std::abs(r.accel_mps2) > 400.0) ++spikes;
    last = r.accel_mps2;
    plant.step(0.0);
  }
  EXPECT_NEAR(stale, 50, 1);
  EXPECT_NEAR(nan, 50, 1);
  EXPECT_TRUE(stuck_held);
  EXPECT_EQ(spikes, 1);
}

TEST(Faults, ActuatorDeadAndSaturated) {
  const config::Config cfg = parse(single_mode_yaml(12.0, 0.05, 2e6));
  const sim::PlantModel model = sim::build_plant_model(cfg);
  auto peak_force = [&](const sim::Fault& f) {
    sim::Plant plant(model, cfg);
    plant.faults().add(f);
    double peak = 0.0;
    for (int i = 0; i < 5000; ++i) {  // 7 V at 60 Hz (flat band): 33.6 N of coil force, inside 36 N
      plant.step(7.0 * std::sin(2 * M_PI * 60.0 * plant.time_s()));
      if (plant.time_s() > 0.5) peak = std::max(peak, std::abs(plant.actuator_force_n()));
    }
    return std::make_pair(peak, plant.counters().force_limited);
  };
  const auto healthy = peak_force({sim::FaultKind::kSensorNan, 10.0, 1.0});  // a fault that never starts
  EXPECT_NEAR(healthy.first, 7.0 * std::abs(model.actuator.n_per_v(60.0)), 0.5);
  EXPECT_EQ(healthy.second, 0u);
  const auto dead = peak_force({sim::FaultKind::kActuatorDead, 0.0});
  EXPECT_EQ(dead.first, 0.0);
  const auto sat = peak_force({sim::FaultKind::kActuatorSaturated, 0.0, 1e9, 12.0});
  EXPECT_GT(sat.first, 11.0);
  EXPECT_LT(sat.first, 14.0);
  EXPECT_GT(sat.second, 0u);
}

// `run --fault` as typed: the kind, the start within the run, a duration, and for a saturated actuator the force
// it still gives; every refusal names the field, its unit and its range.
TEST(Faults, ReadFromTheCommandLinesText) {
  sim::Fault f;
  std::string e;
  ASSERT_TRUE(sim::parse_fault("actuator_saturated:2:0.5:12", 10.0, f, e)) << e;
  EXPECT_EQ(f.kind, sim::FaultKind::kActuatorSaturated);
  EXPECT_EQ(f.start_s, 2.0);
  EXPECT_EQ(f.duration_s, 0.5);
  EXPECT_EQ(f.magnitude, 12.0);
  ASSERT_TRUE(sim::parse_fault("actuator_saturated:1", 10.0, f, e)) << e;
  EXPECT_EQ(f.magnitude, 0.0);  // no force left
  EXPECT_TRUE(std::isinf(f.duration_s));
  const sim::Fault before = f;
  for (const auto& [text, why] : std::vector<std::pair<std::string, std::string>>{
           {"sensor_nan:1:0.2:3", "only actuator_saturated takes one (FORCE_N)"},
           {"actuator_saturated:1:1:-2", "--fault force = -2 N is out of range: allowed 0 <= value <= 1000000 N"},
           {"sensor_nan:11", "--fault start = 11 s is out of range"},
           {"sensor_nan:1:x", "--fault duration = 'x' is not a finite number"},
           {"wet_sensor:1", "names no fault: allowed sensor_dropout, sensor_stuck"}}) {
    EXPECT_FALSE(sim::parse_fault(text, 10.0, f, e)) << text;
    EXPECT_NE(e.find(why), std::string::npos) << text << ": " << e;
    EXPECT_EQ(e.rfind("'" + text + "'", 0), 0U) << e;
    EXPECT_EQ(f.start_s, before.start_s) << text;  // nothing half-written
  }
}

TEST(Plant, SameSeedSameRun) {
  const config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  const analysis::LoopModel model(cfg);
  auto run = [&](std::uint64_t seed) {
    config::Config c = cfg;
    c.disturbances.seed = seed;
    sim::Plant plant(model.plant(), c);
    plant.add_excitation(sim::make_drive_vibration(model.plant(), c));
    std::vector<double> out;
    for (int i = 0; i < 2000; ++i) {
      out.push_back(plant.sense().accel_mps2);
      plant.step(0.0);
    }
    return out;
  };
  EXPECT_EQ(run(5), run(5));
  EXPECT_NE(run(5), run(6));
}

TEST(Plant, DriveVibrationHasTheConfiguredAmplitude) {
  config::Config cfg = config::load_config_file(test::preset("horizontal_c2"));
  cfg.sensor.noise_density_ug_per_rthz = 0.0;
  const analysis::LoopModel model(cfg);
  sim::Plant plant(model.plant(), cfg);
  plant.add_excitation(sim::make_drive_vibration(model.plant(), cfg));
  double peak = 0.0;
  for (int i = 0; i < 5000 * 30; ++i) {
    plant.step(0.0);
    if (plant.time_s() > 20.0) peak = std::max(peak, std::abs(plant.acceleration_mps2(plant.sensor_location())));
  }
  EXPECT_NEAR(peak, cfg.disturbances.drive_vibration_mps2, 0.02 * cfg.disturbances.drive_vibration_mps2);
}

}  // namespace
