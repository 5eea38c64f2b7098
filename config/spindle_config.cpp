#include "config/spindle_config.hpp"

#include <filesystem>

#include "config/config.hpp"
#include "config/file_paths.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config::detail {

std::optional<HarmonicNotchConfig> read_harmonic_notch(MapReader& controller, std::optional<double> rate_hz) {
  const YAML::Node node = controller.child("harmonic_notch", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(controller.diagnostics(), node, "controller.harmonic_notch", controller.mark());
  HarmonicNotchConfig c;
  const double nyquist = rate_hz ? 0.5 * *rate_hz : 1e6;
  if (auto v = read_int(r, "harmonics", {"(harmonics)", 1, 8}, c.harmonics)) c.harmonics = *v;
  if (auto v = r.number("bandwidth_hz", {"Hz", 0.0, 0.5 * nyquist, true}, c.bandwidth_hz)) c.bandwidth_hz = *v;
  if (auto v = r.number("depth_db", {"dB", 0.0, 80.0, true}, c.depth_db)) c.depth_db = *v;
  if (auto v = r.number("slew_fraction", {"(x the centre per update)", 0.0, 1.0, true}, c.slew_fraction))
    c.slew_fraction = *v;
  if (auto v = r.number("min_hz", {"Hz", 0.0, 0.45 * 2.0 * nyquist, true}, c.min_hz)) c.min_hz = *v;
  if (auto v = r.number("fade_s", {"s", 0.0, 10.0}, c.fade_s)) c.fade_s = *v;
  if (auto v = r.number("update_hz", {"Hz", 0.0, 2.0 * nyquist, true}, c.update_hz)) c.update_hz = *v;
  r.finish();
  return c;
}

SpindleConfig read_spindle(MapReader& top, const std::string& source) {
  MapReader r(top.diagnostics(), top.child("spindle", false, ""), "spindle", top.mark());
  SpindleConfig c;
  if (auto v = read_int(r, "teeth", {"(teeth)", 1, 32}, c.teeth)) c.teeth = *v;
  if (auto v = r.number("rpm_max", {"rpm", 0.0, 200000.0, true}, c.rpm_max)) c.rpm_max = *v;
  if (auto v = r.text("job", ""); v && !v->empty()) {
    c.job = *v;
    const FoundFile f = find_named_file(std::filesystem::path(source).parent_path().string(), *v);
    c.job_resolved = f.path;
    if (!f.found)
      r.diagnostics().add(r.mark(), "spindle.job",
                          "= '" + c.job + "': no such file (looked for " + f.looked_text() + ")");
  }
  if (auto v = r.text("structure", "")) c.structure = *v;
  if (auto v = r.number("pose_step_deg", {"deg", 0.1, 45.0}, c.pose_step_deg)) c.pose_step_deg = *v;
  if (auto v = read_bool(r, "apply_advice", c.apply_advice)) c.apply_advice = *v;
  if (auto v = read_int(r, "advice_grid_points", {"(speeds)", 0, 400}, c.advice_grid_points)) c.advice_grid_points = *v;
  r.finish();
  return c;
}

}  // namespace robodamp::config::detail
