// Build identification (set by CMake at configure time).
#pragma once

namespace robodamp::rt {
inline constexpr const char* kVersion = ROBODAMP_VERSION;
inline constexpr const char* kGitCommit = ROBODAMP_GIT_COMMIT;
}  // namespace robodamp::rt
