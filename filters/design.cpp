#include "filters/design.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace robodamp::filters {

namespace {

std::string describe_root(Complex r) {
  std::ostringstream os;
  os.precision(6);
  os << "s = " << r.real() << (r.imag() < 0 ? " - " : " + ") << std::abs(r.imag()) << "j rad/s ("
     << std::abs(r) / kTwoPi << " Hz)";
  return os.str();
}

bool is_real(Complex r) { return r.imag() == 0.0; }

// Removes and returns the element of v nearest to target among those accepted by pred.
template <class Pred>
Complex take_nearest(std::vector<Complex>& v, Complex target, Pred pred) {
  auto best = v.end();
  double best_d = INFINITY;
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (!pred(*it)) continue;
    const double d = std::abs(*it - target);
    if (d < best_d) best_d = d, best = it;
  }
  if (best == v.end()) throw DesignError("section pairing: no root left to pair (internal error)");
  const Complex r = *best;
  v.erase(best);
  return r;
}

// Takes a root and its partner: the exact conjugate for a complex root, the nearest real root otherwise.
std::pair<Complex, Complex> take_pair(std::vector<Complex>& v, Complex near) {
  const Complex first = take_nearest(v, near, [](Complex) { return true; });
  if (!is_real(first)) {
    take_nearest(v, std::conj(first), [](Complex r) { return !is_real(r); });
    return {first, std::conj(first)};  // exact conjugate, so the section's coefficients are real
  }
  return {first, take_nearest(v, near, is_real)};
}

double peak_gain(const BiquadCoefficients& s, double fs_hz) {
  // Log grid from 1e-4 fs to Nyquist, plus DC: enough to find the peak of one section.
  double peak = std::abs(digital_response({s}, 1.0, 0.0, fs_hz));
  constexpr int kPoints = 600;
  for (int i = 0; i <= kPoints; ++i) {
    const double f = fs_hz * 0.5 * std::pow(10.0, -4.0 * (1.0 - static_cast<double>(i) / kPoints));
    peak = std::max(peak, std::abs(digital_response({s}, 1.0, f, fs_hz)));
  }
  return peak;
}

}  // namespace

double bilinear_constant(double fs_hz, double prewarp_hz) {
  if (prewarp_hz == 0.0) return 2.0 * fs_hz;
  return hz_to_rad_per_s(prewarp_hz) / std::tan(std::numbers::pi * prewarp_hz / fs_hz);
}

DigitalDesign bilinear_sos(const TransferFunction& tf, double fs_hz, double prewarp_hz) {
  if (!std::isfinite(fs_hz) || fs_hz <= 0.0) throw DesignError("sample rate must be finite and > 0 Hz");
  if (!std::isfinite(prewarp_hz) || prewarp_hz < 0.0 || prewarp_hz >= 0.5 * fs_hz) {
    std::ostringstream os;
    os << "pre-warp frequency " << prewarp_hz << " Hz must be in [0, " << 0.5 * fs_hz << ") Hz (below Nyquist)";
    throw DesignError(os.str());
  }
  if (!tf.all_finite()) throw DesignError("non-finite coefficient in the transfer function");
  if (!tf.is_proper())
    throw DesignError("improper transfer function: numerator degree " + std::to_string(tf.numerator().degree()) +
                      " > denominator degree " + std::to_string(tf.denominator().degree()));
  const std::vector<Complex> poles = tf.denominator().roots();
  for (const Complex& p : poles)
    if (!(p.real() < 0.0)) throw DesignError("unstable or marginally stable: pole at " + describe_root(p));
  const std::vector<Complex> zeros = tf.numerator().roots();

  const double c = bilinear_constant(fs_hz, prewarp_hz);
  // H(s) = k prod(s - z)/prod(s - p); with s = c(1-w)/(1+w), w = z^-1, each factor (s - r) becomes
  // (c - r)(1 - r_d w)/(1 + w), r_d = (c + r)/(c - r).
  Complex gain = tf.numerator().leading() / tf.denominator().leading();
  std::vector<Complex> zd, pd;
  for (const Complex& z : zeros) {
    if (std::abs(c - z) <= 1e-12 * c) throw DesignError("zero at the bilinear point s = c: " + describe_root(z));
    gain *= (c - z);
    zd.push_back((c + z) / (c - z));
  }
  for (const Complex& p : poles) {
    gain /= (c - p);
    pd.push_back((c + p) / (c - p));
  }
  zd.insert(zd.end(), pd.size() - zeros.size(), Complex(-1.0));
  if (pd.size() % 2 == 1) {  // pad to whole sections
    pd.emplace_back(0.0);
    zd.emplace_back(0.0);
  }
  for (auto* v : {&zd, &pd})
    for (Complex& r : *v)
      if (std::abs(r.imag()) <= 1e-14 * std::max(1.0, std::abs(r))) r.imag(0.0);

  DigitalDesign out;
  out.fs_hz = fs_hz;
  out.prewarp_hz = prewarp_hz;
  double k = gain.real();
  while (!pd.empty()) {
    const auto far =
        std::max_element(pd.begin(), pd.end(), [](Complex a, Complex b) { return std::abs(a) < std::abs(b); });
    const auto [p1, p2] = take_pair(pd, *far);
    const auto [z1, z2] = take_pair(zd, p1);
    BiquadCoefficients s{1.0, -(z1 + z2).real(), (z1 * z2).real(), -(p1 + p2).real(), (p1 * p2).real()};
    const double peak = peak_gain(s, fs_hz);
    if (std::isfinite(peak) && peak > 0.0) {
      s.b0 /= peak, s.b1 /= peak, s.b2 /= peak;
      k *= peak;
    }
    out.sections.push_back(s);
  }
  // Pole pairs nearest the unit circle go last: the sharp resonances see already-filtered input.
  std::reverse(out.sections.begin(), out.sections.end());
  out.gain = k;

  for (const auto& s : out.sections) {
    if (!std::isfinite(s.b0) || !std::isfinite(s.b1) || !std::isfinite(s.b2) || !std::isfinite(s.a1) ||
        !std::isfinite(s.a2) || !std::isfinite(out.gain))
      throw DesignError("non-finite digital coefficients");
    // Jury conditions for a second-order denominator 1 + a1 z^-1 + a2 z^-2.
    if (!(std::abs(s.a2) < 1.0 && std::abs(s.a1) < 1.0 + s.a2))
      throw DesignError("digital section is not strictly stable (rounding at this sample rate)");
  }
  return out;
}

double pole_radius(const BiquadCoefficients& s) {
  const double disc = s.a1 * s.a1 - 4.0 * s.a2;
  if (disc < 0.0) return std::sqrt(s.a2);  // complex pair: |p|^2 = a2
  const double root = std::sqrt(disc);
  return std::max(std::abs(-s.a1 + root), std::abs(-s.a1 - root)) / 2.0;
}

Complex digital_response(const std::vector<BiquadCoefficients>& sections, double gain, double f_hz, double fs_hz) {
  return digital_response(std::span<const BiquadCoefficients>(sections), gain, f_hz, fs_hz);
}

Complex digital_response(std::span<const BiquadCoefficients> sections, double gain, double f_hz, double fs_hz) {
  const Complex w = std::polar(1.0, -kTwoPi * f_hz / fs_hz);  // z^-1
  Complex h(gain);
  for (const auto& s : sections) h *= (s.b0 + w * (s.b1 + w * s.b2)) / (1.0 + w * (s.a1 + w * s.a2));
  return h;
}

Complex bilinear_response(const TransferFunction& tf, double f_hz, double fs_hz, double prewarp_hz) {
  const double c = bilinear_constant(fs_hz, prewarp_hz);
  return tf.evaluate(Complex(0.0, c * std::tan(std::numbers::pi * f_hz / fs_hz)));
}

}  // namespace robodamp::filters
