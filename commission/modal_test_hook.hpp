// The plant-side instruments of a modal test (analysis::ModalTest: the hammer and the recorders) stepped
// with the simulated plant, for commission's measurement and its check on the cell.
#pragma once

#include <cstdint>

#include "analysis/modal_test.hpp"
#include "drivers/sim_backend.hpp"

namespace robodamp::commission {

class ModalTestHook final : public drivers::PlantStepHook {
 public:
  explicit ModalTestHook(analysis::ModalTest& t) : t_(t) {}
  void before_step(std::uint64_t k) noexcept override { t_.before_step(static_cast<std::size_t>(k)); }
  void after_step(std::uint64_t k) noexcept override { t_.after_step(static_cast<std::size_t>(k)); }

 private:
  analysis::ModalTest& t_;
};

}  // namespace robodamp::commission
