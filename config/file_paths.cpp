#include "config/file_paths.hpp"

#include <filesystem>

namespace robodamp::config {

namespace fs = std::filesystem;

const std::vector<std::vector<YamlPathItem>>& file_path_keys() {
  static const std::vector<std::vector<YamlPathItem>> keys = {
      {"pose_schedule", "model"},
      {"spindle", "job"},
      {"parameter_sets", "horizontal"},
      {"parameter_sets", "vertical"},
      {"dds", "security", "identity_ca"},
      {"dds", "security", "identity_certificate"},
      {"dds", "security", "private_key"},
      {"dds", "security", "permissions_ca"},
      {"dds", "security", "governance"},
      {"dds", "security", "permissions"},
      {"dashboard", "credentials"},
      {"dashboard", "action_log"},
  };
  return keys;
}

EditedYaml rebase_file_paths(const std::string& text, const std::string& from_source, const std::string& to_path) {
  // absolute() first: a bare file name's parent is empty, which absolute() refuses.
  const fs::path from_dir = fs::absolute(from_source).lexically_normal().parent_path();
  const fs::path to_dir = fs::absolute(to_path).lexically_normal().parent_path();
  const YAML::Node root = YAML::Load(text);
  std::vector<YamlEdit> edits;
  for (const auto& key : file_path_keys()) {
    const YAML::Node v = yaml_at(root, key);
    if (!v.IsDefined() || !v.IsScalar() || v.Scalar().empty()) continue;
    const fs::path p = v.Scalar();
    if (p.is_absolute()) continue;
    const fs::path file = (from_dir / p).lexically_normal();
    fs::path moved = file.lexically_relative(to_dir);
    if (moved.empty()) moved = file;
    if (moved == p) continue;
    edits.push_back({key, YAML::Node(moved.string())});
  }
  if (edits.empty()) return {text, true};
  return edit_yaml(text, edits);
}

}  // namespace robodamp::config
