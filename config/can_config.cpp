#include "config/can_config.hpp"

#include <cmath>

namespace robodamp::config {

double can_frame_time_s(const CanFrameMapping& f, bool fd, double bitrate, double data_bitrate) {
  const double n = f.length_bytes;
  if (!fd) {
    const double bits =
        f.extended_id ? 8 * n + 67 + std::floor((54 + 8 * n - 1) / 4) : 8 * n + 47 + std::floor((34 + 8 * n - 1) / 4);
    return bits / bitrate;
  }
  // Arbitration: SOF, identifier, RRS, IDE, FDF, res, BRS (+ SRR and the 18-bit extension), stuffed.
  const double arb = f.extended_id ? 36 : 17;
  const double nominal_bits = arb + std::floor((arb - 1) / 4) + 13;  // + CRC delimiter, ACK, EOF, IFS
  const double crc = n <= 16 ? 17 : 21;
  const double data_bits = 5 + 8 * n + std::floor((5 + 8 * n - 1) / 4) + 4 + crc + std::ceil((4 + crc) / 4);
  return nominal_bits / bitrate + data_bits / (data_bitrate > 0.0 ? data_bitrate : bitrate);
}

double can_bus_load(const CanConfig& c, double loop_rate_hz) {
  return loop_rate_hz * (can_frame_time_s(c.sensor, c.fd, c.bitrate_bps, c.data_bitrate_bps) +
                         can_frame_time_s(c.command, c.fd, c.bitrate_bps, c.data_bitrate_bps));
}

}  // namespace robodamp::config
