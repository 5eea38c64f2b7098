// Cells for the loop tests: configured, or the test fails with the reason (an exception gtest reports,
// never an abort).
#pragma once

#include <memory>
#include <stdexcept>

#include "runtime/cell.hpp"

namespace robodamp::test {

inline void configure(runtime::Cell& cell) {
  if (runtime::Status s = cell.configure(); !s.ok()) throw std::runtime_error(s.message);
}

}  // namespace robodamp::test
