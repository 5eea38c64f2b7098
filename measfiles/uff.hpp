// Universal files (UFF), the exchange format of modal testing (docs/measurement_files.md): dataset 58
// (a function at a node and direction: FRF, coherence, time history, spectrum), ASCII and its binary
// form 58b; dataset 15 and 2411 (node coordinates); dataset 55 (data at nodes: mode shapes). Other
// datasets (151 header, 164 units, 2412 elements, ...) are passed over and listed. The layouts are the
// format's own (fixed Fortran columns); the reader also takes what real exporters write beside them:
// CRLF line ends, fields run together or spaced freely, Fortran D exponents, non-ASCII text in the ID
// lines, several records in one file, big- and little-endian 8- and 4-byte binary. Off the real-time path.
#pragma once

#include <array>
#include <complex>
#include <stdexcept>
#include <string>
#include <vector>

namespace robodamp::measfiles {

// What a universal file cannot be read as, naming the file, the dataset's place in it (its number in the
// file and the line it starts on), the record and the field.
class UffError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Dataset 58 function types (record 6 field 1) robodamp uses by name.
inline constexpr int kUffTimeResponse = 1;
inline constexpr int kUffFrf = 4;
inline constexpr int kUffCoherence = 6;

// Dataset 58 specific data types (records 8-11 field 1) robodamp uses by name.
inline constexpr int kUffUnknown = 0;
inline constexpr int kUffGeneral = 1;
inline constexpr int kUffDisplacement = 8;
inline constexpr int kUffReactionForce = 9;
inline constexpr int kUffVelocity = 11;
inline constexpr int kUffAcceleration = 12;
inline constexpr int kUffExcitationForce = 13;
inline constexpr int kUffTime = 17;
inline constexpr int kUffFrequency = 18;

// Records 8-11: an axis's specific data type, unit exponents and labels.
struct UffAxis {
  int data_type{kUffUnknown};
  int length_exp{0}, force_exp{0}, temperature_exp{0};
  std::string label{"NONE"}, units{"NONE"};
};

// Dataset 58: one function of one abscissa (frequency or time) at a response and a reference DOF.
struct UffFunction {
  std::array<std::string, 5> id{"NONE", "NONE", "NONE", "NONE", "NONE"};  // records 1-5
  int function_type{kUffFrf}, function_id{0}, version{0}, load_case{0};
  std::string response_entity{"NONE"};
  int response_node{0}, response_direction{0};  // direction: 0 scalar, +-1..3 X..Z, +-4..6 rotations
  std::string reference_entity{"NONE"};
  int reference_node{0}, reference_direction{0};
  bool is_complex{true};
  bool double_precision{true};
  bool even{true};  // even abscissa: x = min + k step (record 7), not stored per point
  double z_value{0.0};
  UffAxis abscissa, ordinate, denominator, z_axis;
  std::vector<double> x;                // the abscissa, always filled
  std::vector<std::complex<double>> y;  // the ordinate (imaginary 0 for real data)
  // Where it was read from (0 when built in memory).
  int dataset_index{0}, line{0};
  bool binary{false};
};

// Dataset 15 / 2411: a node and its coordinates in the file's length unit.
struct UffNode {
  int label{0};
  std::array<double, 3> xyz{0.0, 0.0, 0.0};
};

// Dataset 55 with complex eigenvalues (analysis type 3): one mode, its pole and its shape as three
// translations per node (record 10), scaled with modal A.
struct UffMode {
  std::array<std::string, 5> id{"NONE", "NONE", "NONE", "NONE", "NONE"};
  int number{1};
  std::complex<double> eigenvalue{0.0, 0.0};  // rad/s: -zeta wn + i wd
  std::complex<double> modal_a{1.0, 0.0}, modal_b{0.0, 0.0};
  std::vector<std::pair<int, std::array<std::complex<double>, 3>>> shape;  // node, (X, Y, Z)
};

struct UffFile {
  std::vector<UffFunction> functions;
  std::vector<UffNode> nodes;
  std::vector<UffMode> modes;
  std::vector<int> skipped_datasets;  // numbers of the datasets passed over
};

// Throws UffError (no such file, not a universal file, a record it cannot take).
[[nodiscard]] UffFile read_uff(const std::string& path);
[[nodiscard]] UffFile parse_uff(const std::string& bytes, const std::string& name);

enum class UffEncoding { kAscii, kBinary };
// Writes the nodes (dataset 15), the functions (58, or 58b little-endian IEEE doubles) and the modes (55)
// in that order. ASCII holds the format's digits (record 12: 4E20.12, an uneven abscissa E13.5); binary
// holds the doubles exactly. Throws UffError when the file cannot be written or a function's columns differ.
void write_uff(const std::string& path, const UffFile& file, UffEncoding encoding);
[[nodiscard]] std::string format_uff(const UffFile& file, UffEncoding encoding);

}  // namespace robodamp::measfiles
