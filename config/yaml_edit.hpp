// Configurations edited as data: set values in a YAML document, whatever style (block or flow) it is
// written in, and keep everything else of the text, comments included, where that can be done exactly.
//
// Each edit names a path (map keys, and sequence indices as numbers) and the new value. An existing value's
// text is replaced in place (a collection by its one-line flow form); a missing key is added to its
// mapping. The result is read back and every edited path compared with its value; when a splice cannot be
// made or does not read back, the whole document is emitted again from the edited tree (block style,
// comments lost) and `comments_kept` says so. Off the real-time path.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace robodamp::config {

using YamlPathItem = std::variant<std::string, std::size_t>;

struct YamlEdit {
  YamlEdit(std::vector<YamlPathItem> p, YAML::Node v, std::string c = {})
      : path(std::move(p)), value(std::move(v)), comment(std::move(c)) {}
  std::vector<YamlPathItem> path;
  YAML::Node value;
  // When not empty and the value ends its line: the line's comment becomes "# " + comment (the old one said
  // where the replaced value came from).
  std::string comment;
};

struct EditedYaml {
  std::string text;
  bool comments_kept{true};
};

// Throws std::invalid_argument when a path cannot exist in the document (an index past a sequence's end,
// a key below a scalar) and YAML::Exception when `text` is not YAML.
[[nodiscard]] EditedYaml edit_yaml(const std::string& text, const std::vector<YamlEdit>& edits);

// The value at `path`, or an undefined node.
[[nodiscard]] YAML::Node yaml_at(const YAML::Node& root, const std::vector<YamlPathItem>& path);

}  // namespace robodamp::config
