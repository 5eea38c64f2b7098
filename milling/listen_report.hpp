// What `robodamp chatter` reports of a recorded cut (milling/chatter_listen.hpp; docs/milling.md, "Listening
// to a recorded cut"): the windows' verdicts, the chatter and the speeds to try, with the speeds the
// accurate method checked, as text, JSON and plots. Off the real-time path.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "config/config.hpp"
#include "config/milling_config.hpp"
#include "milling/chatter_listen.hpp"
#include "milling/speed_advice.hpp"

namespace robodamp::milling {

// signal: the recording as the reader described it ("cut.wav (channel 1 of 2, ...)"). advice: the speeds
// to try checked on the cell (none: not checked); damped: the damper ran in the recorded cut.
[[nodiscard]] std::string listen_text(const ListenReport& r, int teeth, const std::string& signal,
                                      const std::optional<SpeedAdvice>& advice, bool damped);
[[nodiscard]] nlohmann::json listen_json(const ListenReport& r, int teeth, const std::optional<SpeedAdvice>& advice,
                                         bool damped);
// chatter_spectrogram.png and chatter_verdict.png into dir (created): an empty string, or why a plot failed.
[[nodiscard]] std::string plot_listen(const ListenReport& r, const std::string& dir);

// The cell a recorded cut's speeds to try are checked on, as its advisor checks them: its configuration and
// its job (`job_path`, else the configuration's spindle.job).
struct ListenCell {
  config::Config cfg;
  config::MillingConfig job;
};
// None without a configuration (then `job_path` and `needs_cell`, a depth or the damper given, are refused).
// Throws std::invalid_argument when the job is missing or cuts with other than `teeth`.
[[nodiscard]] std::optional<ListenCell> listen_cell(const std::string& config_path, const std::string& job_path,
                                                    bool needs_cell, int teeth);
// Each speed to try checked by the accurate limit at the recorded depth (default the job's) between rpm_lo and
// rpm_hi, with the damper as it ran.
[[nodiscard]] SpeedAdvice checked_speeds(const ListenCell& c, const ListenReport& r, std::optional<double> depth_mm,
                                         bool damped, double rpm_lo, double rpm_hi);

}  // namespace robodamp::milling
