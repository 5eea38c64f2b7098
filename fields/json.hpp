// The JSON form of a struct with a field list (fields/fields.hpp): an object of its fields by key, a key
// with '/' nested ("derate/probes" is {"derate": {"probes": ...}}), and back.
#pragma once

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "fields/fields.hpp"

namespace robodamp::fields {

namespace detail {
// The object at the key's path (created), and the key's last part.
inline nlohmann::json& slot(nlohmann::json& j, std::string_view key) {
  nlohmann::json* at = &j;
  for (std::size_t slash = key.find('/'); slash != std::string_view::npos; slash = key.find('/')) {
    at = &(*at)[std::string(key.substr(0, slash))];
    key.remove_prefix(slash + 1);
  }
  return (*at)[std::string(key)];
}
inline const nlohmann::json* find(const nlohmann::json& j, std::string_view key) {
  const nlohmann::json* at = &j;
  for (;;) {
    const std::size_t slash = key.find('/');
    const std::string part(key.substr(0, slash));
    if (!at->is_object() || !at->contains(part)) return nullptr;
    at = &at->at(part);
    if (slash == std::string_view::npos) return at;
    key.remove_prefix(slash + 1);
  }
}
}  // namespace detail

namespace detail {
template <class F>
struct IsNested : std::false_type {};
template <class S, class T>
struct IsNested<Nested<S, T>> : std::true_type {};
template <class F>
struct IsConverted : std::false_type {};
template <class S, class T, class J>
struct IsConverted<Converted<S, T, J>> : std::true_type {};
// The object a nested field's fields go into: j itself for the key "".
inline nlohmann::json& nested_slot(nlohmann::json& j, std::string_view key) {
  if (key.empty()) return j;
  nlohmann::json& n = slot(j, key);
  if (!n.is_object()) n = nlohmann::json::object();
  return n;
}
inline const nlohmann::json* nested_find(const nlohmann::json& j, std::string_view key) {
  return key.empty() ? &j : find(j, key);
}
}  // namespace detail

// Adds s's fields to j (an object).
template <class S>
void add_json(nlohmann::json& j, const S& s) {
  for_each_field(s, [&](const auto& field, const auto& value) {
    using F = std::decay_t<decltype(field)>;
    using V = std::decay_t<decltype(value)>;
    if constexpr (detail::IsNested<F>::value) {
      add_json(detail::nested_slot(j, field.key), value);
    } else if constexpr (detail::IsConverted<F>::value) {
      detail::slot(j, field.key) = field.to(value);
    } else if constexpr (std::is_arithmetic_v<V>) {
      detail::slot(j, field.key) = value;
    } else {
      nlohmann::json named = nlohmann::json::object();
      for (std::size_t i = 1; i < value.size(); ++i) named[std::string(field.name_of(i))] = value[i];
      detail::slot(j, field.key) = named;
    }
  });
}

template <class S>
[[nodiscard]] nlohmann::json to_json(const S& s) {
  nlohmann::json j = nlohmann::json::object();
  add_json(j, s);
  return j;
}

// s from j, over `start`: a field j does not hold keeps start's value (a summary or a recording written before
// the field existed: start says how such a file behaved).
template <class S>
[[nodiscard]] S from_json(const nlohmann::json& j, S start) {
  std::apply(
      [&](const auto&... field) {
        auto read = [&](const auto& f) {
          using F = std::decay_t<decltype(f)>;
          auto& member = start.*(f.member);
          using V = std::decay_t<decltype(member)>;
          if constexpr (detail::IsNested<F>::value) {
            if (const nlohmann::json* n = detail::nested_find(j, f.key)) member = from_json<V>(*n, member);
          } else {
            const nlohmann::json* v = detail::find(j, f.key);
            if (v == nullptr) return;
            if constexpr (detail::IsConverted<F>::value) {
              member = f.from(*v);
            } else if constexpr (std::is_arithmetic_v<V>) {
              member = v->template get<V>();
            } else {
              for (std::size_t i = 1; i < member.size(); ++i)
                member[i] = v->value(std::string(f.name_of(i)), std::uint64_t{0});
            }
          }
        };
        (read(field), ...);
      },
      list_of<S>());
  return start;
}
template <class S>
[[nodiscard]] S from_json(const nlohmann::json& j) {
  return from_json<S>(j, S{});
}

// A report's number: null where it is not finite or not there.
[[nodiscard]] inline nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
[[nodiscard]] inline nlohmann::json number_or_null(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

// A report's JSON number as text with a printf format ("%.3f"), "-" for null.
[[nodiscard]] inline std::string number_text(const nlohmann::json& v, const char* format) {
  if (v.is_null()) return "-";
  char b[64];
  std::snprintf(b, sizeof b, format, v.get<double>());
  return b;
}

}  // namespace robodamp::fields
