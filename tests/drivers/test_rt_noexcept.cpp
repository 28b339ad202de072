// Every method the control tick reaches in hal/, drivers/ and the simulated HAL is noexcept: the RT path
// reports faults as values and must never unwind. These are compile-time checks: the test does not build
// when one of them loses its noexcept. The runtime case shows that the probe tells the two apart (the
// configure-time calls, which may allocate and build messages, are not noexcept).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>
#include <utility>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/can_error_frame.hpp"
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/can_hal.hpp"
#include "loom/drivers/can_io_modules.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/cia402.hpp"
#include "loom/drivers/cia402_axis.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/le_bytes.hpp"
#include "loom/drivers/nmt.hpp"
#include "loom/drivers/node_supervisor.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/position_scaling.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/drivers/socket_can_bus.hpp"
#include "loom/hal/hal.hpp"
#include "loom/sim_hal/sim_world.hpp"

namespace loom::drivers {
namespace {

template <class T>
T& obj() noexcept {
  return std::declval<T&>();
}
template <class T>
const T& cobj() noexcept {
  return std::declval<const T&>();
}

// Arguments of the right types (unevaluated; noexcept so only the call under test is probed).
template <class = void>
hal::Tick& now() noexcept;
template <class = void>
hal::AxisFeedbacks& fbs() noexcept;
template <class = void>
hal::AxisFeedback& fb() noexcept;
template <class = void>
hal::LinkStatus& link() noexcept;
template <class = void>
hal::AxisCommands& cmds() noexcept;
template <class = void>
hal::AxisCommand& cmd() noexcept;
template <class = void>
hal::DigitalInputs& din() noexcept;
template <class = void>
hal::DigitalOutputs& dout() noexcept;
template <class = void>
hal::AnalogInputs& ain() noexcept;
template <class = void>
hal::HalInputs& hin() noexcept;
template <class = void>
hal::HalOutputs& hout() noexcept;
template <class = void>
CanFrame& frame() noexcept;
template <class = void>
std::uint8_t& u8() noexcept;
template <class = void>
std::uint32_t& u32() noexcept;
template <class = void>
std::uint8_t* bytes() noexcept;

// ---- The HAL ports the loop drives --------------------------------------------------------------
static_assert(noexcept(obj<hal::AxisPort>().read_axes(now(), fbs(), link())));
static_assert(noexcept(obj<hal::AxisPort>().write_axes(now(), cmds())));
static_assert(noexcept(obj<hal::IoPort>().read_io(now(), fbs(), din())));
static_assert(noexcept(obj<hal::IoPort>().read_analog(now(), ain())));
static_assert(noexcept(obj<hal::IoPort>().write_io(now(), dout())));
static_assert(noexcept(obj<hal::Hal>().read(now(), hin())));
static_assert(noexcept(obj<hal::Hal>().write(now(), hout())));
static_assert(noexcept(obj<hal::PortHal>().read(now(), hin())));
static_assert(noexcept(obj<hal::PortHal>().write(now(), hout())));

// ---- The simulated HAL ----------------------------------------------------------------------------
static_assert(noexcept(obj<sim_hal::SimWorld>().read_axes(now(), fbs(), link())));
static_assert(noexcept(obj<sim_hal::SimWorld>().write_axes(now(), cmds())));
static_assert(noexcept(obj<sim_hal::SimWorld>().read_io(now(), fbs(), din())));
static_assert(noexcept(obj<sim_hal::SimWorld>().read_analog(now(), ain())));
static_assert(noexcept(obj<sim_hal::SimWorld>().write_io(now(), dout())));

// ---- The bus ----------------------------------------------------------------------------------------
static_assert(noexcept(obj<CanBus>().send(frame())));
static_assert(noexcept(obj<CanBus>().receive(frame())));
static_assert(noexcept(obj<SocketCanBus>().send(frame())));
static_assert(noexcept(obj<SocketCanBus>().receive(frame())));

// ---- The CAN HAL and its axis port ------------------------------------------------------------------
static_assert(noexcept(obj<CanHal>().read(now(), obj<hal::HalInputs>())));
static_assert(noexcept(obj<CanHal>().write(now(), cobj<hal::HalOutputs>())));
static_assert(noexcept(obj<CanAxisPort>().read_axes(now(), fbs(), link())));
static_assert(noexcept(obj<CanAxisPort>().write_axes(now(), cmds())));
static_assert(noexcept(cobj<CanAxisPort>().configured()));
static_assert(noexcept(cobj<CanAxisPort>().ferror_high_water(0)));
static_assert(noexcept(cobj<CanAxisPort>().last_controlword(0)));
static_assert(noexcept(cobj<CanAxisPort>().last_target_counts(0)));

// ---- The CAN I/O port and the modules ---------------------------------------------------------------
static_assert(noexcept(obj<CanIoPort>().read_io(now(), fbs(), din())));
static_assert(noexcept(obj<CanIoPort>().read_analog(now(), ain())));
static_assert(noexcept(obj<CanIoPort>().write_io(now(), dout())));
static_assert(noexcept(cobj<CanIoPort>().read_wired(din())));
static_assert(noexcept(obj<CanIoPort>().on_profile_frame(now(), frame())));
static_assert(noexcept(cobj<CanIoPort>().inputs_refreshed()));
static_assert(noexcept(cobj<CanIoPort>().last_emcy_code()));
static_assert(noexcept(io_safe_outputs()));
static_assert(noexcept(obj<CanIoModules>().read_io(now(), fbs(), din())));
static_assert(noexcept(obj<CanIoModules>().read_analog(now(), ain())));
static_assert(noexcept(obj<CanIoModules>().write_io(now(), dout())));

// ---- The network, the master and its nodes ----------------------------------------------------------
static_assert(noexcept(obj<CanNetwork>().poll(now())));
static_assert(noexcept(obj<CanNetwork>().read_link(now(), link())));
static_assert(noexcept(obj<CanNetwork>().start_cycle(now())));
static_assert(noexcept(obj<CanNetwork>().acknowledge()));
static_assert(noexcept(cobj<CanNetwork>().any_fault()));
static_assert(noexcept(cobj<CanNetwork>().configured()));
static_assert(noexcept(obj<CanMaster>().poll(now())));
static_assert(noexcept(obj<CanMaster>().start_cycle(now())));
static_assert(noexcept(obj<CanMaster>().send(frame())));
static_assert(noexcept(obj<CanMaster>().acknowledge()));
static_assert(noexcept(cobj<CanMaster>().any_fault()));
static_assert(noexcept(cobj<CanMaster>().report_link(link())));
static_assert(noexcept(cobj<CanMaster>().recovery(now(), u8())));
static_assert(noexcept(cobj<CanMaster>().bus_off()));
static_assert(noexcept(obj<CanNode>().on_frame(now(), frame())));
static_assert(noexcept(obj<CanNode>().on_profile_frame(now(), frame())));
static_assert(noexcept(obj<CanNode>().supervise(now())));
static_assert(noexcept(obj<CanNode>().acknowledge()));
static_assert(noexcept(cobj<CanNode>().reports_own_emcy()));
static_assert(noexcept(cobj<CanNode>().link_fault_code()));
static_assert(noexcept(cobj<CanNode>().heard_again(now())));
static_assert(noexcept(obj<NodeSupervisor>().on_heartbeat(now(), frame())));
static_assert(noexcept(obj<NodeSupervisor>().on_emcy(frame())));
static_assert(noexcept(obj<NodeSupervisor>().supervise(now())));
static_assert(noexcept(obj<NodeSupervisor>().acknowledge(false)));
static_assert(noexcept(cobj<NodeSupervisor>().link_fault()));
static_assert(noexcept(cobj<NodeSupervisor>().emcy_code()));
static_assert(noexcept(cobj<NodeSupervisor>().heard_again(now())));

// ---- The CiA 402 axis -------------------------------------------------------------------------------
static_assert(noexcept(obj<Cia402Axis>().on_profile_frame(now(), frame())));
static_assert(noexcept(obj<Cia402Axis>().acknowledge()));
static_assert(noexcept(obj<Cia402Axis>().fill_feedback(now(), fb(), false, true)));
static_assert(noexcept(cobj<Cia402Axis>().faulted()));
static_assert(noexcept(obj<Cia402Axis>().command(now(), cmd(), false, false, u32(), frame())));
static_assert(noexcept(cobj<Cia402Axis>().last_controlword()));
static_assert(noexcept(cia402_step(hal::DriveState::kUnknown, hal::AxisRequest::kDisable, Cia402Tracker{},
                                   0)));
static_assert(noexcept(decode_statusword(0)));
static_assert(noexcept(cia402_goal_reached(hal::DriveState::kUnknown, hal::AxisRequest::kDisable)));

// ---- Codecs: PDO, EMCY, NMT, SDO frames, error frames, COB-IDs, bytes, scaling -----------------------
static_assert(noexcept(pack_rpdo1(0, Rpdo1{})));
static_assert(noexcept(unpack_rpdo1(frame(), 0)));
static_assert(noexcept(pack_tpdo1(0, Tpdo1{})));
static_assert(noexcept(unpack_tpdo1(frame(), 0)));
static_assert(noexcept(pack_rpdo1_mode(0, Rpdo1Mode{})));
static_assert(noexcept(unpack_rpdo1_mode(frame(), 0)));
static_assert(noexcept(pack_tpdo1_mode(0, Tpdo1Mode{})));
static_assert(noexcept(unpack_tpdo1_mode(frame(), 0)));
static_assert(noexcept(pack_tpdo2(0, Tpdo2{})));
static_assert(noexcept(unpack_tpdo2(frame(), 0)));
static_assert(noexcept(encode_map_entry(PdoMapEntry{})));
static_assert(noexcept(parse_emcy(frame())));
static_assert(noexcept(make_emcy(0, 0, 0)));
static_assert(noexcept(link_fault_kind(0)));
static_assert(noexcept(fault_code_text(0)));
static_assert(noexcept(make_nmt(NmtCommand{}, 0)));
static_assert(noexcept(parse_nmt(frame())));
static_assert(noexcept(make_sync()));
static_assert(noexcept(is_sync(frame())));
static_assert(noexcept(make_heartbeat(0, NmtState{})));
static_assert(noexcept(parse_heartbeat(frame())));
static_assert(noexcept(parse_sdo_reply(frame())));
static_assert(noexcept(parse_sdo_request(frame())));
static_assert(noexcept(make_sdo_download(0, 0, 0, 0, 0)));
static_assert(noexcept(decode_error_frame(frame())));
static_assert(noexcept(decode_cob_id(0)));
static_assert(noexcept(cob::tpdo(1, 0)));
static_assert(noexcept(get_u32(bytes())));
static_assert(noexcept(put_u32(bytes(), 0)));
static_assert(noexcept(si_to_counts(0.0, 1.0)));
static_assert(noexcept(counts_to_si(0, 1.0)));
static_assert(noexcept(obj<PositionUnwrapper>().update(0)));
static_assert(noexcept(frame_bits_worst(8)));

TEST(RtNoexcept, TheProbeTellsConfigureTimeCallsApart) {
  // Configure-time: may allocate (messages, notes), so not noexcept; were the probe always true, the
  // static_asserts above would prove nothing.
  EXPECT_FALSE(noexcept(obj<CanAxisPort>().check(0)));
  EXPECT_FALSE(
      noexcept(bring_up(obj<CanNetwork>(), obj<CanAxisPort>(), obj<CanBus>(), obj<ConfigureClock>())));
  EXPECT_FALSE(noexcept(obj<CanNetwork>().configure(obj<CanBus>(), obj<ConfigureClock>())));
  EXPECT_FALSE(noexcept(obj<CanMaster>().bring_up(obj<CanBus>(), obj<ConfigureClock>())));
  EXPECT_TRUE(noexcept(obj<CanAxisPort>().read_axes(now(), fbs(), link())));
}

}  // namespace
}  // namespace loom::drivers
