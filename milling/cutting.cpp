#include "milling/cutting.hpp"
#include "units/units.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace robodamp::milling {

Engagement engagement(double radius_mm, double radial_mm, config::MillingMode mode) {
  const double r = std::clamp(radial_mm / (2.0 * radius_mm), 0.0, 1.0);
  if (mode == config::MillingMode::kDown) return {std::acos(2.0 * r - 1.0), M_PI};
  return {0.0, std::acos(1.0 - 2.0 * r)};
}

double surface_angle_rad(config::MillingMode mode) { return mode == config::MillingMode::kDown ? M_PI : 0.0; }

Eigen::Matrix2d directional_matrix(const Engagement& e, double kr) {
  // docs/physics.md §2 (Altintas-Budak), [.] = value at exit minus value at entry.
  auto at = [kr](double p) {
    Eigen::Matrix2d a;
    a(0, 0) = 0.5 * (std::cos(2 * p) - 2 * kr * p + kr * std::sin(2 * p));
    a(0, 1) = 0.5 * (-std::sin(2 * p) - 2 * p + kr * std::cos(2 * p));
    a(1, 0) = 0.5 * (-std::sin(2 * p) + 2 * p + kr * std::cos(2 * p));
    a(1, 1) = 0.5 * (-std::cos(2 * p) - 2 * kr * p - kr * std::sin(2 * p));
    return a;
  };
  return at(e.exit_rad) - at(e.start_rad);
}

Cutter cutter_from(const config::ToolConfig& tool) {
  return {tool.kind, 0.5 * tool.diameter_mm, tool.teeth, tool.helix_deg * M_PI / 180.0};
}

std::vector<Slice> slices(const Cutter& c, double axial_mm, int count) {
  std::vector<Slice> out;
  const double db = axial_mm / count;
  for (int j = 0; j < count; ++j) {
    Slice s;
    s.z_mm = (j + 0.5) * db;
    s.height_mm = db;
    s.radius_mm = c.radius_mm;
    s.kappa_rad = 0.5 * M_PI;
    if (c.kind == config::ToolKind::kBallEnd && s.z_mm < c.radius_mm) {
      // On the sphere (docs/physics.md §4): z = R (1 - cos kappa), local radius R sin kappa.
      s.kappa_rad = std::acos(1.0 - s.z_mm / c.radius_mm);
      s.radius_mm = c.radius_mm * std::sin(s.kappa_rad);
    }
    // Lag of the edge behind the tip: z tan(helix) / R (docs/physics.md §3 and 4).
    s.lag_rad = s.z_mm * std::tan(c.helix_rad) / c.radius_mm;
    out.push_back(s);
  }
  return out;
}

namespace {

// A force component A sin^2 + B sin cos + C sin + D cos as coefficients of exp(i m phi), m = -2..2.
std::array<Complex, 5> exponential_form(double A, double B, double C, double D) {
  const Complex i(0.0, 1.0);
  std::array<Complex, 5> c{};  // index m + 2
  c[2] += 0.5 * A;
  c[4] += -0.25 * A;
  c[0] += -0.25 * A;
  c[4] += B / (4.0 * i);
  c[0] += -B / (4.0 * i);
  c[3] += C / (2.0 * i);
  c[1] += -C / (2.0 * i);
  c[3] += 0.5 * D;
  c[1] += 0.5 * D;
  return c;
}

}  // namespace

ForceSpectrum force_spectrum(const Cutter& c, const config::MaterialConfig& mat, const CutConditions& cut,
                             int axial_slices, int harmonics) {
  ForceSpectrum out;
  out.fx.assign(static_cast<std::size_t>(harmonics) + 1, Complex(0.0));
  out.fy.assign(static_cast<std::size_t>(harmonics) + 1, Complex(0.0));
  const int n = c.teeth;
  for (const Slice& s : slices(c, cut.axial_mm, axial_slices)) {
    const double local_radial = slice_radial_mm(c, s, cut.radial_mm);
    if (local_radial <= 0.0) continue;
    const Engagement e = engagement(s.radius_mm, local_radial, cut.mode);
    const double sk = std::sin(s.kappa_rad);
    const double db = s.height_mm, ft = cut.feed_per_tooth_mm;
    // Ft = kt db ft sk sin + kte db, Fr(projected) = sk (kr db ft sk sin + kre db) (section 4 projection).
    const double tc = mat.kt_n_per_mm2 * db * ft * sk, te = mat.kte_n_per_mm * db;
    const double rc = sk * mat.kr_n_per_mm2 * db * ft * sk, re = sk * mat.kre_n_per_mm * db;
    // Fx = -Ft cos - Fr sin = -tc sin cos - te cos - rc sin^2 - re sin
    // Fy =  Ft sin - Fr cos =  tc sin^2 + te sin - rc sin cos - re cos
    const auto ex = exponential_form(-rc, -tc, -re, -te);
    const auto ey = exponential_form(tc, -rc, te, -re);
    // The integral of exp(i q phi) over the engagement [a, b] for q = m - k n is
    // (exp(i m b) exp(-i k n b) - exp(i m a) exp(-i k n a)) / (i q): the factors in m once per slice, those in k
    // by a running product of unit phasors (one rounding per harmonic, no sine or cosine per harmonic).
    const double a = e.start_rad, b = e.exit_rad;
    std::array<Complex, 5> ema{}, emb{};
    for (int m = -2; m <= 2; ++m) {
      ema[static_cast<std::size_t>(m + 2)] = std::polar(1.0, m * a);
      emb[static_cast<std::size_t>(m + 2)] = std::polar(1.0, m * b);
    }
    const Complex step_a = std::polar(1.0, -n * a), step_b = std::polar(1.0, -n * b),
                  step_lag = std::polar(1.0, -n * s.lag_rad);
    Complex eka(1.0), ekb(1.0),
        shift(1.0);  // exp(-i k n a), exp(-i k n b), exp(-i k n lag): the edge reaches phi at (phi + lag) / Omega
    const double scale = n / (kTwoPi);
    for (int k = 0; k <= harmonics; ++k) {
      Complex sx(0.0), sy(0.0);
      for (int m = -2; m <= 2; ++m) {
        const int q = m - k * n;
        const auto im = static_cast<std::size_t>(m + 2);
        const Complex d = emb[im] * ekb - ema[im] * eka;  // divided by i q below
        const Complex integral = q == 0 ? Complex(b - a, 0.0) : Complex(d.imag() / q, -d.real() / q);
        sx += ex[im] * integral;
        sy += ey[im] * integral;
      }
      out.fx[static_cast<std::size_t>(k)] += scale * sx * shift;
      out.fy[static_cast<std::size_t>(k)] += scale * sy * shift;
      eka *= step_a, ekb *= step_b, shift *= step_lag;
    }
  }
  return out;
}

}  // namespace robodamp::milling
