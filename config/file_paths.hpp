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

// A file a configuration names, as found. written relative: first beside the configuration (source_dir),
// as it always was; where it is not there, in the data folders (ROBODAMP_DATA_PATH, ':'-separated, then the
// installed /usr/share/robodamp and the source tree's config/), with its leading "../" and "./" dropped,
// in each data folder and each folder inside it: a job copied out of the tree that names
// ../presets/horizontal_c2.yaml finds the shipped preset. Absolute paths are taken as written.
struct FoundFile {
  std::string path;  // where it was found, or (not found) the path beside the configuration
  bool found{false};
  std::string beside;                 // the path beside the configuration (tried first)
  std::string rest;                   // what was looked for in the data folders (empty: they were not searched)
  std::vector<std::string> searched;  // the data folders searched, in order
  [[nodiscard]] std::string looked_text() const;  // "A, then B in D1, D2 and the folders in them"
};
[[nodiscard]] FoundFile find_named_file(const std::string& source_dir, const std::string& written);
// The data folders searched, in order.
[[nodiscard]] std::vector<std::string> data_dirs();
// A shipped file by its name in the data folders ("presets/horizontal_c2.yaml"): the first data folder that
// has it, or (none has it) its place in the first data folder, which a refusal then names. The commands'
// defaults: an installed robodamp (/usr/share/robodamp) and a source build find their own.
[[nodiscard]] std::string shipped_file(const std::string& name);

// `text` read from `from_source` (a file path; its directory resolves the relative paths), rewritten to be
// written at `to_path`: each relative file path becomes relative to to_path's directory (absolute when no
// relative form exists). Absolute paths, a relative one that is not beside the configuration (found in the
// data folders: find_named_file) and the rest of the text stay as they are (config/yaml_edit.hpp).
[[nodiscard]] EditedYaml rebase_file_paths(const std::string& text, const std::string& from_source,
                                           const std::string& to_path);

}  // namespace robodamp::config
