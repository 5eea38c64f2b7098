// The test binaries' main: every test process gets a directory of its own under the system's temporary
// directory, named in TEST_TMPDIR (::testing::TempDir()) and TMPDIR (std::filesystem::temp_directory_path(),
// and the robodamp processes a test starts), and removes it with everything in it when its tests end.
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>
#include <string>

int main(int argc, char** argv) {
  const char* base = std::getenv("TMPDIR");
  std::string tmpl = std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/robodamp-tests-XXXXXX";
  const char* dir = mkdtemp(tmpl.data());
  if (dir == nullptr) return 1;
  setenv("TEST_TMPDIR", dir, 1);
  setenv("TMPDIR", dir, 1);
  spdlog::default_logger_raw();  // spdlog's registry made before any thread logs (apps/main.cpp says why)
  ::testing::InitGoogleTest(&argc, argv);
  const int rc = RUN_ALL_TESTS();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return rc;
}
