#include "commission/emulated_cell.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "analysis/modal_test.hpp"
#include "config/number_range.hpp"
#include "identify/commissioning.hpp"
#include "identify/modal_fit.hpp"
#include "runtime/cell.hpp"
#include "sim_plant/plant_model.hpp"
#include "threads/worker.hpp"

extern char** environ;

namespace robodamp::commission {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kEmulatorEndS = 60.0;        // after the controller leaves: the emulator writes its files and ends
constexpr double kEmulatorRampMarginS = 2.0;  // after settle and the gain ramp: the loop at full gain

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Lockstep is a ping-pong: one frame each way per tick. On one CPU each hand-over is a context switch; on
// two it is a cross-CPU wake-up, and a run took 10x longer (20 s of plant time: 0.7 s on one CPU, 8.0 s
// split, this VM). The emulator and the controller's threads (created while the calling thread is pinned,
// so they inherit it) share the CPU the caller is on.
class PinnedToOneCpu {
 public:
  PinnedToOneCpu() {
    have_old_ = sched_getaffinity(0, sizeof old_, &old_) == 0;
    cpu_ = sched_getcpu();
    if (cpu_ < 0 || !have_old_) return;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu_, &one);
    (void)sched_setaffinity(0, sizeof one, &one);
  }
  ~PinnedToOneCpu() {
    if (have_old_) (void)sched_setaffinity(0, sizeof old_, &old_);
  }
  PinnedToOneCpu(const PinnedToOneCpu&) = delete;
  PinnedToOneCpu& operator=(const PinnedToOneCpu&) = delete;
  void pin(pid_t pid) const {
    if (cpu_ < 0) return;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu_, &one);
    (void)sched_setaffinity(pid, sizeof one, &one);
  }

 private:
  cpu_set_t old_{};
  bool have_old_{false};
  int cpu_{-1};
};

// The controller side of one run: the runtime cell on `cfg` (its CAN and Modbus drivers), on the virtual
// clock (the emulator paces in lockstep), counting the ticks with the loop active over a window.
struct ControllerRun {
  std::string trip{"none"};
  double active_share{0.0};
  unsigned long long saturated_ticks{0};
  unsigned long long pose_out_of_map{0};
};

// Ends the cell's run when no fresh sensor sample has arrived for stall_s of wall time; joined on every path.
class StallWatch {
 public:
  StallWatch(runtime::Cell& cell, double stall_s) : stall_s_(stall_s) {
    worker_.start("rd-stall-watch", [this, &cell](std::stop_token stop) { watch(cell, stop); });
  }
  ~StallWatch() { worker_.stop(); }
  StallWatch(const StallWatch&) = delete;
  StallWatch& operator=(const StallWatch&) = delete;
  void fresh() noexcept { fresh_.fetch_add(1, std::memory_order_relaxed); }
  [[nodiscard]] bool stalled() const noexcept { return stalled_.load(); }

 private:
  void watch(runtime::Cell& cell, std::stop_token stop) {
    using Clock = std::chrono::steady_clock;
    std::uint64_t seen = fresh_.load();
    auto since = Clock::now();
    while (worker_.sleep_for(stop, std::chrono::milliseconds(200))) {
      if (const std::uint64_t now = fresh_.load(); now != seen) {
        seen = now, since = Clock::now();
      } else if (std::chrono::duration<double>(Clock::now() - since).count() > stall_s_) {
        stalled_ = true;
        cell.request_stop();
        return;
      }
    }
  }
  const double stall_s_;
  std::atomic<std::uint64_t> fresh_{0};
  std::atomic<bool> stalled_{false};
  threads::Worker worker_;  // last: started after what it reads
};

ControllerRun run_controller(const config::Config& cfg, double duration_s, double from_s, double to_s,
                             const EmulatorProcess& emulator, double stall_wall_s = EmulatedCut{}.stall_wall_s) {
  const PinnedToOneCpu pinned;
  pinned.pin(emulator.pid());
  runtime::CellOptions o;
  o.clock = config::ClockKind::kVirtual;
  std::uint64_t in = 0, active = 0;         // written on the drain thread, read after wait()
  std::atomic<StallWatch*> watch{nullptr};  // set once the loop runs, cleared after the drain has stopped
  o.on_frame = [&](const rt::TelemetryFrame& f) {
    if (StallWatch* w = watch.load(); w != nullptr && (f.flags & rt::kFlagFresh)) w->fresh();
    if (f.time_s < from_s || f.time_s >= to_s) return;
    ++in;
    if (f.state == static_cast<std::uint8_t>(rt::State::kActive)) ++active;
  };
  runtime::Cell cell(cfg, o);
  if (runtime::Status s = cell.configure(); !s.ok())
    throw std::runtime_error("the controller could not reach the emulator: " + s.message + "; the emulator's log " +
                             emulator.log_path() + ": " + emulator.log_tail());
  if (runtime::Status s = cell.activate(duration_s); !s.ok()) throw std::runtime_error("the controller: " + s.message);
  bool stalled = false;
  {
    StallWatch w(cell, stall_wall_s);  // from the loop's start: an activation's own waits are bounded by their timeouts
    watch.store(&w);
    cell.wait();
    stalled = w.stalled();
    (void)cell.deactivate();  // the drain thread (on_frame) has ended: w may go
    watch.store(nullptr);
  }
  if (stalled)
    throw std::runtime_error("the lockstep stalled: no fresh sensor sample for " + config::format_number(stall_wall_s) +
                             " s of wall time; the emulator's log " + emulator.log_path() + ": " + emulator.log_tail());
  ControllerRun r;
  r.trip = cell.summary().trip;
  r.saturated_ticks = cell.summary().supervisor.saturated_ticks;
  r.pose_out_of_map = cell.summary().supervisor.pose_out_of_map;
  r.active_share = in == 0 ? 0.0 : static_cast<double>(active) / static_cast<double>(in);
  return r;
}

void expect_exit_zero(EmulatorProcess& p, const std::string& what) {
  const int rc = p.wait(kEmulatorEndS);
  if (rc != 0)
    throw std::runtime_error(
        "the emulator (" + what + ") " +
        (rc < 0 ? "did not end within " + config::format_number(kEmulatorEndS) + " s of the controller"
                : "exited with " + std::to_string(rc)) +
        "; its log " + p.log_path() + ": " + p.log_tail());
}

analysis::FrfEstimate read_estimate(const fs::path& p) {
  if (!fs::exists(p)) throw std::runtime_error(p.string() + " is missing: the emulator did not measure it");
  const identify::FrfData d = identify::read_frf_csv(p.string(), identify::FrfKind::kReceptance);
  analysis::FrfEstimate e;
  e.f_hz = d.f_hz, e.h1 = d.h, e.coherence = d.coherence;
  if (e.coherence.empty()) e.coherence.assign(e.f_hz.size(), 1.0);
  return e;
}

}  // namespace

std::string this_executable() {
  // The running executable itself, even when a rebuild has replaced the file at its path since it started
  // (the path would then start another version).
  if (::access("/proc/self/exe", X_OK) != 0)
    throw std::runtime_error("cannot run this executable again (/proc/self/exe)");
  return "/proc/self/exe";
}

EmulatorProcess::EmulatorProcess(const std::string& binary, const std::vector<std::string>& args,
                                 const std::string& log_path)
    : log_(log_path) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<std::string> copy{binary};
  copy.insert(copy.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int rc = posix_spawn(&pid_, binary.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("cannot start the emulator " + binary + ": " + std::strerror(rc));
}

EmulatorProcess::~EmulatorProcess() {
  if (pid_ > 0 && !reaped_) {
    ::kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

int EmulatorProcess::wait(double timeout_s) {
  if (reaped_) return -1;
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      reaped_ = true;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    }
    if (Clock::now() >= end) {
      ::kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      reaped_ = true;
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string EmulatorProcess::log_tail(std::size_t lines) const {
  std::ifstream in(log_);
  std::deque<std::string> last;
  for (std::string l; std::getline(in, l);) {
    last.push_back(l);
    if (last.size() > lines) last.pop_front();
  }
  std::string s;
  for (const auto& l : last) s += (s.empty() ? "" : " | ") + l;
  return s.empty() ? "(empty)" : s;
}

MeasureOutcome measure_through_emulator(const std::string& cell_path, const std::string& out_dir,
                                        const std::string& binary, const EmulatedMeasure& e) {
  fs::create_directories(out_dir);
  const fs::path dir(out_dir);
  std::vector<std::string> args{
      "plant", "--config", cell_path, "--pacing", "lockstep", "--json", (dir / "plant.json").string()};
  if (e.options.impacts)
    args.insert(args.end(), {"--measure-out", out_dir});
  else
    args.emplace_back("--no-impacts");  // a real cell: nobody swings robodamp's hammer
  EmulatorProcess plant(binary, args, (dir / "plant.log").string());
  MeasureOutcome o;
  {
    const PinnedToOneCpu pinned;
    pinned.pin(plant.pid());
    MeasureOptions mo = e.options;
    mo.clock = "virtual";
    o = e.controller ? measure(*e.controller, cell_path, out_dir, mo) : measure(cell_path, out_dir, mo);
  }
  const int rc = plant.wait(kEmulatorEndS);
  if (rc != 0) {
    if (o.status == MeasureStatus::kOk) o.status = MeasureStatus::kFailed;
    o.message += (o.message.empty() ? "" : "; ") + std::string("the emulator (robodamp plant --measure-out) ") +
                 (rc < 0 ? "did not end" : "exited with " + std::to_string(rc)) + "; its log " + plant.log_path() +
                 ": " + plant.log_tail();
    return o;
  }
  if (!e.options.impacts) return o;
  const auto j = nlohmann::json::parse(text_of(dir / "plant.json"));
  o.impact_records = j["measurement"]["records"].get<int>();
  o.impact_records_planned = j["measurement"]["records_planned"].get<int>();
  o.frf_files = j["measurement"]["files"].size();
  if (o.status == MeasureStatus::kOk && o.impact_records < o.impact_records_planned) {
    o.status = MeasureStatus::kIncomplete;
    o.message = "the emulator measured " + std::to_string(o.impact_records) + " of " +
                std::to_string(o.impact_records_planned) + " impact records";
  }
  return o;
}

std::vector<std::string> with_trajectory(std::vector<std::string> args, const std::vector<std::string>& trajectory) {
  for (const auto& w : trajectory) args.insert(args.end(), {"--pose-at", w});
  return args;
}

PathMeasureOutcome measure_along_path_through_emulator(const config::Config& cell, const std::string& cell_path,
                                                       const std::string& out_dir, const std::string& binary,
                                                       const std::vector<std::string>& trajectory,
                                                       const PathMeasureOptions& o) {
  fs::create_directories(out_dir);
  const fs::path dir(out_dir);
  EmulatorProcess plant(binary,
                        with_trajectory({"plant", "--config", cell_path, "--pacing", "lockstep", "--measure-out",
                                         out_dir, "--json", (dir / "plant.json").string()},
                                        trajectory),
                        (dir / "plant.log").string());
  PathMeasureOutcome r;
  {
    const PinnedToOneCpu pinned;
    pinned.pin(plant.pid());
    PathMeasureOptions po = o;
    po.measure.clock = "virtual";
    r = measure_along_path(cell, cell_path, out_dir, po);
  }
  if (r.run.status != MeasureStatus::kOk) return r;  // the emulator ends with the controller gone (killed if not)
  expect_exit_zero(plant, "the measurement along the path");
  return r;
}

EmulatedPathRun run_along_path_through_emulator(const config::Config& controller, const std::string& cell_path,
                                                const std::string& binary, const std::vector<std::string>& trajectory,
                                                double duration_s, const std::string& dir) {
  const fs::path d(dir);
  fs::create_directories(d);
  EmulatorProcess plant(
      binary,
      with_trajectory({"plant", "--config", cell_path, "--pacing", "lockstep", "--json", (d / "plant.json").string()},
                      trajectory),
      (d / "plant.log").string());
  const double from_s = controller.hil.settle_s;
  const ControllerRun c = run_controller(controller, duration_s, from_s, duration_s, plant);
  expect_exit_zero(plant, "the run along the path");
  EmulatedPathRun r;
  r.trip = c.trip;
  r.active_share = c.active_share;
  r.saturated_ticks = c.saturated_ticks;
  r.pose_out_of_map = c.pose_out_of_map;
  const nlohmann::json report = nlohmann::json::parse(text_of(d / "plant.json"));  // held: the loop reads into it
  for (const auto& j : report["pose"]["dwells"]) {
    EmulatedDwell w;
    w.joints_deg = j["joints_deg"].get<std::vector<double>>();
    w.t0_s = j["t0_s"].get<double>(), w.t1_s = j["t1_s"].get<double>();
    w.records = j["records"].get<int>();
    w.measured_improvement_pct = j["measured_improvement_pct"].get<double>();
    w.coherence_min = j["coherence_min"].get<double>();
    w.dominant_hz = j["dominant_hz"].get<double>();
    r.dwells.push_back(std::move(w));
  }
  return r;
}

CutTrial cut_through_emulator(const config::Config& cell, const config::Config& controller, const EmulatedCut& e,
                              double rpm, double depth_mm, const std::string& dir) {
  CutTrial t;
  t.requested_rpm = rpm;
  t.depth_mm = depth_mm;
  const fs::path d(dir);
  fs::create_directories(d);
  const double start_s = cell.commissioning.settle_s + controller.controller.gain_ramp_s + kEmulatorRampMarginS;
  const double cut_s = e.revolutions * 60.0 / rpm;
  EmulatorProcess plant(e.binary,
                        {"plant", "--config", e.cell_path, "--pacing", "lockstep", "--no-impacts", "--drives-off",
                         "--cut", e.job_path, "--cut-rpm", config::format_number(rpm), "--cut-axial-mm",
                         config::format_number(depth_mm), "--cut-revs", std::to_string(e.revolutions), "--cut-at",
                         config::format_number(start_s), "--json", (d / "plant.json").string()},
                        (d / "plant.log").string());
  // The emulator's speed is within half a loop period per tooth of the request: 2 % more time covers it.
  const ControllerRun c =
      run_controller(controller, start_s + 1.02 * cut_s + 1.0, start_s, start_s + cut_s, plant, e.stall_wall_s);
  expect_exit_zero(plant, "cut");
  const auto j = nlohmann::json::parse(text_of(d / "plant.json"))["regenerative_cut"];
  t.rpm = j["rpm"].get<double>();
  t.complete = j["complete"].get<bool>();
  t.stable = j["stable"].get<bool>();
  t.classification = j["classification"].get<std::string>();
  t.chatter_hz = j["chatter_hz"].is_number() ? j["chatter_hz"].get<double>() : 0.0;
  t.trip = c.trip;
  t.active_share = c.active_share;
  return t;
}

EmulatedCritical critical_through_emulator(const config::Config& cell, const config::Config& controller,
                                           const EmulatedCut& e, double rpm, double guess_mm, double rel_tol,
                                           const std::string& dir,
                                           const std::function<void(const std::string&)>& progress) {
  EmulatedCritical r;
  int n = 0;
  auto trial = [&](double depth) {
    CutTrial t = cut_through_emulator(cell, controller, e, rpm, depth, dir + "/cut_" + std::to_string(++n));
    // A cut that chatters hard enough trips the damper (instability, saturation): not stable either.
    if (t.trip != "none")
      t.stable = false, t.classification = "tripped the damper (" + t.trip + ")";
    else if (!t.complete)
      throw std::runtime_error("the emulator's cut at " + config::format_number(depth) + " mm did not complete");
    r.rpm = t.rpm;
    if (progress)
      progress(
          "depth " + config::format_number(depth) + " mm: " +
          (t.stable ? std::string("stable") : t.classification + " at " + config::format_number(t.chatter_hz) + " Hz"));
    return t;
  };
  // Doubled or halved from the guess until the verdict changes, then halved to rel_tol, as in process.
  double lo = 0.0, hi = 0.0;
  CutTrial t = trial(guess_mm);
  if (t.stable) {
    lo = guess_mm;
    for (double d = 2.0 * guess_mm;; d *= 2.0) {
      t = trial(d);
      if (!t.stable) {
        hi = d;
        break;
      }
      lo = d;
      if (n > 12) throw std::runtime_error("no chatter up to " + config::format_number(d) + " mm");
    }
  } else {
    hi = guess_mm;
    for (double d = 0.5 * guess_mm;; d *= 0.5) {
      t = trial(d);
      if (t.stable) {
        lo = d;
        break;
      }
      hi = d;
      if (n > 12) throw std::runtime_error("chatter down to " + config::format_number(d) + " mm");
    }
  }
  CutTrial above = t.stable ? CutTrial{} : t;
  while (hi - lo > rel_tol * hi) {
    const double mid = 0.5 * (lo + hi);
    t = trial(mid);
    if (t.stable)
      lo = mid;
    else
      hi = mid, above = t;
  }
  if (above.classification == "not run") above = trial(hi);
  r.depth_mm = lo;
  r.above = above.classification;
  r.chatter_hz = above.chatter_hz;
  r.cuts = n;
  return r;
}

CellCheck check_through_emulator(const config::Config& cell, const config::Config& tuned,
                                 const tune::Verification& promise, const EmulatedCheckFiles& f) {
  const auto t0 = Clock::now();
  CellCheck out;
  out.cell = "the HIL emulator (robodamp plant in a second process, lockstep) through the CAN and Modbus drivers";
  const fs::path work(f.work_dir);
  fs::create_directories(work / "impacts");

  // The impacts with the tuned controller; the measurement was the same schedule with control off.
  const analysis::CommissioningPlan plan = analysis::commissioning_plan(cell, sim::build_plant_model(cell));
  {
    EmulatorProcess plant(f.binary,
                          {"plant", "--config", f.cell_path, "--pacing", "lockstep", "--measure-out",
                           (work / "impacts").string(), "--json", (work / "impacts" / "plant.json").string()},
                          (work / "impacts" / "plant.log").string());
    const ControllerRun c =
        run_controller(tuned, plan.duration_s, plan.impacts_start_s.front(), plan.duration_s - 1.0, plant);
    expect_exit_zero(plant, "impacts");
    out.closed_trip = c.trip;
    out.closed_active_share = c.active_share;
    out.closed_saturated_ticks = c.saturated_ticks;
  }
  out.open_trip = identify::read_manifest(f.measurement_dir).run.value("trip", std::string("none"));
  std::map<fs::path, analysis::FrfEstimate> cache;
  auto from = [&cache](const fs::path& dir) {
    return [&cache, dir](int e, int r) -> const analysis::FrfEstimate& {
      const fs::path p = dir / analysis::frf_file_name(r, e);
      auto it = cache.find(p);
      if (it == cache.end()) it = cache.emplace(p, read_estimate(p)).first;
      return it->second;
    };
  };
  out.frfs = frf_checks(tuned, from(f.measurement_dir), from(work / "impacts"));

  // The regenerative cut at each promised speed, at the promise less the tolerance.
  const EmulatedCut ec{f.binary, f.cell_path, f.job_path, f.cut_revolutions};
  const std::pair<double, double> points[] = {{promise.min_rpm, promise.min_depth_mm},
                                              {promise.speed_rpm, promise.depth_at_speed_mm}};
  for (std::size_t i = 0; i < 2; ++i) {
    const CutTrial t =
        cut_through_emulator(cell, tuned, ec, points[i].first, (1.0 - out.depth_tolerance) * points[i].second,
                             (work / ("cut_" + std::to_string(i + 1))).string());
    spdlog::info("commission: the regenerative cut in the emulator, {:.3f} mm at {:.1f} rpm: {}", t.depth_mm, t.rpm,
                 t.classification);
    out.cut_trials.push_back(t);
  }
  out.time_domain_at_min_mm = out.cut_trials[0].held() ? out.cut_trials[0].depth_mm : 0.0;
  out.time_domain_at_speed_mm = out.cut_trials[1].held() ? out.cut_trials[1].depth_mm : 0.0;
  out.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

}  // namespace robodamp::commission
