// Simulated drives built from EDS files (sim_hal/can_drive/eds_dictionary.hpp, the hand-written files of
// tests/drivers/eds/): the master brings up and enables a drive with fixed mappings and one with dynamic
// mappings, refuses one without CSP naming the node, and reads each node's own identity from 0x1018.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "drive_rig.hpp"
#include "loom/drivers/eds_boot.hpp"
#include "loom/sim_can/eds_dictionary.hpp"

namespace loom {
namespace {

namespace eds = drivers::eds;

eds::Description read(const std::string& name) {
  return eds::read_eds_file(std::string(LOOM_EDS_DIR) + "/" + name);
}

std::vector<sim_can::SimDriveConfig> three_of(const eds::Description& d) {
  return {sim_can::drive_from_eds(d, 1), sim_can::drive_from_eds(d, 2), sim_can::drive_from_eds(d, 3)};
}

bool enables(test::DriveRig& rig) {
  rig.run_until(
      test::DriveRig::hold(hal::AxisRequest::kEnable),
      [&] { return rig.all_in(hal::DriveState::kOperationEnabled); }, 500);
  return rig.all_in(hal::DriveState::kOperationEnabled);
}

TEST(EdsNodes, TheDictionaryIsTheDescriptions) {
  const eds::Description d = read("brick_bx2_fixed.eds");
  const std::vector<sim_can::slave::Entry> t = sim_can::dictionary_from_eds(d);
  EXPECT_TRUE(sim_can::slave::sorted(t));
  const auto find = [&](std::uint16_t index, std::uint8_t sub) {
    return std::find_if(t.begin(), t.end(), [&](const auto& e) { return e.index == index && e.sub == sub; });
  };
  ASSERT_NE(find(0x1600, 0), t.end());
  EXPECT_EQ(find(0x1600, 0)->access, sim_can::slave::Access::kRo);  // fixed mapping
  EXPECT_EQ(find(0x1A00, 1)->default_value, 0x60410010u);
  EXPECT_EQ(find(0x1800, 1)->default_value, 0x180u);  // "0x180+$NODEID": the node id is added at reset
  EXPECT_EQ(find(0x6041, 0)->pdo, sim_can::slave::Pdo::kTx);
  EXPECT_EQ(find(0x607A, 0)->pdo, sim_can::slave::Pdo::kRx);
  EXPECT_EQ(find(0x1018, 2)->default_value, 0x202u);
  EXPECT_EQ(find(0x1401, 0), t.end());  // one RPDO only
  const sim_can::SimDriveConfig c = sim_can::drive_from_eds(d, 7);
  EXPECT_TRUE(c.supports_csp);
  EXPECT_FALSE(c.supports_homing);
}

TEST(EdsNodes, AFixedMappingDriveIsBroughtUpAndEnabledAndTellsItsIdentity) {
  const eds::Description d = read("brick_bx2_fixed.eds");
  test::DriveRig rig(three_of(d));
  rig.rack.power_on(rig.now_us);
  rig.advance(20'000);
  drivers::SdoClient sdo(rig.master, rig.clock, 100'000, {});
  const drivers::Result<eds::Identity> id = drivers::read_identity(sdo, 2);
  ASSERT_TRUE(id.is_ok()) << id.error();
  EXPECT_EQ(id.value().vendor, 2844u);  // the file's VendorNumber, in decimal there
  EXPECT_EQ(id.value().product, 0x202u);
  EXPECT_EQ(id.value().revision, 0x10000u);
  EXPECT_TRUE(eds::check_identity(d, "node 2", id.value()).is_ok());
  const drivers::Status wrong =
      eds::check_identity(read("acme_ax400_dynamic.eds"), "node 2 (axes.carriage)", id.value());
  EXPECT_EQ(wrong.message().rfind("node 2 (axes.carriage) is vendor 0x00000B1C product 0x00000202", 0), 0u);

  const drivers::Status s = rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  const std::string notes = ::testing::PrintToString(rig.port.notes());
  EXPECT_NE(notes.find("read back"), std::string::npos) << notes;  // the fixed mappings
  EXPECT_NE(notes.find("1016"), std::string::npos) << notes;       // no consumer heartbeat object
  EXPECT_TRUE(enables(rig));
}

TEST(EdsNodes, ADynamicMappingDriveIsBroughtUpAndEnabled) {
  test::DriveRig rig(three_of(read("acme_ax400_dynamic.eds")));
  const drivers::Status s = rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  // The mappings were written (dynamic): nothing was read back as fixed.
  for (const std::string& n : rig.port.notes()) EXPECT_EQ(n.find("fixed"), std::string::npos) << n;
  EXPECT_TRUE(enables(rig));
}

TEST(EdsNodes, ADriveWithoutCspIsRefusedNamingTheNode) {
  test::DriveRig rig(three_of(read("stepwise_sd7_no_csp.eds")));
  const drivers::Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(s.message().find("node 1"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("does not support cyclic synchronous position (0x6502 = 0x00000005"),
            std::string::npos)
      << s.message();
}

}  // namespace
}  // namespace loom
