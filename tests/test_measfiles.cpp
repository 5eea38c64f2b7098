// Universal files and tables as instruments write them (measfiles/, identify/uff_frf.hpp): round trips,
// files written by hand from the format's specification in several layouts, units, refusals and a fuzz.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "identify/uff_frf.hpp"
#include "measfiles/table.hpp"
#include "measfiles/uff.hpp"
#include "modal/receptance.hpp"
#include "sim_plant/excitation.hpp"
#include "sim_plant/plant.hpp"
#include "sim_plant/plant_model.hpp"
#include "test_util.hpp"

namespace {

using robodamp::measfiles::UffError;
using robodamp::measfiles::UffFile;
using robodamp::measfiles::UffFunction;
namespace mf = robodamp::measfiles;

struct TempDir : robodamp::test::ScratchDir {
  TempDir() : ScratchDir("measfiles") {}
};

// A value as the ASCII writer prints it: E20.12 (12 significant digits) or E13.5 (6).
double as_written(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*E", digits - 1, v);
  return std::strtod(b, nullptr);
}

UffFile sample_file() {
  UffFile file;
  file.nodes = {{1, {0.0, 0.0, 0.0}}, {2, {0.25, -0.125, 1.5}}};
  UffFunction frf;
  frf.id[0] = "H21 accelerance";
  frf.response_node = 2, frf.response_direction = 2, frf.reference_node = 1, frf.reference_direction = -3;
  frf.abscissa = {mf::kUffFrequency, 0, 0, 0, "Frequency", "Hz"};
  frf.ordinate = {mf::kUffAcceleration, 1, 0, 0, "Acceleration", "m/s^2"};
  frf.denominator = {mf::kUffExcitationForce, 0, 1, 0, "Force", "N"};
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 0; k < 37; ++k) frf.x.push_back(0.25 * k), frf.y.emplace_back(n(rng) * 1e-3, n(rng) * 1e5);
  UffFunction coherence = frf;
  coherence.function_type = mf::kUffCoherence, coherence.is_complex = false;
  for (auto& y : coherence.y) y = {std::abs(y.real()) / (1.0 + std::abs(y.real())), 0.0};
  UffFunction uneven = frf;  // uneven abscissa, complex
  uneven.id[0] = "uneven";
  for (std::size_t k = 0; k < uneven.x.size(); ++k) {
    const auto kk = static_cast<double>(k);
    uneven.x[k] = 1.0 + 0.37 * kk * kk + 1e-7 * kk;
  }
  UffFunction history;  // a real time history, uneven
  history.function_type = mf::kUffTimeResponse, history.is_complex = false;
  history.abscissa = {mf::kUffTime, 0, 0, 0, "Time", "s"};
  for (int k = 0; k < 11; ++k)
    history.x.push_back(std::sqrt(k + 0.5)), history.y.emplace_back(std::sin(k) * 3.3e-7, 0.0);
  file.functions = {frf, coherence, uneven, history};
  mf::UffMode mode;
  mode.number = 2, mode.eigenvalue = {-1.5, 62.8}, mode.modal_a = {1.0, 0.0};
  mode.shape = {{1, {std::complex<double>{0.0, 0.0}, {1e-3, -2e-4}, {0.0, 0.0}}},
                {2, {std::complex<double>{0.0, 0.0}, {-5e-4, 1e-4}, {0.0, 0.0}}}};
  file.modes = {mode};
  return file;
}

// Issue 48: robodamp -> UFF -> robodamp, ASCII to the last digit written, binary exactly.
TEST(Uff, RoundTripsAsciiToTheDigitsWrittenAndBinaryExactly) {
  const TempDir tmp;
  const UffFile original = sample_file();
  for (const auto encoding : {mf::UffEncoding::kAscii, mf::UffEncoding::kBinary}) {
    const bool binary = encoding == mf::UffEncoding::kBinary;
    const std::string path = tmp.file(binary ? "b.uff" : "a.uff");
    mf::write_uff(path, original, encoding);
    const UffFile back = mf::read_uff(path);
    ASSERT_EQ(back.functions.size(), original.functions.size());
    ASSERT_EQ(back.nodes.size(), 2u);
    EXPECT_DOUBLE_EQ(back.nodes[1].xyz[2], 1.5);
    for (std::size_t i = 0; i < original.functions.size(); ++i) {
      const UffFunction& a = original.functions[i];
      const UffFunction& b = back.functions[i];
      EXPECT_EQ(b.binary, binary);
      EXPECT_EQ(b.function_type, a.function_type);
      EXPECT_EQ(b.response_node, a.response_node);
      EXPECT_EQ(b.response_direction, a.response_direction);
      EXPECT_EQ(b.reference_direction, a.reference_direction);
      EXPECT_EQ(b.ordinate.units, a.ordinate.units);
      EXPECT_EQ(b.id[0], a.id[0]);
      ASSERT_EQ(b.x.size(), a.x.size());
      for (std::size_t k = 0; k < a.x.size(); ++k) {
        // An even abscissa comes back from its start and step; an uneven one as E13.5 (ASCII).
        const double x = binary || (a.x.size() == 37u && i < 2) ? a.x[k] : as_written(a.x[k], 6);
        EXPECT_EQ(b.x[k], x) << i << " " << k;
        EXPECT_EQ(b.y[k].real(), binary ? a.y[k].real() : as_written(a.y[k].real(), 12)) << i << " " << k;
        EXPECT_EQ(b.y[k].imag(), binary ? a.y[k].imag() : as_written(a.y[k].imag(), 12)) << i << " " << k;
      }
    }
    ASSERT_EQ(back.modes.size(), 1u);
    EXPECT_EQ(back.modes[0].number, 2);
    EXPECT_EQ(back.modes[0].shape[1].second[1], std::complex<double>(-5e-4, 1e-4));
    EXPECT_EQ(back.modes[0].eigenvalue, std::complex<double>(-1.5, 62.8));
    // Written twice, the same bytes.
    const std::string again = tmp.file("again.uff");
    mf::write_uff(again, back, encoding);
    if (!binary) {
      EXPECT_EQ(robodamp::test::read_file(again), robodamp::test::read_file(path));
    }
  }
}

// Layouts written by hand from the format's specification (dataset 58 records 1-12): the fixed columns
// with single-precision complex data (6E13.5), free spacing with CRLF, D exponents and fields run
// together, a 151 header and a 164 units dataset passed over, non-ASCII ID lines.
TEST(Uff, ReadsHandWrittenLayoutsOfTheSpecification) {
  const std::string fixed =
      "    -1\n"
      "   151\n"
      "model\ndescription\nprogram\ncreated\nsaved\ncreated by\n"
      "    -1\n"
      "    -1\n"
      "   164\n"
      "         1  SI: Meter (newton)         2\n"
      "  1.00000000000000000D+00  1.00000000000000000D+00  1.00000000000000000D+00\n"
      "  2.73150000000000000D+02\n"
      "    -1\n"
      "    -1\n"
      "    58\n"
      "Pr\xc3\xbc"
      "fstand \xc2\xb5-Test\nNONE\n27-Nov-26 10:00:00\nNONE\nNONE\n"
      "    4    1    1         0 NONE               3   2 NONE               1   2\n"
      "         5         3         1  1.00000E+01  2.50000E-01  0.00000E+00\n"
      "        18    0    0    0 Frequency            Hz                  \n"
      "        12    0    0    0 Acceleration         g                   \n"
      "        13    0    0    0 Force                lbf                 \n"
      "         0    0    0    0 NONE                 NONE                \n"
      "  1.00000E+00 -2.00000E+00  3.00000E+00 -4.00000E-01  5.00000E-01  6.00000E+00\n"
      "    -1\n";
  const UffFile a = mf::parse_uff(fixed, "fixed.uff");
  EXPECT_EQ(a.skipped_datasets, (std::vector<int>{151, 164}));
  ASSERT_EQ(a.functions.size(), 1u);
  const UffFunction& f = a.functions[0];
  EXPECT_EQ(f.id[0],
            "Pr\xc3\xbc"
            "fstand \xc2\xb5-Test");
  EXPECT_EQ(f.response_node, 3);
  EXPECT_EQ(f.reference_node, 1);
  EXPECT_FALSE(f.double_precision);
  ASSERT_EQ(f.x.size(), 3u);
  EXPECT_DOUBLE_EQ(f.x[2], 10.5);
  EXPECT_EQ(f.y[1], std::complex<double>(3.0, -0.4));
  EXPECT_EQ(f.ordinate.units, "g");
  // g per lbf as accelerance in SI.
  const auto u = robodamp::identify::frf_units(f, 1);
  EXPECT_EQ(u.kind, robodamp::identify::FrfKind::kAccelerance);
  EXPECT_NEAR(u.to_si, 9.80665 / 4.4482216152605, 1e-12);

  // The same function spaced freely, CRLF, D exponents, the data run together, real double uneven.
  const std::string free_form =
      "    -1\r\n    58\r\nid\r\n\r\n\r\n\r\n\r\n"
      "4 0 0 0 NONE 3 2 NONE 1 2\r\n"
      "4 3 0 0.0 0.0 0.0\r\n"
      "18 0 0 0 Frequency Hz\r\n"
      "8 0 0 0 Displacement mm\r\n"
      "13 0 0 0 Force kN\r\n"
      "0 0 0 0 NONE NONE\r\n"
      "  1.00000E+01 1.0D-03  1.02500E+01-2.500000000000E-03\r\n"
      " 1.05000E+01  7.5E-3\r\n"
      "    -1\r\n";
  const UffFile b = mf::parse_uff(free_form, "free.uff");
  ASSERT_EQ(b.functions.size(), 1u);
  EXPECT_FALSE(b.functions[0].even);
  EXPECT_DOUBLE_EQ(b.functions[0].x[1], 10.25);
  EXPECT_DOUBLE_EQ(b.functions[0].y[1].real(), -2.5e-3);
  EXPECT_DOUBLE_EQ(b.functions[0].y[2].real(), 7.5e-3);
  EXPECT_NEAR(robodamp::identify::frf_units(b.functions[0], 1).to_si, 1e-3 / 1e3, 1e-18);  // mm/kN in m/N

  // Big-endian single-precision binary (58b byte order 2), data right after the header and a newline
  // before the closing -1 (some exporters write one).
  std::string big = "    -1\n    58b     2     2          11          24     0     0           0           0\n";
  big += "bin\nNONE\nNONE\nNONE\nNONE\n";
  big += "    4    0    0         0 NONE               1   2 NONE               1   2\n";
  big += "         5         3         1  0.00000E+00  5.00000E-01  0.00000E+00\n";
  big += "        18    0    0    0 NONE                 Hz                  \n";
  big += "         8    0    0    0 NONE                 m                   \n";
  big += "        13    0    0    0 NONE                 N                   \n";
  big += "         0    0    0    0 NONE                 NONE                \n";
  for (float v : {1.0f, -2.0f, 0.5f, 0.25f, -8.0f, 16.0f}) {
    unsigned char bytes[4];
    std::memcpy(bytes, &v, 4);
    for (int k = 3; k >= 0; --k) big += static_cast<char>(bytes[k]);
  }
  big += "\n    -1\n";
  const UffFile c = mf::parse_uff(big, "big.uff");
  ASSERT_EQ(c.functions.size(), 1u);
  EXPECT_TRUE(c.functions[0].binary);
  EXPECT_EQ(c.functions[0].y[2], std::complex<double>(-8.0, 16.0));
  EXPECT_DOUBLE_EQ(c.functions[0].x[2], 1.0);

  // All three in one file: several records.
  const UffFile all = mf::parse_uff(fixed + free_form + big, "all.uff");
  EXPECT_EQ(all.functions.size(), 3u);
  EXPECT_EQ(all.functions[2].dataset_index, 5);
}

// Nodes and modes written by hand from the specification: dataset 15 (4I10,1P3E13.5), 2411 (4I10 then
// 1P3D25.16), 55 with normal modes (analysis type 2: frequency, modal mass, damping; real data) and with
// complex modes (type 3) spaced freely.
TEST(Uff, ReadsHandWrittenNodesAndModes) {
  const std::string text =
      "    -1\n    15\n"
      "         1         0         0        11  1.00000E+00  2.00000E+00  3.00000E+00\n"
      "         2         0         0        11 -5.00000E-01  0.00000E+00  1.25000E+00\n"
      "    -1\n    -1\n  2411\n"
      "         3         1         1        11\n"
      "   4.0000000000000000D+00   5.0000000000000000D-01  -6.0000000000000000D+00\n"
      "    -1\n    -1\n    55\nmode 1\nNONE\nNONE\nNONE\nNONE\n"
      "         1         2         2         8         2         3\n"
      "         2         4         1         1\n"
      "  1.20000E+01  2.50000E+00  3.00000E-02  0.00000E+00\n"
      "         1\n  1.00000E+00  0.00000E+00 -2.50000E-01\n"
      "         2\n  0.00000E+00  5.00000E-01  0.00000E+00\n"
      "    -1\n    -1\n    55\nmode 2\n\n\n\n\n"
      "1 3 2 8 5 3\n2 6 1 2\n-1.5 62.8 1.0 0.0 0.0 0.0\n"
      "1\n0.0 0.0 1.0E-3 -2.0E-4 0.0 0.0\n"
      "    -1\n";
  const UffFile f = mf::parse_uff(text, "nodes.uff");
  ASSERT_EQ(f.nodes.size(), 3u);
  EXPECT_EQ(f.nodes[1].label, 2);
  EXPECT_DOUBLE_EQ(f.nodes[1].xyz[2], 1.25);
  EXPECT_EQ(f.nodes[2].label, 3);
  EXPECT_DOUBLE_EQ(f.nodes[2].xyz[2], -6.0);
  ASSERT_EQ(f.modes.size(), 2u);
  const double wn = 2.0 * M_PI * 12.0;
  EXPECT_NEAR(f.modes[0].eigenvalue.real(), -0.03 * wn, 1e-9);
  EXPECT_NEAR(std::abs(f.modes[0].eigenvalue), wn, 1e-9);
  EXPECT_DOUBLE_EQ(f.modes[0].modal_a.real(), 2.5);  // the modal mass
  ASSERT_EQ(f.modes[0].shape.size(), 2u);
  EXPECT_EQ(f.modes[0].shape[0].second[2], std::complex<double>(-0.25, 0.0));
  EXPECT_EQ(f.modes[1].number, 2);
  EXPECT_EQ(f.modes[1].shape[0].second[1], std::complex<double>(1e-3, -2e-4));
}

// What the reader cannot take is refused naming the file, the dataset, the record and the field.
TEST(Uff, RefusesWhatItCannotTakeNamingTheRecordAndField) {
  const std::string good = mf::format_uff(sample_file(), mf::UffEncoding::kAscii);
  auto refused = [](const std::string& text, const std::string& expected) {
    try {
      (void)mf::parse_uff(text, "f.uff");
      ADD_FAILURE() << "accepted, expected: " << expected;
    } catch (const UffError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  std::string t = good;
  // The first function's record 7 (the nodes' dataset comes first): ordinate type 3.
  const std::size_t r7 = t.find("         6        37         1");
  ASSERT_NE(r7, std::string::npos);
  std::string bad_type = t;
  bad_type.replace(r7, 10, "         3");
  refused(bad_type, "dataset 2 (type 58), record 7: field 1 (ordinate data type) = 3: allowed 2");
  std::string short_count = t;
  short_count.replace(r7 + 10, 10, "        38");
  refused(short_count, "record 12: 76 values expected (38 points, complex, even abscissa), found 74");
  std::string bad_node = t;
  const std::size_t r6 = bad_node.find("NONE               2   2");
  bad_node.replace(r6 + 18, 1, "x");
  refused(bad_node, "f.uff:13: dataset 2 (type 58), record 6: field 6 (response node) 'x2' is not an integer");
  refused(good.substr(0, good.size() - 8), "not closed with -1");
  refused("hello\n", "a dataset opens with a line holding -1");
  refused("    -1\n    58b     1     2          11        9999     0     0           0           0\n",
          "the header announces 9999 bytes");
  std::string nan = t;
  const std::size_t z_axis = nan.find("         0    0    0    0 NONE", r7);
  nan.replace(nan.find('\n', z_axis) + 5, 1, "n");
  refused(nan, "f.uff:19: dataset 2 (type 58): '");
  refused(nan, "' is not a number");
  refused("    -1\n    58b     1     3          11           8     0     0           0           0\n",
          "only 2 (IEEE 754) is read");
}

// Random damage to a valid file (ASCII and binary) is refused or read, never a crash or a hang.
TEST(Uff, FuzzedFilesAreRefusedCleanly) {
  std::mt19937 rng(48);
  for (const auto encoding : {mf::UffEncoding::kAscii, mf::UffEncoding::kBinary}) {
    const std::string good = mf::format_uff(sample_file(), encoding);
    int refused = 0;
    for (int trial = 0; trial < 1500; ++trial) {
      std::string t = good;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int e = 0; e < edits; ++e) {
        const std::size_t at = rng() % t.size();
        switch (rng() % 4) {
          case 0:
            t[at] = static_cast<char>(rng() % 256);
            break;
          case 1:
            t.erase(at, 1 + rng() % 40);
            break;
          case 2:
            t = t.substr(0, at) + std::string(1 + rng() % 5, "-1 \n.E+9b"[rng() % 9]) + t.substr(at);
            break;
          default:
            t.resize(at);
            break;
        }
        if (t.empty()) t.push_back('x');
      }
      try {
        const UffFile f = mf::parse_uff(t, "fuzz.uff");
        for (const auto& fn : f.functions) EXPECT_EQ(fn.x.size(), fn.y.size());
      } catch (const UffError&) {
        ++refused;
      }
    }
    EXPECT_GT(refused, 500);
  }
}

// Issue 48 part 3: the tables people save, one reader.
TEST(Table, ReadsTheDelimitersDecimalMarksHeadersAndUnitsPeopleSave) {
  const std::vector<mf::ColumnSpec> wanted = {{{"time", "t", "time_s"}, mf::Quantity::kTime},
                                              {{"fx", "fx_n"}, mf::Quantity::kForce},
                                              {{"fy", "fy_n"}, mf::Quantity::kForce}};
  auto check = [&](const std::string& text, double t1, double fx1, double fy1, const char* what) {
    const mf::Table t = mf::parse_table(text, what);
    const auto v = mf::select_columns(t, wanted, what, "time, Fx, Fy");
    ASSERT_EQ(v.size(), 2u) << what;
    EXPECT_DOUBLE_EQ(v[1][0], t1) << what;
    EXPECT_DOUBLE_EQ(v[1][1], fx1) << what;
    EXPECT_DOUBLE_EQ(v[1][2], fy1) << what;
  };
  check("time_s,fx_n,fy_n\n0,1.5,-2\n0.001,2.5,-3e1\n", 0.001, 2.5, -30.0, "comma");
  check("\xEF\xBB\xBFTime [ms];Fx [kN];Fy [kN]\r\n0;1,5;-2\r\n1;2,5;-0,125\r\n", 0.001, 2500.0, -125.0,
        "semicolon, decimal comma, BOM, CRLF");
  check("Time\tFx\tFy\n[s]\t[N]\t[lbf]\n0\t1\t1\n0,5\t2\t2\n", 0.5, 2.0, 2.0 * 4.4482216152605, "tab, units row");
  check("Dynamometer export\nSample rate: 1000 Hz\n\n t (s)   Fx (N)  Fy (N)\n 0  1  2\n 1.25  -3  4\n", 1.25, -3.0,
        4.0, "preamble, spaces");
  check("# no header\n0,1,2\n2,3,4\n", 2.0, 3.0, 4.0, "no header: by position");
  check("Fy;Fx;time;\n1;2;0;\n3;4;7;\n", 7.0, 4.0, 3.0, "columns by name, trailing delimiter");
  check("\"time\",\"fx\",\"fy\"\n\"0\",\"1\",\"2\"\n\"1\",\"1.000\",\"2\"\n", 1.0, 1.0, 2.0, "quoted");
  check("time;fx;fy\n0;1;2\n1;1.234,5;2\n", 1.0, 1234.5, 2.0, "a point grouping thousands");

  auto refused = [&](const std::string& text, const std::string& expected) {
    try {
      const mf::Table t = mf::parse_table(text, "t.csv");
      (void)mf::select_columns(t, wanted, "t.csv", "time, Fx, Fy");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("time,fx,fy\n0,1,2\n1,2\n", "t.csv:3: 2 fields where the first row has 3");
  refused("time;fx;fy\n0;1;2\n1;1,234.5;2\n", "t.csv:3: '1,234.5' is not a number");
  refused("time,fx,fy\n", "no rows of numbers");
  refused("time,fz,fy\n0,1,2\n", "t.csv:1: no column 'fx' (the header has time, fz, fy)");
  refused("time [s],fx [mm],fy [N]\n0,1,2\n", "column 'fx' is in 'mm', not a unit of N");
  refused("time,fx,fy\n0,1,2\n1,,2\n", "t.csv:3: '' is not a number (an empty field)");
  refused("0,1\n", "2 columns and no header");
}

// Random damage to tables as people save them is refused with a reason or read consistently.
TEST(Table, FuzzedTablesAreRefusedCleanly) {
  std::mt19937 rng(148);
  const std::vector<mf::ColumnSpec> wanted = {
      {{"time"}, mf::Quantity::kTime}, {{"fx"}, mf::Quantity::kForce}, {{"fy"}, mf::Quantity::kForce}};
  const std::string good =
      "\xEF\xBB\xBFpreamble: 1 kHz\r\nTime [ms];Fx [kN];Fy [N]\r\n0;1,5;-2\r\n1;2,5;-0,125\r\n2;3;4\r\n";
  int refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string t = good;
    for (int e = 0; e < 1 + static_cast<int>(rng() % 3); ++e) {
      const std::size_t at = rng() % t.size();
      switch (rng() % 3) {
        case 0:
          t[at] = ";,.\t\n\r -e[]()#x9"[rng() % 17];
          break;
        case 1:
          t.erase(at, 1 + rng() % 6);
          break;
        default:
          t = t.substr(0, at) + static_cast<char>(rng() % 256) + t.substr(at);
          break;
      }
      if (t.empty()) t.push_back(';');
    }
    try {
      const mf::Table table = mf::parse_table(t, "fuzz.csv");
      for (const auto& row : mf::select_columns(table, wanted, "fuzz.csv", "time, fx, fy")) EXPECT_EQ(row.size(), 3u);
    } catch (const std::invalid_argument&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 300);
}

using Result = robodamp::test::CommandResult;

Result run(const std::string& args) { return robodamp::test::run_robodamp(args); }

// Issue 48: `identify modes --frf FILE.uff` on a file of several records, chosen by number and by DOFs;
// the accelerance in g/lbf converted from its header gives the preset's H21yy modes as the CSV route does.
TEST(Uff, IdentifyModesReadsTheRecordTheUserChooses) {
  const TempDir tmp;
  const auto cfg = robodamp::config::load_config_file(robodamp::test::preset("horizontal_c2"));
  UffFile file;
  for (int which : {0, 1}) {
    const auto& frf = cfg.robot.frfs[static_cast<std::size_t>(which)];
    UffFunction f;
    f.id[0] = frf.name;
    f.response_node = frf.response_location, f.response_direction = 2;
    f.reference_node = frf.excitation_location, f.reference_direction = 2;
    f.abscissa = {mf::kUffFrequency, 0, 0, 0, "Frequency", "Hz"};
    f.ordinate = {mf::kUffAcceleration, 0, 0, 0, "Acceleration", "g"};
    f.denominator = {mf::kUffExcitationForce, 0, 0, 0, "Force", "lbf"};
    UffFunction c = f;
    c.function_type = mf::kUffCoherence, c.is_complex = false;
    for (int k = 160; k <= 4800; ++k) {
      const double hz = 0.0125 * k;
      const std::complex<double> a = -std::pow(2.0 * M_PI * hz, 2) * robodamp::modal::frf_receptance(frf, hz);
      f.x.push_back(hz), f.y.push_back(a / 9.80665 * 4.4482216152605);
      c.x.push_back(hz), c.y.emplace_back(hz < 4.0 ? 0.5 : 0.999, 0.0);
    }
    file.functions.push_back(f), file.functions.push_back(c);
  }
  const std::string uff = tmp.file("tap.uff"), json = tmp.file("modes.json");
  mf::write_uff(uff, file, mf::UffEncoding::kAscii);
  const auto& frf = cfg.robot.frfs[1];  // H21yy: records 3 (FRF) and 4 (coherence)
  for (const std::string& choose :
       {std::string(" --record 3"), " --response " + std::to_string(frf.response_location) + ":+Y --reference " +
                                        std::to_string(frf.excitation_location) + ":Y"}) {
    const Result r = run("identify modes --frf " + uff + choose + " --band-hz 5 40 --json " + json);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("record 3: 2:+Y / 1:+Y, accelerance g/lbf read as m/s^2/N"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("with its coherence"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(robodamp::test::read_file(json));
    ASSERT_EQ(j["modes"].size(), frf.modes.size()) << r.out;
    for (std::size_t i = 0; i < frf.modes.size(); ++i) {
      EXPECT_NEAR(j["modes"][i]["natural_freq_hz"].get<double>(), frf.modes[i].natural_freq_hz,
                  0.005 * frf.modes[i].natural_freq_hz);
      EXPECT_NEAR(j["modes"][i]["damping_ratio"].get<double>(), frf.modes[i].damping_ratio,
                  0.05 * frf.modes[i].damping_ratio);
    }
  }
  const Result ambiguous = run("identify modes --frf " + uff);
  EXPECT_EQ(ambiguous.status, 2) << ambiguous.out;
  EXPECT_NE(ambiguous.out.find("2 FRF records match; choose one with --record N"), std::string::npos) << ambiguous.out;
  EXPECT_NE(ambiguous.out.find("record 4: coherence 2:+Y / 1:+Y"), std::string::npos) << ambiguous.out;
  const Result coherence = run("identify modes --frf " + uff + " --record 2");
  EXPECT_EQ(coherence.status, 2) << coherence.out;
  EXPECT_NE(coherence.out.find("record 2 is not an FRF (function type 6"), std::string::npos) << coherence.out;
  const Result bad_dof = run("identify modes --frf " + uff + " --response 2:+Q");
  EXPECT_EQ(bad_dof.status, 2) << bad_dof.out;
  EXPECT_NE(bad_dof.out.find("'2:+Q' is not a DOF"), std::string::npos) << bad_dof.out;
}

// Issue 48: a modal package's export commissions a robot: the FRFs between the TCP and the actuator's
// location (H12 written as response 1, reference 2: reciprocity), in mm/N, with coherence, and the
// actuator's blocked force per volt in lbf/V (Eq. 3) instead of robodamp's chirp. identify all gives the
// robot's modes and the actuator's parameters.
TEST(Uff, IdentifyAllCommissionsFromAModalPackagesExport) {
  const TempDir tmp;
  const std::string preset = robodamp::test::preset("horizontal_c2");
  const auto cfg = robodamp::config::load_config_file(preset);
  const robodamp::sim::PlantModel plant = robodamp::sim::build_plant_model(cfg);
  UffFile file;
  auto grid = [](UffFunction& f) {
    f.abscissa = {mf::kUffFrequency, 0, 0, 0, "Frequency", "Hz"};
    for (int k = 20; k <= 3000; ++k) f.x.push_back(0.05 * k);
  };
  for (const auto& [g, h] : {std::pair{1, 1}, std::pair{1, 2}, std::pair{2, 2}}) {
    UffFunction f;
    f.id[0] = "tap test H" + std::to_string(g) + std::to_string(h);
    f.response_node = g, f.response_direction = 2, f.reference_node = h, f.reference_direction = 2;
    f.ordinate = {mf::kUffDisplacement, 0, 0, 0, "Displacement", "mm"};
    f.denominator = {mf::kUffExcitationForce, 0, 0, 0, "Force", "N"};
    grid(f);
    for (double hz : f.x) f.y.push_back(1e3 * plant.receptance(plant.index_of(g), plant.index_of(h), hz));
    UffFunction c = f;
    c.function_type = mf::kUffCoherence, c.is_complex = false;
    c.y.assign(f.x.size(), {0.998, 0.0});
    file.functions.push_back(f), file.functions.push_back(c);
  }
  UffFunction act;
  act.id[0] = "shaker blocked force per volt";
  act.response_node = 2, act.response_direction = 2, act.reference_node = 2, act.reference_direction = 2;
  act.ordinate = {mf::kUffReactionForce, 0, 0, 0, "Force", "lbf"};
  act.denominator = {mf::kUffGeneral, 0, 0, 0, "Voltage", "V"};
  grid(act);
  const auto& a = cfg.actuator;
  for (double hz : act.x) {
    const std::complex<double> s(0.0, 2.0 * M_PI * hz);
    const double wa = 2.0 * M_PI * a.natural_freq_hz;
    const std::complex<double> g =
        a.constant_n_per_v * s * s / (s * s + 2.0 * a.damping_ratio * wa * s + wa * wa) * std::exp(-s * a.delay_s);
    act.y.push_back(g / 4.4482216152605);
  }
  file.functions.push_back(act);
  const std::string uff = tmp.file("export.uff"), out = tmp.file("identified.yaml");
  mf::write_uff(uff, file, mf::UffEncoding::kAscii);
  const Result r = run("identify all --uff " + uff + " --config " + preset + " --out " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto id = robodamp::config::load_config_file(out);
  EXPECT_NEAR(id.actuator.constant_n_per_v, a.constant_n_per_v, 0.01 * a.constant_n_per_v);
  EXPECT_NEAR(id.actuator.natural_freq_hz, a.natural_freq_hz, 0.01 * a.natural_freq_hz);
  EXPECT_NEAR(id.actuator.damping_ratio, a.damping_ratio, 0.02 * a.damping_ratio);
  EXPECT_NEAR(id.actuator.delay_s, a.delay_s, 2e-5);
  ASSERT_EQ(id.robot.frfs.size(), 3u);
  for (const auto& f : id.robot.frfs) {
    const robodamp::config::FrfConfig* truth = nullptr;
    for (const auto& t : cfg.robot.frfs)
      if ((t.response_location == f.response_location && t.excitation_location == f.excitation_location) ||
          (t.response_location == f.excitation_location && t.excitation_location == f.response_location))
        truth = &t;
    ASSERT_NE(truth, nullptr) << f.name;
    ASSERT_EQ(f.modes.size(), truth->modes.size()) << f.name << "\n" << r.out;
    for (std::size_t k = 0; k < f.modes.size(); ++k)
      EXPECT_NEAR(f.modes[k].natural_freq_hz, truth->modes[k].natural_freq_hz, 0.005 * truth->modes[k].natural_freq_hz)
          << f.name;
  }
  // Without the actuator's record: refused, naming what is needed.
  file.functions.pop_back();
  mf::write_uff(uff, file, mf::UffEncoding::kAscii);
  const Result missing = run("identify all --uff " + uff + " --config " + preset + " --out " + out);
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_NE(missing.out.find("the actuator needs an FRF per volt with reference node 2"), std::string::npos)
      << missing.out;
}

// A hammer test's time histories in a universal file (binary, the time in ms, the force in kN, the
// acceleration in g): `identify modes --series FILE.uff` gives the preset's H11yy modes, as the CSV route
// (Cli.IdentifyModesFromTimeSeriesOfTheSimulatedPlant) does.
TEST(Uff, IdentifyModesFromTimeHistoriesInAUniversalFile) {
  const TempDir tmp;
  const auto cfg = robodamp::config::load_config_file(robodamp::test::preset("horizontal_c2"));
  const robodamp::sim::PlantModel model = robodamp::sim::build_plant_model(cfg);
  robodamp::sim::Plant plant(model, cfg);
  const std::size_t hammer =
      plant.add_excitation(std::make_unique<robodamp::sim::Noise>(0, 20.0, 5, 2.0, 60.0, cfg.loop.rate_hz));
  UffFunction force, accel;
  force.function_type = accel.function_type = mf::kUffTimeResponse;
  force.is_complex = accel.is_complex = false;
  force.abscissa = accel.abscissa = {mf::kUffTime, 0, 0, 0, "Time", "ms"};
  force.ordinate = {mf::kUffExcitationForce, 0, 0, 0, "Force", "kN"};
  accel.ordinate = {mf::kUffAcceleration, 0, 0, 0, "Acceleration", "g"};
  force.response_node = 1, force.response_direction = 2, accel.response_node = 1, accel.response_direction = 2;
  for (int k = 0; k < 1000000; ++k) {
    const double a = plant.acceleration_mps2(0);
    plant.step(0.0);
    if (k % 10 != 0) continue;
    const double t_ms = 1e3 * k / cfg.loop.rate_hz;
    force.x.push_back(t_ms), accel.x.push_back(t_ms);
    force.y.emplace_back(plant.excitation_force_n(hammer) / 1e3, 0.0), accel.y.emplace_back(a / 9.80665, 0.0);
  }
  UffFile file;
  file.functions = {force, accel};
  const std::string uff = tmp.file("hammer.uff"), json = tmp.file("modes.json");
  mf::write_uff(uff, file, mf::UffEncoding::kBinary);
  const Result r = run("identify modes --series " + uff + " --segment-s 20 --band-hz 5 40 --json " + json);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("records 1 (force) and 2 (response), 100000 samples at 500 Hz"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(robodamp::test::read_file(json));
  const auto& frf = cfg.robot.frfs[0];  // H11yy
  ASSERT_EQ(j["modes"].size(), frf.modes.size()) << r.out;
  for (std::size_t i = 0; i < frf.modes.size(); ++i) {
    EXPECT_NEAR(j["modes"][i]["natural_freq_hz"].get<double>(), frf.modes[i].natural_freq_hz,
                0.01 * frf.modes[i].natural_freq_hz)
        << r.out;
    EXPECT_NEAR(j["modes"][i]["damping_ratio"].get<double>(), frf.modes[i].damping_ratio,
                0.1 * frf.modes[i].damping_ratio)
        << r.out;
  }
  // Two responses and no choice: refused, listing them.
  file.functions.push_back(accel);
  mf::write_uff(uff, file, mf::UffEncoding::kBinary);
  const Result two = run("identify modes --series " + uff + " --segment-s 20");
  EXPECT_EQ(two.status, 2) << two.out;
  EXPECT_NE(two.out.find("2 time histories of a response match; choose one with --response NODE:DIR or --record N"),
            std::string::npos)
      << two.out;
  const Result chosen = run("identify modes --series " + uff + " --record 3 --segment-s 20 --band-hz 5 40");
  EXPECT_EQ(chosen.status, 0) << chosen.out;
}

}  // namespace
