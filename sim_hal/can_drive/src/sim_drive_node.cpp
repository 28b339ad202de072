// Simulated CiA 402 drive node (see sim_drive_node.hpp). The object dictionary below is the only
// description of the node's objects: SDO access, mapping checks and PDO packing all read it through
// slave_od (CiA 301, written independently of drivers/). This file adds what is drive-specific: the
// CiA 402 state machine, CSP with ideal tracking (on SYNC the actual position becomes the last
// received target), following error, the 0x1016 consumer's quick stop, and the slow personality.
#include "loom/sim_can/sim_drive_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "loom/sim_can/drive_fsa.hpp"

namespace loom::sim_can {

using drivers::CanFrame;
using hal::DriveState;
using slave::Access;
using slave::Pdo;
namespace nmt = slave::nmt;

namespace {

// Objects the drive reacts to or reports (CiA 301, CiA 402).
constexpr std::uint16_t kErrorRegister = slave::kErrorRegisterObject;
constexpr std::uint16_t kConsumerHeartbeat = slave::kConsumerHeartbeatObject;
constexpr std::uint16_t kProducerHeartbeat = slave::kProducerHeartbeatObject;
constexpr std::uint16_t kErrorCode = 0x603F;
constexpr std::uint16_t kControlword = 0x6040;
constexpr std::uint16_t kStatusword = 0x6041;
constexpr std::uint16_t kModes = 0x6060;
constexpr std::uint16_t kModesDisplay = 0x6061;
constexpr std::uint16_t kPositionActual = 0x6064;
constexpr std::uint16_t kVelocityActual = 0x606C;
constexpr std::uint16_t kTorqueActual = 0x6077;
constexpr std::uint16_t kTargetPosition = 0x607A;
constexpr std::uint16_t kHomeOffset = 0x607C;
constexpr std::uint16_t kProfileVelocity = 0x6081;
constexpr std::uint16_t kProfileAcceleration = 0x6083;
constexpr std::uint16_t kProfileDeceleration = 0x6084;
constexpr std::uint16_t kMotionProfileType = 0x6086;
constexpr std::uint16_t kHomingMethod = 0x6098;
constexpr std::uint16_t kHomingSpeeds = 0x6099;
constexpr std::uint16_t kHomingAcceleration = 0x609A;
constexpr std::uint16_t kInterpolationPeriod = 0x60C2;
constexpr std::uint16_t kSupportedModes = 0x6502;

constexpr std::uint32_t kDeviceTypeServo402 = 0x00020192;  // profile 402, servo drive
constexpr std::int8_t kModeCsp = 8;
constexpr std::int8_t kModeHoming = 6;
constexpr std::int8_t kModePp = 1;
constexpr std::uint32_t kModePpBit = 1U << 0;       // 0x6502 bit 0 (pp)
constexpr std::uint32_t kModePvBit = 1U << 2;       // 0x6502 bit 2 (pv; announced, not simulated)
constexpr std::uint16_t kCwNewSetpoint = 1U << 4;   // controlword bit 4 in profile position
constexpr std::uint16_t kSwSetpointAck = 1U << 12;  // statusword bit 12 in profile position
constexpr std::uint32_t kModesPpPv = 0x05;          // 0x6502 bits 0 (pp) and 2 (pv)
constexpr std::uint32_t kModeCspBit = 1U << 7;      // 0x6502 bit 7 (csp)
constexpr std::uint32_t kModeHomingBit = 1U << 5;   // 0x6502 bit 5 (hm)
constexpr std::uint16_t kCwHomingStart = 1U << 4;   // controlword bit 4 in homing mode
constexpr std::uint16_t kSwHomingAttained = 1U << 12;
constexpr std::uint16_t kSwHomingError = 1U << 13;
constexpr std::int8_t kInterpolationIndexMin = -6;  // 0x60C2:02, 10^index s: µs … s
constexpr std::int8_t kInterpolationIndexMax = 0;

using slave::map_entry;
using slave::pdo_comm;
using slave::pdo_map;
namespace cob = slave::cob;

constexpr slave::Objects<5> kCommunicationObjects = slave::communication_objects(kDeviceTypeServo402);

constexpr slave::Objects<23> kDriveObjects{{
    {kErrorCode, 0, 2, Access::kRo, Pdo::kTx, 0},
    {kControlword, 0, 2, Access::kRw, Pdo::kRx, 0},
    {kStatusword, 0, 2, Access::kRo, Pdo::kTx, 0},
    {kModes, 0, 1, Access::kRw, Pdo::kRx, 0},
    {kModesDisplay, 0, 1, Access::kRo, Pdo::kTx, 0},
    {kPositionActual, 0, 4, Access::kRo, Pdo::kTx, 0},
    {kVelocityActual, 0, 4, Access::kRo, Pdo::kTx, 0},
    {kTorqueActual, 0, 2, Access::kRo, Pdo::kTx, 0},  // ideal tracking needs no torque: always 0
    {kTargetPosition, 0, 4, Access::kRw, Pdo::kRx, 0},
    {kHomeOffset, 0, 4, Access::kRw, Pdo::kNone, 0},
    {kProfileVelocity, 0, 4, Access::kRw, Pdo::kNone, 100000},       // counts/s
    {kProfileAcceleration, 0, 4, Access::kRw, Pdo::kNone, 1000000},  // counts/s²
    {kProfileDeceleration, 0, 4, Access::kRw, Pdo::kNone, 1000000},  // counts/s²
    {kMotionProfileType, 0, 2, Access::kRw, Pdo::kNone, 0},          // linear ramp
    {kHomingMethod, 0, 1, Access::kRw, Pdo::kNone, 37},
    {kHomingSpeeds, 0, 1, Access::kConst, Pdo::kNone, 2},
    {kHomingSpeeds, 1, 4, Access::kRw, Pdo::kNone, 10000},  // search for switch, counts/s
    {kHomingSpeeds, 2, 4, Access::kRw, Pdo::kNone, 2500},   // search for zero, counts/s
    {kHomingAcceleration, 0, 4, Access::kRw, Pdo::kNone, 100000},
    {kInterpolationPeriod, 0, 1, Access::kConst, Pdo::kNone, 2},
    {kInterpolationPeriod, 1, 1, Access::kRw, Pdo::kNone, 1},     // value …
    {kInterpolationPeriod, 2, 1, Access::kRw, Pdo::kNone, 0xFD},  // … × 10^−3 s: 1 ms
    {kSupportedModes, 0, 4, Access::kRo, Pdo::kNone, kModesPpPv | kModeCspBit},
}};

// The object dictionary, once. Factory PDOs as many drives ship them: RPDO1 {controlword, target} and
// TPDO1 {statusword, position} synchronous; TPDO2 {velocity, torque} active too, so a master that
// forgets to switch it off pays for it in bus load (the tests check that ours does).
// One object per line, so the table reads as the dictionary it is.
// clang-format off
constexpr auto kTable = slave::concat(
    kCommunicationObjects,
    pdo_comm(0x1400, cob::kRpdo1, 1),
    pdo_comm(0x1401, cob::kRpdo2 | cob::kPdoInvalid, 255),
    pdo_comm(0x1402, cob::kRpdo3 | cob::kPdoInvalid, 255),
    pdo_comm(0x1403, cob::kRpdo4 | cob::kPdoInvalid, 255),
    pdo_map(0x1600, {map_entry(kControlword, 0, 16), map_entry(kTargetPosition, 0, 32)}),
    pdo_map(0x1601),
    pdo_map(0x1602),
    pdo_map(0x1603),
    slave::tpdo_comm_timed(0x1800, cob::kTpdo1, 1),
    pdo_comm(0x1801, cob::kTpdo2, 1),
    pdo_comm(0x1802, cob::kTpdo3 | cob::kPdoInvalid, 1),
    pdo_comm(0x1803, cob::kTpdo4 | cob::kPdoInvalid, 1),
    pdo_map(0x1A00, {map_entry(kStatusword, 0, 16), map_entry(kPositionActual, 0, 32)}),
    pdo_map(0x1A01, {map_entry(kVelocityActual, 0, 32), map_entry(kTorqueActual, 0, 16)}),
    pdo_map(0x1A02),
    pdo_map(0x1A03),
    kDriveObjects);
// clang-format on
static_assert(slave::sorted(kTable), "the dictionary is binary-searched: list objects by index, sub");

}  // namespace

SimDriveNode::SimDriveNode(drivers::CanBus& bus, SimDriveConfig config)
    : bus_(bus),
      config_(std::move(config)),
      od_(config_.dictionary.empty() ? std::span<const slave::Entry>(kTable)
                                     : std::span<const slave::Entry>(config_.dictionary),
          slave::OdOptions{config_.missing_objects, config_.fixed_mapping}),
      rng_(config_.power_up_seed) {
  position_ = config_.initial_position;
  previous_position_ = position_;
  od_.set(kTargetPosition, 0, static_cast<std::uint32_t>(position_));
}

// ---------------------------------------------------------------------------------------------------
// Power and resets
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::reset_communication() {
  od_.reset_communication(config_.node_id);
  // A personality's own factory TPDO1 (e.g. position in increments instead of 0x6064).
  if (!config_.tpdo1_factory_mapping.empty()) {
    const std::size_t n = std::min<std::size_t>(slave::kMapEntries, config_.tpdo1_factory_mapping.size());
    for (std::size_t e = 0; e < slave::kMapEntries; ++e) {
      od_.set(slave::kTpdoMap, static_cast<std::uint8_t>(e + 1),
              e < n ? config_.tpdo1_factory_mapping[e] : 0);
    }
    od_.set(slave::kTpdoMap, 0, static_cast<std::uint32_t>(n));
  }
  master_seen_us_ = -1;
  master_lost_ = false;
  rpdos_.clear();
  syncs_ = 0;
  tpdo_sent_us_.fill(-1);
  tpdo_dlc_.fill(0);
  tpdo_held_.fill(false);
}

void SimDriveNode::reset_application() {
  od_.reset_application();
  if (config_.dictionary.empty()) {  // a described drive's 0x6502 is its description's
    od_.set(kSupportedModes, 0,
            kModePvBit | (config_.supports_pp ? kModePpBit : 0U) | (config_.supports_csp ? kModeCspBit : 0U) |
                (config_.supports_homing ? kModeHomingBit : 0U));
  }
  homing_running_ = homing_attained_ = homing_error_ = false;
  pp_latch_ = pp_ack_ = pp_active_ = false;
  pp_goal_ = position_;
  pp_pos_ = position_;
  pp_vel_ = 0.0;
  state_ = drive_settle(DriveState::kNotReadyToSwitchOn);
  controlword_ = 0;
  od_.set(kTargetPosition, 0, static_cast<std::uint32_t>(position_));  // no jump when first enabled
  previous_position_ = position_;
  error_code_ = 0;
  error_register_ = 0;
  following_error_ = false;
}

// Reset communication's common tail: pre-operational, heartbeat timer restarted, boot-up.
void SimDriveNode::restart(std::int64_t now_us) {
  reset_communication();
  nmt_ = nmt::kPreOperational;
  next_heartbeat_us_ = now_us;
  boot_up(now_us);
}

void SimDriveNode::power_on(std::int64_t now_us) {
  powered_ = true;
  if (config_.power_up_seed != 0) {
    // An incremental encoder: the same physical position, a count that means nothing.
    const std::int64_t physical = physical_position();
    const std::int64_t range = std::max<std::int32_t>(1, config_.power_up_range);
    count_offset_ = std::uniform_int_distribution<std::int64_t>(-range, range)(rng_);
    position_ = static_cast<std::int32_t>(physical + count_offset_);
    previous_position_ = position_;
  }
  reset_application();
  restart(now_us);
}

void SimDriveNode::boot_up(std::int64_t now_us) {
  operational_at_us_ = -1;
  if (config_.boot_delay_us > 0) {
    boot_at_us_ = now_us + config_.boot_delay_us;  // silent until then
    return;
  }
  boot_at_us_ = -1;
  send(slave::heartbeat(config_.node_id, nmt::kBootUp));
}

void SimDriveNode::power_off() {
  powered_ = false;
}

void SimDriveNode::send(const CanFrame& f) {
  if (powered_) bus_.send(f);
}

// ---------------------------------------------------------------------------------------------------
// Frames in
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::handle(const CanFrame& f, std::int64_t now_us) {
  if (!powered_ || boot_at_us_ >= 0) return;
  slave::deliver(od_, config_.node_id, nmt_, f, now_us, *this);
}

// The master's heartbeat, watched through 0x1016:01.
void SimDriveNode::on_watched_heartbeat(std::int64_t now_us) {
  master_seen_us_ = now_us;
}

void SimDriveNode::on_nmt(std::uint8_t command, std::int64_t now_us) {
  switch (command) {
    case nmt::kStart:
      if (config_.operational_delay_us > 0) {
        operational_at_us_ = now_us + config_.operational_delay_us;
      } else {
        nmt_ = nmt::kOperational;
      }
      break;
    case nmt::kStop:
      nmt_ = nmt::kStopped;
      break;
    case nmt::kEnterPreOperational:
      nmt_ = nmt::kPreOperational;
      break;
    case nmt::kResetNode:
      reset_application();
      restart(now_us);
      break;
    case nmt::kResetCommunication:
      restart(now_us);
      break;
    default:
      break;
  }
}

void SimDriveNode::on_sdo(const CanFrame& f, std::int64_t now_us) {
  publish();  // an upload reads what the drive reports now
  if (const auto reply = slave::sdo_serve(od_, *this, config_.node_id, f, now_us)) send(*reply);
}

void SimDriveNode::on_rpdo(int pdo, const CanFrame& f, std::int64_t now_us) {
  if (!rpdos_.receive(od_, *this, pdo, f, now_us)) {
    send(slave::emcy(config_.node_id, slave::emcy_code::kPdoLength, error_register_));
    return;
  }
  latch_setpoint();  // (an event-driven RPDO's objects are all written now, target included)
  send_event_tpdos(now_us);
}

void SimDriveNode::on_sync(std::int64_t now_us) {
  ++syncs_;
  rpdos_.apply_at_sync(od_, *this, now_us);
  latch_setpoint();
  previous_position_ = position_;
  track_target();
  run_homing();
  run_profile();
  send_tpdos();
  send_event_tpdos(now_us);
  // The fault reaction (a ramp in a real drive) completes before the next SYNC.
  if (state_ == DriveState::kFaultReactionActive) state_ = drive_settle(state_);
}

// Profile position: the target becomes the set-point on bit 4's rising edge (with bit 5 or not: the
// simulation always changes immediately, from where the axis is and at the speed it has), acknowledged
// with bit 12 until bit 4 falls.
void SimDriveNode::latch_setpoint() {
  if (!pp_latch_) return;
  pp_latch_ = false;
  if (state_ != DriveState::kOperationEnabled || mode() != kModePp) return;
  pp_goal_ = target();
  pp_active_ = true;
  pp_ack_ = true;
  ++pp_latched_;
}

double SimDriveNode::sync_period_s() const {
  return static_cast<double>(od_.get(kInterpolationPeriod, 1)) *
         std::pow(10.0, static_cast<std::int8_t>(od_.get(kInterpolationPeriod, 2)));
}

// One SYNC of the drive's own trapezoidal profile (0x6081 speed, 0x6083 acceleration, 0x6084
// deceleration): the speed that still stops at the goal, reached at the allowed rate.
void SimDriveNode::run_profile() {
  if (state_ != DriveState::kOperationEnabled || mode() != kModePp) {
    pp_active_ = false;  // quick stop, disable, fault: the move is abandoned where the axis is
    pp_vel_ = 0.0;
    pp_pos_ = position_;
    return;
  }
  if (!pp_active_) return;
  const double dt = sync_period_s();
  const double vmax = std::max(1.0, static_cast<double>(od_.get(kProfileVelocity, 0)));
  const double acc = std::max(1.0, static_cast<double>(od_.get(kProfileAcceleration, 0)));
  const double dec = std::max(1.0, static_cast<double>(od_.get(kProfileDeceleration, 0)));
  const double d = static_cast<double>(pp_goal_) - pp_pos_;
  const double dir = d >= 0.0 ? 1.0 : -1.0;
  // Highest speed toward the goal from which deceleration still stops there (discrete: one step late).
  const double v_stop = std::sqrt(2.0 * dec * std::abs(d)) - 0.5 * dec * dt;
  const double wanted = dir * std::min(vmax, std::max(0.0, v_stop));
  const double step = (wanted > pp_vel_ ? acc : dec) * dt;
  pp_vel_ = std::clamp(wanted, pp_vel_ - step, pp_vel_ + step);
  pp_pos_ += pp_vel_ * dt;
  if (std::abs(static_cast<double>(pp_goal_) - pp_pos_) <= std::max(1.0, std::abs(pp_vel_) * dt * 0.5) ||
      (static_cast<double>(pp_goal_) - pp_pos_) * dir < 0.0) {
    pp_pos_ = pp_goal_;  // arrived (or would pass it): standing at the goal
    pp_vel_ = 0.0;
    pp_active_ = false;
  }
  position_ = static_cast<std::int32_t>(std::llround(pp_pos_));
}

// TPDOs with an event-driven transmission type: on change, never closer than the inhibit time, and at
// least every event timer period (0 = no timer).
void SimDriveNode::send_event_tpdos(std::int64_t now_us) {
  if (nmt_ != nmt::kOperational) return;
  publish();
  for (int k = 0; k < slave::kPdos; ++k) {
    const auto comm = static_cast<std::uint16_t>(slave::kTpdoComm + k);
    const std::uint8_t type = od_.pdo_type(comm);
    if (!od_.pdo_valid(comm) || (type != 254 && type != 255)) continue;
    const auto kk = static_cast<std::size_t>(k);
    std::array<std::uint8_t, 8> data{};
    const std::uint8_t dlc = od_.pack_tpdo(k, data);
    const std::int64_t inhibit_us = static_cast<std::int64_t>(od_.get(comm, 3)) * 100;
    const std::int64_t timer_us = static_cast<std::int64_t>(od_.get(comm, 5)) * 1000;
    const std::int64_t last = tpdo_sent_us_[kk];
    const bool changed = last < 0 || dlc != tpdo_dlc_[kk] || data != tpdo_data_[kk] || tpdo_held_[kk];
    const bool timer_due = timer_us > 0 && last >= 0 && now_us - last >= timer_us;
    if (!changed && !timer_due) continue;
    if (last >= 0 && now_us - last < inhibit_us) {
      tpdo_held_[kk] = changed;  // sent when the inhibit time is over
      continue;
    }
    send(slave::pdo_frame(od_.pdo_can_id(comm), dlc, data));
    tpdo_sent_us_[kk] = now_us;
    tpdo_data_[kk] = data;
    tpdo_dlc_[kk] = dlc;
    tpdo_held_[kk] = false;
  }
}

// CSP with ideal tracking: the actual position becomes the target, unless the step is larger than the
// drive can follow (following error).
void SimDriveNode::track_target() {
  if (state_ != DriveState::kOperationEnabled || mode() != kModeCsp) return;
  const std::int32_t goal = target();
  const auto step =
      static_cast<std::int32_t>(static_cast<std::uint32_t>(goal) - static_cast<std::uint32_t>(position_));
  if (config_.max_step_counts != 0 && std::llabs(step) > static_cast<long long>(config_.max_step_counts)) {
    following_error_ = true;
    enter_fault(slave::emcy_code::kFollowingError);
    return;
  }
  position_ = goal;
}

// ---------------------------------------------------------------------------------------------------
// Frames out
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::send_tpdos() {
  publish();
  slave::send_due_tpdos(od_, syncs_, [this](const CanFrame& f) { send(f); });
}

// What the drive reports, into its objects: the dictionary is what SDO uploads and TPDOs read.
void SimDriveNode::publish() {
  od_.set(kErrorRegister, 0, error_register_);
  od_.set(kErrorCode, 0, error_code_);
  od_.set(kStatusword, 0, statusword());
  od_.set(kModesDisplay, 0, od_.get(kModes, 0));
  od_.set(kPositionActual, 0, static_cast<std::uint32_t>(position_));
  od_.set(kVelocityActual, 0, static_cast<std::uint32_t>(velocity()));
}

std::uint16_t SimDriveNode::statusword() const {
  if (mode() == kModeHoming) {
    // CiA 402 homing mode: bit 10 = the run is over (or none runs), bit 12 attained, bit 13 error.
    std::uint16_t sw = drive_statusword(state_, false, !homing_running_, false);
    if (homing_attained_) sw |= kSwHomingAttained;
    if (homing_error_) sw = static_cast<std::uint16_t>(sw | kSwHomingError);
    return sw;
  }
  if (mode() == kModePp) {
    // Bit 12 set-point acknowledge, bit 10 target reached (the profile is over, standing at its goal).
    std::uint16_t sw = drive_statusword(state_, false, !pp_active_, false);
    if (pp_ack_ && state_ == DriveState::kOperationEnabled) sw |= kSwSetpointAck;
    return sw;
  }
  return drive_statusword(state_, mode() == kModeCsp, position_ == target(), following_error_);
}

// The home point is found: the count becomes the home offset there (0x607C); the physical axis stays.
void SimDriveNode::set_home() {
  const auto home = static_cast<std::int32_t>(od_.get(kHomeOffset, 0));
  count_offset_ += static_cast<std::int64_t>(home) - position_;
  position_ = home;
  previous_position_ = position_;
  od_.set(kTargetPosition, 0, static_cast<std::uint32_t>(position_));
  homing_running_ = false;
  homing_attained_ = true;
}

// One SYNC of a homing run: travel at the search speed toward the home point of the method.
void SimDriveNode::run_homing() {
  if (!homing_running_) return;
  if (state_ != DriveState::kOperationEnabled || mode() != kModeHoming ||
      (controlword_ & kCwHomingStart) == 0) {
    homing_running_ = false;  // interrupted (bit 4 dropped, mode changed, power stage off)
    return;
  }
  const auto method = static_cast<std::int8_t>(od_.get(kHomingMethod, 0));
  if (method == 37) {
    set_home();
    return;
  }
  ++homing_syncs_;
  const double period_s = static_cast<double>(od_.get(kInterpolationPeriod, 1)) *
                          std::pow(10.0, static_cast<std::int8_t>(od_.get(kInterpolationPeriod, 2)));
  const auto step =
      std::max<std::int64_t>(1, std::llround(static_cast<double>(od_.get(kHomingSpeeds, 1)) * period_s));
  const std::int64_t here = physical_position();
  std::int64_t goal = here;
  if (method == 19 || method == 21) {
    if (config_.home_switch_missing) {
      if (homing_syncs_ > 200) {  // travelled far enough without seeing a switch
        homing_running_ = false;
        homing_error_ = true;
      } else {
        position_ += static_cast<std::int32_t>(method == 19 ? step : -step);
      }
      return;
    }
    goal = config_.home_switch_at;
  } else {  // 33: the next index pulse below, 34: above
    const std::int64_t n = std::max<std::int32_t>(1, config_.index_every);
    const std::int64_t below = (here >= 0 ? here / n : -((-here + n - 1) / n)) * n;
    goal = method == 33 ? (below == here ? here - n : below) : below + n;
  }
  const std::int64_t d = goal - here;
  if (std::llabs(d) <= step) {
    position_ = static_cast<std::int32_t>(goal + count_offset_);
    set_home();
    return;
  }
  position_ += static_cast<std::int32_t>(d > 0 ? step : -step);
}

std::int32_t SimDriveNode::target() const {
  return static_cast<std::int32_t>(od_.get(kTargetPosition, 0));
}

std::int8_t SimDriveNode::mode() const {
  return static_cast<std::int8_t>(od_.get(kModes, 0));
}

std::uint16_t SimDriveNode::heartbeat_ms() const {
  return static_cast<std::uint16_t>(od_.get(kProducerHeartbeat, 0));
}

// Counts per second over the last SYNC interval, the interpolation period 0x60C2 being that interval.
std::int32_t SimDriveNode::velocity() const {
  const auto delta = static_cast<std::int32_t>(static_cast<std::uint32_t>(position_) -
                                               static_cast<std::uint32_t>(previous_position_));
  const double period_s = static_cast<double>(od_.get(kInterpolationPeriod, 1)) *
                          std::pow(10.0, static_cast<std::int8_t>(od_.get(kInterpolationPeriod, 2)));
  return static_cast<std::int32_t>(std::lround(delta / period_s));
}

void SimDriveNode::set_controlword(std::uint16_t cw) {
  const DriveState before = state_;
  // Homing starts on the rising edge of bit 4 in homing mode with the power stage enabled.
  if (mode() == kModeHoming && before == DriveState::kOperationEnabled && (cw & kCwHomingStart) != 0 &&
      (controlword_ & kCwHomingStart) == 0) {
    homing_running_ = true;
    homing_attained_ = homing_error_ = false;
    homing_syncs_ = 0;
  }
  if (mode() == kModePp && (cw & kCwNewSetpoint) != 0 && (controlword_ & kCwNewSetpoint) == 0)
    pp_latch_ = true;
  if ((cw & kCwNewSetpoint) == 0) pp_ack_ = false;  // the master released bit 4: ready for the next one
  state_ = drive_apply_controlword(state_, cw, controlword_);
  controlword_ = cw;
  if (before == DriveState::kFault && state_ != DriveState::kFault) {
    error_code_ = 0;
    error_register_ = 0;
    following_error_ = false;
    send(slave::emcy(config_.node_id, slave::emcy_code::kErrorReset, 0));
  }
  if (before != DriveState::kOperationEnabled && state_ == DriveState::kOperationEnabled) {
    following_error_ = false;
  }
}

void SimDriveNode::enter_fault(std::uint16_t code) {
  if (!powered_ || state_ == DriveState::kFault || state_ == DriveState::kFaultReactionActive) return;
  state_ = DriveState::kFaultReactionActive;
  error_code_ = code;
  error_register_ |= slave::kErrorRegisterGeneric;
  if (nmt_ == nmt::kOperational || nmt_ == nmt::kPreOperational) {
    send(slave::emcy(config_.node_id, code, error_register_));
  }
}

void SimDriveNode::inject_fault(std::uint16_t code) {
  enter_fault(code);
}

// ---------------------------------------------------------------------------------------------------
// Object rules beyond CiA 301 and the drive's reactions to writes (SDO and RPDO)
// ---------------------------------------------------------------------------------------------------
std::uint32_t SimDriveNode::check(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const {
  if (index == kModes) {
    // Only "no mode" and the modes 0x6502 announces; of those the simulation implements CSP and homing.
    const auto mode = static_cast<std::int8_t>(value);
    const bool csp_offered = (od_.get(kSupportedModes, 0) & kModeCspBit) != 0;
    const bool homing_offered = (od_.get(kSupportedModes, 0) & kModeHomingBit) != 0;
    const bool pp_offered = (od_.get(kSupportedModes, 0) & kModePpBit) != 0;
    return (mode == 0 || (mode == kModeCsp && csp_offered) || (mode == kModeHoming && homing_offered) ||
            (mode == kModePp && pp_offered))
               ? 0
               : slave::abort_code::kValueRange;
  }
  if (index == kMotionProfileType) {
    return value == 0 ? 0 : slave::abort_code::kValueRange;  // a linear ramp only: no jerk limit
  }
  if ((index == kProfileVelocity || index == kProfileAcceleration || index == kProfileDeceleration) &&
      value == 0) {
    return slave::abort_code::kValueRange;
  }
  if (index == kHomingMethod) {
    const auto m = static_cast<std::int8_t>(value);
    return (m == 19 || m == 21 || m == 33 || m == 34 || m == 37) ? 0 : slave::abort_code::kValueRange;
  }
  if (index == kInterpolationPeriod && sub == 1) {
    return value == 0 ? slave::abort_code::kValueRange : 0;  // a zero period has no SYNC rate
  }
  if (index == kInterpolationPeriod && sub == 2) {
    const auto exponent = static_cast<std::int8_t>(value);
    const bool ok = exponent >= kInterpolationIndexMin && exponent <= kInterpolationIndexMax;
    return ok ? 0 : slave::abort_code::kValueRange;
  }
  return 0;
}

void SimDriveNode::written(std::uint16_t index, std::uint8_t, std::uint32_t value, std::int64_t now_us) {
  switch (index) {
    case kControlword:
      set_controlword(static_cast<std::uint16_t>(value));
      break;
    case kProducerHeartbeat:
      next_heartbeat_us_ = now_us + static_cast<std::int64_t>(value) * 1000;
      break;
    case kConsumerHeartbeat:  // a new consumer time starts with the next heartbeat seen
      master_seen_us_ = -1;
      master_lost_ = false;
      break;
    default:
      break;
  }
}

// ---------------------------------------------------------------------------------------------------
// Timers
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::step(std::int64_t now_us) {
  if (!powered_) return;
  if (boot_at_us_ >= 0) {
    if (now_us < boot_at_us_) return;
    boot_at_us_ = -1;
    send(slave::heartbeat(config_.node_id, nmt::kBootUp));
  }
  if (operational_at_us_ >= 0 && now_us >= operational_at_us_) {
    operational_at_us_ = -1;
    nmt_ = nmt::kOperational;
  }
  watch_master(now_us);
  produce_heartbeat(now_us);
  send_event_tpdos(now_us);
}

std::int64_t SimDriveNode::consumer_window_us() const {
  return static_cast<std::int64_t>(od_.get(kConsumerHeartbeat, 1) & 0xFFFF) * 1000;
}

// Heartbeat consumer expired: the drive's abort-connection reaction (0x6007 = 3, quick stop) and an
// EMCY 0x8130, by itself, whatever the master last commanded.
void SimDriveNode::watch_master(std::int64_t now_us) {
  const std::int64_t window_us = consumer_window_us();
  if (window_us <= 0 || master_seen_us_ < 0 || master_lost_ || now_us - master_seen_us_ <= window_us) return;
  master_lost_ = true;
  if (state_ == DriveState::kOperationEnabled) state_ = DriveState::kQuickStopActive;
  error_register_ |= slave::kErrorRegisterCommunication;
  send(slave::emcy(config_.node_id, slave::emcy_code::kHeartbeatLost, error_register_));
}

void SimDriveNode::produce_heartbeat(std::int64_t now_us) {
  const std::int64_t period_us = static_cast<std::int64_t>(heartbeat_ms()) * 1000;
  if (period_us == 0 || now_us < next_heartbeat_us_) return;
  send(slave::heartbeat(config_.node_id, nmt_));
  next_heartbeat_us_ += period_us;
  if (next_heartbeat_us_ <= now_us) next_heartbeat_us_ = now_us + period_us;
}

std::int64_t SimDriveNode::next_deadline_us() const {
  if (!powered_) return std::numeric_limits<std::int64_t>::max();
  std::int64_t t = heartbeat_ms() == 0 ? std::numeric_limits<std::int64_t>::max() : next_heartbeat_us_;
  if (boot_at_us_ >= 0) t = std::min(t, boot_at_us_);
  if (operational_at_us_ >= 0) t = std::min(t, operational_at_us_);
  for (int k = 0; k < slave::kPdos; ++k) {  // event-driven TPDOs: the held one and the event timer
    const auto comm = static_cast<std::uint16_t>(slave::kTpdoComm + k);
    const auto kk = static_cast<std::size_t>(k);
    const std::uint8_t type = od_.pdo_type(comm);
    if (!od_.pdo_valid(comm) || (type != 254 && type != 255) || tpdo_sent_us_[kk] < 0) continue;
    if (tpdo_held_[kk])
      t = std::min(t, tpdo_sent_us_[kk] + static_cast<std::int64_t>(od_.get(comm, 3)) * 100);
    if (od_.get(comm, 5) != 0)
      t = std::min(t, tpdo_sent_us_[kk] + static_cast<std::int64_t>(od_.get(comm, 5)) * 1000);
  }
  if (od_.get(kConsumerHeartbeat, 1) != 0 && master_seen_us_ >= 0 && !master_lost_) {
    t = std::min(t, master_seen_us_ + consumer_window_us() + 1);
  }
  return t;
}

}  // namespace loom::sim_can
