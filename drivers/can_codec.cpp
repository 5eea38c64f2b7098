#include "drivers/can_codec.hpp"

#include <cmath>

namespace robodamp::drivers {

std::int64_t unpack_field(const std::uint8_t* data, int start, int size, bool is_signed,
                          config::ByteOrder order) noexcept {
  std::uint64_t raw = 0;
  for (int i = 0; i < size; ++i) {
    const int byte = order == config::ByteOrder::kLittle ? start + size - 1 - i : start + i;
    raw = (raw << 8) | data[byte];
  }
  if (is_signed && size < 8 && (raw >> (8 * size - 1)) & 1u) raw |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(raw);
}

void pack_field(std::uint8_t* data, int start, int size, config::ByteOrder order, std::uint64_t raw) noexcept {
  for (int i = 0; i < size; ++i) {
    const auto b = static_cast<std::uint8_t>(raw >> (8 * i));
    data[order == config::ByteOrder::kLittle ? start + i : start + size - 1 - i] = b;
  }
}

Decoded decode(const config::CanFrameMapping& m, const canfd_frame& f, int frame_bytes) noexcept {
  Decoded d;
  if (f.can_id & CAN_ERR_FLAG) {
    d.error = DecodeError::kErrorFrame;
    return d;
  }
  if (f.can_id & CAN_RTR_FLAG) {
    d.error = DecodeError::kRemoteFrame;
    return d;
  }
  const bool extended = (f.can_id & CAN_EFF_FLAG) != 0;
  const std::uint32_t id = f.can_id & (extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (extended != m.extended_id || id != m.id) {
    d.error = DecodeError::kWrongId;
    return d;
  }
  const int max_len = frame_bytes == CANFD_MTU ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  if (m.length_bytes > max_len) {
    d.error = DecodeError::kNotFd;
    return d;
  }
  if (f.len < m.length_bytes || f.len > max_len) {
    d.error = DecodeError::kShort;
    return d;
  }
  const auto& v = m.value;
  d.value = static_cast<double>(unpack_field(f.data, v.start_byte, v.size_bytes, v.is_signed, v.byte_order)) * v.scale +
            v.offset;
  if (m.counter)
    d.counter = static_cast<std::uint32_t>(
        unpack_field(f.data, m.counter->start_byte, m.counter->size_bytes, false, config::ByteOrder::kLittle));
  return d;
}

Encoded encode(const config::CanFrameMapping& m, bool fd, double value, std::uint32_t counter) noexcept {
  Encoded e;
  e.frame.can_id = m.id | (m.extended_id ? CAN_EFF_FLAG : 0u);
  e.frame.len = static_cast<std::uint8_t>(m.length_bytes);
  e.frame_bytes = fd ? CANFD_MTU : CAN_MTU;
  if (fd) e.frame.flags = CANFD_BRS;
  const auto& v = m.value;
  const int bits = 8 * v.size_bytes;
  const double lo = v.is_signed ? -std::ldexp(1.0, bits - 1) : 0.0;
  const double hi = v.is_signed ? std::ldexp(1.0, bits - 1) - 1.0 : std::ldexp(1.0, bits) - 1.0;
  double counts = std::nearbyint((std::isfinite(value) ? value - v.offset : 0.0) / v.scale);
  if (!std::isfinite(value) || counts < lo || counts > hi) {
    e.clipped = true;
    counts = std::isfinite(counts) ? std::fmin(std::fmax(counts, lo), hi) : 0.0;
  }
  pack_field(e.frame.data, v.start_byte, v.size_bytes, v.byte_order,
             static_cast<std::uint64_t>(static_cast<std::int64_t>(counts)));
  if (m.counter)
    pack_field(e.frame.data, m.counter->start_byte, m.counter->size_bytes, config::ByteOrder::kLittle, counter);
  return e;
}

std::uint32_t counter_mask(const config::CanCounter& c) noexcept {
  const int bits = 8 * c.size_bytes;
  return bits >= 32 ? 0xFFFFFFFFu : (1u << bits) - 1u;
}

CounterStep counter_step(std::uint32_t previous, std::uint32_t current, std::uint32_t mask) noexcept {
  const std::uint32_t step = (current - previous) & mask;
  if (step == 0) return {true, 0};
  return {false, step > 1 && step <= mask / 2 ? step - 1 : 0};
}

}  // namespace robodamp::drivers
