#include "commission/hil_critical.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "commission/emulated_cell.hpp"

namespace robodamp::commission {

namespace {
constexpr double kHilRelTol = 1e-2;  // each step of the emulator's bisection is a pair of processes
}  // namespace

nlohmann::json hil_critical_json(const std::string& cell_path, const std::string& job_path, bool damped,
                                 const milling::CutJob& job, double rpm, double in_process_mm) {
  const config::Config cell = config::load_config_file(cell_path);
  config::Config controller = cell;
  if (!damped) controller.controller.gain_ns_per_m = 0.0;
  const std::string dir = (std::filesystem::temp_directory_path() /
                           ("robodamp_cut_hil_" + std::to_string(::getpid()) + "_" + std::to_string(std::lround(rpm))))
                              .string();
  const auto t0 = std::chrono::steady_clock::now();
  const EmulatedCritical c = critical_through_emulator(
      cell, controller, {this_executable(), cell_path, job_path, job.settings.revolutions}, rpm, in_process_mm,
      kHilRelTol, dir, [](const std::string& line) { std::cerr << "[cut hil] " << line << '\n'; });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "          through the HIL emulator (%s): critical %.4f mm at %.1f rpm (%+.1f %% against in process), above it "
      "%s at %.1f Hz; %d cuts across processes in %.1f s\n",
      cell_path.c_str(), c.depth_mm, c.rpm, (c.depth_mm / in_process_mm - 1.0) * 100.0, c.above.c_str(), c.chatter_hz,
      c.cuts, wall);
  return {{"cell", cell_path},          {"rpm", c.rpm},   {"critical_depth_mm", c.depth_mm}, {"above", c.above},
          {"chatter_hz", c.chatter_hz}, {"cuts", c.cuts}, {"rel_tol", kHilRelTol},           {"wall_s", wall}};
}

}  // namespace robodamp::commission
