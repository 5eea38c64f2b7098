# The build's time (CMakeLists.txt, ROBODAMP_UNITY and ROBODAMP_PCH; docs/performance.md, "The build in batches").
#
# Precompiled headers: one for the off-line targets and one for the tests. GCC uses a precompiled header only
# where every macro defined when it was made is defined the same way, so the two carriers below are compiled with
# no definitions of their own (NDEBUG comes from the build type, the same everywhere); a target's own definitions
# (spdlog's, Fast DDS's) do not touch these headers.
set(ROBODAMP_PCH_HEADERS
    <algorithm> <array> <chrono> <cmath> <complex> <cstdint> <cstdio> <filesystem> <fstream> <functional>
    <limits> <map> <memory> <optional> <sstream> <stdexcept> <string> <utility> <vector>
    <Eigen/Dense> <nlohmann/json.hpp> <yaml-cpp/yaml.h>)
# Folders whose targets keep their own translation units and includes: the real-time core and what it links
# (House.TheRealTimeCore*), and the command line's parsing; scripts/tidy.sh reads these by their own compile
# commands (and config/number_text.cpp, below). The tests are one file per binary, mostly: batches gain nothing.
set(ROBODAMP_FAST_BUILD_EXCLUDED_FOLDERS units threads rt_settings fields filters control rt drivers)
set(ROBODAMP_UNITY_EXCLUDED_FOLDERS command_line tests)
set_source_files_properties(number_text.cpp DIRECTORY "${PROJECT_SOURCE_DIR}/config"
                            PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)

if(ROBODAMP_PCH)
  file(WRITE "${CMAKE_BINARY_DIR}/pch/pch_offline.cpp" "// The carrier of the off-line targets' precompiled header.\n")
  add_library(pch_offline OBJECT "${CMAKE_BINARY_DIR}/pch/pch_offline.cpp")
  target_link_libraries(pch_offline PRIVATE Eigen3::Eigen nlohmann_json::nlohmann_json yaml-cpp robodamp_warnings)
  target_precompile_headers(pch_offline PRIVATE ${ROBODAMP_PCH_HEADERS})
  if(TARGET GTest::gtest)
    file(WRITE "${CMAKE_BINARY_DIR}/pch/pch_tests.cpp" "// The carrier of the tests' precompiled header.\n")
    add_library(pch_tests OBJECT "${CMAKE_BINARY_DIR}/pch/pch_tests.cpp")
    target_link_libraries(pch_tests PRIVATE Eigen3::Eigen nlohmann_json::nlohmann_json yaml-cpp GTest::gtest
                                            robodamp_warnings)
    target_compile_options(pch_tests PRIVATE $<$<CONFIG:Release>:-O1>)  # as the tests (tests/CMakeLists.txt)
    target_precompile_headers(pch_tests PRIVATE ${ROBODAMP_PCH_HEADERS} <gtest/gtest.h>)
  endif()
endif()

# Every target made in a folder, its subfolders' included.
function(robodamp_targets_under dir out)
  get_property(found DIRECTORY "${dir}" PROPERTY BUILDSYSTEM_TARGETS)
  get_property(subdirs DIRECTORY "${dir}" PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    robodamp_targets_under("${sub}" below)
    list(APPEND found ${below})
  endforeach()
  set(${out} ${found} PARENT_SCOPE)
endfunction()

robodamp_targets_under("${PROJECT_SOURCE_DIR}" all_targets)
foreach(t IN LISTS all_targets)
  get_target_property(type ${t} TYPE)
  get_target_property(dir ${t} SOURCE_DIR)
  get_filename_component(folder "${dir}" NAME)
  if(NOT type MATCHES "^(STATIC_LIBRARY|EXECUTABLE|OBJECT_LIBRARY)$" OR t MATCHES "^pch_"
     OR folder IN_LIST ROBODAMP_FAST_BUILD_EXCLUDED_FOLDERS)
    continue()
  endif()
  if(ROBODAMP_UNITY AND NOT folder IN_LIST ROBODAMP_UNITY_EXCLUDED_FOLDERS)
    set_target_properties(${t} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  if(ROBODAMP_PCH AND folder STREQUAL "tests" AND TARGET pch_tests)
    target_precompile_headers(${t} REUSE_FROM pch_tests)
  elseif(ROBODAMP_PCH)
    target_precompile_headers(${t} REUSE_FROM pch_offline)
  endif()
endforeach()
