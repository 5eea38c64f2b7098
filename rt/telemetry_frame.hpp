// One fixed-size frame per loop tick: what the loop pushes into the telemetry ring, what the recorder
// writes (docs/recording_format.md), what the CSV export and replay read. Every input of the
// supervisor's decision is in it (TickInput), so a recording replays bit for bit.
#pragma once

#include <array>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>

#include "rt/supervisor.hpp"

namespace robodamp::rt {

// Bits of TelemetryFrame::flags.
enum FrameFlag : std::uint16_t {
  kFlagFresh = 1U << 0,
  kFlagSensorOk = 1U << 1,
  kFlagActuatorOk = 1U << 2,
  kFlagActuatorSaturated = 1U << 3,
  kFlagAmplifierReady = 1U << 4,
  kFlagAmplifierFault = 1U << 5,
  kFlagOverrun = 1U << 6,
  kFlagShutdown = 1U << 7,
  kFlagAmplifierEnable = 1U << 8,  // output
  kFlagSaturated = 1U << 9,        // output: counted as saturated
  kFlagDerated = 1U << 10,         // output: the command derated (supervision.derate)
};

struct TelemetryFrame {
  std::uint64_t tick{0};          // nominal periods since start (gaps = missed ticks)
  double time_s{0.0};             // the tick's deadline since start
  double dt_s{0.0};               // measured time since the previous tick's wake-up
  double accel_mps2{0.0};         // raw sample as read
  double filtered_mps{0.0};       // chain output (velocity estimate)
  double controller_v{0.0};       // controller output before the supervisor's fade / trip ramp
  double command_v{0.0};          // to the amplifier
  double gain_ns_per_m{0.0};      // K now (ramping)
  double command_value{0.0};      // operator command's argument
  float wake_latency_us{0.0F};    // wake-up minus deadline (0 on the virtual clock)
  float compute_us{0.0F};         // wake-up to the end of the tick's work (0 on the virtual clock)
  std::uint32_t missed_ticks{0};  // totals since start from here on
  std::uint32_t overruns{0};
  std::uint32_t saturated_ticks{0};
  std::uint32_t ring_drops{0};
  std::uint32_t stale_ticks{0};
  std::uint32_t invalid_samples{0};
  std::uint16_t flags{0};
  std::uint8_t state{0};         // rt::State
  std::uint8_t trip{0};          // rt::Trip latched
  std::uint8_t command_kind{0};  // rt::CommandKind applied at this tick
  std::uint8_t reserved[3]{};
};
static_assert(sizeof(TelemetryFrame) == 112, "the recording format fixes the frame layout");

enum class FieldType : std::uint8_t { kU8, kU16, kU32, kU64, kF32, kF64 };
[[nodiscard]] const char* to_string(FieldType t);

struct FieldInfo {
  std::string_view name;
  FieldType type;
  std::size_t offset;
  std::string_view unit;
};

// The frame's fields in layout order (the recording header and CSV columns list them).
[[nodiscard]] const std::array<FieldInfo, 21>& frame_fields();

// The supervisor inputs a frame holds.
[[nodiscard]] TickInput tick_input(const TelemetryFrame& f);

// The spindle speed a frame sets (a set_spindle command at its tick): the commanded rpm, 0 for a stop or a
// value that is not a finite positive speed; nullopt when the frame sets none. The one reading of it (the
// runtime's machining and spectrum monitors).
[[nodiscard]] inline std::optional<double> spindle_rpm_set(const TelemetryFrame& f) noexcept {
  if (static_cast<CommandKind>(f.command_kind) != CommandKind::kSetSpindle) return std::nullopt;
  return std::isfinite(f.command_value) && f.command_value > 0.0 ? f.command_value : 0.0;
}

}  // namespace robodamp::rt
