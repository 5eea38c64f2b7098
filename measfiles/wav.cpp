#include "measfiles/wav.hpp"

#include <sndfile.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace robodamp::measfiles {

namespace {

std::string subtype(int format) {
  switch (format & SF_FORMAT_SUBMASK) {
    case SF_FORMAT_PCM_S8:
    case SF_FORMAT_PCM_U8:
      return "8-bit PCM";
    case SF_FORMAT_PCM_16:
      return "16-bit PCM";
    case SF_FORMAT_PCM_24:
      return "24-bit PCM";
    case SF_FORMAT_PCM_32:
      return "32-bit PCM";
    case SF_FORMAT_FLOAT:
      return "32-bit float";
    case SF_FORMAT_DOUBLE:
      return "64-bit float";
    default:
      return "another encoding";
  }
}

}  // namespace

bool looks_like_sound(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[4] = {};
  in.read(head, 4);
  const std::string h(head, 4);
  return h == "RIFF" || h == "RF64" || h == "FORM" || h == "fLaC";
}

Sound read_sound(const std::string& path, int channel) {
  SF_INFO info{};
  std::unique_ptr<SNDFILE, int (*)(SNDFILE*)> f(sf_open(path.c_str(), SFM_READ, &info), sf_close);
  if (!f) throw std::invalid_argument(path + ": not a sound file libsndfile reads (" + sf_strerror(nullptr) + ")");
  if (channel < 0 || channel >= info.channels)
    throw std::invalid_argument(path + ": channel " + std::to_string(channel + 1) + ": the file has " +
                                std::to_string(info.channels) + " (allowed 1 .. " + std::to_string(info.channels) +
                                ")");
  if (info.frames <= 0) throw std::invalid_argument(path + ": no samples");
  Sound s;
  s.rate_hz = info.samplerate, s.channels = info.channels;
  s.format = std::string((info.format & SF_FORMAT_TYPEMASK) == SF_FORMAT_WAV ? "WAV" : "sound file") + ", " +
             subtype(info.format);
  std::vector<double> frame(static_cast<std::size_t>(info.channels) * 4096);
  s.samples.reserve(static_cast<std::size_t>(info.frames));
  for (;;) {
    const sf_count_t got = sf_readf_double(f.get(), frame.data(), 4096);
    if (got <= 0) break;
    for (sf_count_t i = 0; i < got; ++i) {
      const double v = frame[static_cast<std::size_t>(i * info.channels + channel)];
      s.samples.push_back(v), s.peak = std::max(s.peak, std::abs(v));
    }
  }
  if (s.samples.empty()) throw std::invalid_argument(path + ": no samples could be read");
  return s;
}

}  // namespace robodamp::measfiles
