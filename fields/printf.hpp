// printf's formatting into a std::string, of any length: the reports' one helper (a table's row, a verdict's
// sentence), where each library had a fixed buffer of its own. Off the real-time path (it allocates).
#pragma once

#include <cstdio>
#include <string>

namespace robodamp::fields {

template <class... A>
[[nodiscard]] std::string printf_string(const char* format, A... args) {
  char small[256];
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-vararg): printf's format strings are the reports' house style
  const int n = std::snprintf(small, sizeof small, format, args...);
  if (n < 0) return {};
  if (static_cast<std::size_t>(n) < sizeof small) return std::string(small, static_cast<std::size_t>(n));
  std::string out(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), format, args...);  // NOLINT(cppcoreguidelines-pro-type-vararg)
  out.resize(static_cast<std::size_t>(n));
  return out;
}

}  // namespace robodamp::fields
