#include "config/commissioning_config.hpp"

#include "config/config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config::detail {

CommissioningConfig read_commissioning(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("commissioning", false, ""), "commissioning", top.mark());
  CommissioningConfig c;
  if (auto v = r.number("settle_s", {"s", 0.5, 600.0}, c.settle_s)) c.settle_s = *v;
  if (auto v = r.number("chirp_f0_hz", {"Hz", 0.1, 1000.0}, c.chirp_f0_hz)) c.chirp_f0_hz = *v;
  if (auto v = r.number("chirp_f1_hz", {"Hz", 0.1, 1000.0}, c.chirp_f1_hz)) c.chirp_f1_hz = *v;
  if (c.chirp_f1_hz <= c.chirp_f0_hz)
    r.diagnostics().add(r.mark(), "commissioning.chirp_f1_hz",
                        "= " + format_number(c.chirp_f1_hz) +
                            " Hz must be above chirp_f0_hz = " + format_number(c.chirp_f0_hz) + " Hz");
  if (auto v = r.number("chirp_period_s", {"s", 1.0, 600.0}, c.chirp_period_s)) c.chirp_period_s = *v;
  if (auto v = read_int(r, "chirp_periods", {"(periods, the first discarded)", 2, 100}, c.chirp_periods))
    c.chirp_periods = *v;
  if (auto v = r.number("chirp_force_fraction", {"(x actuator.force_limit_n)", 0.0, 0.9, true}, c.chirp_force_fraction))
    c.chirp_force_fraction = *v;
  if (auto v = r.number("quiet_s", {"s", 0.0, 600.0}, c.quiet_s)) c.quiet_s = *v;
  if (auto v = read_int(r, "impacts_per_location", {"(impacts)", 1, 1000}, c.impacts_per_location))
    c.impacts_per_location = *v;
  if (auto v = r.number("record_s", {"s", 0.5, 600.0}, c.record_s)) c.record_s = *v;
  if (auto v = r.number("rest_accel_rms_mps2", {"m/s^2 RMS", 0.0, 1000.0, true}, c.rest_accel_rms_mps2))
    c.rest_accel_rms_mps2 = *v;
  r.finish();
  return c;
}

}  // namespace robodamp::config::detail
