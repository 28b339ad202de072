// Simulated CiA 402 drive node (see sim_drive_node.hpp). Behaviour follows CiA 301 (NMT, SDO server,
// PDO communication/mapping parameters and the re-map rules, SYNC, heartbeat, EMCY) and CiA 402 (state
// machine, CSP). Ideal tracking: on SYNC the actual position becomes the last received target.
#include "loom/sim_can/sim_drive_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/sim_can/drive_fsa.hpp"

namespace loom::sim_can {

using drivers::CanFrame;
using drivers::NmtState;
using hal::DriveState;
namespace od = drivers::od;
namespace abort_code = drivers::sdo_abort;

namespace {
constexpr std::uint32_t kInvalid = od::kPdoInvalidBit;
constexpr std::uint32_t kDeviceTypeServo402 = 0x00020192;  // profile 402, servo drive

// Length check of an expedited download against the object's size (0 = size not indicated: accept).
std::uint32_t check_size(std::uint8_t given, std::uint8_t expected) {
  if (given == 0 || given == expected) return 0;
  return given > expected ? abort_code::kLengthTooHigh : abort_code::kLengthTooLow;
}
}  // namespace

SimDriveNode::SimDriveNode(drivers::CanBus& bus, SimDriveConfig config)
    : bus_(bus), config_(std::move(config)) {
  position_ = config_.initial_position;
  target_ = position_;
  previous_position_ = position_;
}

// ---------------------------------------------------------------------------------------------------
// Power and resets
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::reset_communication() {
  const std::uint8_t id = config_.node_id;
  heartbeat_ms_ = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    rpdo_comm_[k] = PdoComm{drivers::cob::rpdo(static_cast<int>(k + 1), id) | (k == 0 ? 0U : kInvalid), 255};
    tpdo_comm_[k] = PdoComm{drivers::cob::tpdo(static_cast<int>(k + 1), id) | (k <= 1 ? 0U : kInvalid), 1};
    rpdo_map_[k] = PdoMap{};
    tpdo_map_[k] = PdoMap{};
  }
  // Factory mapping as many drives ship it: TPDO2 is active, so a master that forgets to switch it
  // off pays for it in bus load (the tests check that ours does).
  rpdo_comm_[0].type = 1;
  rpdo_map_[0] = PdoMap{2, {0x60400010, 0x607A0020}};
  tpdo_map_[0] = PdoMap{2, {0x60410010, 0x60640020}};
  if (!config_.tpdo1_factory_mapping.empty()) {
    tpdo_map_[0] = PdoMap{};
    for (std::size_t e = 0; e < config_.tpdo1_factory_mapping.size() && e < 8; ++e) {
      tpdo_map_[0].entries[e] = config_.tpdo1_factory_mapping[e];
    }
    tpdo_map_[0].count = static_cast<std::uint8_t>(std::min<std::size_t>(8, config_.tpdo1_factory_mapping.size()));
  }
  consumer_ = 0;
  master_seen_us_ = -1;
  master_lost_ = false;
  tpdo_map_[1] = PdoMap{2, {0x606C0020, 0x60770010}};
  rpdo_pending_.fill(false);
  syncs_ = 0;
}

void SimDriveNode::reset_application() {
  state_ = drive_settle(DriveState::kNotReadyToSwitchOn);
  controlword_ = 0;
  mode_ = 0;
  target_ = position_;
  previous_position_ = position_;
  error_code_ = 0;
  error_register_ = 0;
  ip_value_ = 1;
  ip_index_ = -3;
  following_error_ = false;
}

void SimDriveNode::power_on(std::int64_t now_us) {
  powered_ = true;
  reset_communication();
  reset_application();
  nmt_ = NmtState::kPreOperational;
  next_heartbeat_us_ = now_us;
  boot_up(now_us);
}

void SimDriveNode::boot_up(std::int64_t now_us) {
  operational_at_us_ = -1;
  if (config_.boot_delay_us > 0) {
    boot_at_us_ = now_us + config_.boot_delay_us;  // silent until then
    return;
  }
  boot_at_us_ = -1;
  send(drivers::make_heartbeat(config_.node_id, NmtState::kBootUp));
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
  if (!powered_ || f.is_error() || f.is_rtr() || boot_at_us_ >= 0) return;
  // The master's heartbeat, watched through 0x1016:01 (node << 16 | ms).
  if (consumer_ != 0 && f.id == drivers::cob::heartbeat(static_cast<std::uint8_t>((consumer_ >> 16) & 0x7F))) {
    master_seen_us_ = now_us;
    return;
  }
  if (f.id == drivers::cob::kNmt) {
    on_nmt(f, now_us);
    return;
  }
  if (f.id == drivers::cob::sdo_rx(config_.node_id)) {
    if (nmt_ != NmtState::kStopped) on_sdo(f, now_us);
    return;
  }
  if (nmt_ != NmtState::kOperational) return;
  if (drivers::is_sync(f)) {
    on_sync();
    return;
  }
  for (std::size_t k = 0; k < rpdo_comm_.size(); ++k) {
    if ((rpdo_comm_[k].cob_id & kInvalid) == 0 && f.id == (rpdo_comm_[k].cob_id & 0x7FF)) {
      on_rpdo(k, f);
      return;
    }
  }
}

void SimDriveNode::on_nmt(const CanFrame& f, std::int64_t now_us) {
  const auto msg = drivers::parse_nmt(f);
  if (!msg || (msg->node != 0 && msg->node != config_.node_id)) return;
  switch (msg->command) {
    case drivers::NmtCommand::kStart:
      if (config_.operational_delay_us > 0) {
        operational_at_us_ = now_us + config_.operational_delay_us;
      } else {
        nmt_ = NmtState::kOperational;
      }
      break;
    case drivers::NmtCommand::kStop:
      nmt_ = NmtState::kStopped;
      break;
    case drivers::NmtCommand::kEnterPreOperational:
      nmt_ = NmtState::kPreOperational;
      break;
    case drivers::NmtCommand::kResetNode:
      reset_application();
      [[fallthrough]];
    case drivers::NmtCommand::kResetCommunication:
      reset_communication();
      nmt_ = NmtState::kPreOperational;
      next_heartbeat_us_ = now_us;
      boot_up(now_us);
      break;
  }
}

void SimDriveNode::on_sdo(const CanFrame& f, std::int64_t now_us) {
  const std::uint8_t id = config_.node_id;
  const drivers::SdoRequest req = drivers::parse_sdo_request(f);
  const std::uint32_t reply_id = drivers::cob::sdo_tx(id);
  switch (req.kind) {
    case drivers::SdoRequestKind::kUpload: {
      std::uint32_t value = 0;
      std::uint8_t size = 0;
      const std::uint32_t err = read_object(req.index, req.sub, value, size);
      send(err != 0 ? drivers::make_sdo_abort(reply_id, req.index, req.sub, err)
                    : drivers::make_sdo_upload_reply(id, req.index, req.sub, value, size));
      return;
    }
    case drivers::SdoRequestKind::kDownloadExpedited: {
      const std::uint32_t err = write_object(req.index, req.sub, req.value, req.size, now_us);
      send(err != 0 ? drivers::make_sdo_abort(reply_id, req.index, req.sub, err)
                    : drivers::make_sdo_download_ack(id, req.index, req.sub));
      return;
    }
    case drivers::SdoRequestKind::kDownloadSegmented:
      send(drivers::make_sdo_abort(reply_id, req.index, req.sub, abort_code::kUnsupportedAccess));
      return;
    case drivers::SdoRequestKind::kAbort:
      return;
    case drivers::SdoRequestKind::kInvalid:
      send(drivers::make_sdo_abort(reply_id, req.index, req.sub, abort_code::kInvalidCommand));
      return;
  }
}

void SimDriveNode::on_rpdo(std::size_t k, const CanFrame& f) {
  unsigned bits = 0;
  for (std::size_t e = 0; e < rpdo_map_[k].count; ++e) bits += rpdo_map_[k].entries[e] & 0xFF;
  if (f.dlc < bits / 8) {
    send(drivers::make_emcy(config_.node_id, drivers::fault_code::kPdoLength, error_register_));
    return;
  }
  if (rpdo_comm_[k].type <= 240) {
    rpdo_data_[k] = f.data;
    rpdo_pending_[k] = true;  // synchronous: applied at the next SYNC
  } else {
    apply_rpdo(k, f.data);
  }
}

void SimDriveNode::apply_rpdo(std::size_t k, const std::array<std::uint8_t, 8>& data) {
  std::size_t offset = 0;
  for (std::size_t e = 0; e < rpdo_map_[k].count; ++e) {
    const drivers::PdoMapEntry m = drivers::decode_map_entry(rpdo_map_[k].entries[e]);
    const std::size_t bytes = m.bits / 8U;
    std::uint32_t v = 0;
    for (std::size_t b = 0; b < bytes; ++b) v |= static_cast<std::uint32_t>(data[offset + b]) << (8 * b);
    offset += bytes;
    switch (m.index) {
      case od::kControlword:
        set_controlword(static_cast<std::uint16_t>(v));
        break;
      case od::kTargetPosition:
        target_ = static_cast<std::int32_t>(v);
        break;
      case od::kModesOfOperation:
        mode_ = static_cast<std::int8_t>(v);
        break;
      default:
        break;
    }
  }
}

void SimDriveNode::on_sync() {
  ++syncs_;
  for (std::size_t k = 0; k < rpdo_pending_.size(); ++k) {
    if (rpdo_pending_[k]) {
      rpdo_pending_[k] = false;
      apply_rpdo(k, rpdo_data_[k]);
    }
  }
  previous_position_ = position_;
  if (state_ == DriveState::kOperationEnabled && mode_ == od::kModeCsp) {
    const auto step = static_cast<std::int32_t>(static_cast<std::uint32_t>(target_) -
                                                static_cast<std::uint32_t>(position_));
    if (config_.max_step_counts != 0 && std::llabs(step) > static_cast<long long>(config_.max_step_counts)) {
      following_error_ = true;
      enter_fault(drivers::fault_code::kFollowingError);
    } else {
      position_ = target_;
    }
  }
  for (std::size_t k = 0; k < tpdo_comm_.size(); ++k) {
    const PdoComm& c = tpdo_comm_[k];
    if ((c.cob_id & kInvalid) != 0 || c.type > 240) continue;
    if (c.type <= 1 || syncs_ % c.type == 0) send_tpdo(k);
  }
  // The fault reaction (a ramp in a real drive) completes before the next SYNC.
  if (state_ == DriveState::kFaultReactionActive) state_ = drive_settle(state_);
}

// ---------------------------------------------------------------------------------------------------
// Frames out
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::send_tpdo(std::size_t k) {
  CanFrame f;
  f.id = tpdo_comm_[k].cob_id & 0x7FF;
  std::size_t offset = 0;
  for (std::size_t e = 0; e < tpdo_map_[k].count; ++e) {
    const drivers::PdoMapEntry m = drivers::decode_map_entry(tpdo_map_[k].entries[e]);
    const std::uint32_t v = mapped_value(m.index);
    for (std::size_t b = 0; b < m.bits / 8U; ++b) f.data[offset++] = static_cast<std::uint8_t>(v >> (8 * b));
  }
  f.dlc = static_cast<std::uint8_t>(offset);
  send(f);
}

std::uint16_t SimDriveNode::statusword() const {
  return drive_statusword(state_, mode_ == od::kModeCsp, position_ == target_, following_error_);
}

double SimDriveNode::interpolation_period_s() const {
  return static_cast<double>(ip_value_) * std::pow(10.0, ip_index_);
}

std::uint32_t SimDriveNode::mapped_value(std::uint16_t index) const {
  switch (index) {
    case od::kStatusword:
      return statusword();
    case od::kPositionActual:
      return static_cast<std::uint32_t>(position_);
    case od::kVelocityActual: {
      const auto delta = static_cast<std::int32_t>(static_cast<std::uint32_t>(position_) -
                                                   static_cast<std::uint32_t>(previous_position_));
      return static_cast<std::uint32_t>(
          static_cast<std::int32_t>(std::lround(delta / interpolation_period_s())));
    }
    case od::kTorqueActual:
      return 0;  // ideal tracking needs no torque
    case od::kModesOfOperationDisplay:
      return static_cast<std::uint8_t>(mode_);
    case od::kErrorCode:
      return error_code_;
    default:
      return 0;
  }
}

void SimDriveNode::set_controlword(std::uint16_t cw) {
  const DriveState before = state_;
  state_ = drive_apply_controlword(state_, cw, controlword_);
  controlword_ = cw;
  if (before == DriveState::kFault && state_ != DriveState::kFault) {
    error_code_ = 0;
    error_register_ = 0;
    following_error_ = false;
    send(drivers::make_emcy(config_.node_id, 0x0000, 0));  // error reset
  }
  if (before != DriveState::kOperationEnabled && state_ == DriveState::kOperationEnabled) {
    following_error_ = false;
  }
}

void SimDriveNode::enter_fault(std::uint16_t code) {
  if (!powered_ || state_ == DriveState::kFault || state_ == DriveState::kFaultReactionActive) return;
  state_ = DriveState::kFaultReactionActive;
  error_code_ = code;
  error_register_ |= 0x01;  // generic error
  if (nmt_ == NmtState::kOperational || nmt_ == NmtState::kPreOperational) {
    send(drivers::make_emcy(config_.node_id, code, error_register_));
  }
}

void SimDriveNode::inject_fault(std::uint16_t code) {
  enter_fault(code);
}

// ---------------------------------------------------------------------------------------------------
// Timers
// ---------------------------------------------------------------------------------------------------
void SimDriveNode::step(std::int64_t now_us) {
  if (!powered_) return;
  if (boot_at_us_ >= 0) {
    if (now_us < boot_at_us_) return;
    boot_at_us_ = -1;
    send(drivers::make_heartbeat(config_.node_id, NmtState::kBootUp));
  }
  if (operational_at_us_ >= 0 && now_us >= operational_at_us_) {
    operational_at_us_ = -1;
    nmt_ = NmtState::kOperational;
  }
  // Heartbeat consumer expired: the drive's abort-connection reaction (0x6007 = 3, quick stop) and an
  // EMCY 0x8130, by itself, whatever the master last commanded.
  const std::int64_t window_us = static_cast<std::int64_t>(consumer_ & 0xFFFF) * 1000;
  if (consumer_ != 0 && window_us > 0 && master_seen_us_ >= 0 && !master_lost_ &&
      now_us - master_seen_us_ > window_us) {
    master_lost_ = true;
    if (state_ == DriveState::kOperationEnabled) state_ = DriveState::kQuickStopActive;
    error_register_ |= 0x10;  // communication
    send(drivers::make_emcy(config_.node_id, drivers::fault_code::kHeartbeatLost, error_register_));
  }
  if (heartbeat_ms_ == 0) return;
  if (now_us >= next_heartbeat_us_) {
    send(drivers::make_heartbeat(config_.node_id, nmt_));
    const std::int64_t period_us = static_cast<std::int64_t>(heartbeat_ms_) * 1000;
    next_heartbeat_us_ += period_us;
    if (next_heartbeat_us_ <= now_us) next_heartbeat_us_ = now_us + period_us;
  }
}

std::int64_t SimDriveNode::next_deadline_us() const {
  if (!powered_) return std::numeric_limits<std::int64_t>::max();
  std::int64_t t = heartbeat_ms_ == 0 ? std::numeric_limits<std::int64_t>::max() : next_heartbeat_us_;
  if (boot_at_us_ >= 0) t = std::min(t, boot_at_us_);
  if (operational_at_us_ >= 0) t = std::min(t, operational_at_us_);
  if (consumer_ != 0 && master_seen_us_ >= 0 && !master_lost_) {
    t = std::min(t, master_seen_us_ + static_cast<std::int64_t>(consumer_ & 0xFFFF) * 1000 + 1);
  }
  return t;
}

// ---------------------------------------------------------------------------------------------------
// Object dictionary (SDO server)
// ---------------------------------------------------------------------------------------------------
bool SimDriveNode::object_missing(std::uint16_t index) const {
  return std::find(config_.missing_objects.begin(), config_.missing_objects.end(), index) !=
         config_.missing_objects.end();
}

bool SimDriveNode::mappable(std::uint32_t entry, bool rx) const {
  const drivers::PdoMapEntry m = drivers::decode_map_entry(entry);
  if (m.sub != 0 || object_missing(m.index)) return false;
  struct Mappable {
    std::uint16_t index;
    std::uint8_t bits;
    bool rx;
  };
  static constexpr Mappable kTable[] = {
      {od::kControlword, 16, true},     {od::kTargetPosition, 32, true},
      {od::kModesOfOperation, 8, true}, {od::kStatusword, 16, false},
      {od::kPositionActual, 32, false}, {od::kVelocityActual, 32, false},
      {od::kTorqueActual, 16, false},   {od::kModesOfOperationDisplay, 8, false},
      {od::kErrorCode, 16, false},
  };
  for (const Mappable& t : kTable) {
    if (t.index == m.index && t.bits == m.bits && t.rx == rx) return true;
  }
  return false;
}

std::uint32_t SimDriveNode::read_object(std::uint16_t index, std::uint8_t sub, std::uint32_t& value,
                                        std::uint8_t& size) const {
  if (object_missing(index)) return abort_code::kNoObject;
  const auto one = [&](std::uint32_t v, std::uint8_t s) -> std::uint32_t {
    if (sub != 0) return abort_code::kNoSubIndex;
    value = v;
    size = s;
    return 0;
  };
  const auto pdo_comm = [&](const PdoComm& c) -> std::uint32_t {
    switch (sub) {
      case 0:
        value = 2;
        size = 1;
        return 0;
      case 1:
        value = c.cob_id;
        size = 4;
        return 0;
      case 2:
        value = c.type;
        size = 1;
        return 0;
      default:
        return abort_code::kNoSubIndex;
    }
  };
  const auto pdo_map = [&](const PdoMap& m) -> std::uint32_t {
    if (sub == 0) {
      value = m.count;
      size = 1;
      return 0;
    }
    if (sub > 8) return abort_code::kNoSubIndex;
    value = m.entries[sub - 1];
    size = 4;
    return 0;
  };
  if (index >= od::kRpdoComm && index < od::kRpdoComm + 4) return pdo_comm(rpdo_comm_[index - od::kRpdoComm]);
  if (index >= od::kRpdoMap && index < od::kRpdoMap + 4) return pdo_map(rpdo_map_[index - od::kRpdoMap]);
  if (index >= od::kTpdoComm && index < od::kTpdoComm + 4) return pdo_comm(tpdo_comm_[index - od::kTpdoComm]);
  if (index >= od::kTpdoMap && index < od::kTpdoMap + 4) return pdo_map(tpdo_map_[index - od::kTpdoMap]);
  switch (index) {
    case od::kDeviceType:
      return one(kDeviceTypeServo402, 4);
    case od::kErrorRegister:
      return one(error_register_, 1);
    case od::kHeartbeatProducer:
      return one(heartbeat_ms_, 2);
    case 0x1016:
      if (sub == 0) {
        value = 1;
        size = 1;
        return 0;
      }
      if (sub != 1) return abort_code::kNoSubIndex;
      value = consumer_;
      size = 4;
      return 0;
    case od::kErrorCode:
      return one(error_code_, 2);
    case od::kControlword:
      return one(controlword_, 2);
    case od::kStatusword:
      return one(statusword(), 2);
    case od::kModesOfOperation:
    case od::kModesOfOperationDisplay:
      return one(static_cast<std::uint8_t>(mode_), 1);
    case od::kPositionActual:
      return one(static_cast<std::uint32_t>(position_), 4);
    case od::kVelocityActual:
      return one(mapped_value(od::kVelocityActual), 4);
    case od::kTorqueActual:
      return one(0, 2);
    case od::kTargetPosition:
      return one(static_cast<std::uint32_t>(target_), 4);
    case od::kSupportedDriveModes:
      return one(config_.supports_csp ? 0x85U : 0x05U, 4);  // pp, pv [, csp]
    case od::kInterpolationPeriod:
      switch (sub) {
        case 0:
          value = 2;
          size = 1;
          return 0;
        case 1:
          value = ip_value_;
          size = 1;
          return 0;
        case 2:
          value = static_cast<std::uint8_t>(ip_index_);
          size = 1;
          return 0;
        default:
          return abort_code::kNoSubIndex;
      }
    default:
      return abort_code::kNoObject;
  }
}

std::uint32_t SimDriveNode::write_pdo_comm(PdoComm& c, bool rx, std::uint8_t sub, std::uint32_t value) {
  switch (sub) {
    case 0:
      return abort_code::kReadOnly;
    case 1: {
      const bool was_valid = (c.cob_id & kInvalid) == 0;
      const bool valid = (value & kInvalid) == 0;
      if ((value & (1U << 29)) != 0) return abort_code::kValueRange;  // 29-bit ids not supported
      if (was_valid && valid && value != c.cob_id) return abort_code::kValueRange;  // invalidate first
      c.cob_id = value;
      return 0;
    }
    case 2: {
      const bool ok = value <= 240 || value == 254 || value == 255 || (!rx && value >= 252 && value <= 253);
      if (!ok) return abort_code::kValueRange;
      c.type = static_cast<std::uint8_t>(value);
      return 0;
    }
    default:
      return abort_code::kNoSubIndex;
  }
}

std::uint32_t SimDriveNode::write_pdo_map(PdoMap& m, const PdoComm& c, bool rx, std::uint8_t sub,
                                          std::uint32_t value) {
  if (sub > 8) return abort_code::kNoSubIndex;
  if (config_.fixed_mapping) return abort_code::kReadOnly;
  // CiA 301: the mapping may change only while the PDO is invalid, entries only while :00 = 0.
  if ((c.cob_id & kInvalid) == 0) return abort_code::kUnsupportedAccess;
  if (sub == 0) {
    if (value > 8) return abort_code::kValueRange;
    unsigned bits = 0;
    for (std::size_t e = 0; e < value; ++e) {
      if (!mappable(m.entries[e], rx)) return abort_code::kNotMappable;
      bits += m.entries[e] & 0xFF;
    }
    if (bits > 64) return abort_code::kPdoLengthExceeded;
    m.count = static_cast<std::uint8_t>(value);
    return 0;
  }
  if (m.count != 0) return abort_code::kUnsupportedAccess;
  if (!mappable(value, rx)) return abort_code::kNotMappable;
  m.entries[sub - 1] = value;
  return 0;
}

std::uint32_t SimDriveNode::write_object(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                         std::uint8_t size, std::int64_t now_us) {
  if (object_missing(index)) return abort_code::kNoObject;
  if (index >= od::kRpdoComm && index < od::kRpdoComm + 4) {
    if (const std::uint32_t e = check_size(size, sub == 1 ? 4 : 1)) return e;
    return write_pdo_comm(rpdo_comm_[index - od::kRpdoComm], true, sub, value);
  }
  if (index >= od::kTpdoComm && index < od::kTpdoComm + 4) {
    if (const std::uint32_t e = check_size(size, sub == 1 ? 4 : 1)) return e;
    return write_pdo_comm(tpdo_comm_[index - od::kTpdoComm], false, sub, value);
  }
  if (index >= od::kRpdoMap && index < od::kRpdoMap + 4) {
    if (const std::uint32_t e = check_size(size, sub == 0 ? 1 : 4)) return e;
    const std::size_t k = index - od::kRpdoMap;
    return write_pdo_map(rpdo_map_[k], rpdo_comm_[k], true, sub, value);
  }
  if (index >= od::kTpdoMap && index < od::kTpdoMap + 4) {
    if (const std::uint32_t e = check_size(size, sub == 0 ? 1 : 4)) return e;
    const std::size_t k = index - od::kTpdoMap;
    return write_pdo_map(tpdo_map_[k], tpdo_comm_[k], false, sub, value);
  }
  if (index == 0x1016) {
    if (sub == 0) return abort_code::kReadOnly;
    if (sub != 1) return abort_code::kNoSubIndex;
    if (const std::uint32_t e = check_size(size, 4)) return e;
    consumer_ = value;
    master_seen_us_ = -1;
    master_lost_ = false;
    return 0;
  }
  if (index == od::kInterpolationPeriod) {
    if (sub == 0) return abort_code::kReadOnly;
    if (sub > 2) return abort_code::kNoSubIndex;
    if (const std::uint32_t e = check_size(size, 1)) return e;
    if (sub == 1) {
      if (value == 0 || value > 255) return abort_code::kValueRange;
      ip_value_ = static_cast<std::uint8_t>(value);
    } else {
      const auto idx = static_cast<std::int8_t>(value & 0xFF);
      if (idx < -6 || idx > 0) return abort_code::kValueRange;
      ip_index_ = idx;
    }
    return 0;
  }
  switch (index) {
    case od::kDeviceType:
    case od::kErrorRegister:
    case od::kErrorCode:
    case od::kStatusword:
    case od::kModesOfOperationDisplay:
    case od::kPositionActual:
    case od::kVelocityActual:
    case od::kTorqueActual:
    case od::kSupportedDriveModes:
      return sub == 0 ? abort_code::kReadOnly : abort_code::kNoSubIndex;
    default:
      break;
  }
  if (sub != 0) {
    switch (index) {
      case od::kHeartbeatProducer:
      case od::kControlword:
      case od::kModesOfOperation:
      case od::kTargetPosition:
        return abort_code::kNoSubIndex;
      default:
        return abort_code::kNoObject;
    }
  }
  switch (index) {
    case od::kHeartbeatProducer:
      if (const std::uint32_t e = check_size(size, 2)) return e;
      heartbeat_ms_ = static_cast<std::uint16_t>(value);
      next_heartbeat_us_ = now_us + static_cast<std::int64_t>(heartbeat_ms_) * 1000;
      return 0;
    case od::kControlword:
      if (const std::uint32_t e = check_size(size, 2)) return e;
      set_controlword(static_cast<std::uint16_t>(value));
      return 0;
    case od::kModesOfOperation: {
      if (const std::uint32_t e = check_size(size, 1)) return e;
      const auto mode = static_cast<std::int8_t>(value & 0xFF);
      if (mode != 0 && !(mode == od::kModeCsp && config_.supports_csp)) return abort_code::kValueRange;
      mode_ = mode;
      return 0;
    }
    case od::kTargetPosition:
      if (const std::uint32_t e = check_size(size, 4)) return e;
      target_ = static_cast<std::int32_t>(value);
      return 0;
    default:
      return abort_code::kNoObject;
  }
}

}  // namespace loom::sim_can
