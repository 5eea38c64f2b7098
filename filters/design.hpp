// Discretisation of continuous blocks into second-order sections (off the real-time path).
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "filters/biquad.hpp"
#include "filters/transfer_function.hpp"

namespace robodamp::filters {

// A design that cannot run: unstable, non-finite, improper, or a frequency at or above Nyquist.
class DesignError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// H(z) = gain * prod sections[i](z). Each section is normalised to a peak gain of 1 over
// [0, fs/2], so no section amplifies round-off; the remaining gain is one scalar.
struct DigitalDesign {
  std::vector<BiquadCoefficients> sections;
  double gain{1.0};
  double fs_hz{0.0};
  double prewarp_hz{0.0};
};

// Bilinear constant c of s = c (1 - z^-1)/(1 + z^-1), pre-warped so the digital response equals the
// analog one exactly at prewarp_hz (0 means no pre-warping: c = 2 fs).
[[nodiscard]] double bilinear_constant(double fs_hz, double prewarp_hz);

// Pre-warped bilinear transform, by poles and zeros: roots of numerator and denominator (Eigen),
// each mapped z = (c + s)/(c - s), excess poles give zeros at z = -1, then paired into sections
// (pole pair nearest the unit circle with the zeros nearest it, those sections last).
// Throws DesignError for a non-finite or improper tf, an analog pole with Re(s) >= 0, a frequency
// at or above Nyquist, or a non-finite result.
[[nodiscard]] DigitalDesign bilinear_sos(const TransferFunction& tf, double fs_hz, double prewarp_hz);

// Largest pole magnitude of one section (its denominator 1 + a1 z^-1 + a2 z^-2).
[[nodiscard]] double pole_radius(const BiquadCoefficients& s);

// Response of sections x gain at f_hz for sample rate fs_hz.
[[nodiscard]] Complex digital_response(const std::vector<BiquadCoefficients>& sections, double gain, double f_hz,
                                       double fs_hz);
[[nodiscard]] Complex digital_response(std::span<const BiquadCoefficients> sections, double gain, double f_hz,
                                       double fs_hz);
// The exact response of the bilinear image of tf: tf evaluated at the warped frequency
// j c tan(pi f / fs). Defined for any tf, also a pure integrator that is never realised alone.
[[nodiscard]] Complex bilinear_response(const TransferFunction& tf, double f_hz, double fs_hz, double prewarp_hz);

}  // namespace robodamp::filters
