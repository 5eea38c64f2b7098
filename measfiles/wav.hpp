// WAV files (and the other formats libsndfile reads: AIFF, FLAC, ...) as a recorder writes them: any rate,
// 8/16/24/32-bit integer or float, any number of channels. Off the real-time path.
#pragma once

#include <string>
#include <vector>

namespace robodamp::measfiles {

struct Sound {
  double rate_hz{0.0};
  int channels{0};
  std::vector<double> samples;  // the chosen channel, full scale = 1
  std::string format;           // e.g. "WAV, 24-bit PCM"
  double peak{0.0};             // largest |sample|
};

// channel: 0-based. Throws std::invalid_argument naming the file: not readable, not a sound file, no such
// channel, empty.
[[nodiscard]] Sound read_sound(const std::string& path, int channel);
[[nodiscard]] bool looks_like_sound(const std::string& path);

}  // namespace robodamp::measfiles
