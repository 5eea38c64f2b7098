// Cutting tests from raw force records (docs/identification.md, "Cutting tests from force records"): one
// time series per test, as a dynamometer or a logger exports it (measfiles/table.hpp: any delimiter,
// decimal comma, preamble, units in the header), in; the mean forces of its steady cut out, for
// identify_cutting. The steady cut is found, not guessed: whole spindle revolutions; the ones with cutting
// in them tell themselves from air by the tooth-passing fluctuation; the charge amplifier's offset and
// drift are fitted in the air before and after the cut and removed; of the cutting revolutions, the longest
// run whose means agree (the entry and the exit left out) is averaged. Whole revolutions average a
// runout out. Off the real-time path.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "identify/cutting_coefficients.hpp"

namespace robodamp::identify {

// The cutter frame from the record's columns: cutter x, y, z = sign * the record's Fx, Fy or Fz.
struct AxisMap {
  std::array<int, 3> column{0, 1, 2};
  std::array<double, 3> sign{1.0, 1.0, 1.0};
};
// "fx,fy,fz" (the default), "-fy,fx,fz", ...: each of fx, fy, fz once, a sign optional. Throws
// std::invalid_argument naming the text.
[[nodiscard]] AxisMap parse_axes(const std::string& text);

struct RecordSettings {
  AxisMap axes;
  bool force_on_workpiece{true};  // a table dynamometer under the workpiece: the tool's force is the opposite
};

struct ForceRecord {
  std::string source;
  double fs_hz{0.0};
  std::vector<double> t_s;
  std::array<std::vector<double>, 3> f_n;  // the record's Fx, Fy, Fz in N
};
// Columns time, Fx, Fy, Fz by name (time, t; fx, force_x; ...) with their units, or by position without a
// header; a constant sample rate. Throws std::invalid_argument naming the file and line.
[[nodiscard]] ForceRecord read_force_record(const std::string& path);

struct SteadyCut {
  MeanForces means;  // on the tool, in the cutter frame
  double start_s{0.0}, end_s{0.0};
  int revolutions{0};                                 // whole revolutions averaged
  int cutting_revolutions{0};                         // revolutions with cutting in them
  std::array<double, 3> offset_n{}, drift_n_per_s{};  // removed, in the record's axes
  std::string drift_from;                             // where the offset and drift were measured
  double spread_pct{0.0};  // largest revolution mean's departure from the average, % of its magnitude
  // The share of the force's variance in the steady cut that repeats with every revolution (the
  // revolution-synchronous average's): near 1 for a cut at the stated speed, near 0 for noise.
  double periodic_share{0.0};
};
// Below it a record is refused: its forces do not repeat with the stated spindle speed.
inline constexpr double kMinPeriodicShare = 0.5;

// Throws std::invalid_argument naming the record: too short, no cutting found, no steady run of 3
// revolutions.
[[nodiscard]] SteadyCut steady_cut(const ForceRecord& r, double spindle_rpm, double feed_per_tooth_mm,
                                   const RecordSettings& s);

// One line per test in a table: file, feed_per_tooth_mm, spindle_rpm (files relative to the table).
struct RecordTest {
  std::string file;
  double feed_per_tooth_mm{0.0};
  double spindle_rpm{0.0};
};
[[nodiscard]] std::vector<RecordTest> read_record_tests(const std::string& path);

}  // namespace robodamp::identify
