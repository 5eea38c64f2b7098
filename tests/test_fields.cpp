// A reported struct's fields declared once (fields/fields.hpp): each counters struct's list names every
// member once, its JSON goes there and back, and its text carries every count with its words.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "drivers/can_driver.hpp"
#include "drivers/modbus_client.hpp"
#include "fields/json.hpp"
#include "runtime/joint_state_pose.hpp"
#include "runtime/path_ahead.hpp"
#include "rt/recording.hpp"
#include "rt/settings_fields.hpp"
#include "rt/supervisor.hpp"

namespace robodamp {
namespace {

struct ThreeCounts {
  std::uint64_t a{0}, b{0}, c{0};
};
// A list that forgot c.
[[nodiscard]] constexpr auto field_list(fields::Tag<ThreeCounts>) {
  using F = fields::Field<ThreeCounts, std::uint64_t>;
  return std::tuple{F{"a", &ThreeCounts::a, "as"}, F{"b", &ThreeCounts::b, "bs"}};
}

TEST(Fields, AListThatForgetsAMemberIsCaught) {
  static_assert(fields::detail::member_count<ThreeCounts>() == 3);
  static_assert(fields::detail::member_count<rt::SupervisorCounters>() == 29, "the trips' array counts as one");
  EXPECT_FALSE(fields::lists_every_member<ThreeCounts>());
}

// Each field a value of its own (1, 2, ...; a named count's entries 100 + index): the JSON has one key per
// field (nested where the key says), reads back to the same struct, and the text says each value with its words.
template <class S>
void check_round_trip(const char* name) {
  SCOPED_TRACE(name);
  S s{};
  std::uint64_t next = 1;
  std::apply(
      [&](const auto&... f) {
        auto fill = [&](const auto& field) {
          auto& m = s.*(field.member);
          if constexpr (std::is_integral_v<std::decay_t<decltype(m)>>)
            m = next++;
          else
            for (std::size_t i = 0; i < m.size(); ++i) m[i] = 100 + i;
        };
        (fill(f), ...);
      },
      fields::list_of<S>());

  const nlohmann::json j = fields::to_json(s);
  std::set<std::string> keys;
  fields::for_each_field(
      s, [&](const auto& field, const auto&) { EXPECT_TRUE(keys.insert(std::string(field.key)).second) << field.key; });
  const S back = fields::from_json<S>(j);
  EXPECT_EQ(fields::to_json(back), j);
  const std::string text = fields::text(s);
  fields::for_each_field(s, [&](const auto& field, const auto& value) {
    if constexpr (std::is_integral_v<std::decay_t<decltype(value)>>) {
      EXPECT_NE(text.find(std::to_string(value) + " " + std::string(field.label)), std::string::npos) << text;
      EXPECT_EQ(back.*(field.member), value);
    } else {
      EXPECT_EQ((back.*(field.member))[0], 0U) << "the enum's none is not reported";
      for (std::size_t i = 1; i < value.size(); ++i) {
        EXPECT_EQ((back.*(field.member))[i], value[i]);
        EXPECT_NE(text.find(std::string(field.name_of(i)) + " " + std::to_string(value[i])), std::string::npos) << text;
      }
    }
  });
}

TEST(Fields, EachCountersListGoesToJsonAndBackAndIntoItsText) {
  check_round_trip<rt::SupervisorCounters>("SupervisorCounters");
  check_round_trip<drivers::CanCounters>("CanCounters");
  check_round_trip<drivers::ModbusCounters>("ModbusCounters");
  check_round_trip<dds::BridgeCounters>("BridgeCounters");
  check_round_trip<runtime::JointStateCounters>("JointStateCounters");
  check_round_trip<runtime::PathAheadCounters>("PathAheadCounters");
}

TEST(Fields, NestedKeysAndTheTripsByName) {
  rt::SupervisorCounters c{};
  c.derate_probes = 4;
  c.trips[static_cast<std::size_t>(rt::Trip::kInstability)] = 2;
  const nlohmann::json j = fields::to_json(c);
  EXPECT_EQ(j.at("derate").at("probes"), 4);
  EXPECT_EQ(j.at("trips").at("instability"), 2);
  EXPECT_FALSE(j.at("trips").contains("none"));
  EXPECT_EQ(j.at("trips").size(), rt::kTripCount - 1);
  EXPECT_NE(fields::text(c).find("trips: instability 2"), std::string::npos) << fields::text(c);
  EXPECT_NE(fields::text(rt::SupervisorCounters{}).find("trips: none"), std::string::npos);
  // A summary written before a counter existed reads with that counter 0.
  const auto old = fields::from_json<rt::SupervisorCounters>(nlohmann::json{{"stale_ticks", 7}});
  EXPECT_EQ(old.stale_ticks, 7U);
  EXPECT_EQ(old.derate_probes, 0U);
}

}  // namespace
// The recording header's settings (rt/settings_fields.hpp): every member with a value of its own goes to the
// header's JSON and back (the recovery's trips by name, the limits at the supervisor object's level, recovery
// and derating nested), and a header written before a key existed reads as that recording ran.
TEST(Fields, TheRecordedSettingsGoToJsonAndBackAndOldHeadersReadAsTheyRan) {
  rt::SupervisorSettings s;
  rt::SupervisionLimits& l = s.limits;
  l.stale_sensor_cycles = 7, l.zero_command_while_stale = false, l.invalid_sample_cycles = 3;
  l.sample_limit_mps2 = 123.5, l.overrun_cycles = 11, l.overrun_delay_margin_share = 0.25;
  l.saturation_window_s = 0.7, l.saturation_duty_max = 0.3, l.instability_block_s = 0.2, l.instability_blocks = 5;
  l.instability_growth_factor = 1.7, l.instability_floor_v = 0.03, l.trip_ramp_s = 0.02, l.arming_live_cycles = 40;
  l.arm_retry_s = 0.6, l.arm_deadline_s = 12.0, l.amplifier_ready_timeout_s = 0.3, l.max_gain_fraction = 0.8;
  l.recovery.recoverable = {rt::Trip::kSensorStale, rt::Trip::kOverruns};
  l.recovery.cool_down_s = 1.5, l.recovery.healthy_for_s = 2.5, l.recovery.max_recoveries = 4;
  l.recovery.window_s = 500.0, l.recovery.probation_s = 9.0;
  l.derate.enabled = false, l.derate.probe_blocks = 3, l.derate.probe_factor = 0.1, l.derate.hold_factor = 0.4;
  l.derate.probe_ramp_s = 0.03, l.derate.quiet_s = 1.2, l.derate.restore_s = 2.2, l.derate.saturation_factor = 0.6;
  l.derate.min_factor = 0.05;
  s.fs_hz = 4000.0, s.sample_limit_mps2 = 490.5, s.fade_s = 0.4, s.analysis_stable = true;
  s.max_stable_gain_ns_per_m = 4321.0, s.delay_margin_s = 0.012, s.command_limit_v = 9.0, s.pose_scheduled = true;
  const nlohmann::json j = rt::to_json(s);
  EXPECT_EQ(j["stale_sensor_cycles"], 7);
  EXPECT_EQ(j["resolved_sample_limit_mps2"], 490.5);
  EXPECT_EQ(j["recovery"]["recoverable"], (nlohmann::json{"sensor_stale", "overruns"}));
  EXPECT_EQ(j["derate"]["min_factor"], 0.05);
  const rt::SupervisorSettings back = rt::supervisor_settings_from(j);
  EXPECT_EQ(rt::to_json(back), j);  // every field, the nested ones and the trips included
  EXPECT_EQ(back.limits.recovery.recoverable, l.recovery.recoverable);
  // A header from before the stale and overrun ride-throughs, recovery, derating and the supervisor's own
  // command limit: the chirp's voltage limit, and what such a recording ran with.
  nlohmann::json old = j;
  for (const char* key : {"zero_command_while_stale", "overrun_delay_margin_share", "recovery", "derate",
                          "command_limit_v", "arm_retry_s", "arm_deadline_s"})
    old.erase(key);
  old["test_signal"] = {{"voltage_limit_v", 7.5}};
  const rt::SupervisorSettings was = rt::supervisor_settings_from(old);
  EXPECT_FALSE(was.limits.zero_command_while_stale);
  EXPECT_EQ(was.limits.overrun_delay_margin_share, 0.0);
  EXPECT_TRUE(was.limits.recovery.recoverable.empty());
  EXPECT_FALSE(was.limits.derate.enabled);
  EXPECT_EQ(was.command_limit_v, 7.5);
  EXPECT_EQ(was.limits.arm_retry_s, rt::SupervisionLimits{}.arm_retry_s);
  EXPECT_EQ(was.limits.stale_sensor_cycles, 7);
  // A trip the program does not know is refused by name.
  nlohmann::json bad = j;
  bad["recovery"]["recoverable"] = {"sensor_stale", "gremlins"};
  EXPECT_THROW((void)rt::supervisor_settings_from(bad), rt::RecordingError);
  // The chirp, and one recorded before its ramp and its start on command.
  rt::PeriodicChirp c{true, 1.0, 6.0, 3, 2.0, 60.0, 0.4, 0.5, true};
  EXPECT_EQ(fields::to_json(fields::from_json<rt::PeriodicChirp>(rt::to_json(c))), rt::to_json(c));
  nlohmann::json old_chirp = rt::to_json(c);
  old_chirp.erase("ramp_s"), old_chirp.erase("on_command");
  const auto oc = fields::from_json<rt::PeriodicChirp>(old_chirp);
  EXPECT_EQ(oc.ramp_s, 0.0);
  EXPECT_FALSE(oc.on_command);
  EXPECT_EQ(oc.f1_hz, 60.0);
}

}  // namespace robodamp
