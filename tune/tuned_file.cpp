#include "tune/tuned_file.hpp"

#include <charconv>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

#include "analysis/loop_model.hpp"
#include "config/file_paths.hpp"
#include "tune/speed_schedule.hpp"

namespace robodamp::tune {

std::string exact(double x) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}

// The configuration's own text with the compensator, the gain and the polarity set, as data
// (config/yaml_edit.hpp): any YAML style; comments kept where the splice is exact.
config::EditedYaml tuned_config_text(const config::Config& base, const Candidate& c) {
  const config::Config tuned = with_candidate(base, c);
  std::size_t index = 0;
  for (std::size_t i = 0; i < tuned.controller.chain.size(); ++i)
    if (tuned.controller.chain[i].kind == config::BlockKind::kCompensator) index = i;
  const config::BlockConfig& block = tuned.controller.chain[index];
  const YAML::Node original = config::yaml_at(YAML::Load(base.yaml_text), {"controller", "chain", index});
  YAML::Node entry(YAML::NodeType::Map);
  entry["kind"] = "compensator";
  for (const char* key : {"name", "prewarp_hz"})  // what a rational compensator keeps of the original entry
    if (original.IsMap() && original[key]) entry[key] = original[key];
  entry["model"] = "rational";
  auto numbers = [](const std::vector<double>& v) {
    YAML::Node n(YAML::NodeType::Sequence);
    for (const double x : v) n.push_back(exact(x));
    return n;
  };
  entry["numerator"] = numbers(block.numerator);
  entry["denominator"] = numbers(block.denominator);
  // A speed schedule chose its K for the controller the tune replaces: dropped (robodamp schedule writes one).
  const std::string text = base.controller.speed_schedule ? without_schedule(base.yaml_text) : base.yaml_text;
  return config::edit_yaml(text,
                           {{{"controller", "gain_ns_per_m"}, YAML::Node(exact(c.gain_ns_per_m)), "robodamp tune"},
                            {{"controller", "polarity"}, YAML::Node(c.polarity > 0 ? "+1" : "-1"), "robodamp tune"},
                            {{"controller", "chain", index}, entry, "robodamp tune"}});
}

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// The written file's header: where it comes from, the command that writes it again, and what was verified.
std::string tuned_header(const TuneCommand& a, const std::optional<Verification>& v, bool scheduled) {
  std::ostringstream h;
  h << "# robodamp tune wrote this (docs/tuning.md) from " << a.config_path;
  if (!a.job_path.empty()) h << " for " << a.job_path;
  h << ":\n#   " << tune_command_line(a) << "\n";
  if (v) {
    char b[400];
    std::snprintf(b, sizeof b,
                  "# Verified (%s, %zu speeds): damped minimum %.3f mm at %.1f rpm, %.3f mm at the job's %.1f rpm;\n"
                  "# the time-domain cut with the real Controller: %.3f mm and %.3f mm there.\n",
                  v->method.c_str(), v->damped_curve_mm.size(), v->min_depth_mm, v->min_rpm, v->depth_at_speed_mm,
                  v->speed_rpm, v->time_domain_at_min_mm, v->time_domain_at_speed_mm);
    h << b;
  }
  if (scheduled)
    h << "# " << a.config_path
      << "'s controller.speed_schedule is not kept: it chose K for the controller tuned here "
         "(robodamp schedule writes one for this file).\n";
  h << "# Everything else is " << a.config_path << "'s, whose header follows.\n#\n";
  return h.str();
}

}  // namespace

// The command that writes this file again (the options that differ from their defaults).
std::string tune_command_line(const TuneCommand& a) {
  const TuneSettings d;
  std::string c = "robodamp tune --config " + a.config_path + (a.job_path.empty() ? "" : " --job " + a.job_path);
  for (const auto& p : a.also_paths) c += " --also " + p;
  if (a.shift_pct) c += " --shift-pct " + num(*a.shift_pct);
  if (!a.start_path.empty()) c += " --start " + a.start_path;
  const TuneSettings& s = a.settings;
  if (s.gain_margin_min_db != d.gain_margin_min_db) c += " --gain-margin-db " + num(s.gain_margin_min_db);
  if (s.phase_margin_min_deg != d.phase_margin_min_deg) c += " --phase-margin-deg " + num(s.phase_margin_min_deg);
  if (s.delay_margin_min_ms != d.delay_margin_min_ms) c += " --delay-margin-ms " + num(s.delay_margin_min_ms);
  if (s.impact_peak_n) c += " --impact-n " + num(*s.impact_peak_n);
  if (s.impact_duration_ms) c += " --impact-ms " + num(*s.impact_duration_ms);
  if (s.depth_at_speed_min_mm > 0.0) c += " --depth-at-speed-mm " + num(s.depth_at_speed_min_mm);
  if (s.global_evaluations != d.global_evaluations) c += " --evaluations " + std::to_string(s.global_evaluations);
  if (s.local_evaluations != d.local_evaluations) c += " --polish " + std::to_string(s.local_evaluations);
  if (s.seed != d.seed) c += " --seed " + std::to_string(s.seed);
  if (s.restarts != d.restarts) c += " --restarts " + std::to_string(s.restarts);
  if (s.no_worse_mode) c += " --no-worse-mode";
  return c + " --out " + a.out_path;
}

// --start's candidate: a configuration robodamp tune wrote (its chain's rational compensator, K, polarity).
Candidate start_candidate(const std::string& path) {
  const config::Config c = config::load_config_file(path);
  if (const auto start = candidate_of(c)) return *start;
  throw config::ConfigError(
      {config::Problem{path,
                       {},
                       "--start",
                       "--start " + path +
                           ": its chain's compensator is not the form robodamp tune writes (model: "
                           "rational, a cubic over a cubic with every root in the left half plane); start from a "
                           "file robodamp tune wrote, or leave --start out"}});
}

std::string tuned_file_text(const TuneCommand& c, const config::Config& base, const Candidate& candidate,
                            const std::optional<Verification>& verified, bool& comments_kept) {
  const config::EditedYaml edited = tuned_config_text(base, candidate);
  comments_kept = edited.comments_kept;
  // Written beside another file than the one read: its relative file paths rebased (config/file_paths.hpp).
  const std::string text = tuned_header(c, verified, base.controller.speed_schedule.has_value()) +
                           config::rebase_file_paths(edited.text, base.source, c.out_path).text;
  const config::Config check = config::parse_config(text, c.out_path);  // throws (exit 2) before writing
  if (!analysis::LoopModel(check).stable(check.controller.gain_ns_per_m, check.controller.polarity))
    throw std::runtime_error("the written configuration's loop is not stable: nothing written");
  return text;
}

}  // namespace robodamp::tune
