// A reported struct's fields declared once (docs/architecture.md "Fields"): next to the struct, a function
// `field_list(Tag<S>)` returns its members as a tuple of `Field`s, each with its JSON key and the words a person
// reads in the run summary. The JSON form (fields/json.hpp) and the text form (`text` below) come from that list,
// and `lists_every_member<S>()` makes a member the list forgot a compile error, so a counter added to the
// struct is added to its list beside it and nowhere else.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>

namespace robodamp::fields {

template <class S>
struct Tag {};

// key: the JSON key; a '/' nests it in an object ("derate/probes"). label: the words after the number in the
// text form ("lost" in "3 lost").
template <class S, class T>
struct Field {
  std::string_view key;
  T S::*member;
  std::string_view label;
};

// An array of counts indexed by an enum: JSON an object of name: count, text "name count"; index 0 (the
// enum's "none") left out of both.
template <class S, std::size_t N>
struct NamedCounts {
  std::string_view key;
  std::array<std::uint64_t, N> S::*member;
  std::string_view (*name_of)(std::size_t index);
};

// A member that is a struct with a field list of its own: its fields under key ("" at this level).
template <class S, class T>
struct Nested {
  std::string_view key;
  T S::*member;
};

// A member with a JSON form of its own (a set of enum values by name): to and from nlohmann::json, declared
// in fields/json.hpp's terms by the list that uses it (the list's header includes fields/json.hpp).
template <class S, class T, class Json>
struct Converted {
  std::string_view key;
  T S::*member;
  Json (*to)(const T&);
  T (*from)(const Json&);
};

template <class S>
[[nodiscard]] constexpr auto list_of() {
  return field_list(Tag<S>{});
}

// Calls f(field, value) for each field of s, in the list's order.
template <class S, class F>
constexpr void for_each_field(const S& s, F&& f) {
  std::apply([&](const auto&... field) { (f(field, s.*(field.member)), ...); }, list_of<S>());
}

namespace detail {
struct AnyMember {
  template <class T>
  constexpr operator T() const noexcept;  // NOLINT(google-explicit-constructor): only in unevaluated contexts
};
// The number of members of the aggregate S: the most initialisers S{...} accepts.
template <class S, class... A>
constexpr std::size_t member_count() {
  if constexpr (requires { S{A{}..., AnyMember{}}; })
    return member_count<S, A..., AnyMember>();
  else
    return sizeof...(A);
}
}  // namespace detail

// True when S's list names as many fields as S has members (each member once: a list is checked by its
// tests' round trip through JSON).
template <class S>
[[nodiscard]] constexpr bool lists_every_member() {
  return std::tuple_size_v<decltype(list_of<S>())> == detail::member_count<S>();
}

// The text form: "12 sensor frames, 0 lost, ..." (NamedCounts: "instability 1, overruns 2", or "none").
template <class S>
[[nodiscard]] std::string text(const S& s) {
  std::string out;
  auto add = [&out](std::string_view part) {
    if (!out.empty()) out += ", ";
    out += part;
  };
  for_each_field(s, [&](const auto& field, const auto& value) {
    if constexpr (std::is_integral_v<std::decay_t<decltype(value)>>) {
      add(std::to_string(value) + " " + std::string(field.label));
    } else {
      std::string named;
      for (std::size_t i = 1; i < value.size(); ++i)
        if (value[i] > 0)
          named += (named.empty() ? "" : ", ") + std::string(field.name_of(i)) + " " + std::to_string(value[i]);
      add(std::string(field.key) + ": " + (named.empty() ? "none" : named));
    }
  });
  return out;
}

}  // namespace robodamp::fields
