// Channel names and their validation, and — through a real in-process LCM (memq://) — that the
// subscription regexes select exactly one loom's channel, or one channel kind of every loom.
#include "loom/telemetry/channels.hpp"

#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace loom::telemetry;

TEST(Channels, NamesCarryPrefixAndLoomId) {
  const ChannelNames c = channel_names("LOOM", "hall2-07");
  EXPECT_EQ(c.status, "LOOM.hall2-07.STATUS");
  EXPECT_EQ(c.axes, "LOOM.hall2-07.AXES");
  EXPECT_EQ(c.rt, "LOOM.hall2-07.RT");
}

TEST(Channels, LoomIdValidationNamesTheValue) {
  EXPECT_EQ(loom_id_error("loom_1-A"), "");
  EXPECT_EQ(loom_id_error(std::string(kMaxLoomIdLength, 'x')), "");
  for (const std::string& bad :
       std::vector<std::string>{"", "a.b", "a b", "a*", "\xc3\xa9", std::string(kMaxLoomIdLength + 1, 'x')}) {
    const std::string e = loom_id_error(bad);
    EXPECT_NE(e, "") << bad;
    EXPECT_NE(e.find("'" + bad + "'"), std::string::npos) << e;
  }
}

TEST(Channels, PrefixValidation) {
  EXPECT_EQ(channel_prefix_error("LOOM"), "");
  EXPECT_EQ(channel_prefix_error("FACTORY.HALL_2"), "");
  for (const std::string bad : {"", ".LOOM", "LOOM.", "A..B", "LO OM", "L*"}) {
    EXPECT_NE(channel_prefix_error(bad), "") << bad;
  }
}

// Collects the channels an LCM subscription actually delivers. (A static handler with a context:
// LCM 1.3.1's member-function subscribe crashes under -fsanitize=undefined.)
struct Seen {
  std::set<std::string> channels;
  static void on(const lcm::ReceiveBuffer*, const std::string& channel, Seen* self) {
    self->channels.insert(channel);
  }
};

std::set<std::string> delivered(const std::string& regex, const std::set<std::string>& published) {
  lcm::LCM lcm("memq://");
  EXPECT_TRUE(lcm.good());
  Seen seen;
  lcm.subscribeFunction(regex, &Seen::on, &seen);
  const char payload[1] = {0};
  for (const auto& ch : published) lcm.publish(ch, payload, sizeof payload);
  while (lcm.handleTimeout(0) > 0) {
  }
  return seen.channels;
}

TEST(Channels, RegexSelectsOneLoomThroughLcm) {
  const std::set<std::string> all = {"LOOM.a.STATUS", "LOOM.ab.STATUS", "LOOM.a.STATUSX", "LOOMX.a.STATUS",
                                     "LOOM.a.AXES",   "XLOOM.a.STATUS", "LOOM.b.STATUS",  "LOOMxaxSTATUS"};
  EXPECT_EQ(delivered(channel_regex("LOOM", "a", "STATUS"), all), std::set<std::string>{"LOOM.a.STATUS"});
  EXPECT_EQ(delivered(channel_regex("LOOM", "", "STATUS"), all),
            (std::set<std::string>{"LOOM.a.STATUS", "LOOM.ab.STATUS", "LOOM.b.STATUS"}));
  EXPECT_EQ(delivered(channel_regex("F.H", "", "RT"), {"F.H.x.RT", "FxH.x.RT", "F.H.x.y.RT"}),
            std::set<std::string>{"F.H.x.RT"});
}

}  // namespace
