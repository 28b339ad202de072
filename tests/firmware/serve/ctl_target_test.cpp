// Which control socket `loomctl ctl` talks to (issue 30: on an installed board `ctl status` with no
// options must reach the board's loom, whose id postinst derived into /etc/loomctl/loom-id).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "loom/firmware/serve/commands.hpp"

using loom::firmware::serve::ctl_socket;
using loom::firmware::serve::CtlArgs;
namespace fs = std::filesystem;

namespace {

class CtlTarget : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("loom_ctl_target_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "run");
    a_.loom_id_file = (dir_ / "loom-id").string();
    a_.run_dir = (dir_ / "run").string();
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  std::string error_of() {
    std::string how;
    try {
      ctl_socket(a_, how);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
  CtlArgs a_;
};

}  // namespace

TEST_F(CtlTarget, TheBoardsIdFileAsPostinstWritesIt) {
  write(dir_ / "loom-id",
        "# This board's loom id (loomctl.service --loom-id). Unique per LCM "
        "group\nLOOMCTL_LOOM_ID=loom-196736c6\n");
  std::string how;
  EXPECT_EQ(ctl_socket(a_, how), a_.run_dir + "/loom-196736c6.sock");
  EXPECT_NE(how.find("loom-196736c6 from " + a_.loom_id_file), std::string::npos) << how;
  // Quoted as a shell would take it; the last assignment counts, as in a shell.
  write(dir_ / "loom-id", "LOOMCTL_LOOM_ID=loom-a\nLOOMCTL_LOOM_ID=\"hall-2\"\n");
  EXPECT_EQ(ctl_socket(a_, how), a_.run_dir + "/hall-2.sock");
  // --socket and --loom-id still win.
  a_.loom_id = "other";
  EXPECT_EQ(ctl_socket(a_, how), a_.run_dir + "/other.sock");
  a_.socket = "/tmp/x.sock";
  EXPECT_EQ(ctl_socket(a_, how), "/tmp/x.sock");
}

TEST_F(CtlTarget, AMalformedIdFileIsNamedByFileAndLine) {
  write(dir_ / "loom-id", "# comment\nLOOMCTL_LOOM_ID=loom 1\n");
  EXPECT_EQ(error_of().rfind(a_.loom_id_file + ":2: LOOMCTL_LOOM_ID 'loom 1': ", 0), 0u) << error_of();
  write(dir_ / "loom-id", "# nothing\n");
  EXPECT_NE(error_of().find("no LOOMCTL_LOOM_ID= line"), std::string::npos) << error_of();
}

TEST_F(CtlTarget, WithoutAnIdFileTheOnlySocketServedHere) {
  EXPECT_NE(error_of().find("which loom? no " + a_.loom_id_file + " and no control socket in " + a_.run_dir),
            std::string::npos)
      << error_of();
  write(dir_ / "run" / "loom7.sock", "");
  write(dir_ / "run" / "loom7.lock", "");
  std::string how;
  EXPECT_EQ(ctl_socket(a_, how), a_.run_dir + "/loom7.sock");
  EXPECT_EQ(how, "the only socket in " + a_.run_dir);
  write(dir_ / "run" / "loom8.sock", "");
  EXPECT_NE(error_of().find("has 2 (loom7.sock, loom8.sock): give --loom-id ID"), std::string::npos)
      << error_of();
}

// The request line ctl sends: the words after the command as the socket takes them.
TEST(CtlRequestLine, EachCommandTakesItsOwnWords) {
  const auto line = [](const std::string& cmd, std::vector<std::string> args, int hours = 0) {
    CtlArgs a;
    a.command = cmd;
    a.args = std::move(args);
    a.hours = hours;
    std::string error;
    const std::string l = loom::firmware::serve::ctl_request_line(a, error);
    return l.empty() ? "error: " + error : l;
  };
  EXPECT_EQ(line("reload", {"2", "1"}), "reload head=2 slot=1");
  EXPECT_EQ(line("reload", {"2", "1", "120"}), "reload head=2 slot=1 knots=120");
  EXPECT_EQ(line("reload", {"2"}),
            "error: reload takes HEAD SLOT [KNOTS] (as the heads' request names them: reload 2 1), got 1 "
            "word(s)");
  EXPECT_EQ(line("pair", {"tablet-1"}, 12), "pair tablet-1 hours=12");
  EXPECT_EQ(line("pair", {}), "error: pair takes one NAME (e.g. pair tablet-1), got 0");
  EXPECT_EQ(line("status", {}), "status");
  EXPECT_EQ(line("start", {"now"}), "error: start takes no argument (got 'now')");
}
