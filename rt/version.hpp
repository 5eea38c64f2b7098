// Build identification (set by CMake at configure time, rt/version.cpp).
#pragma once

namespace robodamp::rt {
[[nodiscard]] const char* version() noexcept;     // the project's version
[[nodiscard]] const char* git_commit() noexcept;  // git describe --always --dirty at configure time
}  // namespace robodamp::rt
