// The latched fault on disk (issue 22: a restart is not a reset): what serve writes it reads back, an
// acknowledgement removes it, and a record that is not exactly what serve writes is refused naming the
// file:line, the field and the value — never half read, never re-latched as something else.
#include "loom/firmware/serve/latched_fault.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "loom/config/config.hpp"
#include "test_dir.hpp"

using namespace loom::firmware::serve;
using loom::firmware::ConfigError;
using loom::sequencer::Fault;

namespace {

std::string temp_dir() {
  return loom::test::fresh_test_dir("lf").string();
}

LatchedFault drive_fault() {
  LatchedFault f;
  f.fault = Fault::kDriveFault;
  f.record.kind = "fault";
  f.record.name = "drive_fault";
  f.record.code = 0x1002;
  f.record.axis = "carriage";
  f.record.device_code = 0x7310;
  f.record.rows = 3;
  f.record.picks = 4;
  f.record.beats = 45;
  f.record.text = "a servo drive reported a fault\n(motion stopped on stale_feedback)";
  f.latched_at_s = 1'795'000'000;
  return f;
}

std::string refusal(const std::string& text) {
  try {
    LatchedFaultStore::parse(text, "/state/latched-fault");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const std::string kGood =
    "kind = fault\nfault = drive_fault\naxis = carriage\ndevice_code = 0x7310\nlatched_at = "
    "2026-11-18T11:06:40Z\n"
    "rows = 3\npicks = 4\nbeats = 45\n";

}  // namespace

TEST(LatchedFault, WhatIsSavedIsLoadedBackAndAnAcknowledgementRemovesIt) {
  const std::string dir = temp_dir();
  const LatchedFaultStore store(dir + "/latched-fault", dir + "/reserve");
  EXPECT_FALSE(store.load().has_value()) << "no file: no fault latched";
  store.save(drive_fault());
  const auto back = store.load();
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->fault, Fault::kDriveFault);
  EXPECT_EQ(back->record.kind, "fault");
  EXPECT_EQ(back->record.name, "drive_fault");
  EXPECT_EQ(back->record.code, 0x1002);
  EXPECT_EQ(back->record.axis, "carriage");
  EXPECT_EQ(back->record.device_code, 0x7310);
  EXPECT_EQ(back->record.rows, 3u);
  EXPECT_EQ(back->record.picks, 4u);
  EXPECT_EQ(back->record.beats, 45u);
  EXPECT_EQ(back->record.text, "a servo drive reported a fault (motion stopped on stale_feedback)");
  EXPECT_EQ(back->latched_at_s, 1'795'000'000);
  EXPECT_FALSE(std::filesystem::exists(dir + "/latched-fault.tmp"));
  store.clear();
  EXPECT_FALSE(std::filesystem::exists(dir + "/latched-fault"));
  EXPECT_FALSE(store.load().has_value());
  EXPECT_NO_THROW(store.clear()) << "clearing twice is not an error";
  std::filesystem::remove_all(dir);
}

TEST(LatchedFault, TheFileReadsAsATechnicianExpects) {
  const std::string text = LatchedFaultStore::format(drive_fault());
  EXPECT_NE(text.find("\nfault = drive_fault\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nlatched_at = 2026-11-18T11:06:40Z\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\ndevice_code = 0x7310\n"), std::string::npos) << text;
  EXPECT_EQ(LatchedFaultStore::parse(kGood, "f").fault, Fault::kDriveFault);
}

TEST(LatchedFault, ABadRecordIsRefusedNamingFileLineFieldAndValue) {
  struct Case {
    std::string text;
    std::string expect;  // a part of the error
  };
  const std::string head = "kind = fault\nfault = drive_fault\n";
  const Case cases[] = {
      {"kind = fault\nfault = drive_fualt\nlatched_at = 2026-11-18T11:06:40Z\n",
       "/state/latched-fault:2: fault = \"drive_fualt\": not a fault of the fault table"},
      {"kind = fault\nfault = none\nlatched_at = 2026-11-18T11:06:40Z\n", ":2: fault = \"none\""},
      {"kind = reset\nfault = estop\nlatched_at = 2026-11-18T11:06:40Z\n", ":1: kind = \"reset\""},
      {head + "latched_at = 2026-02-30T11:06:40Z\n", ":3: latched_at = \"2026-02-30T11:06:40Z\""},
      {head + "latched_at = yesterday\n", ":3: latched_at = \"yesterday\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\nrows = 4294967296\n", ":4: rows = \"4294967296\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\npicks = -1\n", ":4: picks = \"-1\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\nbeats = 1.5\n", ":4: beats = \"1.5\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\ndevice_code = 0x17310\n", ":4: device_code = \"0x17310\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\naxis = Carriage!\n", ":4: axis = \"Carriage!\""},
      {head + "latched_at = 2026-11-18T11:06:40Z\ncolour = red\n", ":4: colour = \"red\": unknown field"},
      {head + "latched_at = 2026-11-18T11:06:40Z\nfault = estop\n",
       ":4: fault = \"estop\": given twice (first at line 2)"},
      {head + "latched_at = 2026-11-18T11:06:40Z\nthe end\n", ":4: line = \"the end\": not `key = value`"},
      {head + "latched_at = 2026-11-18T11:06:40Z\ntext = a\x01"
              "b\n",
       ":4: text = "},
      {head, "latched_at = \"\": missing"},
      {"", "kind = \"\": missing"},
  };
  for (const Case& c : cases) {
    const std::string why = refusal(c.text);
    EXPECT_NE(why.find(c.expect), std::string::npos) << "record:\n" << c.text << "\nerror: " << why;
    EXPECT_NE(why.find("/state/latched-fault:"), std::string::npos) << why;
  }
}

// A record saved with Windows line ends (an editor on a laptop): refused, and the \r it carries is shown
// as \r, not printed raw (issue 30: the message showed `kind = "fault"` with an invisible CR in it).
TEST(LatchedFault, ACrlfRecordIsRefusedShowingTheCarriageReturn) {
  const std::string why =
      refusal("kind = fault\r\nfault = drive_fault\r\nlatched_at = 2026-11-18T11:06:40Z\r\n");
  EXPECT_EQ(why.find('\r'), std::string::npos) << why;
  EXPECT_NE(why.find("/state/latched-fault:1: kind = \"fault\\r\": must be fault or overrun_stop"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("Windows line ends (CRLF)"), std::string::npos) << why;
  // Other control bytes as \xNN.
  const std::string bell =
      refusal("kind = fa\x07ult\nfault = drive_fault\nlatched_at = 2026-11-18T11:06:40Z\n");
  EXPECT_NE(bell.find("kind = \"fa\\x07ult\""), std::string::npos) << bell;
}

TEST(LatchedFault, AFileThatIsNotARecordIsRefusedAndLeftAlone) {
  const std::string dir = temp_dir();
  const LatchedFaultStore store(dir + "/latched-fault", dir + "/reserve");
  std::filesystem::create_directories(dir + "/latched-fault");
  EXPECT_THROW(store.load(), ConfigError);
  std::filesystem::remove_all(dir + "/latched-fault");
  { std::ofstream(dir + "/latched-fault") << std::string(5000, 'x'); }
  EXPECT_THROW(store.load(), ConfigError);
  const std::string bad = "kind = fault\nfault = estop\nlatched_at = now\n";
  { std::ofstream(dir + "/latched-fault") << bad; }
  EXPECT_THROW(store.load(), ConfigError);
  EXPECT_EQ(std::filesystem::file_size(dir + "/latched-fault"), bad.size())
      << "a refused record is left as it was";
  std::filesystem::remove_all(dir);
}
