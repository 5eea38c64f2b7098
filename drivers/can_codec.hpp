// Frame codec of the CAN link: signals packed into and unpacked from a payload by the configured layout
// (config/can_config.hpp). Pure functions on fixed-size buffers: no allocation, no exceptions, safe on
// the real-time path and against any payload (tests/test_can.cpp fuzzes it).
#pragma once

#include <cstdint>
#include <linux/can.h>

#include "config/can_config.hpp"

namespace robodamp::drivers {

// Raw integer of a field (sign-extended when signed); the caller guarantees the field lies within len.
[[nodiscard]] std::int64_t unpack_field(const std::uint8_t* data, int start, int size, bool is_signed,
                                        config::ByteOrder order) noexcept;
void pack_field(std::uint8_t* data, int start, int size, config::ByteOrder order, std::uint64_t raw) noexcept;

enum class DecodeError : std::uint8_t { kNone, kWrongId, kErrorFrame, kRemoteFrame, kShort, kNotFd };

struct Decoded {
  DecodeError error{DecodeError::kNone};
  double value{0.0};         // SI unit
  std::uint32_t counter{0};  // raw counter when the mapping has one
};

// frame_bytes: what the transport read (CAN_MTU or CANFD_MTU); the frame's own len is checked against it.
[[nodiscard]] Decoded decode(const config::CanFrameMapping& m, const canfd_frame& f, int frame_bytes) noexcept;

struct Encoded {
  canfd_frame frame{};
  int frame_bytes{CAN_MTU};  // to write
  bool clipped{false};       // the value was outside the field's range and was clamped
};
[[nodiscard]] Encoded encode(const config::CanFrameMapping& m, bool fd, double value, std::uint32_t counter) noexcept;

// A sender's wrapping counter from one frame to the next: the same value again (a stale frame), or the
// frames missing in between. A large step backwards is a restarted sender, not half a counter's range of
// lost frames.
struct CounterStep {
  bool repeated{false};
  std::uint32_t lost{0};
};
[[nodiscard]] std::uint32_t counter_mask(const config::CanCounter& c) noexcept;
[[nodiscard]] CounterStep counter_step(std::uint32_t previous, std::uint32_t current, std::uint32_t mask) noexcept;

}  // namespace robodamp::drivers
