#include "config/file_paths.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace robodamp::config {

namespace fs = std::filesystem;

const std::vector<std::vector<YamlPathItem>>& file_path_keys() {
  static const std::vector<std::vector<YamlPathItem>> keys = {
      {"pose_schedule", "model"},
      {"hil", "robot_model"},
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
      {"dashboard", "tls_certificate"},
      {"dashboard", "tls_private_key"},
  };
  return keys;
}

std::vector<std::string> data_dirs() {
  std::vector<std::string> dirs;
  auto add = [&](const std::string& list) {
    std::stringstream in(list);
    for (std::string d; std::getline(in, d, ':');)
      if (!d.empty() && std::find(dirs.begin(), dirs.end(), d) == dirs.end()) dirs.push_back(d);
  };
  if (const char* env = std::getenv("ROBODAMP_DATA_PATH"); env != nullptr) add(env);
  add(ROBODAMP_DATA_DIRS);
  return dirs;
}

std::string shipped_file(const std::string& name) {
  const std::vector<std::string> dirs = data_dirs();
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::is_regular_file(fs::path(d) / name, ec)) return (fs::path(d) / name).string();
  return dirs.empty() ? name : (fs::path(dirs.front()) / name).string();
}

std::string FoundFile::looked_text() const {
  if (rest.empty()) return beside;
  std::string dirs;
  for (const auto& d : searched) dirs += (dirs.empty() ? "" : ", ") + d;
  return beside + ", then " + rest + " in " +
         (dirs.empty() ? std::string("no data folder") : dirs + " and the folders in them");
}

FoundFile find_named_file(const std::string& source_dir, const std::string& written) {
  FoundFile f;
  const fs::path p(written);
  std::error_code ec;
  auto is_file = [&](const fs::path& c) { return fs::is_regular_file(c, ec); };
  f.path = f.beside = (p.is_absolute() ? p : fs::path(source_dir) / p).lexically_normal().string();
  if (is_file(f.path) || p.is_absolute() || written.empty()) {
    f.found = is_file(f.path);
    return f;
  }
  fs::path rest;  // the path without its leading ../ and ./
  bool leading = true;
  for (const auto& part : p.lexically_normal()) {
    if (leading && (part == ".." || part == ".")) continue;
    leading = false;
    rest /= part;
  }
  f.rest = rest.string();
  for (const auto& dir : data_dirs()) {
    f.searched.push_back(dir);
    std::vector<fs::path> places{fs::path(dir)};
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.is_directory(ec)) places.push_back(e.path());
    std::sort(places.begin() + 1, places.end());
    for (const auto& place : places) {
      const fs::path candidate = (place / rest).lexically_normal();
      if (is_file(candidate)) {
        f.path = candidate.string(), f.found = true;
        return f;
      }
    }
  }
  return f;
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
    // Not beside the configuration: found (or not) in the data folders, from the new place as from the old.
    std::error_code ec;
    if (!fs::exists(file, ec)) continue;
    fs::path moved = file.lexically_relative(to_dir);
    if (moved.empty()) moved = file;
    if (moved == p) continue;
    edits.push_back({key, YAML::Node(moved.string())});
  }
  if (edits.empty()) return {text, true};
  return edit_yaml(text, edits);
}

}  // namespace robodamp::config
