// SocketCanBus::open on whatever kernel runs the tests: it must fail with a sentence naming the
// interface and the cause, never crash. This machine's kernel has no PF_CAN, which is checked directly
// with socket(2) so the expectation follows the kernel, not a guess. Real-vcan tests live in tests/hil.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

#include "loom/drivers/can_link_info.hpp"
#include "loom/drivers/socket_can_bus.hpp"

namespace loom::drivers {
namespace {

bool kernel_has_can() {
  const int fd = ::socket(PF_CAN, SOCK_RAW, 1 /* CAN_RAW */);
  if (fd >= 0) {
    ::close(fd);
    return true;
  }
  return errno != EAFNOSUPPORT;
}

TEST(SocketCanBus, OpenNamesTheInterfaceAndTheCause) {
  auto r = SocketCanBus::open("loomnone0");
  ASSERT_FALSE(r.is_ok());
  EXPECT_NE(r.error().find("'loomnone0'"), std::string::npos) << r.error();
  if (kernel_has_can()) {
    EXPECT_NE(r.error().find("no network interface of that name"), std::string::npos) << r.error();
  } else {
    EXPECT_NE(r.error().find("this kernel has no CAN support"), std::string::npos) << r.error();
  }
}

TEST(SocketCanBus, NoCanKernelIsReportedAsSuch) {
  if (kernel_has_can()) GTEST_SKIP() << "this kernel has CAN; the no-CAN diagnosis cannot be observed here";
  auto r = SocketCanBus::open("vcan0");
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.error().rfind("cannot open CAN interface 'vcan0': this kernel has no CAN support", 0), 0u)
      << r.error();
}

TEST(SocketCanBus, BadNamesAreRefusedBeforeAnySyscall) {
  auto empty = SocketCanBus::open("");
  ASSERT_FALSE(empty.is_ok());
  EXPECT_NE(empty.error().find("empty"), std::string::npos);
  auto long_name = SocketCanBus::open("a_very_long_interface_name");
  ASSERT_FALSE(long_name.is_ok());
  EXPECT_NE(long_name.error().find("longer than 15 characters"), std::string::npos) << long_name.error();
}

}  // namespace
}  // namespace loom::drivers

// ---- the kernel's view of the link (netlink) ------------------------------------------------------
TEST(CanLinkInfo, LoopbackIsNotACanLinkAndMissingInterfacesAreNamed) {
  auto lo = loom::drivers::read_can_link_info("lo");
  ASSERT_TRUE(lo) << lo.error();
  EXPECT_EQ(lo.value().kind, "");
  EXPECT_TRUE(lo.value().up);
  std::string note;
  EXPECT_EQ(loom::drivers::check_can_bitrate("lo", lo.value(), 1000000, note).message(),
            "lo is not a CAN interface (link kind '')");
  auto none = loom::drivers::read_can_link_info("nosuchcan9");
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error(), "CAN interface 'nosuchcan9' does not exist");
}

TEST(CanLinkInfo, BitrateMismatchIsRefusedWithTheFixAndVcanIsAcceptedWithANote) {
  std::string note;
  loom::drivers::CanLinkInfo can0{"can", 500000, true};
  const auto s = loom::drivers::check_can_bitrate("can0", can0, 1000000, note);
  EXPECT_EQ(s.message(),
            "can0 runs at 500000 bit/s but can.bitrate = 1000000; bring it up with: ip link set can0 down && "
            "ip link set can0 type can bitrate 1000000 && ip link set can0 up");
  can0.bitrate_bps = 1000000;
  EXPECT_TRUE(loom::drivers::check_can_bitrate("can0", can0, 1000000, note));
  EXPECT_TRUE(note.empty());
  loom::drivers::CanLinkInfo vcan{"vcan", 0, true};
  EXPECT_TRUE(loom::drivers::check_can_bitrate("vcan0", vcan, 1000000, note));
  EXPECT_NE(note.find("virtual CAN link (vcan): it has no bitrate"), std::string::npos);
}
