// What `robodamp chatter` reports of a recorded cut (milling/chatter_listen.hpp; docs/milling.md, "Listening
// to a recorded cut"): the windows' verdicts, the chatter and the speeds to try, with the speeds the
// accurate method checked, as text, JSON and plots. Off the real-time path.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

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

}  // namespace robodamp::milling
