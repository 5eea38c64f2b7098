#include "tune/speed_schedule_file.hpp"

#include <sstream>

#include "config/file_paths.hpp"
#include "config/number_range.hpp"
#include "tune/speed_schedule_report.hpp"

namespace robodamp::tune {

namespace {

// A header this command wrote before (a file scheduled again): it is replaced, not stacked.
std::string without_schedule_header(const std::string& text) {
  const std::string start = "# robodamp schedule wrote", end = "'s, whose header follows.\n#\n";
  if (text.rfind(start, 0) != 0) return text;
  const std::size_t e = text.find(end);
  return e == std::string::npos ? text : text.substr(e + end.size());
}

}  // namespace

std::string schedule_command_line(const ScheduleCommand& a) {
  const ScheduleSettings d;
  const ScheduleSettings& s = a.settings;
  std::string c = "robodamp schedule --config " + a.config_path + (a.job_path.empty() ? "" : " --job " + a.job_path);
  for (const auto& p : a.controllers) c += " --controller " + p;
  if (s.speeds != d.speeds) c += " --speeds " + std::to_string(s.speeds);
  if (s.gains_per_controller != d.gains_per_controller) c += " --gains " + std::to_string(s.gains_per_controller);
  if (s.gain_margin_min_db != d.gain_margin_min_db)
    c += " --gain-margin-db " + config::format_number(s.gain_margin_min_db);
  if (s.phase_margin_min_deg != d.phase_margin_min_deg)
    c += " --phase-margin-deg " + config::format_number(s.phase_margin_min_deg);
  if (s.delay_margin_min_ms != d.delay_margin_min_ms)
    c += " --delay-margin-ms " + config::format_number(s.delay_margin_min_ms);
  return c + " --out " + a.out_path;
}

std::string scheduled_file_text(const ScheduleCommand& a, config::Config cell, const SpeedSchedule& s,
                                bool& comments_kept) {
  cell.yaml_text = without_schedule_header(cell.yaml_text);
  const config::EditedYaml edited = scheduled_config_text(cell, s);
  comments_kept = edited.comments_kept;
  std::ostringstream header;
  header << "# robodamp schedule wrote the speed schedule into " << a.config_path << " (docs/tuning.md):\n#   "
         << schedule_command_line(a) << "\n"
         << schedule_header(s) << "# Everything else is " << a.config_path << "'s, whose header follows.\n#\n";
  const std::string text = header.str() + config::rebase_file_paths(edited.text, cell.source, a.out_path).text;
  (void)config::parse_config(text, a.out_path);  // throws before anything is written
  return text;
}

}  // namespace robodamp::tune
