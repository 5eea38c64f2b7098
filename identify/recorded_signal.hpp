// A recorded vibration or sound signal from whatever wrote it (docs/milling.md, "Listening to a recorded
// cut"): a table (measfiles/table.hpp: a time column or a given rate, the column by name or number), a
// sound file (measfiles/wav.hpp: a channel, scaled by its full scale), a universal file's time history
// (identify/uff_frf.hpp's reader, dataset 58/58b), or a robodamp recording (its accelerometer, missed ticks
// as dropouts). Units where the file says them; accelerations in m/s^2. Off the real-time path.
#pragma once

#include <optional>
#include <string>

#include "identify/uff_frf.hpp"
#include "milling/chatter_listen.hpp"

namespace robodamp::identify {

struct SignalOptions {
  std::string column;                     // a table's column: its name or 1-based number (default: the first not time)
  std::string rpm_column;                 // a table's spindle-speed column (rpm), name or number; empty: none
  std::optional<double> rate_hz;          // a table without a time column
  int channel{1};                         // a sound file's channel, 1-based
  std::optional<double> full_scale_mps2;  // a sound file: the acceleration at full scale (else not an acceleration)
  std::optional<int> record;              // a universal file's function record
  std::optional<Dof> response;            // ... or its response DOF
};

// Throws std::invalid_argument naming the file and what is wrong. described: what was read, for the report.
[[nodiscard]] milling::RecordedSignal read_recorded_signal(const std::string& path, const SignalOptions& o,
                                                           std::string& described);

}  // namespace robodamp::identify
