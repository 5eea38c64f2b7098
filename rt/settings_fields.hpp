// The settings a recording's header stores (docs/recording_format.md), each struct's fields declared once
// (fields/fields.hpp): the header's JSON is written and read from these lists, and a member a list forgets is
// a compile error. Keys are the members' names but for the resolved sample limit; the supervision limits sit
// at the supervisor object's own level, recovery and derating under their keys.
#pragma once

#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "fields/fields.hpp"
#include "fields/json.hpp"
#include "rt/excitation.hpp"
#include "rt_settings/rt_settings.hpp"

namespace robodamp::rt {

// The trip classes by name, and back (throws RecordingError for a name that is no trip).
[[nodiscard]] nlohmann::json trips_to_json(const std::vector<Trip>& trips);
[[nodiscard]] std::vector<Trip> trips_from_json(const nlohmann::json& names);

[[nodiscard]] constexpr auto field_list(fields::Tag<RecoverySettings>) {
  using S = RecoverySettings;
  using fields::Field;
  return std::tuple{fields::Converted<S, std::vector<Trip>, nlohmann::json>{"recoverable", &S::recoverable,
                                                                            &trips_to_json, &trips_from_json},
                    Field<S, double>{"cool_down_s", &S::cool_down_s, ""},
                    Field<S, double>{"healthy_for_s", &S::healthy_for_s, ""},
                    Field<S, int>{"max_recoveries", &S::max_recoveries, ""},
                    Field<S, double>{"window_s", &S::window_s, ""},
                    Field<S, double>{"probation_s", &S::probation_s, ""}};
}
static_assert(fields::lists_every_member<RecoverySettings>());

[[nodiscard]] constexpr auto field_list(fields::Tag<DerateSettings>) {
  using S = DerateSettings;
  using fields::Field;
  return std::tuple{Field<S, bool>{"enabled", &S::enabled, ""},
                    Field<S, int>{"probe_blocks", &S::probe_blocks, ""},
                    Field<S, double>{"probe_factor", &S::probe_factor, ""},
                    Field<S, double>{"hold_factor", &S::hold_factor, ""},
                    Field<S, double>{"probe_ramp_s", &S::probe_ramp_s, ""},
                    Field<S, double>{"quiet_s", &S::quiet_s, ""},
                    Field<S, double>{"restore_s", &S::restore_s, ""},
                    Field<S, double>{"saturation_factor", &S::saturation_factor, ""},
                    Field<S, double>{"min_factor", &S::min_factor, ""}};
}
static_assert(fields::lists_every_member<DerateSettings>());

[[nodiscard]] constexpr auto field_list(fields::Tag<SupervisionLimits>) {
  using S = SupervisionLimits;
  using fields::Field;
  return std::tuple{Field<S, int>{"stale_sensor_cycles", &S::stale_sensor_cycles, ""},
                    Field<S, bool>{"zero_command_while_stale", &S::zero_command_while_stale, ""},
                    Field<S, int>{"invalid_sample_cycles", &S::invalid_sample_cycles, ""},
                    Field<S, double>{"sample_limit_mps2", &S::sample_limit_mps2, ""},
                    Field<S, int>{"overrun_cycles", &S::overrun_cycles, ""},
                    Field<S, double>{"overrun_delay_margin_share", &S::overrun_delay_margin_share, ""},
                    Field<S, double>{"saturation_window_s", &S::saturation_window_s, ""},
                    Field<S, double>{"saturation_duty_max", &S::saturation_duty_max, ""},
                    Field<S, double>{"instability_block_s", &S::instability_block_s, ""},
                    Field<S, int>{"instability_blocks", &S::instability_blocks, ""},
                    Field<S, double>{"instability_growth_factor", &S::instability_growth_factor, ""},
                    Field<S, double>{"instability_floor_v", &S::instability_floor_v, ""},
                    Field<S, double>{"trip_ramp_s", &S::trip_ramp_s, ""},
                    Field<S, int>{"arming_live_cycles", &S::arming_live_cycles, ""},
                    Field<S, double>{"arm_retry_s", &S::arm_retry_s, ""},
                    Field<S, double>{"arm_deadline_s", &S::arm_deadline_s, ""},
                    Field<S, double>{"amplifier_ready_timeout_s", &S::amplifier_ready_timeout_s, ""},
                    Field<S, double>{"max_gain_fraction", &S::max_gain_fraction, ""},
                    fields::Nested<S, RecoverySettings>{"recovery", &S::recovery},
                    fields::Nested<S, DerateSettings>{"derate", &S::derate}};
}
static_assert(fields::lists_every_member<SupervisionLimits>());

[[nodiscard]] constexpr auto field_list(fields::Tag<SupervisorSettings>) {
  using S = SupervisorSettings;
  using fields::Field;
  return std::tuple{fields::Nested<S, SupervisionLimits>{"", &S::limits},
                    Field<S, double>{"fs_hz", &S::fs_hz, ""},
                    Field<S, double>{"resolved_sample_limit_mps2", &S::sample_limit_mps2, ""},
                    Field<S, double>{"fade_s", &S::fade_s, ""},
                    Field<S, bool>{"analysis_stable", &S::analysis_stable, ""},
                    Field<S, double>{"max_stable_gain_ns_per_m", &S::max_stable_gain_ns_per_m, ""},
                    Field<S, double>{"delay_margin_s", &S::delay_margin_s, ""},
                    Field<S, double>{"command_limit_v", &S::command_limit_v, ""},
                    Field<S, bool>{"pose_scheduled", &S::pose_scheduled, ""}};
}
static_assert(fields::lists_every_member<SupervisorSettings>());

[[nodiscard]] constexpr auto field_list(fields::Tag<PeriodicChirp>) {
  using S = PeriodicChirp;
  using fields::Field;
  return std::tuple{Field<S, bool>{"enabled", &S::enabled, ""},
                    Field<S, double>{"start_s", &S::start_s, ""},
                    Field<S, double>{"period_s", &S::period_s, ""},
                    Field<S, int>{"periods", &S::periods, ""},
                    Field<S, double>{"f0_hz", &S::f0_hz, ""},
                    Field<S, double>{"f1_hz", &S::f1_hz, ""},
                    Field<S, double>{"amplitude_v", &S::amplitude_v, ""},
                    Field<S, double>{"ramp_s", &S::ramp_s, ""},
                    Field<S, bool>{"on_command", &S::on_command, ""}};
}
static_assert(fields::lists_every_member<PeriodicChirp>());

}  // namespace robodamp::rt
