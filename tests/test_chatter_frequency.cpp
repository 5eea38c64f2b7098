// Issue 51, item 5: one chatter frequency. A regenerative chatter is one Floquet mode; its vibration has
// every alias f0 + k f_p and k f_p - f0 of the period's frequency f_p, and each method saw another: SDM's
// eigenvector 5486 Hz, the detector's spectrum 141.7 Hz on the robot SLE study's robot at 10 700 rpm
// (docs/milling.md, "One chatter frequency"). Now SDM, the time-domain detector and the chatter indicator
// (the cell's and `robodamp chatter`'s) all take the mode's strongest harmonic by displacement, and every
// screen can name the family (chatter_family_hz) when a band hides that harmonic.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "config/milling_config.hpp"
#include "milling/accurate_stability.hpp"
#include "milling/chatter.hpp"
#include "milling/chatter_listen.hpp"
#include "milling/cut_job.hpp"
#include "milling/lobes.hpp"
#include "milling/structure.hpp"

namespace {

namespace ml = robodamp::milling;
namespace cfg = robodamp::config;

struct Case {
  const char* what;
  const char* job;
  const char* drop_part;  // a part of the job's structure left out ("" none)
  double rpm;
  double over;             // the cut's depth over SDM's limit
  double max_hz;           // the indicator's band (covers the harmonic SDM names)
  double cut_s, window_s;  // the simulated cut, the indicator's window
  bool damped;             // the job's controller running (sampled-loop SDM; the real Controller in the cut)
};

struct Frequencies {
  double sdm_hz{0.0}, detector_hz{0.0}, long_detector_hz{0.0}, indicator_hz{0.0}, low_band_hz{0.0}, tooth_hz{0.0};
};

Frequencies measure(const Case& c) {
  cfg::MillingConfig job =
      cfg::load_milling_config(std::string(ROBODAMP_SOURCE_DIR).append("/config/milling/").append(c.job));
  cfg::StructureConfig sc = job.selected_structure();
  std::erase_if(sc.parts, [&](const cfg::StructurePartConfig& p) { return p.name == c.drop_part; });
  const ml::Structure structure(sc, c.damped);
  Frequencies f;
  f.tooth_hz = c.rpm * job.tool.teeth / 60.0;
  const ml::LobeModel lobes(structure, ml::chatter_process(job.tool, job.material, job.cut), job.lobes);
  const ml::SdmPoint sdm = ml::AccurateStability(structure, job).critical(c.rpm, lobes.critical_depth_mm(c.rpm));
  f.sdm_hz = sdm.chatter_hz;
  // The detector at SDM's limit with the job's own cut (0.8 % above the time domain's limit on the industrial
  // robot, where the robot's decaying modes still fill the spectrum: the old detector said 140.3 Hz there).
  ml::CutOverrides at;
  at.damped = c.damped, at.rpm = c.rpm, at.axial_mm = sdm.critical_depth_mm * (c.over > 1.1 ? c.over : 1.0);
  const ml::CutOutcome near = ml::run_job(ml::make_cut_job(job, structure, at));
  EXPECT_FALSE(near.verdict.stable) << c.what;
  f.detector_hz = near.verdict.chatter_hz;
  ml::CutOverrides o;
  o.damped = c.damped, o.rpm = c.rpm, o.axial_mm = c.over * sdm.critical_depth_mm,
  o.revolutions = static_cast<int>(std::ceil(c.cut_s * c.rpm / 60.0));
  const ml::CutOutcome cut = ml::run_job(ml::make_cut_job(job, structure, o));
  EXPECT_FALSE(cut.verdict.stable) << c.what;
  f.long_detector_hz = cut.verdict.chatter_hz;
  // The wall-normal acceleration, as the cell's accelerometer or a recorder holds it.
  ml::RecordedSignal sig;
  sig.source = "simulated cut", sig.rate_hz = 1.0 / cut.record.step_s;
  const auto& y = job.cut.feed_axis == cfg::Axis::kX ? cut.record.y_m : cut.record.x_m;
  for (std::size_t i = 2; i < y.size(); ++i)
    sig.samples.push_back((y[i] - 2.0 * y[i - 1] + y[i - 2]) * sig.rate_hz * sig.rate_hz);
  ml::ListenSettings s;
  s.teeth = job.tool.teeth, s.rpm = c.rpm, s.window_s = c.window_s, s.max_hz = c.max_hz;
  f.indicator_hz = ml::listen(sig, s).chatter_hz;
  s.max_hz = 1000.0;  // `robodamp chatter`'s default band
  const ml::ListenReport low = ml::listen(sig, s);
  f.low_band_hz = low.chatter_hz;
  std::string notes;
  for (const auto& w : low.warnings) notes += w + "\n";
  // The user is told when the recording holds more than the band (1.5 x).
  EXPECT_EQ(notes.find("analysed up to 1000 Hz of the") != std::string::npos, 0.5 * sig.rate_hz > 1500.0)
      << c.what << ": " << notes;
  std::printf(
      "%-44s SDM %.1f mm at %.1f Hz; detector %.1f Hz at it, %.1f Hz above; indicator %.1f Hz (band %.0f Hz), %.1f Hz "
      "(band 1 kHz); "
      "families %.1f %.1f %.1f %.1f Hz (f_p %.1f Hz)\n",
      c.what, sdm.critical_depth_mm, f.sdm_hz, f.detector_hz, f.long_detector_hz, f.indicator_hz, c.max_hz,
      f.low_band_hz, ml::chatter_family_hz(f.sdm_hz, f.tooth_hz), ml::chatter_family_hz(f.detector_hz, f.tooth_hz),
      ml::chatter_family_hz(f.indicator_hz, f.tooth_hz), ml::chatter_family_hz(f.low_band_hz, f.tooth_hz), f.tooth_hz);
  return f;
}

TEST(ChatterFrequency, SdmTheDetectorAndTheIndicatorNameOneAlias) {
  const Case cases[] = {
      {"industrial robot, robot and workpiece, 10700 rpm", "industrial_robot_aluminium.yaml", "", 10700.0, 1.05, 8000.0,
       3.0, 1.0, false},
      {"industrial robot, robot alone, 10700 rpm", "industrial_robot_aluminium.yaml", "workpiece", 10700.0, 1.05,
       8000.0, 3.0, 1.0, false},
      {"default job, open loop, 700 rpm", "active_damping_c2.yaml", "", 700.0, 1.3, 1000.0, 16.0, 4.0, false},
      {"default job, damped at K = 2000 N s/m, 700 rpm", "active_damping_c2.yaml", "", 700.0, 1.3, 1000.0, 16.0, 4.0,
       true},
  };
  for (const Case& c : cases) {
    const Frequencies f = measure(c);
    EXPECT_NEAR(f.detector_hz, f.sdm_hz, 0.005 * f.sdm_hz) << c.what;
    EXPECT_NEAR(f.long_detector_hz, f.sdm_hz, 0.005 * f.sdm_hz) << c.what;
    EXPECT_NEAR(f.indicator_hz, f.sdm_hz, 0.005 * f.sdm_hz + 1.0 / c.window_s) << c.what;  // + one bin
    // A band below the strongest harmonic (`robodamp chatter`'s default 1 kHz at 10 700 rpm): the indicator
    // says stable (the 141 Hz alias is under 0.1 % of the displacement there, the spindle's lines the rest),
    // never another frequency.
    if (f.low_band_hz > 0.0) {
      EXPECT_TRUE(ml::same_chatter(f.low_band_hz, f.sdm_hz, f.tooth_hz, 0.01 * f.tooth_hz)) << c.what;
    }
  }
}

}  // namespace
