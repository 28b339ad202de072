// Simulated CiA 401 I/O module (see sim_io_node.hpp). The object dictionary below is the only
// description of the node: SDO access, mapping checks and PDO packing all read it through slave_od
// (CiA 301 written out on its own, no drivers/ encoders). This file adds the module's wiring, its
// output error behaviour and the plant behind it.
#include "loom/sim_can/sim_io_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace loom::sim_can {

namespace {

using slave::Access;
using slave::map_entry;
using slave::Pdo;
using slave::pdo_comm;
using slave::pdo_map;
namespace cob = slave::cob;
namespace nmt = slave::nmt;

// Device type: profile 401, bits 16..18 = digital inputs, digital outputs, analog inputs.
constexpr std::uint32_t kDeviceType = 0x00070191;

constexpr std::uint16_t kErrorRegister = slave::kErrorRegisterObject;
constexpr std::uint16_t kConsumerHeartbeat = slave::kConsumerHeartbeatObject;
constexpr std::uint16_t kProducerHeartbeat = slave::kProducerHeartbeatObject;
constexpr std::uint16_t kDigitalInputs = 0x6000;
constexpr std::uint16_t kDigitalInputs16 = 0x6100;  // read input 16-bit: terminals 16(k-1)..16k-1 in sub k
constexpr std::uint16_t kDigitalOutputs = 0x6200;
constexpr std::uint16_t kOutputErrorMode = 0x6206;
constexpr std::uint16_t kOutputErrorValue = 0x6207;
constexpr std::uint16_t kAnalogInputs = 0x6401;

// The node's wiring (its own terminal numbering; the master's default wiring matches it by config).
// The six safety sensors in hal::SafetySensor order: piston A extended/retracted, piston B
// extended/retracted, shuttle at left/right; each has two switches at the same place, on terminals
// 0..5 and 16..21.
constexpr std::array<int, hal::kSafetySensorCount> kInSafetyFirst{0, 1, 2, 3, 4, 5};
constexpr std::array<int, hal::kSafetySensorCount> kInSafetySecond{16, 17, 18, 19, 20, 21};
constexpr int kInEstopOk = 6, kInStart = 8, kInPause = 9, kInAck = 10, kInKnotted = 11;
constexpr int kOutValveA = 0, kOutValveB = 1;
// The knotting heads' terminals: head h's gripper and cutter outputs, its yarn-present input.
constexpr int kOutGripperFirst = 8, kOutCutterFirst = 20, kInYarnPresentFirst = 24;
static_assert(kOutCutterFirst + static_cast<int>(hal::kMaxKnottingHeads) <= 32, "four 8-bit output groups");
static_assert(kInYarnPresentFirst + static_cast<int>(hal::kMaxKnottingHeads) <= 64,
              "eight 8-bit input groups");

constexpr slave::Objects<5> kCommunicationObjects = slave::communication_objects(kDeviceType);

// Digital inputs (8-bit groups), outputs, output error mode and value, analog inputs.
// 64 digital inputs (0x6000:01..08): the loom's sensors and buttons on terminals 0..21, the knotting heads'
// yarn-present switches from 24. 32 digital outputs (0x6200:01..04): valves and stack light on 0..7, the
// heads' grippers from 8 and cutters from 20.
// One object per line, so the table reads as the dictionary it is.
// clang-format off
constexpr slave::Objects<29> kIoObjects{{
    {kDigitalInputs, 0, 1, Access::kConst, Pdo::kNone, 8},
    {kDigitalInputs, 1, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 2, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 3, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 4, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 5, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 6, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 7, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalInputs, 8, 1, Access::kRo, Pdo::kTx, 0},
    {kDigitalOutputs, 0, 1, Access::kConst, Pdo::kNone, 4},
    {kDigitalOutputs, 1, 1, Access::kRw, Pdo::kRx, 0},
    {kDigitalOutputs, 2, 1, Access::kRw, Pdo::kRx, 0},
    {kDigitalOutputs, 3, 1, Access::kRw, Pdo::kRx, 0},
    {kDigitalOutputs, 4, 1, Access::kRw, Pdo::kRx, 0},
    {kOutputErrorMode, 0, 1, Access::kConst, Pdo::kNone, 4},
    // CiA 401 default: every output to its error value.
    {kOutputErrorMode, 1, 1, Access::kRw, Pdo::kNone, 0xFF},
    {kOutputErrorMode, 2, 1, Access::kRw, Pdo::kNone, 0xFF},
    {kOutputErrorMode, 3, 1, Access::kRw, Pdo::kNone, 0xFF},
    {kOutputErrorMode, 4, 1, Access::kRw, Pdo::kNone, 0xFF},
    {kOutputErrorValue, 0, 1, Access::kConst, Pdo::kNone, 4},
    {kOutputErrorValue, 1, 1, Access::kRw, Pdo::kNone, 0},
    {kOutputErrorValue, 2, 1, Access::kRw, Pdo::kNone, 0},
    {kOutputErrorValue, 3, 1, Access::kRw, Pdo::kNone, 0},
    {kOutputErrorValue, 4, 1, Access::kRw, Pdo::kNone, 0},
    {kAnalogInputs, 0, 1, Access::kConst, Pdo::kNone, 4},
    {kAnalogInputs, 1, 2, Access::kRo, Pdo::kTx, 0},
    {kAnalogInputs, 2, 2, Access::kRo, Pdo::kTx, 0},
    {kAnalogInputs, 3, 2, Access::kRo, Pdo::kTx, 0},
    {kAnalogInputs, 4, 2, Access::kRo, Pdo::kTx, 0},
}};
// clang-format on

// The object dictionary: every object the module has, once. Pre-defined PDOs of CiA 401: RPDO1 the
// digital outputs (the first group; a master that wires more maps more), TPDO1 the digital inputs on
// change (the three groups the loom's sensors use, terminals 0..23), TPDO2 the analog inputs; RPDO2 and
// TPDO3/4 present but invalid.
// clang-format off
constexpr auto kTable = slave::concat(
    kCommunicationObjects,
    pdo_comm(0x1400, cob::kRpdo1, 255),
    pdo_comm(0x1401, cob::kRpdo2 | cob::kPdoInvalid, 255),
    pdo_map(0x1600, {map_entry(kDigitalOutputs, 1, 8)}),
    pdo_map(0x1601),
    pdo_comm(0x1800, cob::kTpdo1, 255),
    pdo_comm(0x1801, cob::kTpdo2, 255),
    pdo_comm(0x1802, cob::kTpdo3 | cob::kPdoInvalid, 255),
    pdo_comm(0x1803, cob::kTpdo4 | cob::kPdoInvalid, 255),
    pdo_map(0x1A00, {map_entry(kDigitalInputs, 1, 8), map_entry(kDigitalInputs, 2, 8),
                     map_entry(kDigitalInputs, 3, 8)}),
    pdo_map(0x1A01, {map_entry(kAnalogInputs, 1, 16)}),
    pdo_map(0x1A02),
    pdo_map(0x1A03),
    kIoObjects);
// clang-format on
static_assert(slave::sorted(kTable), "the dictionary is binary-searched: list objects by index, sub");

}  // namespace

SimIoNode::SimIoNode(drivers::CanBus& bus, SimIoConfig config)
    : bus_(bus),
      config_(std::move(config)),
      od_(config_.dictionary.empty() ? std::span<const slave::Entry>(kTable)
                                     : std::span<const slave::Entry>(config_.dictionary),
          slave::OdOptions{config_.absent_objects, config_.fixed_mapping}) {
  // A module with fewer than the table's three mapped input groups pre-defines TPDO1 with the ones it
  // has (resolved here, so resets allocate nothing). A described module's mapping is its description's.
  if (config_.dictionary.empty() && config_.tpdo1_factory_mapping.empty() && input_groups() < 3) {
    for (int k = 1; k <= input_groups(); ++k) {
      config_.tpdo1_factory_mapping.push_back(map_entry(kDigitalInputs, static_cast<std::uint8_t>(k), 8));
    }
  }
  reset_application();
  if (config_.knotting.heads > 0) {
    sim_hal::Knotter k;
    k.miss_probability = 0.0;
    k.weaver_s = config_.weaver_s;
    knotter_ = std::make_unique<sim_hal::SimKnotter>(config_.knotting, k, kKnotterPeriodS);
  }
}

SimIoNode::~SimIoNode() = default;

// ---------------------------------------------------------------------------------------------------
// Resets and power
// ---------------------------------------------------------------------------------------------------
void SimIoNode::reset_communication(std::int64_t now_us) {
  od_.reset_communication(config_.node_id);
  set_factory_mapping(0, config_.tpdo1_factory_mapping);
  set_factory_mapping(1, config_.tpdo2_factory_mapping);
  nmt_ = nmt::kPreOperational;
  syncs_ = 0;
  rpdos_.clear();
  master_seen_us_ = -1;
  comm_lost_ = false;
  boot_at_us_ = now_us + config_.boot_delay_us;
}

int SimIoNode::input_groups() const {
  return std::clamp(config_.digital_input_groups, 1, static_cast<int>(kInputGroups));
}

// A personality's own factory mapping of TPDO `tpdo` (empty: the table's default stays).
void SimIoNode::set_factory_mapping(int tpdo, const std::vector<std::uint32_t>& entries) {
  if (entries.empty()) return;
  const auto map = static_cast<std::uint16_t>(slave::kTpdoMap + tpdo);
  const std::size_t n = std::min<std::size_t>(slave::kMapEntries, entries.size());
  for (std::size_t e = 0; e < slave::kMapEntries; ++e) {
    od_.set(map, static_cast<std::uint8_t>(e + 1), e < n ? entries[e] : 0);
  }
  od_.set(map, 0, static_cast<std::uint32_t>(n));
}

void SimIoNode::reset_application() {
  od_.reset_application();
  if (config_.dictionary.empty()) od_.set(kDigitalInputs, 0, static_cast<std::uint32_t>(input_groups()));
}

void SimIoNode::power_on(std::int64_t now_us) {
  powered_ = true;
  reset_application();
  reset_communication(now_us);
  next_hb_us_ = now_us;
}

void SimIoNode::power_off() {
  powered_ = false;
}

void SimIoNode::send(const drivers::CanFrame& f) {
  if (!powered_ || plant_.silent || boot_at_us_ >= 0) return;
  bus_.send(f);
}

std::uint8_t SimIoNode::outputs(int byte) const {
  const auto b = static_cast<std::uint8_t>(byte + 1);
  const auto normal = static_cast<std::uint8_t>(od_.get(kDigitalOutputs, b));
  // Communication lost or NMT stopped: outputs selected in 0x6206 take their 0x6207 value. A module
  // without 0x6206 has no error mode: its outputs hold.
  if ((!comm_lost_ && nmt_ != nmt::kStopped) || !od_.exists(kOutputErrorMode)) return normal;
  const auto mode = static_cast<std::uint8_t>(od_.get(kOutputErrorMode, b));
  const auto err =
      od_.exists(kOutputErrorValue) ? static_cast<std::uint8_t>(od_.get(kOutputErrorValue, b)) : 0;
  return static_cast<std::uint8_t>((normal & ~mode) | (err & mode));
}

// ---------------------------------------------------------------------------------------------------
// Frames in
// ---------------------------------------------------------------------------------------------------
void SimIoNode::handle(const drivers::CanFrame& f, std::int64_t now_us) {
  if (!powered_ || plant_.silent || boot_at_us_ >= 0) return;
  slave::deliver(od_, config_.node_id, nmt_, f, now_us, *this);
}

// The master's heartbeat, watched through 0x1016:01.
void SimIoNode::on_watched_heartbeat(std::int64_t now_us) {
  master_seen_us_ = now_us;
}

void SimIoNode::on_nmt(std::uint8_t command, std::int64_t now_us) {
  switch (command) {
    case nmt::kStart:
      nmt_ = nmt::kOperational;
      comm_lost_ = false;
      break;
    case nmt::kStop:
      nmt_ = nmt::kStopped;
      break;
    case nmt::kEnterPreOperational:
      nmt_ = nmt::kPreOperational;
      break;
    case nmt::kResetNode:
      reset_application();
      reset_communication(now_us);
      break;
    case nmt::kResetCommunication:
      reset_communication(now_us);
      break;
    default:
      break;
  }
}

void SimIoNode::on_sdo(const drivers::CanFrame& f, std::int64_t now_us) {
  if (const auto reply = slave::sdo_serve(od_, *this, config_.node_id, f, now_us)) send(*reply);
}

void SimIoNode::on_rpdo(int pdo, const drivers::CanFrame& f, std::int64_t now_us) {
  if (!rpdos_.receive(od_, *this, pdo, f, now_us)) {
    send(slave::emcy(config_.node_id, slave::emcy_code::kPdoLength, slave::kErrorRegisterGeneric));
  }
}

void SimIoNode::send_tpdo(int pdo) {
  std::array<std::uint8_t, 8> data{};
  const std::uint8_t dlc = od_.pack_tpdo(pdo, data);
  send(slave::pdo_frame(od_.pdo_can_id(static_cast<std::uint16_t>(slave::kTpdoComm + pdo)), dlc, data));
}

void SimIoNode::on_sync(std::int64_t now_us) {
  ++syncs_;
  ++syncs_total_;
  rpdos_.apply_at_sync(od_, *this, now_us);
  update_inputs();
  slave::send_due_tpdos(od_, syncs_, [this](const drivers::CanFrame& f) { send(f); });
}

// Event-driven input TPDOs (types 254/255) go out when an input changed.
void SimIoNode::send_changed_inputs() {
  for (int k = 0; k < slave::kPdos; ++k) {
    const auto comm = static_cast<std::uint16_t>(slave::kTpdoComm + k);
    if (od_.pdo_valid(comm) && od_.pdo_type(comm) >= 254) send_tpdo(k);
  }
}

// A group the module lacks cannot be mapped (the dictionary table is shared by every personality, so
// the rule is here rather than in it).
std::uint32_t SimIoNode::check(std::uint16_t index, std::uint8_t sub, std::uint32_t value) const {
  const bool map_entry_write = index >= slave::kTpdoMap && index < slave::kTpdoMap + slave::kPdos && sub >= 1;
  const auto group = static_cast<int>((value >> 8) & 0xFF);
  const bool missing_group = (value >> 16) == kDigitalInputs && group > input_groups();
  return map_entry_write && missing_group ? slave::abort_code::kNotMappable : 0;
}

void SimIoNode::written(std::uint16_t index, std::uint8_t, std::uint32_t value, std::int64_t now_us) {
  if (index == kProducerHeartbeat) {
    next_hb_us_ = now_us + static_cast<std::int64_t>(value) * 1000;
  } else if (index == kConsumerHeartbeat) {  // a new consumer time starts with the next heartbeat seen
    master_seen_us_ = -1;
    comm_lost_ = false;
  }
}

// ---------------------------------------------------------------------------------------------------
// Plant and timers
// ---------------------------------------------------------------------------------------------------
// What the six safety sensors should see (hal::SafetySensor order): end positions of the pistons, the
// shuttle within its window of either selvedge.
std::array<bool, hal::kSafetySensorCount> SimIoNode::safety_sensors_truth() const {
  const double x = plant_.helix_rad * config_.helix_lead_m / (2.0 * 3.14159265358979323846);
  return {piston_[0] >= 1.0,
          piston_[0] <= 0.0,
          piston_[1] >= 1.0,
          piston_[1] <= 0.0,
          x <= config_.selvedge_window_m,
          x >= config_.width_m - config_.selvedge_window_m};
}

void SimIoNode::update_inputs() {
  std::array<std::uint8_t, kInputGroups> in{};
  const auto set = [&](int bit, bool on) {
    if (on) in[static_cast<std::size_t>(bit / 8)] |= static_cast<std::uint8_t>(1U << (bit % 8));
  };
  // Both switches of a sensor follow the same truth; only the stuck one (test hook) departs from it.
  const std::array<bool, hal::kSafetySensorCount> truth = safety_sensors_truth();
  const StuckSwitch& stuck = plant_.stuck;
  for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
    const bool here = stuck.active && static_cast<std::size_t>(stuck.sensor) == i;
    set(kInSafetyFirst[i], here && !stuck.second ? stuck.level : truth[i]);
    set(kInSafetySecond[i], here && stuck.second ? stuck.level : truth[i]);
  }
  set(kInEstopOk, !plant_.estop_open);
  set(kInStart, plant_.button_start);
  set(kInPause, plant_.button_pause);
  set(kInAck, plant_.button_ack);
  set(kInKnotted, plant_.row_knotted);
  if (knotter_) {
    hal::DigitalInputs seen;
    knotter_->inputs(plant_.axis_position, seen);
    for (int h = 0; h < config_.knotting.heads; ++h) {
      set(kInYarnPresentFirst + h, seen.yarn_present[static_cast<std::size_t>(h)]);
    }
  }
  for (std::size_t k = static_cast<std::size_t>(input_groups()); k < in.size(); ++k)
    in[k] = 0;  // no terminals
  in_ = in;
  // The same terminals in both of CiA 401's forms (a module has one or both; set() ignores the other).
  for (std::size_t k = 0; k < in.size(); ++k)
    od_.set(kDigitalInputs, static_cast<std::uint8_t>(k + 1), in[k]);
  for (std::size_t k = 0; k < in.size() / 2; ++k) {
    od_.set(kDigitalInputs16, static_cast<std::uint8_t>(k + 1),
            static_cast<std::uint32_t>(in[2 * k]) | static_cast<std::uint32_t>(in[2 * k + 1]) << 8);
  }
  // Load cell: a narrow pulse around the crank angle at which the beater meets the fell.
  const double two_pi = 2.0 * 3.14159265358979323846;
  double d = std::fmod(plant_.crank_rad - config_.fell_crank_rad, two_pi);
  if (d > two_pi / 2) d -= two_pi;
  if (d < -two_pi / 2) d += two_pi;
  const double c = std::cos(d);
  const double force = c > 0.0 ? config_.beat_peak_n * std::pow(c, 32.0) : 0.0;
  const double counts = std::clamp(std::round(force / config_.load_cell_n_per_count), -32768.0, 32767.0);
  analog_ = static_cast<std::int16_t>(counts);
  od_.set(kAnalogInputs, 1, static_cast<std::uint16_t>(analog_));
}

void SimIoNode::step(std::int64_t now_us, const IoPlant& plant) {
  plant_ = plant;
  double dt = last_step_us_ < 0 ? 0.0 : static_cast<double>(now_us - last_step_us_) * 1e-6;
  last_step_us_ = now_us;
  if (config_.plant_cycle_s > 0.0) {  // machine time = SYNCs seen × the controller's cycle
    dt = static_cast<double>(syncs_total_ - syncs_at_last_step_) * config_.plant_cycle_s;
    syncs_at_last_step_ = syncs_total_;
  }
  if (!powered_) return;
  move_pistons(dt);
  if (knotter_) step_knotter();
  const std::int64_t hb_us = static_cast<std::int64_t>(od_.get(kProducerHeartbeat, 0)) * 1000;
  if (plant_.silent) {
    // A silenced node (HIL: the I/O node dies) sends nothing, but its heartbeat timer runs on: a deadline
    // left in the past made the rack's loop spin at real-time priority and starve the master under test.
    if (hb_us > 0 && now_us >= next_hb_us_) next_hb_us_ = now_us + hb_us;
    return;
  }
  if (boot_at_us_ >= 0 && now_us >= boot_at_us_) {
    boot_at_us_ = -1;  // first, or send() would still hold the boot-up back
    send(slave::heartbeat(config_.node_id, nmt::kBootUp));
    next_hb_us_ = now_us + hb_us;
  }
  if (boot_at_us_ >= 0) return;
  const std::array<std::uint8_t, kInputGroups> before = in_;
  update_inputs();
  if (nmt_ == nmt::kOperational && in_ != before) send_changed_inputs();
  produce_heartbeat(now_us);
  watch_master(now_us);
}

// Pistons follow their valve coils (as the outputs really are, error state included).
void SimIoNode::move_pistons(double dt) {
  const std::uint8_t out = outputs(0);
  const bool valve[2] = {((out >> kOutValveA) & 1U) != 0, ((out >> kOutValveB) & 1U) != 0};
  for (std::size_t i = 0; i < 2; ++i) {
    const double step = dt / config_.piston_travel_s;
    piston_[i] = std::clamp(piston_[i] + (valve[i] ? step : -step), 0.0, 1.0);
  }
}

// The heads act on their outputs as they really are (error state included): a gripper closing at TAKE
// takes yarn, a cutter firing with the gripper in the warp ties the knot under the head. A weft (the
// shuttle arriving at the other selvedge) locks the row of knots in.
void SimIoNode::step_knotter() {
  hal::DigitalOutputs out;
  const auto bit = [this](int terminal) { return ((outputs(terminal / 8) >> (terminal % 8)) & 1U) != 0; };
  for (int h = 0; h < config_.knotting.heads; ++h) {
    out.gripper_close[static_cast<std::size_t>(h)] = bit(kOutGripperFirst + h);
    out.cutter[static_cast<std::size_t>(h)] = bit(kOutCutterFirst + h);
  }
  knotter_->on_outputs(out, plant_.axis_position, rng_);
  const std::array<bool, hal::kSafetySensorCount> truth = safety_sensors_truth();
  const int side = truth[static_cast<std::size_t>(hal::SafetySensor::kShuttleAtLeft)]    ? -1
                   : truth[static_cast<std::size_t>(hal::SafetySensor::kShuttleAtRight)] ? 1
                                                                                         : 0;
  if (side != 0 && shuttle_side_ != 0 && side != shuttle_side_) knotter_->on_weft();
  if (side != 0) shuttle_side_ = side;
}

void SimIoNode::produce_heartbeat(std::int64_t now_us) {
  const std::int64_t period_us = static_cast<std::int64_t>(od_.get(kProducerHeartbeat, 0)) * 1000;
  if (period_us == 0 || now_us < next_hb_us_) return;
  send(slave::heartbeat(config_.node_id, nmt_));
  next_hb_us_ += period_us;
  if (next_hb_us_ <= now_us) next_hb_us_ = now_us + period_us;
}

// Master heartbeat consumer: silence longer than its time → outputs to their error values, EMCY 0x8130.
void SimIoNode::watch_master(std::int64_t now_us) {
  const std::uint32_t consumer = od_.get(kConsumerHeartbeat, 1);
  const std::int64_t window_us = static_cast<std::int64_t>(consumer & 0xFFFF) * 1000;
  if (window_us <= 0 || master_seen_us_ < 0 || comm_lost_ || now_us - master_seen_us_ <= window_us) return;
  comm_lost_ = true;
  const auto reg = static_cast<std::uint8_t>(od_.get(kErrorRegister, 0) | slave::kErrorRegisterGeneric |
                                             slave::kErrorRegisterCommunication);
  od_.set(kErrorRegister, 0, reg);
  send(slave::emcy(config_.node_id, slave::emcy_code::kHeartbeatLost, reg));
}

std::int64_t SimIoNode::next_deadline_us() const {
  if (!powered_) return std::numeric_limits<std::int64_t>::max();
  std::int64_t t = std::numeric_limits<std::int64_t>::max();
  // Silent: only the plant keeps time (nothing is sent, so no boot-up or heartbeat deadline applies).
  if (plant_.silent) return last_step_us_ + 10'000;
  if (boot_at_us_ >= 0) t = boot_at_us_;
  if (od_.get(kProducerHeartbeat, 0) != 0) t = std::min(t, next_hb_us_);
  // The plant moves continuously: step at least every 10 ms.
  return std::min(t, last_step_us_ + 10'000);
}

}  // namespace loom::sim_can
