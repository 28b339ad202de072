// The COMMAND channel (issue 22: every command carries who gave it into a COMMAND/AUDIT event): a
// CommandEvents writing through LCM's file:// provider, read back with lcm::LogFile and decoded by the
// generated type. The expected channel and fields are written out here, not taken from the code.
#include "loom/telemetry/command_events.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "loomlcm/command_t.hpp"

namespace {

using loom::telemetry::CommandAudit;
using loom::telemetry::CommandEvents;

struct Logged {
  std::string channel;
  loomlcm::command_t m;
};

std::vector<Logged> read_back(const std::string& path) {
  std::vector<Logged> out;
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good()) << path;
  if (!log.good()) return out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    Logged l;
    l.channel = ev->channel;
    EXPECT_GE(l.m.decode(ev->data, 0, static_cast<int>(ev->datalen)), 0) << ev->channel;
    out.push_back(l);
  }
  return out;
}

TEST(CommandEvents, EachAuditIsOneEventOnTheLoomsCommandChannel) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("command_events_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "audit.lcmlog").string();
  const auto before = std::chrono::system_clock::now();
  {
    CommandEvents ev("file://" + path + "?mode=w", "LOOM", "hall3-7");
    EXPECT_EQ(ev.channel(), "LOOM.hall3-7.COMMAND");
    CommandAudit started{"start", "local", "local user anna (uid 1000, pid 42)", true, "ok start", "idle"};
    CommandAudit refused{
        "resume",
        "panel",
        "panel client 10.0.0.5 (not paired) via local user www (uid 33, pid 7)",
        false,
        "refused: resume: a command that starts motion or resets a fault needs a paired panel client",
        "paused"};
    CommandAudit button{"pause", "button", "the I/O module's pause button", true, "ok pause", "pick"};
    EXPECT_TRUE(ev.publish(started));
    EXPECT_TRUE(ev.publish(refused));
    EXPECT_TRUE(ev.publish(button));
    EXPECT_EQ(ev.published(), 3u);
    EXPECT_EQ(ev.failures(), 0u);
  }
  const auto after = std::chrono::system_clock::now();
  const auto us = [](auto t) {
    return std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
  };
  const std::vector<Logged> got = read_back(path);
  ASSERT_EQ(got.size(), 3u);
  for (const Logged& l : got) {
    EXPECT_EQ(l.channel, "LOOM.hall3-7.COMMAND");
    EXPECT_EQ(l.m.loom_id, "hall3-7");
    EXPECT_GE(l.m.utime, us(before));
    EXPECT_LE(l.m.utime, us(after));
  }
  EXPECT_EQ(got[0].m.word, "start");
  EXPECT_EQ(got[0].m.station, "local");
  EXPECT_EQ(got[0].m.who, "local user anna (uid 1000, pid 42)");
  EXPECT_TRUE(got[0].m.accepted);
  EXPECT_EQ(got[0].m.reply, "ok start");
  EXPECT_EQ(got[0].m.state, "idle");
  EXPECT_EQ(got[1].m.word, "resume");
  EXPECT_EQ(got[1].m.station, "panel");
  EXPECT_FALSE(got[1].m.accepted);
  EXPECT_EQ(got[1].m.who, "panel client 10.0.0.5 (not paired) via local user www (uid 33, pid 7)");
  EXPECT_EQ(got[1].m.state, "paused");
  EXPECT_EQ(got[2].m.station, "button");
  EXPECT_EQ(got[2].m.who, "the I/O module's pause button");
  std::filesystem::remove_all(dir);
}

TEST(CommandEvents, AnUnopenableUrlIsRefusedAtConfigureTime) {
  EXPECT_THROW(CommandEvents("file:///no_such_dir_for_loom/x.lcmlog?mode=w", "LOOM", "loom1"),
               std::invalid_argument);
}

}  // namespace
