// A loom whose signals are spread over two CiA 401 modules (drivers::CanIoModules over two CanIoPorts),
// against two simulated modules on the fake CAN network: both brought up in the bus' one NMT sequence,
// each signal read from and written to the module the wiring puts it on, and the joint sample as old as
// its oldest module. The peers (sim_can::SimIoNode) have their own dictionary and frame layouts.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>

#include "drive_rig.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_modules.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace loom::test {
namespace {

using drivers::CanIoConfig;
using drivers::IoWiring;
using hal::AxisRequest;
using hal::DriveState;

// The loom's wiring: valves, sensors and e-stop on module 0 (node 4); the stack light, the buzzer and
// the start/pause buttons on module 1 (node 5). The buttons are crossed on purpose: start is read from
// module 0's terminal 9 (the simulated module's "pause" terminal) and pause from module 1's terminal 8
// (its "start" terminal), so which module a reading came from shows in which button it becomes.
IoWiring two_module_wiring() {
  IoWiring w;
  w.button_start = {9, false, 0};
  w.button_pause = {8, false, 1};
  w.button_ack = {};
  w.row_knotted = {};
  for (drivers::IoBit* b : {&w.lamp_green, &w.lamp_amber, &w.lamp_red, &w.buzzer}) b->module = 1;
  return w;
}

CanIoConfig module_config(std::uint8_t module) {
  CanIoConfig c;
  c.wiring = two_module_wiring();
  c.module = module;
  c.node_id = module == 0 ? 4 : 5;
  c.name = module == 0 ? "" : "panel";
  return c;
}

sim_can::SimIoConfig sim_module(std::uint8_t node) {
  sim_can::SimIoConfig c;
  c.node_id = node;
  return c;
}

struct TwoModuleRig {
  TwoModuleRig()
      : rig(three_drives(), with_io_frames()),
        io4(rig.drives, sim_module(4)),
        io5(rig.drives, sim_module(5)),
        m0(module_config(0)),
        m1(module_config(1)) {
    const sim_can::SimDriveRack::IoPlantSource src{
        0, 2, drivers::kDefaultCountsPerRad, drivers::kDefaultCountsPerRad, {}};
    rig.rack.attach_io(io4, src);
    rig.rack.attach_io(io5, src);
    EXPECT_TRUE(rig.network.add(m0));
    EXPECT_TRUE(rig.network.add(m1));
    io.add(m0);
    io.add(m1);
  }
  static drivers::CanAxisPortConfig with_io_frames() {
    drivers::CanAxisPortConfig c;
    for (int m = 0; m < 2; ++m) {
      const auto f = drivers::io_frames_per_cycle(
          drivers::module_wiring(two_module_wiring(), static_cast<std::uint8_t>(m)));
      c.other_frames_per_cycle[0].insert(c.other_frames_per_cycle[0].end(), f.begin(), f.end());
    }
    // Both modules beside three drives on one bus at 2 ms: 72.5 % with blocking, EMCY and heartbeats; this
    // rig is about the modules, not the budget.
    c.bus_load_budget = 0.75;
    return c;
  }
  void tick(AxisRequest r, const hal::DigitalOutputs& out = {}) {
    drivers::CanHal hal(rig.network, rig.port, io);
    hal.read(rig.tick_index, in);
    rig.feedback = in.axes;
    rig.link = in.link;
    hal::HalOutputs o;
    for (std::size_t i = 0; i < hal::kCoreAxisCount; ++i) {
      o.axes[i].request = r;
      o.axes[i].target_position = in.axes[i].position;
    }
    o.io = out;
    hal.write(rig.tick_index, o);
    ++rig.tick_index;
    rig.advance(rig.period_us());
  }
  // The first data byte of the last frame on the wire with `id`.
  std::optional<std::uint8_t> last_byte(std::uint32_t id) const {
    std::optional<std::uint8_t> b;
    for (const auto& l : rig.net.log()) {
      if (l.frame.id == id && !l.frame.is_error() && l.frame.dlc > 0) b = l.frame.data[0];
    }
    return b;
  }

  DriveRig rig;
  sim_can::SimIoNode io4, io5;
  drivers::CanIoPort m0, m1;
  drivers::CanIoModules io;
  hal::HalInputs in{};
};

TEST(CanIoModules, BothModulesAreBroughtUpInTheBusSequence) {
  TwoModuleRig r;
  const drivers::Status s = r.rig.configure();
  ASSERT_TRUE(s) << s.message();
  EXPECT_TRUE(r.m0.configured());
  EXPECT_TRUE(r.m1.configured());
  EXPECT_EQ(r.io4.nmt_state(), 0x05);  // operational
  EXPECT_EQ(r.io5.nmt_state(), 0x05);
  EXPECT_EQ(r.m1.label(), "node 5 (I/O module panel)");
  EXPECT_EQ(r.m0.label(), "node 4 (I/O node)");
}

TEST(CanIoModules, EachOutputGoesToItsModuleAndEachInputComesFromIts) {
  TwoModuleRig r;
  ASSERT_TRUE(r.rig.configure());
  hal::DigitalOutputs out;
  out.piston_a_extend = true;  // module 0, bit 0
  out.lamp_green = true;       // module 1, bit 4
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  ASSERT_TRUE(r.last_byte(0x204).has_value());
  ASSERT_TRUE(r.last_byte(0x205).has_value());
  EXPECT_EQ(*r.last_byte(0x204), 0x01);  // the valve only: no lamp bit on module 0
  EXPECT_EQ(*r.last_byte(0x205), 0x10);  // the green lamp only: no valve bit on module 1
  EXPECT_EQ(r.io4.outputs(0), 0x01);
  EXPECT_EQ(r.io5.outputs(0), 0x10);

  // The e-stop chain (module 0) closed, no button pressed.
  EXPECT_TRUE(r.in.io.estop_ok);
  EXPECT_FALSE(r.in.io.button_start);
  EXPECT_FALSE(r.in.io.button_pause);
  // The plant's "start" button lights terminal 8 of both modules: only module 1 reads terminal 8 (as pause).
  r.rig.rack.io_controls().button_start = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_TRUE(r.in.io.button_pause);
  EXPECT_FALSE(r.in.io.button_start);
  r.rig.rack.io_controls().button_start = false;
  // The plant's "pause" button lights terminal 9: only module 0 reads it (as start).
  r.rig.rack.io_controls().button_pause = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_TRUE(r.in.io.button_start);
  EXPECT_FALSE(r.in.io.button_pause);
  // The e-stop chain opens: module 0 reports it.
  r.rig.rack.io_controls().estop_open = true;
  for (int i = 0; i < 5; ++i) r.tick(AxisRequest::kEnable, out);
  EXPECT_FALSE(r.in.io.estop_ok);
}

TEST(CanIoModules, TheSampleIsAsOldAsItsOldestModuleAndASilentModuleIsLost) {
  TwoModuleRig r;
  ASSERT_TRUE(r.rig.configure());
  for (int i = 0; i < 10; ++i) r.tick(AxisRequest::kEnable);
  const hal::Tick fresh = r.in.io.refreshed;
  EXPECT_GE(fresh, r.rig.tick_index - 3);  // both modules answer every SYNC
  EXPECT_FALSE(r.in.link.link_fault);
  // Module 1 loses power: module 0 stays fresh, the joint sample does not.
  r.io5.power_off();
  r.tick(AxisRequest::kEnable);  // a frame it sent before may still arrive
  const hal::Tick last_seen = r.m1.inputs_refreshed();
  for (int i = 0; i < 20; ++i) r.tick(AxisRequest::kEnable);
  EXPECT_GE(r.m0.inputs_refreshed(), r.rig.tick_index - 3);
  EXPECT_LE(r.in.io.refreshed, last_seen);
  EXPECT_EQ(r.in.io.refreshed, r.m1.inputs_refreshed());
  // Its heartbeat supervision then declares it lost: a link fault, every axis stopped.
  for (int i = 0; i < 400 && !r.in.link.link_fault; ++i) r.tick(AxisRequest::kEnable);
  EXPECT_TRUE(r.in.link.link_fault);
  EXPECT_EQ(r.in.link.link_fault_kind, hal::FaultKind::kNodeLost);
  for (int i = 0; i < 5; ++i)
    r.tick(AxisRequest::kEnable);  // the sequencer would ask on; the port stops them
  for (std::size_t a = 0; a < 3; ++a) EXPECT_NE(r.rig.feedback[a].state, DriveState::kOperationEnabled) << a;
}

TEST(CanIoModules, TheLoadCellIsReadFromItsModuleAndNoneMeansNone) {
  IoWiring w = two_module_wiring();
  w.load_cell_module = 1;
  EXPECT_EQ(drivers::module_wiring(w, 0).load_cell_channel, 0);
  EXPECT_EQ(drivers::module_wiring(w, 1).load_cell_channel, 1);
  EXPECT_EQ(drivers::module_wiring(w, 1).piston_a_extend.bit, -1);  // not on module 1
  EXPECT_EQ(drivers::module_wiring(w, 1).lamp_green.bit, 4);
  CanIoConfig c0 = module_config(0), c1 = module_config(1);
  c0.wiring = c1.wiring = w;
  drivers::CanIoPort p0(c0), p1(c1);
  EXPECT_FALSE(p0.has_load_cell());
  EXPECT_TRUE(p1.has_load_cell());
  drivers::CanIoModules none;
  hal::AnalogInputs a;
  a.beat_force_valid = true;
  none.read_analog(0, a);
  EXPECT_FALSE(a.beat_force_valid);
  EXPECT_EQ(a.refreshed, hal::kNeverTick);
}

TEST(CanIoModules, ABitIsUsedOncePerModuleNotOncePerLoom) {
  IoWiring w = two_module_wiring();
  w.buzzer = {0, false, 1};  // bit 0 of module 1, while valve A is bit 0 of module 0: fine
  EXPECT_TRUE(drivers::validate(w)) << drivers::validate(w).message();
  w.lamp_red = {0, false, 1};  // bit 0 of module 1 twice
  const drivers::Status s = drivers::validate(w);
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find(
                "io.outputs.buzzer.bit = 0 is already used by io.outputs.lamp_red (both on I/O module 1)"),
            std::string::npos)
      << s.message();
  w = two_module_wiring();
  w.estop_ok.module = drivers::kMaxIoModules;
  EXPECT_FALSE(drivers::validate(w));
}

}  // namespace
}  // namespace loom::test
