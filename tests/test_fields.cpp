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
}  // namespace robodamp
