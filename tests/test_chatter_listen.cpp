// Issue 50: `robodamp chatter` on recorded signals with a known truth (milling/chatter_listen.hpp,
// identify/recorded_signal.hpp): a cut at 700 rpm with three teeth and runout, stable for 6 s, then
// chatter at 17.3 Hz growing to a limit cycle, written at 10, 25.6 and 48 kHz as a table (semicolons,
// decimal commas, the time in ms), a 24-bit WAV and a universal file's time history.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "config/milling_config.hpp"
#include "filters/design.hpp"
#include "identify/recorded_signal.hpp"
#include "measfiles/uff.hpp"
#include "milling/chatter_listen.hpp"
#include "milling/cut_job.hpp"
#include "milling/structure.hpp"
#include "test_util.hpp"

namespace {

namespace ml = robodamp::milling;

struct TempDir : robodamp::test::ScratchDir {
  TempDir() : ScratchDir("chatter") {}
};

constexpr double kRpm = 700.0, kChatterHz = 17.3, kOnsetS = 6.0;
constexpr int kTeeth = 3;

// Acceleration, m/s^2: the spindle's and the teeth's forced lines (runout: every spindle harmonic), noise,
// and from kOnsetS chatter growing to a limit cycle.
std::vector<double> cut_signal(double rate_hz, double duration_s, bool chatter, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  const double f_sp = kRpm / 60.0;
  std::vector<double> x;
  for (int i = 0; i < static_cast<int>(duration_s * rate_hz); ++i) {
    const double t = i / rate_hz;
    double v = noise(rng);
    for (int k = 1; k <= 30; ++k)
      v += (k % kTeeth == 0 ? 0.4 : 0.05) / std::sqrt(k) * std::sin(2.0 * M_PI * k * f_sp * t + 0.7 * k);
    if (chatter && t > kOnsetS)
      v += std::min(0.05 * std::exp(3.0 * (t - kOnsetS)), 1.5) * std::sin(2.0 * M_PI * kChatterHz * t);
    x.push_back(v);
  }
  return x;
}

ml::ListenSettings settings() {
  ml::ListenSettings s;
  s.teeth = kTeeth;
  s.rpm_min = 300.0, s.rpm_max = 3000.0;
  return s;
}

// The verdicts against the truth: stable windows wholly before the onset, chatter from the first window
// after the onset on (the growth takes about 1 s to pass the floor).
void expect_truth(const ml::ListenReport& r, bool chatter, const std::string& what) {
  int right = 0, judged = 0;
  for (const auto& w : r.windows) {
    if (chatter && w.end_s > kOnsetS && w.start_s < kOnsetS + 1.0) continue;  // the onset's window: either
    ++judged;
    const bool should = chatter && w.start_s >= kOnsetS;
    right += (w.verdict == (should ? ml::WindowVerdict::kChatter : ml::WindowVerdict::kStable));
    if (w.verdict == ml::WindowVerdict::kChatter) {
      EXPECT_NEAR(w.chatter_hz, kChatterHz, 0.01 * kChatterHz) << what << " " << w.start_s;
    }
  }
  EXPECT_GE(right, (95 * judged + 99) / 100) << what;
  if (chatter) {
    ASSERT_TRUE(r.onset_s.has_value()) << what;
    EXPECT_NEAR(*r.onset_s, kOnsetS, 0.2) << what;
    EXPECT_NEAR(r.chatter_hz, kChatterHz, 0.01 * kChatterHz) << what;
  } else {
    EXPECT_FALSE(r.onset_s.has_value()) << what;
  }
}

TEST(ChatterListen, KnownCutsAtThreeRatesGiveTheVerdictsTheOnsetAndTheFrequency) {
  for (const double rate : {10000.0, 25600.0, 48000.0}) {
    for (const bool chatter : {false, true}) {
      ml::RecordedSignal sig;
      sig.source = "synthetic", sig.rate_hz = rate, sig.samples = cut_signal(rate, 20.0, chatter, 5);
      const ml::ListenReport r = ml::listen(sig, settings());
      const std::string what = std::to_string(rate) + (chatter ? " chatter" : " stable");
      EXPECT_EQ(r.windows.size(), 5u) << what;                                // 4 s each
      EXPECT_NEAR(r.rpm, kRpm, 0.01 * kRpm) << what << ": " << r.rpm_source;  // estimated: not given
      expect_truth(r, chatter, what);
      if (chatter) {
        ASSERT_FALSE(r.speeds.empty());
        // The pockets: the tooth frequency at 17.3 Hz / k; the nearest to 700 rpm is k = 1 (346 rpm) or none
        // above; all within the range.
        for (const auto& s : r.speeds) EXPECT_NEAR(s.rpm * kTeeth / 60.0 * s.lobe, r.chatter_hz, 1e-9);
      }
      // The spectrogram's plotted data: in the last chatter column the loudest row below 30 Hz is the chatter.
      if (chatter) {
        const auto& col = r.spectrogram_db.back();
        std::size_t best = 0;
        for (std::size_t k = 0; k < col.size(); ++k)
          if (r.spectrogram_hz[k] > 5.0 && r.spectrogram_hz[k] < 30.0 && (best == 0 || col[k] > col[best])) best = k;
        EXPECT_NEAR(r.spectrogram_hz[best], kChatterHz, 0.3) << what;  // rows of 0.25-0.3 Hz there (log spaced)
      }
    }
  }
}

TEST(ChatterListen, AwkwardRecordingsAreSaidPlainly) {
  ml::RecordedSignal sig;
  sig.source = "awkward", sig.rate_hz = 10000.0, sig.samples = cut_signal(10000.0, 12.0, true, 9);
  for (std::size_t i = 30000; i < 30500; ++i) sig.samples[i] = NAN;  // a dropout: 1.25 % of a 4 s window
  for (double& v : sig.samples) v = std::clamp(v + 3.0, 1.0, 4.0);   // a DC offset, and clipped at 4
  const ml::ListenReport r = ml::listen(sig, settings());
  std::string all;
  for (const auto& w : r.warnings) all += w + "\n";
  EXPECT_NE(all.find("500 samples are not finite (dropouts)"), std::string::npos) << all;
  EXPECT_NE(all.find("a DC offset of"), std::string::npos) << all;
  EXPECT_NE(all.find("clipped:"), std::string::npos) << all;
  EXPECT_EQ(r.windows[0].verdict, ml::WindowVerdict::kNoSignal);  // the window with the dropout (over 1 % held)
  // Too short, no teeth, a rate too low: refused with the reason.
  ml::RecordedSignal shorter = sig;
  shorter.samples.resize(5000);
  EXPECT_THROW((void)ml::listen(shorter, settings()), std::invalid_argument);
  ml::ListenSettings no_teeth = settings();
  no_teeth.teeth = 0;
  EXPECT_THROW((void)ml::listen(sig, no_teeth), std::invalid_argument);
  ml::RecordedSignal slow;  // 30 Hz: no room for a chatter band from 5 Hz
  slow.source = "slow", slow.rate_hz = 30.0, slow.samples.assign(3000, 0.1);
  try {
    (void)ml::listen(slow, settings());
    ADD_FAILURE() << "a 30 Hz recording was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("too low a rate for a chatter band from 5 Hz"), std::string::npos) << e.what();
  }
  // Air: the spindle turning, no cut: noise only, below the floor.
  ml::RecordedSignal air;
  air.source = "air", air.rate_hz = 10000.0;
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 0.01);
  for (int i = 0; i < 80000; ++i) air.samples.push_back(n(rng));
  ml::ListenSettings given = settings();
  given.rpm = kRpm;
  for (const auto& w : ml::listen(air, given).windows) EXPECT_EQ(w.verdict, ml::WindowVerdict::kNoSignal);
}

using Result = robodamp::test::CommandResult;

Result run(const std::string& args) { return robodamp::test::run_robodamp(args); }

void write_wav24(const std::string& path, const std::vector<double>& x, double rate, double full_scale) {
  std::ofstream f(path, std::ios::binary);
  auto u32 = [&](std::uint32_t v) { f.write(reinterpret_cast<const char*>(&v), 4); };
  auto u16 = [&](std::uint16_t v) { f.write(reinterpret_cast<const char*>(&v), 2); };
  const auto bytes = static_cast<std::uint32_t>(x.size() * 3);
  f << "RIFF";
  u32(36 + bytes);
  f << "WAVEfmt ";
  u32(16), u16(1), u16(1), u32(static_cast<std::uint32_t>(rate)), u32(static_cast<std::uint32_t>(rate) * 3), u16(3),
      u16(24);
  f << "data";
  u32(bytes);
  for (double v : x) {
    const auto s = static_cast<std::int32_t>(std::lround(std::clamp(v / full_scale, -1.0, 1.0) * 8388607.0));
    const char b[3] = {static_cast<char>(s & 0xff), static_cast<char>((s >> 8) & 0xff),
                       static_cast<char>((s >> 16) & 0xff)};
    f.write(b, 3);
  }
}

// The command on the formats a user has, with the JSON and the plots.
TEST(ChatterListen, TheCommandReadsTablesWavAndUniversalFiles) {
  const TempDir tmp;
  const double rate = 25600.0;
  const std::vector<double> x = cut_signal(rate, 12.0, true, 21);
  {
    std::ofstream csv(tmp.file("cut.csv"));
    csv << "Messung 27.11.2026\nZeit [ms];Beschleunigung [g]\n";
    char line[80];
    for (std::size_t i = 0; i < x.size(); ++i) {
      std::snprintf(line, sizeof line, "%.4f;%.7f\n", 1e3 * static_cast<double>(i) / rate, x[i] / 9.80665);
      std::string s = line;
      for (char& c : s)
        if (c == '.') c = ',';
      csv << s;
    }
  }
  write_wav24(tmp.file("cut.wav"), x, rate, 20.0);
  {
    robodamp::measfiles::UffFunction f;
    f.function_type = robodamp::measfiles::kUffTimeResponse, f.is_complex = false;
    f.response_node = 1, f.response_direction = 2;
    f.abscissa = {robodamp::measfiles::kUffTime, 0, 0, 0, "Time", "s"};
    f.ordinate = {robodamp::measfiles::kUffAcceleration, 0, 0, 0, "Acceleration", "m/s^2"};
    for (std::size_t i = 0; i < x.size(); ++i)
      f.x.push_back(static_cast<double>(i) / rate), f.y.emplace_back(x[i], 0.0);
    robodamp::measfiles::UffFile file;
    file.functions = {f};
    robodamp::measfiles::write_uff(tmp.file("cut.uff"), file, robodamp::measfiles::UffEncoding::kBinary);
  }
  const std::string json = tmp.file("c.json"), plots = tmp.file("plots");
  for (const std::string input : {"cut.csv --column 2", "cut.wav --full-scale-mps2 20", "cut.uff"}) {
    const Result r = run("chatter --signal " + tmp.path + "/" + input + " --teeth 3 --rpm-range 300 3000 --json " +
                         json + " --plot-dir " + plots);
    ASSERT_EQ(r.status, 0) << input << "\n" << r.out;
    EXPECT_NE(r.out.find("CHATTER from"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(robodamp::test::read_file(json));
    EXPECT_NEAR(j["chatter_hz"].get<double>(), kChatterHz, 0.01 * kChatterHz) << input;
    EXPECT_NEAR(j["rpm"].get<double>(), kRpm, 0.01 * kRpm) << input;
    EXPECT_NEAR(j["rate_hz"].get<double>(), rate, 0.01) << input;
    ASSERT_EQ(j["windows"].size(), 3u) << input;
    EXPECT_EQ(j["windows"][0]["verdict"], "stable") << input;
    EXPECT_EQ(j["windows"][2]["verdict"], "chatter") << input;
    for (const char* png : {"chatter_spectrogram.png", "chatter_verdict.png"})
      EXPECT_GT(std::filesystem::file_size(plots + "/" + png), 5000u) << png;
  }
  // With the cell and its job: each speed to try checked by the accurate method, as the cell's advisor does.
  const Result checked = run("chatter --signal " + tmp.file("cut.uff") + " --teeth 3 --config " +
                             robodamp::test::preset("horizontal_c2") + " --job " + std::string(ROBODAMP_SOURCE_DIR) +
                             "/config/milling/active_damping_c2.yaml --depth-mm 1.0 --json " + json);
  ASSERT_EQ(checked.status, 0) << checked.out;
  EXPECT_NE(checked.out.find("Checked by SDM at"), std::string::npos) << checked.out;
  const auto c = nlohmann::json::parse(robodamp::test::read_file(json))["checked"];
  EXPECT_TRUE(c["found"].get<bool>()) << checked.out;
  ASSERT_FALSE(c["options"].empty());
  for (const auto& o : c["options"]) {
    EXPECT_GE(o["margin"].get<double>(), 1.3) << checked.out;  // the advisor's margin where the cut chattered
    EXPECT_GE(o["rpm"].get<double>(), 100.0);
    EXPECT_LE(o["rpm"].get<double>(), 1500.0);  // the job's range
  }
  const Result wrong_teeth =
      run("chatter --signal " + tmp.file("cut.uff") + " --teeth 4 --config " + robodamp::test::preset("horizontal_c2") +
          " --job " + std::string(ROBODAMP_SOURCE_DIR) + "/config/milling/active_damping_c2.yaml");
  EXPECT_EQ(wrong_teeth.status, 2) << wrong_teeth.out;
  EXPECT_NE(wrong_teeth.out.find("--teeth 4 but the job"), std::string::npos) << wrong_teeth.out;
  // A recording without chatter: its verdict and both plots (no chatter frequency to draw on the right axis).
  {
    const std::vector<double> quiet = cut_signal(rate, 12.0, false, 22);
    std::ofstream csv(tmp.file("quiet.csv"));
    csv << "t_s,a_mps2\n";  // the time column as a logger names it with its unit
    char line[64];
    for (std::size_t i = 0; i < quiet.size(); ++i) {
      std::snprintf(line, sizeof line, "%.8f,%.7f\n", static_cast<double>(i) / rate, quiet[i]);
      csv << line;
    }
  }
  const std::string quiet_plots = tmp.file("quiet_plots");
  const Result quiet = run("chatter --signal " + tmp.file("quiet.csv") + " --teeth 3 --rpm-range 300 3000 --json " +
                           json + " --plot-dir " + quiet_plots);
  ASSERT_EQ(quiet.status, 0) << quiet.out;
  EXPECT_NE(quiet.out.find("NO CHATTER in 3 windows"), std::string::npos) << quiet.out;
  const auto quiet_report = nlohmann::json::parse(robodamp::test::read_file(json));  // named: the loop reads it
  for (const auto& w : quiet_report["windows"]) EXPECT_EQ(w["verdict"], "stable") << quiet.out;
  for (const char* png : {"chatter_spectrogram.png", "chatter_verdict.png"})
    EXPECT_GT(std::filesystem::file_size(quiet_plots + "/" + png), 5000u) << png;
  const Result no_teeth = run("chatter --signal " + tmp.file("cut.uff"));
  EXPECT_EQ(no_teeth.status, 2) << no_teeth.out;
  EXPECT_NE(no_teeth.out.find("--teeth"), std::string::npos) << no_teeth.out;
  const Result bad_channel = run("chatter --signal " + tmp.file("cut.wav") + " --teeth 3 --channel 2");
  EXPECT_EQ(bad_channel.status, 2) << bad_channel.out;
  EXPECT_NE(bad_channel.out.find("channel 2: the file has 1"), std::string::npos) << bad_channel.out;
}

// A microphone beside the spindle hears the head's acceleration (a surface small against the wavelength
// radiates a pressure proportional to its acceleration) through the microphone's own band: a second-order
// high-pass at 10 Hz and a low-pass at 8 kHz (where the rate allows), 0.3 Pa per m/s^2.
std::vector<double> microphone(const std::vector<double>& a, double rate_hz) {
  namespace rf = robodamp::filters;
  rf::TransferFunction band = rf::highpass2(10.0, 1.0 / std::sqrt(2.0));
  if (rate_hz > 20000.0) band = band * rf::lowpass2(8000.0, 1.0 / std::sqrt(2.0));
  const rf::DigitalDesign d = rf::bilinear_sos(band, rate_hz, 0.0);
  std::vector<double> y = a;
  for (const auto& c : d.sections) {
    double x1 = 0.0, x2 = 0.0, y1 = 0.0, y2 = 0.0;
    for (double& v : y) {
      const double out = c.b0 * v + c.b1 * x1 + c.b2 * x2 - c.a1 * y1 - c.a2 * y2;
      x2 = x1, x1 = v, y2 = y1, y1 = out, v = out;
    }
  }
  for (double& v : y) v *= 0.3 * d.gain;
  return y;
}

struct SimulatedCut {
  std::vector<double> accel_mps2;  // wall-normal, at the simulation's step
  double fs_hz{0.0}, rpm{0.0};
  bool chatter{false};
  double chatter_hz{0.0};
  std::string mechanism;
};

// One cut of config/milling/active_damping_c2.yaml (open, or damped at its controller's K = 2000 N s/m) with
// 10 um of runout on one tooth, 20 s; the wall-normal acceleration by differences.
SimulatedCut simulate(double rpm, double depth_mm, bool damped) {
  robodamp::config::MillingConfig job = robodamp::config::load_milling_config(std::string(ROBODAMP_SOURCE_DIR) +
                                                                              "/config/milling/active_damping_c2.yaml");
  job.time_domain.runout_um = {10.0, 0.0, 0.0};
  const ml::Structure structure(*job.find_structure(job.structure), damped);
  ml::CutOverrides o;
  o.rpm = rpm, o.axial_mm = depth_mm, o.revolutions = static_cast<int>(20.0 * rpm / 60.0), o.damped = damped;
  const ml::CutOutcome cut = ml::run_job(ml::make_cut_job(job, structure, o));
  SimulatedCut s;
  s.fs_hz = 1.0 / cut.record.step_s, s.rpm = cut.record.rpm;
  s.chatter = !cut.verdict.stable, s.chatter_hz = cut.verdict.chatter_hz,
  s.mechanism = ml::to_string(cut.verdict.classification);
  const auto& y = cut.record.y_m;
  for (std::size_t i = 2; i < y.size(); ++i)
    s.accel_mps2.push_back((y[i] - 2.0 * y[i - 1] + y[i - 2]) * s.fs_hz * s.fs_hz);
  return s;
}

// As a recorder holds it: resampled (linear) to rate_hz, with 0.01 m/s^2 of sensor noise, through the
// microphone when asked.
ml::RecordedSignal recorded(const SimulatedCut& c, double rate_hz, bool mic, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  ml::RecordedSignal sig;
  sig.source = "simulated cut", sig.rate_hz = rate_hz;
  const std::vector<double>& a = c.accel_mps2;
  for (double t = 0.0; t < static_cast<double>(a.size() - 1) / c.fs_hz; t += 1.0 / rate_hz) {
    const auto k = static_cast<std::size_t>(t * c.fs_hz);
    const double w = t * c.fs_hz - static_cast<double>(k);
    sig.samples.push_back((1.0 - w) * a[k] + w * a[k + 1] + noise(rng));
  }
  if (mic) sig.samples = microphone(sig.samples, rate_hz), sig.acceleration_mps2 = false, sig.unit = "Pa";
  return sig;
}

// The truth from the clean simulation: the chatter's onset is where the vibration the spindle does not repeat,
// a(t) - a(t - one revolution), rises above the indicator's floor (per revolution RMS) and stays there.
// Through the microphone: the clean signal through the same band, against the floor in pascals.
double truth_onset_s(const SimulatedCut& c, bool mic, double floor) {
  const std::vector<double> x = mic ? microphone(c.accel_mps2, c.fs_hz) : c.accel_mps2;
  const auto per = static_cast<std::size_t>(std::lround(c.fs_hz * 60.0 / c.rpm));
  double onset = 0.0;
  for (std::size_t b = per; b + per <= x.size(); b += per) {
    double e = 0.0;
    for (std::size_t i = b; i < b + per; ++i) e += std::pow(x[i] - x[i - per], 2);
    if (std::sqrt(e / static_cast<double>(per)) <= floor) onset = static_cast<double>(b + per) / c.fs_hz;
  }
  return onset;
}

// Cuts simulated in time with known truth, open and damped, Hopf and flip, with runout and sensor noise,
// recorded at 10, 25.6 and 48 kHz, by an accelerometer and by a microphone (its band and no floor of its own:
// --floor in pascals). The speed is estimated from the recording. The open loop's limits by SDM: 1.111 mm at
// 700 rpm (Hopf, 23.8 Hz), 0.220 mm at 381 rpm (flip, 9.5 Hz); damped at K = 2000 N s/m: 0.782 mm at
// 699.3 rpm (`lobes --job config/milling/active_damping_c2.yaml --damped --rpm 700 381`). The speed is
// estimated from the recording, except for the flip: its lines (half the tooth frequency and its odd
// multiples) and the teeth's make a comb at half the spindle speed, so the recording alone says 190 rpm as
// well as 381 (`estimate_rpm` finds neither within 300-3000 rpm and says to give --rpm).
TEST(ChatterListen, SimulatedCutsOpenAndDampedHopfAndFlipAtThreeRatesAndThroughAMicrophone) {
  struct Case {
    const char* what;
    double rpm, depth_mm;
    bool damped;
  };
  const Case cases[] = {{"open 700 rpm below", 700.0, 0.8, false},  {"open 700 rpm above (Hopf)", 700.0, 1.5, false},
                        {"open 381 rpm below", 381.0, 0.15, false}, {"open 381 rpm above (flip)", 381.0, 0.35, false},
                        {"damped 700 rpm below", 700.0, 0.6, true}, {"damped 700 rpm above (Hopf)", 700.0, 1.1, true}};
  for (const Case& c : cases) {
    const SimulatedCut cut = simulate(c.rpm, c.depth_mm, c.damped);
    for (const double rate : {10000.0, 25600.0, 48000.0}) {
      for (const bool mic : {false, true}) {
        ml::ListenSettings s = settings();
        if (mic) s.floor = 0.05 * 0.3;
        const double onset = cut.chatter ? truth_onset_s(cut, mic, mic ? 0.05 * 0.3 : 0.05) : 0.0;
        if (cut.mechanism == std::string("flip")) s.rpm = cut.rpm;  // see above
        const ml::ListenReport r = ml::listen(recorded(cut, rate, mic, 11), s);
        const std::string what =
            std::string(c.what) + " at " + std::to_string(static_cast<int>(rate)) + " Hz" + (mic ? ", microphone" : "");
        EXPECT_NEAR(r.rpm, cut.rpm, 0.01 * cut.rpm) << what << ": " << r.rpm_source;
        int right = 0, judged = 0;
        for (const auto& w : r.windows) {
          if (w.start_s < 2.0 || (cut.chatter && w.end_s > onset && w.start_s < onset + 1.0))
            continue;  // the entry; the onset's
          ++judged;
          const bool should = cut.chatter && w.start_s >= onset;
          right += w.verdict == (should ? ml::WindowVerdict::kChatter : ml::WindowVerdict::kStable);
        }
        std::printf(
            "%-28s %5.1f kHz %-4s: %s %s %.2f Hz (truth %s %.2f Hz), onset %.2f s (truth %.2f s), %d of %d windows "
            "right\n",
            c.what, rate / 1000.0, mic ? "mic" : "acc", r.onset_s ? "chatter" : "stable", "", r.chatter_hz,
            cut.mechanism.c_str(), cut.chatter_hz, r.onset_s.value_or(0.0), onset, right, judged);
        EXPECT_GE(right, (95 * judged + 99) / 100) << what;
        EXPECT_EQ(r.onset_s.has_value(), cut.chatter) << what;
        if (cut.chatter && r.onset_s) {
          EXPECT_NEAR(*r.onset_s, onset, 0.2) << what;
          EXPECT_NEAR(r.chatter_hz, cut.chatter_hz, 0.01 * cut.chatter_hz) << what;
        }
      }
    }
  }
}

// Without runout only the tooth-passing comb is there: the speed is the comb's fundamental / teeth.
TEST(ChatterListen, TheSpeedFromATeethOnlyComb) {
  std::vector<double> x;
  const double rate = 2500.0, f_tooth = 3.0 * kRpm / 60.0;
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < 20000; ++i)
    x.push_back(noise(rng) + 0.4 * std::sin(2.0 * M_PI * f_tooth * i / rate) +
                0.2 * std::sin(2.0 * M_PI * 2.0 * f_tooth * i / rate + 1.0) +
                0.1 * std::sin(2.0 * M_PI * 3.0 * f_tooth * i / rate + 2.0));
  const auto e = ml::estimate_rpm(x, rate, kTeeth, 300.0, 3000.0);
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(e->rpm, kRpm, 0.01 * kRpm) << e->how;
  EXPECT_NE(e->how.find("tooth-passing harmonics"), std::string::npos) << e->how;
}

// The speed changes in the recording (a speed column; a robodamp recording's spindle commands): each window
// is judged at the speed that held over it. 700 rpm with chatter for 8 s, then 900 rpm stable: at one
// speed for the whole recording, the 900 rpm lines would read as non-harmonic.
TEST(ChatterListen, EachWindowAtTheSpeedTheRecordingHeld) {
  const TempDir tmp;
  const double rate = 5000.0;
  std::mt19937 rng(8);
  std::normal_distribution<double> noise(0.0, 0.01);
  {
    std::ofstream csv(tmp.file("two_speeds.csv"));
    csv << "t,accel_mps2,spindle_rpm\n";
    for (int i = 0; i < static_cast<int>(16.0 * rate); ++i) {
      const double t = i / rate, rpm = t < 8.0 ? 700.0 : 900.0, f_sp = rpm / 60.0;
      double v = noise(rng);
      for (int k = 1; k <= 30; ++k)
        v += (k % kTeeth == 0 ? 0.4 : 0.05) / std::sqrt(k) * std::sin(2.0 * M_PI * k * f_sp * t + 0.7 * k);
      if (t < 8.0) v += 1.5 * std::sin(2.0 * M_PI * kChatterHz * t);
      csv << t << ',' << v << ',' << rpm << '\n';
    }
  }
  const std::string json = tmp.file("c.json");
  const Result r =
      run("chatter --signal " + tmp.file("two_speeds.csv") + " --teeth 3 --rpm-column spindle_rpm --json " + json);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(robodamp::test::read_file(json));
  ASSERT_EQ(j["windows"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(j["windows"][i]["rpm"].get<double>(), i < 2 ? 700.0 : 900.0) << i;
    EXPECT_EQ(j["windows"][i]["verdict"], i < 2 ? "chatter" : "stable") << i << "\n" << r.out;
  }
  EXPECT_NE(j["rpm_source"].get<std::string>().find("the column 'spindle_rpm'"), std::string::npos);
  // A robodamp recording: its spindle command gives the speed.
  const std::string rec = tmp.file("run.rdrec");
  const Result ran = run("run --config " + robodamp::test::preset("horizontal_c2") +
                         " --duration 5 --clock virtual --spindle-rpm 700 --record " + rec);
  ASSERT_EQ(ran.status, 0) << ran.out;
  const Result heard = run("chatter --signal " + rec + " --teeth 3 --json " + json);
  ASSERT_EQ(heard.status, 0) << heard.out;
  const auto h = nlohmann::json::parse(robodamp::test::read_file(json));
  EXPECT_NE(h["rpm_source"].get<std::string>().find("the recording's spindle commands"), std::string::npos)
      << heard.out;
  EXPECT_EQ(h["windows"].back()["rpm"].get<double>(), 700.0) << heard.out;
  EXPECT_EQ(h["rate_hz"].get<double>(), 5000.0);
}

}  // namespace
