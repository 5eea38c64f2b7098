#include "rt/version.hpp"

namespace robodamp::rt {
const char* version() noexcept { return ROBODAMP_VERSION; }
const char* git_commit() noexcept { return ROBODAMP_GIT_COMMIT; }
}  // namespace robodamp::rt
