#include "config/yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <filesystem>
#include <sstream>

#include "config/file_paths.hpp"

namespace robodamp::config::detail {

SourceMark to_mark(const YAML::Mark& m) {
  if (m.is_null()) return {};
  return {m.line + 1, m.column + 1};  // yaml-cpp marks are 0-based
}

void Diagnostics::add(const YAML::Mark& mark, std::string key, std::string message) {
  add(to_mark(mark), std::move(key), std::move(message));
}

void Diagnostics::add(SourceMark mark, std::string key, std::string message) {
  problems_.push_back({file_, mark, std::move(key), std::move(message)});
}

namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

MapReader::MapReader(Diagnostics& d, const YAML::Node& node, std::string path, const YAML::Mark& parent_mark)
    : d_(d), node_(node), path_(std::move(path)), mark_(node.IsDefined() ? node.Mark() : parent_mark) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    d_.add(node_.Mark(), path_,
           "expected a map of keys, found " + std::string(node_.IsSequence() ? "a list" : "a single value"));
    node_ = YAML::Node();
  }
  quiet_ = !node_.IsDefined() || !node_.IsMap();
}

YAML::Node MapReader::lookup(const std::string& key) {
  known_.push_back(key);
  if (!node_.IsDefined() || !node_.IsMap()) return YAML::Node();
  for (auto it = node_.begin(); it != node_.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->second;
  return YAML::Node();
}

YAML::Node MapReader::child(const std::string& key, bool required, std::string_view what) {
  YAML::Node n = lookup(key);
  if (required && !quiet_ && (!n.IsDefined() || n.IsNull()))
    d_.add(mark_, path_of(key), "missing (required: " + std::string(what) + ")");
  return n;
}

std::optional<double> MapReader::number(const std::string& key, const Range& range,
                                        std::optional<double> default_value) {
  const YAML::Node n = lookup(key);
  const std::string k = path_of(key);
  if (!n.IsDefined() || n.IsNull()) {
    if (default_value || quiet_) return default_value;
    d_.add(mark_, k, "missing (required: a number in " + std::string(range.unit) + ", " + describe_range(range) + ")");
    return std::nullopt;
  }
  double v = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v)) {
    d_.add(n.Mark(), k,
           "= '" + (n.IsScalar() ? n.Scalar() : std::string("<not a scalar>")) + "' is not a number (" +
               std::string(range.unit) + ", " + describe_range(range) + ")");
    return std::nullopt;
  }
  if (!std::isfinite(v) || !in_range(v, range)) {
    d_.add(n.Mark(), k,
           "= " + format_number(v) + ' ' + std::string(range.unit) + " is out of range: " + describe_range(range));
    return std::nullopt;
  }
  return v;
}

std::optional<std::string> MapReader::choice(const std::string& key, const std::vector<std::string>& allowed,
                                             std::optional<std::string> default_value) {
  const YAML::Node n = lookup(key);
  const std::string k = path_of(key);
  if (!n.IsDefined() || n.IsNull()) {
    if (default_value || quiet_) return default_value;
    d_.add(mark_, k, "missing (required: one of " + joined(allowed) + ")");
    return std::nullopt;
  }
  if (!n.IsScalar() || std::find(allowed.begin(), allowed.end(), n.Scalar()) == allowed.end()) {
    d_.add(n.Mark(), k,
           "= '" + (n.IsScalar() ? n.Scalar() : std::string("<not a scalar>")) + "' is not allowed: one of " +
               joined(allowed));
    return std::nullopt;
  }
  return n.Scalar();
}

std::optional<std::string> MapReader::text(const std::string& key, std::optional<std::string> default_value) {
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) {
    if (!default_value && !quiet_) d_.add(mark_, path_of(key), "missing (required: a name)");
    return default_value;
  }
  if (!n.IsScalar() || n.Scalar().empty()) {
    d_.add(n.Mark(), path_of(key), "must be a non-empty text");
    return std::nullopt;
  }
  return n.Scalar();
}

std::optional<std::vector<double>> MapReader::number_list(const std::string& key, std::string_view unit) {
  const YAML::Node n = lookup(key);
  const std::string k = path_of(key);
  if (!n.IsDefined() || n.IsNull()) {
    if (!quiet_) d_.add(mark_, k, "missing (required: a list of finite numbers, " + std::string(unit) + ")");
    return std::nullopt;
  }
  if (!n.IsSequence() || n.size() == 0) {
    d_.add(n.Mark(), k, "must be a non-empty list of finite numbers (" + std::string(unit) + ")");
    return std::nullopt;
  }
  std::vector<double> out;
  bool ok = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    const YAML::Node e = n[i];
    if (!e.IsScalar() || !YAML::convert<double>::decode(e, v) || !std::isfinite(v)) {
      d_.add(e.Mark(), k + "[" + std::to_string(i) + "]",
             "= '" + (e.IsScalar() ? e.Scalar() : std::string("<not a scalar>")) + "' is not a finite number (" +
                 std::string(unit) + ")");
      ok = false;
    }
    out.push_back(v);
  }
  return ok ? std::optional(out) : std::nullopt;
}

void MapReader::finish() {
  if (!node_.IsDefined() || !node_.IsMap()) return;
  std::map<std::string, int> seen;
  std::vector<std::string> allowed = known_;
  std::sort(allowed.begin(), allowed.end());
  allowed.erase(std::unique(allowed.begin(), allowed.end()), allowed.end());
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : std::string("<complex key>");
    if (++seen[key] == 2) d_.add(it->first.Mark(), path_of(key), "duplicate key (YAML would silently keep one)");
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      d_.add(it->first.Mark(), path_of(key), "unknown key; allowed here: " + joined(allowed));
  }
}

std::string read_config_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError({Problem{path, {}, "(file)", "cannot be opened for reading"}});
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

YAML::Node load_top_map(Diagnostics& d, const std::string& yaml_text, const std::string& expected) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    d.add(e.mark, "(yaml)", "syntax error: " + e.msg);
    throw ConfigError(d.problems());
  }
  if (!root.IsMap()) {
    // An empty document has no mark: its problem is at its first line.
    d.add(root.Mark().is_null() ? SourceMark{1, 1} : to_mark(root.Mark()), "(top level)",
          "expected a map with " + expected);
    throw ConfigError(d.problems());
  }
  return root;
}

bool present(const YAML::Node& n) { return n.IsDefined() && !n.IsNull(); }

std::optional<int> read_int(MapReader& r, const std::string& key, const Range& range, std::optional<double> def) {
  const auto v = r.number(key, range, def);
  if (!v) return std::nullopt;
  if (*v != std::floor(*v)) {
    r.diagnostics().add(r.mark(), r.path_of(key), "= " + format_number(*v) + " must be a whole number");
    return std::nullopt;
  }
  return static_cast<int>(*v);
}

std::optional<int> read_sign(MapReader& r, const std::string& key, int def) {
  const YAML::Node n = r.child(key, false, "");
  if (!n.IsDefined() || n.IsNull()) return def;
  int p = 0;
  if (!n.IsScalar() || !YAML::convert<int>::decode(n, p) || (p != 1 && p != -1)) {
    r.diagnostics().add(n.Mark(), r.path_of(key),
                        "= '" + (n.IsScalar() ? n.Scalar() : std::string("?")) + "' is not allowed: +1 or -1");
    return std::nullopt;
  }
  return p;
}

std::optional<bool> read_bool(MapReader& r, const std::string& key, bool def) {
  if (auto v = r.choice(key, {"true", "false"}, def ? "true" : "false")) return *v == "true";
  return std::nullopt;
}

ModeConfig read_mode(MapReader& mr, const Range& frequency_range) {
  ModeConfig m;
  if (auto v = mr.number("natural_freq_hz", frequency_range)) m.natural_freq_hz = *v;
  if (auto v = mr.number("damping_ratio", {"(dimensionless)", 0.0, 1.0, true, true})) m.damping_ratio = *v;
  const bool stiffness = present(mr.child("stiffness_n_per_m", false, ""));
  if (stiffness) {
    m.form = ModeForm::kStiffness;
    if (auto v = mr.number("stiffness_n_per_m", {"N/m", 0.0, 1e12, true, false, "modal-stiffness form"}))
      m.stiffness_n_per_m = *v;
    for (const char* k : {"residue_re_m_per_n", "residue_im_m_per_n"})
      if (present(mr.child(k, false, "")))
        mr.diagnostics().add(mr.mark(), mr.path_of(k),
                             "given together with stiffness_n_per_m: a mode is in residue form (Eq. 1) or in "
                             "modal-stiffness form, not both");
  } else {
    if (auto v = mr.number("residue_re_m_per_n", {"m/N", -1.0, 1.0})) m.residue_re_m_per_n = *v;
    if (auto v = mr.number("residue_im_m_per_n", {"m/N", -1.0, 1.0})) m.residue_im_m_per_n = *v;
  }
  mr.finish();
  return m;
}

std::optional<RobotModelConfig> read_robot_model_file(MapReader& r, const std::string& key, const std::string& source,
                                                      const std::string& value, std::string& written,
                                                      std::string& resolved) {
  written = value;
  const FoundFile f = find_named_file(std::filesystem::path(source).parent_path().string(), value);
  resolved = f.path;
  try {
    if (f.found) return load_robot_model(resolved);
    r.diagnostics().add(r.mark(), key, "= '" + value + "': no such file (looked for " + f.looked_text() + ")");
  } catch (const ConfigError& e) {
    const std::string why = e.problems().empty() ? e.what() : e.problems().front().to_string();
    r.diagnostics().add(r.mark(), key, "= '" + value + "': " + why);
  }
  return std::nullopt;
}

}  // namespace robodamp::config::detail
