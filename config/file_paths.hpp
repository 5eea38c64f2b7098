// The configuration keys that name files relative to the configuration file (the robot model, the
// spindle's job, the mounting's parameter sets, the DDS security files, the dashboard's credentials and
// action log), and moving a configuration's text to another directory with every such path still naming
// the same file. `identify all`, `tune --out` and `commission` write configurations away from the one they
// read; without this a relative path would name a file beside the new one.
#pragma once

#include <string>
#include <vector>

#include "config/yaml_edit.hpp"

namespace robodamp::config {

[[nodiscard]] const std::vector<std::vector<YamlPathItem>>& file_path_keys();

// `text` read from `from_source` (a file path; its directory resolves the relative paths), rewritten to be
// written at `to_path`: each relative file path becomes relative to to_path's directory (absolute when no
// relative form exists). Absolute paths and the rest of the text stay as they are (config/yaml_edit.hpp).
[[nodiscard]] EditedYaml rebase_file_paths(const std::string& text, const std::string& from_source,
                                           const std::string& to_path);

}  // namespace robodamp::config
