#include "config/yaml_edit.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>

namespace robodamp::config {

namespace {

constexpr std::size_t kUnknown = std::string::npos;

std::string path_text(const std::vector<YamlPathItem>& path) {
  std::string s;
  for (const auto& p : path) {
    if (const auto* k = std::get_if<std::string>(&p)) {
      if (!s.empty()) s += '.';
      s += *k;
    } else {
      s += '[';
      s += std::to_string(std::get<std::size_t>(p));
      s += ']';
    }
  }
  return s;
}

// One line, flow collections: what replaces a value's text.
std::string flow(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

// Where a scalar's text ends, or kUnknown (block scalars, multi-line plain scalars).
std::size_t scalar_end(const std::string& t, const YAML::Node& n) {
  const auto pos = static_cast<std::size_t>(n.Mark().pos);
  if (pos >= t.size()) return kUnknown;
  if (t[pos] == '"') {
    for (std::size_t i = pos + 1; i < t.size(); ++i) {
      if (t[i] == '\\')
        ++i;
      else if (t[i] == '"')
        return i + 1;
    }
    return kUnknown;
  }
  if (t[pos] == '\'') {
    for (std::size_t i = pos + 1; i < t.size(); ++i)
      if (t[i] == '\'') {
        if (i + 1 < t.size() && t[i + 1] == '\'')
          ++i;
        else
          return i + 1;
      }
    return kUnknown;
  }
  const std::string& s = n.Scalar();
  return !s.empty() && t.compare(pos, s.size(), s) == 0 ? pos + s.size() : kUnknown;
}

// Flow brackets opened and not closed in t[a, b), outside quotes and comments.
int open_brackets(const std::string& t, std::size_t a, std::size_t b) {
  int open = 0;
  char quote = 0;
  for (std::size_t i = a; i < b; ++i) {
    const char c = t[i];
    if (quote) {
      if (quote == '"' && c == '\\')
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == a || t[i - 1] == ' ' || t[i - 1] == '\t')) {
      while (i < b && t[i] != '\n') ++i;
    } else if (c == '[' || c == '{') {
      ++open;
    } else if (c == ']' || c == '}') {
      --open;
    }
  }
  return open;
}

// Where a node's text ends (past its closing brackets), or kUnknown.
std::size_t node_end(const std::string& t, const YAML::Node& n) {
  if (n.Mark().is_null()) return kUnknown;
  if (n.IsScalar()) return scalar_end(t, n);
  if (!n.IsMap() && !n.IsSequence()) return kUnknown;
  const auto start = static_cast<std::size_t>(n.Mark().pos);
  std::size_t end = start + 1;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::size_t e1 = n.IsMap() ? node_end(t, it->first) : node_end(t, *it);
    const std::size_t e2 = n.IsMap() ? node_end(t, it->second) : e1;
    if (e1 == kUnknown || e2 == kUnknown) return kUnknown;
    end = std::max({end, e1, e2});
  }
  for (int open = open_brackets(t, start, end); open > 0; --open) {
    while (end < t.size() && (t[end] == ' ' || t[end] == '\t' || t[end] == '\n' || t[end] == '\r' || t[end] == ','))
      ++end;
    if (end >= t.size() || (t[end] != ']' && t[end] != '}')) return kUnknown;
    ++end;
  }
  return end;
}

struct Splice {
  std::size_t from{0}, to{0};
  std::string text;
};

// The splice for one edit, or nothing when it cannot be made exactly.
std::optional<Splice> splice_for(const std::string& t, const YAML::Node& root, const YamlEdit& e) {
  if (e.path.empty()) return std::nullopt;
  const YAML::Node at = yaml_at(root, e.path);
  if (at.IsDefined()) {
    const std::size_t end = node_end(t, at);
    if (end == kUnknown) return std::nullopt;
    Splice s{static_cast<std::size_t>(at.Mark().pos), end, flow(e.value)};
    const std::size_t line_end = std::min(t.find('\n', end), t.size());
    const std::size_t rest = t.find_first_not_of(" \t", end);
    if (!e.comment.empty() && (rest >= line_end || t[rest] == '#')) s.to = line_end, s.text += "   # " + e.comment;
    return s;
  }
  // A missing key: added to its mapping.
  const auto* key = std::get_if<std::string>(&e.path.back());
  const YAML::Node parent = yaml_at(root, {e.path.begin(), e.path.end() - 1});
  if (!key || !parent.IsMap()) return std::nullopt;
  const std::size_t end = node_end(t, parent);
  if (end == kUnknown) return std::nullopt;
  const std::string entry = flow(YAML::Node(*key)) + ": " + flow(e.value);
  const auto start = static_cast<std::size_t>(parent.Mark().pos);
  if (t[start] == '{') return Splice{end - 1, end - 1, (parent.size() > 0 ? ", " : "") + entry};
  const std::size_t line_end = std::min(t.find('\n', end), t.size());
  return Splice{line_end, line_end, "\n" + std::string(static_cast<std::size_t>(parent.Mark().column), ' ') + entry};
}

bool reads_back(const std::string& text, const std::vector<YamlEdit>& edits) {
  try {
    const YAML::Node root = YAML::Load(text);
    return std::all_of(edits.begin(), edits.end(), [&](const YamlEdit& e) {
      const YAML::Node at = yaml_at(root, e.path);
      return at.IsDefined() && flow(at) == flow(e.value);
    });
  } catch (const YAML::Exception&) {
    return false;
  }
}

void check_path(const YAML::Node& root, const std::vector<YamlPathItem>& path) {
  YAML::Node n;
  n.reset(root);
  for (const auto& p : path) {
    if (!n.IsDefined() || n.IsNull()) return;  // created by the edit
    const YAML::Node& c = n;
    if (const auto* i = std::get_if<std::size_t>(&p)) {
      if (!c.IsSequence() || *i >= c.size())
        throw std::invalid_argument(path_text(path) + ": no such element in the document");
    } else if (!c.IsMap()) {
      throw std::invalid_argument(path_text(path) + ": not a mapping in the document");
    }
    const YAML::Node next =
        std::holds_alternative<std::size_t>(p) ? c[std::get<std::size_t>(p)] : c[std::get<std::string>(p)];
    if (!next.IsDefined()) return;  // created by the edit
    n.reset(next);
  }
}

std::string emitted_again(const std::string& text, const std::vector<YamlEdit>& edits) {
  YAML::Node root = YAML::Load(text);
  for (const auto& e : edits) {
    YAML::Node n;
    n.reset(root);
    for (std::size_t k = 0; k + 1 < e.path.size(); ++k) {
      YAML::Node next;
      if (const auto* i = std::get_if<std::size_t>(&e.path[k]))
        next.reset(n[*i]);
      else
        next.reset(n[std::get<std::string>(e.path[k])]);
      n.reset(next);
    }
    if (const auto* i = std::get_if<std::size_t>(&e.path.back()))
      n[*i] = e.value;
    else
      n[std::get<std::string>(e.path.back())] = e.value;
  }
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

YAML::Node yaml_at(const YAML::Node& root, const std::vector<YamlPathItem>& path) {
  YAML::Node n;
  n.reset(root);
  for (const auto& p : path) {
    const YAML::Node& c = n;
    if (const auto* i = std::get_if<std::size_t>(&p)) {
      if (!c.IsSequence() || *i >= c.size()) return YAML::Node(YAML::NodeType::Undefined);
    } else if (!c.IsMap()) {
      return YAML::Node(YAML::NodeType::Undefined);
    }
    // A missing key gives an invalid node, which reset() refuses: test it first.
    const YAML::Node next =
        std::holds_alternative<std::size_t>(p) ? c[std::get<std::size_t>(p)] : c[std::get<std::string>(p)];
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    n.reset(next);
  }
  return n;
}

EditedYaml edit_yaml(const std::string& text, const std::vector<YamlEdit>& edits) {
  const YAML::Node root = YAML::Load(text);
  for (const auto& e : edits) {
    if (e.path.empty()) throw std::invalid_argument("edit_yaml: an empty path");
    check_path(root, e.path);
  }
  std::vector<Splice> splices;
  bool exact = true;
  for (const auto& e : edits) {
    if (auto s = splice_for(text, root, e))
      splices.push_back(*s);
    else
      exact = false;
  }
  if (exact) {
    std::sort(splices.begin(), splices.end(), [](const Splice& a, const Splice& b) { return a.from > b.from; });
    for (std::size_t k = 1; k < splices.size(); ++k) exact = exact && splices[k].to <= splices[k - 1].from;
  }
  if (exact) {
    std::string out = text;
    for (const auto& s : splices) out.replace(s.from, s.to - s.from, s.text);
    if (reads_back(out, edits)) return {out, true};
  }
  std::string out = emitted_again(text, edits);
  if (!reads_back(out, edits)) throw std::invalid_argument("edit_yaml: the edited document does not read back");
  return {out, false};
}

}  // namespace robodamp::config
