// An I/O module described by its EDS: digital inputs as CiA 401's 16-bit groups (0x6100) where the file
// has only those, and the store-parameters option (0x1010:01 = "save"). The file decides the form
// (input_group_bits_of), the needs and the check name 0x6100, the master maps and decodes it; judged
// from hand-built TPDO frames and SDO downloads on the fake bus, against a module simulated from the
// vendor-style kordis_dio32w.eds (sim_can's own dictionary and PDO packing, not the master's codec).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "drive_rig.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/eds_check.hpp"
#include "loom/drivers/eds_dcf.hpp"
#include "loom/drivers/node_description.hpp"
#include "loom/drivers/required_objects.hpp"
#include "loom/sim_can/eds_dictionary.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::drivers {
namespace {

std::string path_of(const std::string& name) {
  return std::string(LOOM_EDS_DIR) + "/" + name;
}
bool has(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

IoWiring single_channel() {
  IoWiring w;
  for (IoBit& b : w.second) b = IoBit{};
  return w;
}

// ---------------------------------------------------------------------------------------------------
// Arithmetic and the EDS's say
// ---------------------------------------------------------------------------------------------------
TEST(IoInputGroups, SixteenBitGroupsCountWordsAndCarryTheSameBits) {
  const IoWiring w;  // inputs up to bit 21 (second switches on 16..21)
  EXPECT_EQ(io_input_subs(w, 8), 3);
  EXPECT_EQ(io_input_subs(w, 16), 2);
  EXPECT_EQ(io_frames_per_cycle(w, 8)[1].data_bytes, 3u);
  EXPECT_EQ(io_frames_per_cycle(w, 16)[1].data_bytes, 4u);
  IoWiring high = w;
  high.second[5] = IoBit{32};  // the 33rd terminal: a third word
  EXPECT_EQ(io_input_subs(high, 16), 3);
  EXPECT_EQ(io_frames_per_cycle(high, 16)[1].data_bytes, 6u);
  const std::vector<RequiredObject> objects = io_module_objects(w, 16);
  const auto in =
      std::find_if(objects.begin(), objects.end(), [](const RequiredObject& o) { return o.index == 0x6100; });
  ASSERT_NE(in, objects.end());
  EXPECT_TRUE(has(describe(*in), "0x6100:01..02 read digital inputs, 16-bit")) << describe(*in);
  EXPECT_TRUE(std::none_of(objects.begin(), objects.end(),
                           [](const RequiredObject& o) { return o.index == 0x6000; }));
  CanIoConfig c;
  c.input_group_bits = 12;
  EXPECT_FALSE(validate(c).is_ok());
  EXPECT_TRUE(has(validate(c).message(), "io.input_group_bits = 12")) << validate(c).message();
}

TEST(IoInputGroups, TheEdsSaysWhichFormTheModuleHas) {
  const eds::Description kordis = eds::read_eds_file(path_of("kordis_dio32w.eds"));
  const eds::Description tecto = eds::read_eds_file(path_of("tecto_io16.eds"));
  ASSERT_FALSE(kordis.has_errors());
  // Kordis: 0x6100:01..02 only.
  EXPECT_EQ(eds::input_group_bits_of(kordis, IoWiring{}), 16);
  // Tecto: 0x6000:01..02 and 0x6100:01. Bits 0..11: 8-bit groups (preferred where both serve).
  EXPECT_EQ(eds::input_group_bits_of(tecto, single_channel()), 8);
  // Bits up to 21 need 0x6000:03 or 0x6100:02: it has neither.
  EXPECT_EQ(eds::input_group_bits_of(tecto, IoWiring{}), 0);
}

TEST(IoInputGroups, CheckUsesTheSixteenBitGroupsAndNamesBothFormsWhenNeitherServes) {
  const eds::Description kordis = eds::read_eds_file(path_of("kordis_dio32w.eds"));
  CanIoConfig io;
  io.input_group_bits = 16;
  const eds::NodeNeeds needs = eds::io_module_needs(io);
  const eds::NodeCheck c = eds::check_node(kordis, needs);
  for (const eds::Finding& f : c.findings) {
    EXPECT_NE(f.level, eds::Level::kError) << eds::format(kordis, needs, f);
  }
  // What the loom writes: TPDO1 re-mapped to both words (the file's factory TPDO1 has the first only).
  const std::vector<eds::SdoWrite> writes = eds::loom_writes(kordis, needs, c);
  const auto wrote = [&](std::uint16_t index, std::uint8_t sub, std::uint64_t value) {
    return std::any_of(writes.begin(), writes.end(), [&](const eds::SdoWrite& w) {
      return w.index == index && w.sub == sub && w.value == value;
    });
  };
  EXPECT_TRUE(wrote(0x1A00, 1, 0x61000110));
  EXPECT_TRUE(wrote(0x1A00, 2, 0x61000210));
  EXPECT_TRUE(wrote(0x1A00, 0, 2));

  // Tecto with the default wiring: neither 0x6000:03 nor 0x6100:02. The error names the 8-bit group at
  // the [6000] section's line and the 16-bit one in the remedy.
  const eds::Description tecto = eds::read_eds_file(path_of("tecto_io16.eds"));
  const eds::NodeNeeds eight = eds::io_module_needs(CanIoConfig{});
  const eds::NodeCheck t = eds::check_node(tecto, eight);
  std::vector<eds::Finding> errors;
  std::copy_if(t.findings.begin(), t.findings.end(), std::back_inserter(errors),
               [](const eds::Finding& f) { return f.level == eds::Level::kError; });
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].line, tecto.object(0x6000)->line);
  EXPECT_EQ(errors[0].remedy,
            "the file has no 16-bit group 0x6100:02 for these inputs either: wire the signals to lower bits "
            "(fewer groups) or choose a module with more I/O");
}

// ---------------------------------------------------------------------------------------------------
// The master against the module simulated from the EDS
// ---------------------------------------------------------------------------------------------------
constexpr std::uint8_t kIoNode = 4;

std::shared_ptr<NodeDescription> describe_io(const std::string& file, const CanIoConfig& io, bool store) {
  auto d = std::make_shared<NodeDescription>();
  d->eds = eds::read_eds_file(path_of(file));
  const eds::NodeNeeds needs = eds::io_module_needs(io);
  const eds::NodeCheck check = eds::check_node(d->eds, needs);
  if (check.ok()) d->writes = eds::loom_writes(d->eds, needs, check);
  d->store = store;
  return d;
}

struct DescribedIoRig {
  explicit DescribedIoRig(sim_can::SimIoConfig sim, bool store)
      : rig(test::three_drives(), frames()), io(rig.drives, std::move(sim)), port(config(store)) {
    rig.rack.attach_io(io, {0, 2, kDefaultCountsPerRad, kDefaultCountsPerRad});
    EXPECT_TRUE(rig.network.add(port));
  }
  static CanIoConfig config(bool store) {
    CanIoConfig c;
    c.node_id = kIoNode;
    c.input_group_bits = 16;
    c.description = describe_io("kordis_dio32w.eds", c, store);
    return c;
  }
  static CanAxisPortConfig frames() {
    CanAxisPortConfig c;
    c.other_frames_per_cycle[0] = io_frames_per_cycle(IoWiring{}, 16);
    return c;
  }
  // Downloads (client → node 4) since log index `from`, each as its 8 data bytes.
  std::vector<std::array<std::uint8_t, 8>> downloads(std::size_t from = 0) const {
    std::vector<std::array<std::uint8_t, 8>> out;
    for (std::size_t i = from; i < rig.net.log().size(); ++i) {
      const auto& l = rig.net.log()[i];
      if (l.from == 0 && l.frame.id == 0x600U + kIoNode && (l.frame.data[0] & 0xE0) == 0x20) {
        out.push_back(l.frame.data);
      }
    }
    return out;
  }
  // Log index of the first frame `id` with first data byte `b0` (NMT start: 0x000, 0x01), npos none.
  std::size_t first(std::uint32_t id, std::uint8_t b0) const {
    for (std::size_t i = 0; i < rig.net.log().size(); ++i) {
      if (rig.net.log()[i].frame.id == id && rig.net.log()[i].frame.data[0] == b0) return i;
    }
    return std::string::npos;
  }

  test::DriveRig rig;
  sim_can::SimIoNode io;
  CanIoPort port;
};

sim_can::SimIoConfig kordis_module() {
  return sim_can::io_from_eds(eds::read_eds_file(path_of("kordis_dio32w.eds")), kIoNode);
}

// The expedited download request of a 4-byte value, as CiA 301 writes it: 0x23, index LE, sub, value LE.
std::array<std::uint8_t, 8> download4(std::uint16_t index, std::uint8_t sub, std::uint32_t v) {
  return {0x23,
          static_cast<std::uint8_t>(index & 0xFF),
          static_cast<std::uint8_t>(index >> 8),
          sub,
          static_cast<std::uint8_t>(v & 0xFF),
          static_cast<std::uint8_t>((v >> 8) & 0xFF),
          static_cast<std::uint8_t>((v >> 16) & 0xFF),
          static_cast<std::uint8_t>(v >> 24)};
}

TEST(IoInputGroups, TheMasterMapsBothWordsAndReadsEachBitFromHandBuiltFrames) {
  DescribedIoRig r(kordis_module(), false);
  const Status s = r.rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  // TPDO1 sub 2 = 0x6100:02, 16 bits: 23 00 1A 02 10 02 00 61.
  const auto d = r.downloads();
  EXPECT_NE(std::find(d.begin(), d.end(), download4(0x1A00, 2, 0x61000210)), d.end());
  // No 8-bit input group was ever asked for.
  for (const auto& l : r.rig.net.log()) {
    if (l.from == 0 && l.frame.id == 0x604) {
      EXPECT_FALSE(l.frame.data[1] == 0x00 && l.frame.data[2] == 0x60);
    }
  }
  // The module's own TPDO1 after SYNCs: two words, 4 bytes.
  r.rig.advance(20'000);
  for (int i = 0; i < 5; ++i) r.rig.tick(test::DriveRig::hold(hal::AxisRequest::kDisable));
  int dlc = -1;
  for (const auto& l : r.rig.net.log()) {
    if (l.frame.id == 0x184) dlc = l.frame.dlc;
  }
  EXPECT_EQ(dlc, 4);

  // A hand-built TPDO1: word 1 = 0x0141 (bit 0 piston A extended, bit 6 e-stop chain closed, bit 8 start),
  // word 2 = 0x0020 (bit 21 = terminal 16 + 5: the shuttle-at-right second switch).
  CanFrame f;
  f.id = 0x184;
  f.dlc = 4;
  f.data = {0x41, 0x01, 0x20, 0x00, 0, 0, 0, 0};
  r.port.on_profile_frame(1000, f);
  hal::DigitalInputs in;
  r.port.read_io(1000, {}, in);
  EXPECT_EQ(in.refreshed, 1000);
  EXPECT_TRUE(in.piston_a_extended);
  EXPECT_FALSE(in.piston_a_retracted);
  EXPECT_TRUE(in.estop_ok);
  EXPECT_TRUE(in.button_start);
  EXPECT_FALSE(in.button_pause);
  EXPECT_FALSE(in.shuttle_at_right);
  EXPECT_TRUE(in.second_channel[static_cast<std::size_t>(hal::SafetySensor::kShuttleAtRight)]);
  EXPECT_FALSE(in.second_channel[static_cast<std::size_t>(hal::SafetySensor::kShuttleAtLeft)]);
  // Bit 17 (piston A retracted, second switch) and bit 9 (pause) from the high bytes of each word.
  f.data = {0x00, 0x02, 0x02, 0x00, 0, 0, 0, 0};
  r.port.on_profile_frame(2000, f);
  r.port.read_io(2000, {}, in);
  EXPECT_FALSE(in.piston_a_extended);
  EXPECT_FALSE(in.estop_ok);
  EXPECT_TRUE(in.button_pause);
  EXPECT_TRUE(in.second_channel[static_cast<std::size_t>(hal::SafetySensor::kPistonARetracted)]);
  // A short frame (one word) changes nothing: the inputs stay one sample.
  f.dlc = 2;
  f.data = {0xFF, 0xFF, 0, 0, 0, 0, 0, 0};
  r.port.on_profile_frame(3000, f);
  r.port.read_io(3000, {}, in);
  EXPECT_EQ(in.refreshed, 2000);
  EXPECT_TRUE(in.button_pause);
  EXPECT_FALSE(in.button_start);
}

TEST(IoInputGroups, AnEightBitMasterCannotMapTheSixteenBitModule) {
  // Without the EDS (so without the derived form) the master asks for 0x6000, which the module lacks.
  sim_can::SimIoConfig sim = kordis_module();
  test::DriveRig rig(test::three_drives(), DescribedIoRig::frames());
  sim_can::SimIoNode io(rig.drives, sim);
  CanIoConfig c;
  c.node_id = kIoNode;
  CanIoPort port(c);
  rig.rack.attach_io(io, {0, 2, kDefaultCountsPerRad, kDefaultCountsPerRad});
  ASSERT_TRUE(rig.network.add(port));
  const Status s = rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_TRUE(has(s.message(), "0x6000:01")) << s.message();
}

// ---------------------------------------------------------------------------------------------------
// Store parameters (0x1010)
// ---------------------------------------------------------------------------------------------------
const std::array<std::uint8_t, 8> kSave = download4(0x1010, 1, 0x65766173);  // 23 10 10 01 73 61 76 65

TEST(StoreConfig, SaveIsWrittenOnceAfterEveryConfigurationWriteAndBeforeTheStart) {
  DescribedIoRig r(kordis_module(), true);
  const Status s = r.rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  const auto d = r.downloads();
  ASSERT_GE(d.size(), 2u);
  EXPECT_EQ(std::count(d.begin(), d.end(), kSave), 1);
  EXPECT_EQ(d.back(), kSave);  // the last download to the node
  std::size_t save_at = std::string::npos;
  for (std::size_t i = 0; i < r.rig.net.log().size(); ++i) {
    const auto& l = r.rig.net.log()[i];
    if (l.from == 0 && l.frame.id == 0x604 && l.frame.data == kSave) save_at = i;
  }
  ASSERT_NE(save_at, std::string::npos);
  EXPECT_LT(save_at, r.first(0x000, 0x01));  // before NMT start
  // The drives, without a description, are never asked to store.
  for (const auto& l : r.rig.net.log()) {
    if (l.from == 0 && l.frame.id >= 0x601 && l.frame.id <= 0x603) {
      EXPECT_FALSE(l.frame.data[1] == 0x10 && l.frame.data[2] == 0x10);
    }
  }
}

TEST(StoreConfig, NotAskedForOrNothingWrittenMeansNoSave) {
  {
    DescribedIoRig r(kordis_module(), false);
    ASSERT_TRUE(r.rig.configure().is_ok());
    const auto d = r.downloads();
    EXPECT_FALSE(d.empty());
    EXPECT_EQ(std::count(d.begin(), d.end(), kSave), 0);
  }
  // The module's factory values already what the loom writes (as after a stored configuration): every
  // download of a first bring-up, in order, made the simulated module's default (COB-IDs without the
  // node id, which it adds at reset communication).
  sim_can::SimIoConfig sim = kordis_module();
  {
    DescribedIoRig first(kordis_module(), false);
    ASSERT_TRUE(first.rig.configure().is_ok());
    for (const auto& w : first.downloads()) {
      const auto index = static_cast<std::uint16_t>(w[1] | w[2] << 8);
      const std::uint32_t v = w[4] | w[5] << 8 | w[6] << 16 | static_cast<std::uint32_t>(w[7]) << 24;
      const bool cob =
          w[3] == 1 && ((index >= 0x1400 && index < 0x1600) || (index >= 0x1800 && index < 0x1A00));
      for (sim_can::slave::Entry& e : sim.dictionary) {
        if (e.index == index && e.sub == w[3]) e.default_value = cob ? v - kIoNode : v;
      }
    }
  }
  DescribedIoRig r(sim, true);
  const Status s = r.rig.configure();
  ASSERT_TRUE(s.is_ok()) << s.message();
  const auto d = r.downloads();
  EXPECT_EQ(std::count(d.begin(), d.end(), kSave), 0);
  EXPECT_TRUE(d.empty()) << d.size() << " downloads, the first to 0x" << std::hex
                         << (d.empty() ? 0 : (d[0][2] << 8 | d[0][1])) << ":" << int{d.empty() ? 0 : d[0][3]};
}

TEST(StoreConfig, ARefusedSaveStopsBringUpNamingTheNodeAndTheAbort) {
  sim_can::SimIoConfig sim = kordis_module();
  sim.absent_objects = {0x1010};  // the module on the bus cannot store, whatever its file says
  DescribedIoRig r(sim, true);
  const Status s = r.rig.configure();
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.message().rfind(
                "node 4 (I/O node): storing the configuration failed (bring-up fault store_refused)", 0),
            0u)
      << s.message();
  EXPECT_TRUE(has(s.message(), "0x1010:01 (store parameters)")) << s.message();
  EXPECT_TRUE(has(s.message(), "0x06020000")) << s.message();
  EXPECT_EQ(r.first(0x000, 0x01), std::string::npos);  // no NMT start
}

}  // namespace
}  // namespace loom::drivers
