// A YAML document written again with every collection in one style: identify all writes block style, the
// presets use flow style for short entries, a person may write either.
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

namespace robodamp::test {

inline void restyle(YAML::Node n, YAML::EmitterStyle::value style) {
  if (n.IsMap() || n.IsSequence()) n.SetStyle(style);
  if (n.IsMap())
    for (auto it = n.begin(); it != n.end(); ++it) restyle(it->second, style);
  if (n.IsSequence())
    for (auto it = n.begin(); it != n.end(); ++it) restyle(*it, style);
}

inline std::string in_style(const std::string& text, YAML::EmitterStyle::value style) {
  YAML::Node root = YAML::Load(text);
  restyle(root, style);
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace robodamp::test
