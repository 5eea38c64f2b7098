// The CAN link to the accelerometer/DAQ node and the actuator amplifier (drivers/can_*): which frames,
// where each signal sits in the payload and how it scales to SI units, and the bus's bit rates. The
// bus-load check rejects a loop rate the bus cannot carry (worst-case bit stuffing). Off the real-time
// path.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace robodamp::config {

enum class ByteOrder { kLittle, kBig };

// An integer field of the payload and its affine map to a physical value: value = raw * scale + offset.
struct CanSignal {
  int start_byte{0};
  int size_bytes{2};  // 1-4 (up to 32-bit counts)
  bool is_signed{true};
  ByteOrder byte_order{ByteOrder::kLittle};
  double scale{1.0};   // SI unit per count (m/s^2 or V)
  double offset{0.0};  // SI unit
};

// A wrapping counter the sender increments every frame: gaps are lost frames, a repeat is a stale frame.
struct CanCounter {
  int start_byte{0};
  int size_bytes{1};  // 1-4
};

struct CanFrameMapping {
  std::uint32_t id{0};
  bool extended_id{false};
  int length_bytes{8};  // payload length; classic CAN 0-8, CAN FD one of 0-8, 12, 16, 20, 24, 32, 48, 64
  CanSignal value;
  std::optional<CanCounter> counter;
};

struct CanConfig {
  std::string interface { "can0" };  // PF_CAN raw socket bound to it (production)
  double bitrate_bps{1'000'000.0};
  bool fd{false};
  double data_bitrate_bps{0.0};  // CAN FD data phase (bit-rate switch); 0 = no switch
  CanFrameMapping sensor;        // DAQ -> controller, acceleration in m/s^2
  CanFrameMapping command;       // controller -> amplifier, volts
  double bus_load_max{0.7};      // of the bus time, both frames every loop period
  int lost_frames_fault{5};      // lost frames within one second that make the sensor driver faulty
  double backoff_initial_s{0.01};
  double backoff_max_s{1.0};
};

// Worst-case time on the bus of one frame (bit stuffing included, interframe space included), seconds.
// Classic CAN: Davis et al. (2007), 8n + 47 + floor((34 + 8n - 1)/4) bits (standard id), 8n + 67 +
// floor((54 + 8n - 1)/4) (extended). CAN FD: arbitration and end of frame at the nominal rate, the data
// phase (DLC, data, stuff count, CRC) at the data rate with one stuff bit per 4 bits.
[[nodiscard]] double can_frame_time_s(const CanFrameMapping& frame, bool fd, double bitrate_bps,
                                      double data_bitrate_bps);
// Share of the bus that both frames take at the loop rate.
[[nodiscard]] double can_bus_load(const CanConfig& can, double loop_rate_hz);

}  // namespace robodamp::config
