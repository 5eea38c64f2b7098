// The file `robodamp tune` writes: the configuration it started from with the tuned compensator (a
// rational block in the chain's compensator entry), gain and polarity set as data (config/yaml_edit.hpp),
// in whatever YAML style the configuration is written, its comments kept where the edit is exact.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "config/yaml_edit.hpp"
#include "tune/compensator_search.hpp"
#include "tune/verification.hpp"

namespace robodamp::tune {

// The shortest decimal text that reads back as exactly x: a written file holds the verified numbers.
[[nodiscard]] std::string exact(double x);

// base: a configuration with a compensator in its chain (Evaluator refuses one without); base.yaml_text is
// edited, without its controller.speed_schedule (it chose K for the controller the tune replaces; run robodamp
// schedule on the tuned file). Throws std::invalid_argument when the text cannot be edited to read back.
[[nodiscard]] config::EditedYaml tuned_config_text(const config::Config& base, const Candidate& c);

// What `robodamp tune` was asked (its options as given): the written file's header repeats it as a command.
struct TuneCommand {
  std::string config_path, job_path, out_path;
  std::vector<std::string> also_paths;  // more plants: the worst case is tuned
  std::optional<double> shift_pct;      // each plant also with its modes shifted by -/+ this
  std::string start_path;               // resume from this configuration's tuned compensator, K and polarity
  TuneSettings settings;
};

// The command that writes the file again (the options that differ from their defaults).
[[nodiscard]] std::string tune_command_line(const TuneCommand& c);

// --start's candidate: a configuration robodamp tune wrote (its chain's rational compensator, K, polarity).
// Throws config::ConfigError otherwise.
[[nodiscard]] Candidate start_candidate(const std::string& path);

// The tuned file's text: its header (where it comes from, the command, what was verified) over base's text with
// the candidate, its relative file paths rebased beside c.out_path; parsed and its loop analysed first (throws
// config::ConfigError, or std::runtime_error for an unstable loop). comments_kept: false when the text had to be
// written again from its data.
[[nodiscard]] std::string tuned_file_text(const TuneCommand& c, const config::Config& base, const Candidate& candidate,
                                          const std::optional<Verification>& verified, bool& comments_kept);

}  // namespace robodamp::tune
