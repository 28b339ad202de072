// Boot from the description (eds_boot.hpp) against the simulated CiA 402 drive (sim_hal/can_drive,
// written from the standard, not from this code): only values that differ from the drive's factory
// dictionary are written, a changed mapping goes through CiA 301's re-map sequence, a second pass
// writes nothing; judged from the frames on the fake bus and from reading the values back.
#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "drive_rig.hpp"
#include "loom/drivers/eds_boot.hpp"
#include "loom/drivers/node_description.hpp"
#include "loom/sim_can/eds_dictionary.hpp"

namespace loom::drivers {
namespace {

std::string path_of(const std::string& name) {
  return std::string(LOOM_EDS_DIR) + "/" + name;
}

struct BootRig {
  test::DriveRig rig{test::three_drives()};
  SdoClient sdo{rig.master, rig.clock, 100'000, {}};
  BootRig() {
    rig.rack.power_on(rig.now_us);
    rig.advance(20'000);  // boot-up: pre-operational, SDO served
  }
  // SDO download requests (client → server, 0x600 + node) sent since log index `from`.
  int downloads_to(std::uint8_t node, std::size_t from) const {
    int n = 0;
    for (std::size_t i = from; i < rig.net.log().size(); ++i) {
      const auto& l = rig.net.log()[i];
      const std::uint8_t ccs = l.frame.data[0] & 0xE0;
      if (l.from == 0 && l.frame.id == 0x600U + node && ccs == 0x20) ++n;  // initiate download
    }
    return n;
  }
};

TEST(EdsBoot, OnlyWhatDiffersFromTheDrivesDictionaryIsWrittenAndASecondPassWritesNothing) {
  const eds::Description d = eds::read_eds_file(path_of("acme_ax400_dynamic.eds"));
  const CanAxisPortConfig port;
  const eds::NodeNeeds needs = eds::drive_needs(port.axes[1], port);  // node 2
  const std::vector<eds::SdoWrite> writes = eds::loom_writes(d, needs, eds::check_node(d, needs));
  ASSERT_EQ(writes.size(), 15u);
  BootRig b;
  const std::size_t from = b.rig.net.log().size();
  Result<ApplyReport> r = apply_configuration(b.sdo, 2, writes, false);
  ASSERT_TRUE(r.is_ok()) << r.error();
  // The simulated drive's factory values: 0x1016:01 = 0, 0x1017 = 0, 0x6060 = 0, 0x60C2:01 = 1 differ;
  // its RPDO1/TPDO1 COB-IDs, synchronous types, mappings and 0x60C2:02 = -3 are as described.
  EXPECT_EQ(r.value().written, 4);
  EXPECT_EQ(r.value().skipped, 11);
  EXPECT_FALSE(r.value().stored);
  EXPECT_EQ(b.downloads_to(2, from), 4);
  EXPECT_EQ(b.sdo.read(2, 0x1017, 0).value(), 100u);
  EXPECT_EQ(b.sdo.read(2, 0x1016, 1).value(), 0x007F01F4u);
  EXPECT_EQ(b.sdo.read(2, 0x6060, 0).value(), 8u);
  EXPECT_EQ(b.sdo.read(2, 0x60C2, 1).value(), 2u);

  const std::size_t again = b.rig.net.log().size();
  Result<ApplyReport> second = apply_configuration(b.sdo, 2, writes, false);
  ASSERT_TRUE(second.is_ok()) << second.error();
  EXPECT_EQ(second.value().written, 0);
  EXPECT_EQ(second.value().skipped, 15);
  EXPECT_EQ(b.downloads_to(2, again), 0);
}

TEST(EdsBoot, AChangedMappingIsReMappedWholeWithThePdoInvalidMeanwhile) {
  BootRig b;
  // TPDO2 of the simulated drive maps {0x606C/32, 0x6077/16}; the description wants {0x6041/16} only.
  const std::vector<eds::SdoWrite> writes{{0x1A01, 0, 1, 1}, {0x1A01, 1, 4, 0x60410010}};
  const std::size_t from = b.rig.net.log().size();
  Result<ApplyReport> r = apply_configuration(b.sdo, 3, writes, false);
  ASSERT_TRUE(r.is_ok()) << r.error();
  // 0x1801:01 invalid, 0x1A01:00 = 0, 0x1A01:01, 0x1A01:00 = 1, 0x1801:01 valid.
  EXPECT_EQ(r.value().written, 5);
  std::vector<std::uint32_t> order;  // index << 8 | sub of each download, in order
  for (std::size_t i = from; i < b.rig.net.log().size(); ++i) {
    const auto& l = b.rig.net.log()[i];
    if (l.from == 0 && l.frame.id == 0x603 && (l.frame.data[0] & 0xE0) == 0x20) {
      order.push_back((std::uint32_t{l.frame.data[1]} | std::uint32_t{l.frame.data[2]} << 8) << 8 |
                      l.frame.data[3]);
    }
  }
  EXPECT_EQ(order, (std::vector<std::uint32_t>{0x180101, 0x1A0100, 0x1A0101, 0x1A0100, 0x180101}));
  EXPECT_EQ(b.sdo.read(3, 0x1A01, 0).value(), 1u);
  EXPECT_EQ(b.sdo.read(3, 0x1A01, 1).value(), 0x60410010u);
  EXPECT_EQ(b.sdo.read(3, 0x1801, 1).value(), 0x283u);  // TPDO2 of node 3, valid again
}

TEST(EdsBoot, StoringOnANodeWithout1010AndReadingAnIdentityItLacksAreErrorsNamingNodeAndObject) {
  BootRig b;
  Result<ApplyReport> r = apply_configuration(b.sdo, 1, {{0x1017, 0, 2, 250}}, true);
  ASSERT_FALSE(r.is_ok());
  EXPECT_EQ(r.error().rfind("node 1: SDO write 0x1010:01", 0), 0u) << r.error();
  EXPECT_NE(r.error().find("0x06020000"), std::string::npos) << r.error();
  Result<eds::Identity> id = read_identity(b.sdo, 1);
  ASSERT_FALSE(id.is_ok());
  EXPECT_NE(id.error().find("0x1018:01"), std::string::npos) << id.error();
  // More than 4 bytes is refused before anything is sent.
  const std::size_t from = b.rig.net.log().size();
  EXPECT_FALSE(apply_configuration(b.sdo, 1, {{0x2000, 0, 8, 1}}, false).is_ok());
  EXPECT_EQ(b.rig.net.log().size(), from);
}

// The master's bring-up of a port whose axes name their EDS (CanAxisConfig::description), against
// simulated drives built from EDS files (sim_can::drive_from_eds).
struct DescribedRig {
  static std::shared_ptr<const NodeDescription> describe(const std::string& file, const CanAxisConfig& axis,
                                                         const CanAxisPortConfig& port) {
    auto d = std::make_shared<NodeDescription>();
    d->eds = eds::read_eds_file(path_of(file));
    const eds::NodeNeeds needs = eds::drive_needs(axis, port);
    d->writes = eds::loom_writes(d->eds, needs, eds::check_node(d->eds, needs));
    return d;
  }
  // Nodes 1..3 are simulated from `sim`, the port's axes described by `described`.
  static test::DriveRig make(const std::array<const char*, 3>& sim,
                             const std::array<const char*, 3>& described) {
    std::vector<sim_can::SimDriveConfig> nodes;
    CanAxisPortConfig port;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto node = static_cast<std::uint8_t>(i + 1);
      nodes.push_back(sim_can::drive_from_eds(eds::read_eds_file(path_of(sim[i])), node));
      port.axes[i].description = describe(described[i], port.axes[i], port);
    }
    return test::DriveRig(std::move(nodes), port);
  }
};

// Downloads (index << 8 | sub) to `node` since log index `from`.
std::multiset<std::uint32_t> downloads(const test::DriveRig& rig, std::uint8_t node, std::size_t from) {
  std::multiset<std::uint32_t> out;
  for (std::size_t i = from; i < rig.net.log().size(); ++i) {
    const auto& l = rig.net.log()[i];
    if (l.from == 0 && l.frame.id == 0x600U + node && (l.frame.data[0] & 0xE0) == 0x20) {
      out.insert((std::uint32_t{l.frame.data[1]} | std::uint32_t{l.frame.data[2]} << 8) << 8 |
                 l.frame.data[3]);
    }
  }
  return out;
}

TEST(EdsBringUp, ANodeWhoseIdentityDiffersFromItsEdsStopsBringUpNamingTheNodeAndBothIdentities) {
  // Node 3 is a Brick BX2 on the bus, but the machine description says an Acme AX400.
  test::DriveRig rig =
      DescribedRig::make({"acme_ax400_dynamic.eds", "acme_ax400_dynamic.eds", "brick_bx2_fixed.eds"},
                         {"acme_ax400_dynamic.eds", "acme_ax400_dynamic.eds", "acme_ax400_dynamic.eds"});
  const Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  // The identities as the two files write them ([DeviceInfo] of brick_bx2_fixed.eds and
  // acme_ax400_dynamic.eds).
  EXPECT_NE(s.message().find("node 3 (helix)"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("vendor 0x00000B1C product 0x00000202"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("vendor 0x000004A2 product 0x00401234"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("acme_ax400_dynamic.eds"), std::string::npos) << s.message();
  // Nothing was written to the wrong node, and no node was started.
  EXPECT_TRUE(downloads(rig, 3, 0).empty());
  for (const auto& l : rig.net.log()) EXPECT_FALSE(l.frame.id == 0x000 && l.frame.data[0] == 0x01);
}

// Judged against the EDS files themselves: the downloads a described node gets at bring-up are exactly
// the loom's values that differ from the file's DefaultValues (the simulated node starts from them after
// NMT reset) plus the unused TPDOs' invalidation where the file has them valid — each object once.
TEST(EdsBringUp, OnlyTheValuesThatDifferFromTheNodesDictionaryAreWritten) {
  const std::array<const char*, 3> files{"acme_ax400_dynamic.eds", "acme_ax400_dynamic.eds",
                                         "brick_bx2_fixed.eds"};
  test::DriveRig rig = DescribedRig::make(files, files);
  ASSERT_TRUE(rig.configure().is_ok());
  for (std::uint8_t node = 1; node <= 3; ++node) {
    SCOPED_TRACE(int{node});
    const eds::Description d = eds::read_eds_file(path_of(files[node - 1u]));
    const NodeDescription& nd = *rig.port.config().axes[node - 1u].description;
    std::multiset<std::uint32_t> expected;
    for (const eds::SdoWrite& w : nd.writes) {
      const eds::Entry* e = d.entry(w.index, w.sub);
      ASSERT_NE(e, nullptr);
      const auto def = e->value().bits(node, e->type);
      const std::uint64_t mask = w.size >= 8 ? ~0ULL : (1ULL << (8 * w.size)) - 1;
      if (!def || (*def & mask) != (w.value & mask)) expected.insert(std::uint32_t{w.index} << 8 | w.sub);
    }
    for (std::uint16_t comm = 0x1801; comm <= 0x1803; ++comm) {  // TPDO2..4: unused, invalidated
      const eds::Entry* e = d.entry(comm, 1);
      if (e == nullptr || !eds::writable(e->access)) continue;
      const auto def = e->value().bits(node, e->type);
      if (def && (*def & 0x80000000u) == 0) expected.insert(std::uint32_t{comm} << 8 | 1);
    }
    EXPECT_EQ(downloads(rig, node, 0), expected);
  }
}

}  // namespace
}  // namespace loom::drivers
