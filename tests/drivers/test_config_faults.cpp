// The CAN configuration checks say which field they refuse — the loom config maps the field to its TOML
// key for the file:line:col message, never reading the text — and keep the messages validate() gives.
// Links loom::canopen_config alone: the checks need no CANopen runtime.
#include <gtest/gtest.h>

#include "loom/drivers/can_axis_config.hpp"
#include "loom/drivers/can_io_config.hpp"

namespace loom::drivers {
namespace {

TEST(CanAxisConfigFault, NamesTheFieldAndTheAxisBesideTheMessage) {
  CanAxisPortConfig c;
  EXPECT_FALSE(find_fault(c).has_value());
  EXPECT_TRUE(validate(c).is_ok());
  c.axes[1].counts_per_unit = 0.0;
  const std::optional<CanAxisConfigFault> f = find_fault(c);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->field, CanAxisField::kCountsPerUnit);
  EXPECT_EQ(f->axis, 1u);
  EXPECT_EQ(f->message, "axes.carriage.counts_per_unit = 0 must be a positive number");
  EXPECT_EQ(validate(c).message(), f->message);
}

TEST(CanAxisConfigFault, ThePortsFields) {
  const auto field_of = [](auto change) {
    CanAxisPortConfig c;
    change(c);
    const std::optional<CanAxisConfigFault> f = find_fault(c);
    return f ? f->field : CanAxisField::kOtherFrames;
  };
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.heartbeat_producer_s = 0.0005; }),
            CanAxisField::kHeartbeatProducer);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.heartbeat_consumer_s = 0.05; }),
            CanAxisField::kHeartbeatConsumer);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.sdo_timeout_s = 0.0; }), CanAxisField::kSdoTimeout);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.master_consumer_s = 0.05; }),
            CanAxisField::kMasterHeartbeat);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.bitrate_bps = 0; }), CanAxisField::kBitrate);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.axes[2].node_id = 0x7F; }), CanAxisField::kNodeIdIsMaster);
  EXPECT_EQ(field_of([](CanAxisPortConfig& c) { c.axes[2].node_id = 1; }), CanAxisField::kNodeIdTaken);
}

TEST(IoConfigFault, AKnottingHeadsBitUsedTwiceNamesTheSignalAndTheHead) {
  IoWiring w;
  w.heads = 2;
  w.gripper_close[0] = IoBit{8};
  w.gripper_close[1] = IoBit{9};
  w.cutter[0] = IoBit{20};
  w.cutter[1] = IoBit{5};  // lamp_amber's
  w.yarn_present[0] = IoBit{24};
  w.yarn_present[1] = IoBit{25};
  const std::optional<IoConfigFault> f = find_fault(w);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->field, IoField::kSignalBit);
  EXPECT_EQ(f->signal, "cutter");
  EXPECT_EQ(f->head, 2);
  EXPECT_EQ(f->shared_module, std::uint8_t{0});
  EXPECT_EQ(f->message, "io.outputs.cutter.head2.bit = 5 is already used by io.outputs.lamp_amber");
  EXPECT_EQ(validate(w).message(), f->message);
}

TEST(IoConfigFault, ABitUsedTwiceOnAFurtherModuleSaysWhichModule) {
  IoWiring w;
  w.lamp_green = IoBit{4, false, 1};
  w.buzzer = IoBit{4, false, 1};
  const std::optional<IoConfigFault> f = find_fault(w);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->field, IoField::kSignalBit);
  EXPECT_EQ(f->signal, "buzzer");
  EXPECT_EQ(f->head, 0);
  EXPECT_EQ(f->shared_module, std::uint8_t{1});
  EXPECT_EQ(f->message, "io.outputs.buzzer.bit = 4 is already used by io.outputs.lamp_green");
  EXPECT_EQ(validate(w).message(), f->message + " (both on I/O module 1)");
}

TEST(IoConfigFault, FieldsThatAreNotASignalsBit) {
  IoWiring w;
  w.estop_ok.module = 7;
  EXPECT_EQ(find_fault(w)->field, IoField::kSignalModule);
  EXPECT_EQ(find_fault(w)->signal, "estop_ok");
  w = IoWiring{};
  w.load_cell_channel = 300;
  EXPECT_EQ(find_fault(w)->field, IoField::kLoadCellChannel);
  CanIoConfig c;
  c.node_id = 0;
  EXPECT_EQ(find_fault(c)->field, IoField::kNode);
  EXPECT_EQ(validate(c).message(), "io.node = 0 is outside 1..127");
}

}  // namespace
}  // namespace loom::drivers
