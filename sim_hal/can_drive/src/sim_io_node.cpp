// Simulated CiA 401 I/O module (see sim_io_node.hpp). The object dictionary below is the only
// description of the node: SDO access, mapping checks and PDO packing all read it. Frame layouts are
// written out from CiA 301 here on purpose (no drivers/ encoders).
#include "loom/sim_can/sim_io_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace loom::sim_can {

namespace {

using Access = SimIoNode::Access;
using Entry = SimIoNode::Entry;

// CiA 301 identifiers, written out here (not taken from the master's cob_id.hpp).
constexpr std::uint32_t kNmtId = 0x000, kSyncId = 0x080, kEmcyBase = 0x080, kSdoTx = 0x580, kSdoRx = 0x600,
                        kErrCtl = 0x700;
constexpr std::uint32_t kInvalidBit = 0x80000000U;

// SDO abort codes (CiA 301 table 22), written out here.
constexpr std::uint32_t kAbortCommand = 0x05040001, kAbortUnsupported = 0x06010000, kAbortReadOnly = 0x06010002,
                        kAbortNoObject = 0x06020000, kAbortNotMappable = 0x06040041, kAbortPdoLength = 0x06040042,
                        kAbortLengthHigh = 0x06070012, kAbortLengthLow = 0x06070013, kAbortNoSub = 0x06090011,
                        kAbortRange = 0x06090030;

// Device type: profile 401, bits 16..18 = digital inputs, digital outputs, analog inputs.
constexpr std::uint32_t kDeviceType = 0x00070191;

// The node's wiring (its own terminal numbering; the master's default wiring matches it by config).
constexpr int kInPistonAExt = 0, kInPistonARet = 1, kInPistonBExt = 2, kInPistonBRet = 3, kInShuttleLeft = 4,
              kInShuttleRight = 5, kInEstopOk = 6, kInStart = 8, kInPause = 9, kInAck = 10, kInKnotted = 11;
constexpr int kOutValveA = 0, kOutValveB = 1;

#define LOOM_MAP_OBJ(idx, n, e1, e2)                                                              \
  {idx, 0, 1, Access::kRw, 0, n}, {idx, 1, 4, Access::kRw, 0, e1}, {idx, 2, 4, Access::kRw, 0, e2},   \
      {idx, 3, 4, Access::kRw, 0, 0}, {idx, 4, 4, Access::kRw, 0, 0}, {idx, 5, 4, Access::kRw, 0, 0}, \
      {idx, 6, 4, Access::kRw, 0, 0}, {idx, 7, 4, Access::kRw, 0, 0}, {idx, 8, 4, Access::kRw, 0, 0}
// COB-ID defaults carry the function code only; the node id is added at reset (kAddNodeId flag).
#define LOOM_COMM_OBJ(idx, cob, type)                                                             \
  {idx, 0, 1, Access::kConst, 0, 2}, {idx, 1, 4, Access::kRw, 0, cob}, {idx, 2, 1, Access::kRw, 0, type}

// The object dictionary: every object the module has, once.
constexpr Entry kTable[] = {
    {0x1000, 0, 4, Access::kConst, 0, kDeviceType},
    {0x1001, 0, 1, Access::kRo, 0, 0},
    {0x1016, 0, 1, Access::kConst, 0, 1},
    {0x1016, 1, 4, Access::kRw, 0, 0},  // consumer: master node << 16 | ms
    {0x1017, 0, 2, Access::kRw, 0, 0},  // heartbeat producer, ms
    // RPDO1: digital outputs (pre-defined); RPDO2 present but invalid.
    LOOM_COMM_OBJ(0x1400, 0x200, 255),
    LOOM_COMM_OBJ(0x1401, 0x300 | kInvalidBit, 255),
    LOOM_MAP_OBJ(0x1600, 1, 0x62000108, 0),
    LOOM_MAP_OBJ(0x1601, 0, 0, 0),
    // TPDO1: digital inputs on change; TPDO2: analog inputs; TPDO3/4 present, invalid.
    LOOM_COMM_OBJ(0x1800, 0x180, 255),
    LOOM_COMM_OBJ(0x1801, 0x280, 255),
    LOOM_COMM_OBJ(0x1802, 0x380 | kInvalidBit, 255),
    LOOM_COMM_OBJ(0x1803, 0x480 | kInvalidBit, 255),
    LOOM_MAP_OBJ(0x1A00, 2, 0x60000108, 0x60000208),
    LOOM_MAP_OBJ(0x1A01, 1, 0x64010110, 0),
    LOOM_MAP_OBJ(0x1A02, 0, 0, 0),
    LOOM_MAP_OBJ(0x1A03, 0, 0, 0),
    // Digital inputs (8-bit groups), outputs, output error mode and value, analog inputs.
    {0x6000, 0, 1, Access::kConst, 0, 2},
    {0x6000, 1, 1, Access::kRo, 'T', 0},
    {0x6000, 2, 1, Access::kRo, 'T', 0},
    {0x6200, 0, 1, Access::kConst, 0, 2},
    {0x6200, 1, 1, Access::kRw, 'R', 0},
    {0x6200, 2, 1, Access::kRw, 'R', 0},
    {0x6206, 0, 1, Access::kConst, 0, 2},
    {0x6206, 1, 1, Access::kRw, 0, 0xFF},  // CiA 401 default: every output to its error value
    {0x6206, 2, 1, Access::kRw, 0, 0xFF},
    {0x6207, 0, 1, Access::kConst, 0, 2},
    {0x6207, 1, 1, Access::kRw, 0, 0},
    {0x6207, 2, 1, Access::kRw, 0, 0},
    {0x6401, 0, 1, Access::kConst, 0, 4},
    {0x6401, 1, 2, Access::kRo, 'T', 0},
    {0x6401, 2, 2, Access::kRo, 'T', 0},
    {0x6401, 3, 2, Access::kRo, 'T', 0},
    {0x6401, 4, 2, Access::kRo, 'T', 0},
};
constexpr std::size_t kEntries = sizeof(kTable) / sizeof(kTable[0]);

#undef LOOM_MAP_OBJ
#undef LOOM_COMM_OBJ

bool is_comm(std::uint16_t i) {
  return (i >= 0x1400 && i <= 0x1403) || (i >= 0x1800 && i <= 0x1803);
}
bool is_map(std::uint16_t i) {
  return (i >= 0x1600 && i <= 0x1603) || (i >= 0x1A00 && i <= 0x1A03);
}

}  // namespace

SimIoNode::SimIoNode(drivers::CanBus& bus, SimIoConfig config)
    : bus_(bus), config_(std::move(config)), values_(kEntries, 0) {
  reset_application();
}

int SimIoNode::find(std::uint16_t index, std::uint8_t sub) const {
  if (!object_exists(index)) return -1;
  for (std::size_t k = 0; k < kEntries; ++k) {
    if (kTable[k].index == index && kTable[k].sub == sub) return static_cast<int>(k);
  }
  return -1;
}

bool SimIoNode::object_exists(std::uint16_t index) const {
  if (std::find(config_.absent_objects.begin(), config_.absent_objects.end(), index) != config_.absent_objects.end()) {
    return false;
  }
  for (const Entry& e : kTable) {
    if (e.index == index) return true;
  }
  return false;
}

std::uint32_t& SimIoNode::value(std::uint16_t index, std::uint8_t sub) {
  static std::uint32_t scratch = 0;
  const int k = find(index, sub);
  if (k < 0) {
    scratch = 0;
    return scratch;
  }
  return values_[static_cast<std::size_t>(k)];
}

std::uint32_t SimIoNode::get(std::uint16_t index, std::uint8_t sub) const {
  const int k = find(index, sub);
  return k < 0 ? 0 : values_[static_cast<std::size_t>(k)];
}

// ---------------------------------------------------------------------------------------------------
// Resets and power
// ---------------------------------------------------------------------------------------------------
void SimIoNode::reset_communication(std::int64_t now_us) {
  for (std::size_t k = 0; k < kEntries; ++k) {
    if (kTable[k].index < 0x2000) {
      std::uint32_t v = kTable[k].default_value;
      if (is_comm(kTable[k].index) && kTable[k].sub == 1) v += config_.node_id;
      values_[k] = v;
    }
  }
  nmt_ = 0x7F;
  syncs_ = 0;
  rpdo_pending_.fill(false);
  master_seen_us_ = -1;
  comm_lost_ = false;
  boot_at_us_ = now_us + config_.boot_delay_us;
}

void SimIoNode::reset_application() {
  for (std::size_t k = 0; k < kEntries; ++k) {
    if (kTable[k].index >= 0x2000) values_[k] = kTable[k].default_value;
  }
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

void SimIoNode::send(std::uint32_t id, std::uint8_t dlc, const std::array<std::uint8_t, 8>& data) {
  if (!powered_ || plant_.silent || boot_at_us_ >= 0) return;
  drivers::CanFrame f;
  f.id = id;
  f.dlc = dlc;
  f.data = data;
  bus_.send(f);
}

std::uint8_t SimIoNode::outputs(int byte) const {
  const auto b = static_cast<std::uint8_t>(byte + 1);
  const auto normal = static_cast<std::uint8_t>(get(0x6200, b));
  // Communication lost or NMT stopped: outputs selected in 0x6206 take their 0x6207 value.
  if (!comm_lost_ && nmt_ != 0x04) return normal;
  const auto mode = static_cast<std::uint8_t>(get(0x6206, b));
  const auto err = static_cast<std::uint8_t>(get(0x6207, b));
  return static_cast<std::uint8_t>((normal & ~mode) | (err & mode));
}

// ---------------------------------------------------------------------------------------------------
// Frames in
// ---------------------------------------------------------------------------------------------------
void SimIoNode::handle(const drivers::CanFrame& f, std::int64_t now_us) {
  if (!powered_ || plant_.silent || f.is_error() || f.is_rtr() || boot_at_us_ >= 0) return;
  const std::uint8_t id = config_.node_id;
  if (f.id == kNmtId && f.dlc == 2 && (f.data[1] == 0 || f.data[1] == id)) {
    switch (f.data[0]) {
      case 0x01: nmt_ = 0x05; comm_lost_ = false; break;
      case 0x02: nmt_ = 0x04; break;
      case 0x80: nmt_ = 0x7F; break;
      case 0x81: reset_application(); reset_communication(now_us); break;
      case 0x82: reset_communication(now_us); break;
      default: break;
    }
    return;
  }
  // The master's heartbeat, watched through 0x1016:01.
  const std::uint32_t consumer = get(0x1016, 1);
  if (consumer != 0 && f.id == kErrCtl + ((consumer >> 16) & 0x7F) && f.dlc >= 1) {
    master_seen_us_ = now_us;
    return;
  }
  if (f.id == kSdoRx + id) {
    if (nmt_ != 0x04) on_sdo(f, now_us);
    return;
  }
  if (nmt_ != 0x05) return;
  if (f.id == kSyncId && f.dlc <= 1) {
    on_sync();
    return;
  }
  for (int k = 0; k < 4; ++k) {
    const auto comm = static_cast<std::uint16_t>(0x1400 + k);
    if (!object_exists(comm)) continue;
    const std::uint32_t cob = get(comm, 1);
    if ((cob & kInvalidBit) != 0 || f.id != (cob & 0x7FF)) continue;
    const std::uint32_t type = get(comm, 2);
    if (type <= 240) {
      rpdo_data_[static_cast<std::size_t>(k)] = f.data;
      rpdo_dlc_[static_cast<std::size_t>(k)] = f.dlc;
      rpdo_pending_[static_cast<std::size_t>(k)] = true;
    } else {
      apply_rpdo(k, f.data, f.dlc);
    }
    return;
  }
}

void SimIoNode::apply_rpdo(int pdo, const std::array<std::uint8_t, 8>& data, std::uint8_t dlc) {
  const auto map = static_cast<std::uint16_t>(0x1600 + pdo);
  const std::uint32_t n = get(map, 0);
  std::uint32_t bits = 0;
  for (std::uint8_t e = 1; e <= n; ++e) bits += get(map, e) & 0xFF;
  if (dlc * 8U < bits) {
    send(kEmcyBase + config_.node_id, 8, {0x10, 0x82, 0x01, 0, 0, 0, 0, 0});  // 0x8210 PDO length
    return;
  }
  std::size_t offset = 0;
  for (std::uint8_t e = 1; e <= n; ++e) {
    const std::uint32_t m = get(map, e);
    const auto bytes = static_cast<std::size_t>((m & 0xFF) / 8);
    std::uint32_t v = 0;
    for (std::size_t b = 0; b < bytes; ++b) v |= static_cast<std::uint32_t>(data[offset + b]) << (8 * b);
    offset += bytes;
    const int k = find(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>((m >> 8) & 0xFF));
    if (k >= 0 && kTable[k].pdo == 'R') values_[static_cast<std::size_t>(k)] = v;
  }
}

void SimIoNode::send_tpdo(int pdo) {
  const auto comm = static_cast<std::uint16_t>(0x1800 + pdo);
  const auto map = static_cast<std::uint16_t>(0x1A00 + pdo);
  std::array<std::uint8_t, 8> d{};
  std::size_t offset = 0;
  const std::uint32_t n = get(map, 0);
  for (std::uint8_t e = 1; e <= n; ++e) {
    const std::uint32_t m = get(map, e);
    const std::uint32_t v = get(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>((m >> 8) & 0xFF));
    for (std::size_t b = 0; b < (m & 0xFF) / 8 && offset < 8; ++b) d[offset++] = static_cast<std::uint8_t>(v >> (8 * b));
  }
  send(get(comm, 1) & 0x7FF, static_cast<std::uint8_t>(offset), d);
}

void SimIoNode::on_sync() {
  ++syncs_;
  ++syncs_total_;
  for (int k = 0; k < 4; ++k) {
    if (rpdo_pending_[static_cast<std::size_t>(k)]) {
      rpdo_pending_[static_cast<std::size_t>(k)] = false;
      apply_rpdo(k, rpdo_data_[static_cast<std::size_t>(k)], rpdo_dlc_[static_cast<std::size_t>(k)]);
    }
  }
  update_inputs();
  for (int k = 0; k < 4; ++k) {
    const auto comm = static_cast<std::uint16_t>(0x1800 + k);
    if (!object_exists(comm) || (get(comm, 1) & kInvalidBit) != 0) continue;
    const std::uint32_t type = get(comm, 2);
    if (type >= 1 && type <= 240 && syncs_ % type == 0) send_tpdo(k);
  }
}

void SimIoNode::on_sdo(const drivers::CanFrame& f, std::int64_t now_us) {
  const std::uint32_t reply = kSdoTx + config_.node_id;
  const auto index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
  const std::uint8_t sub = f.data[3];
  std::array<std::uint8_t, 8> d{0, f.data[1], f.data[2], sub, 0, 0, 0, 0};
  const auto put32 = [&](std::uint32_t v) {
    for (int b = 0; b < 4; ++b) d[static_cast<std::size_t>(4 + b)] = static_cast<std::uint8_t>(v >> (8 * b));
  };
  const auto abort = [&](std::uint32_t code) {
    d[0] = 0x80;
    put32(code);
    send(reply, 8, d);
  };
  if (f.dlc != 8) return;
  const std::uint8_t cs = f.data[0];
  if (cs == 0x40) {  // upload
    std::uint32_t v = 0;
    int size = 0;
    if (const std::uint32_t e = sdo_read(index, sub, v, size)) return abort(e);
    d[0] = static_cast<std::uint8_t>(0x43 | ((4 - size) << 2));
    put32(v);
    send(reply, 8, d);
    return;
  }
  if ((cs & 0xE0) == 0x20 && (cs & 0x02) != 0) {  // expedited download
    const int size = (cs & 0x01) != 0 ? 4 - ((cs >> 2) & 0x03) : 0;
    std::uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= static_cast<std::uint32_t>(f.data[static_cast<std::size_t>(4 + b)]) << (8 * b);
    if (size != 0 && size < 4) v &= (1U << (8 * size)) - 1U;
    if (const std::uint32_t e = sdo_write(index, sub, v, size, now_us)) return abort(e);
    d[0] = 0x60;
    send(reply, 8, d);
    return;
  }
  if (cs == 0x80) return;  // client abort
  abort(kAbortCommand);
}

std::uint32_t SimIoNode::sdo_read(std::uint16_t index, std::uint8_t sub, std::uint32_t& v, int& size) const {
  if (!object_exists(index)) return kAbortNoObject;
  const int k = find(index, sub);
  if (k < 0) return kAbortNoSub;
  v = values_[static_cast<std::size_t>(k)];
  size = kTable[k].bytes;
  return 0;
}

std::uint32_t SimIoNode::sdo_write(std::uint16_t index, std::uint8_t sub, std::uint32_t v, int size,
                                   std::int64_t now_us) {
  if (!object_exists(index)) return kAbortNoObject;
  const int k = find(index, sub);
  if (k < 0) return kAbortNoSub;
  const Entry& e = kTable[k];
  if (e.access != Access::kRw) return kAbortReadOnly;
  if (size != 0 && size != e.bytes) return size > e.bytes ? kAbortLengthHigh : kAbortLengthLow;

  if (is_map(index)) {
    if (config_.fixed_mapping) return kAbortReadOnly;
    const bool rx = index < 0x1A00;
    const auto comm = static_cast<std::uint16_t>((rx ? 0x1400 : 0x1800) + (index & 0x3));
    // CiA 301: a mapping changes only while its PDO is invalid, entries only while :00 = 0.
    if ((get(comm, 1) & kInvalidBit) == 0) return kAbortUnsupported;
    if (sub == 0) {
      if (v > 8) return kAbortRange;
      std::uint32_t bits = 0;
      for (std::uint8_t n = 1; n <= v; ++n) {
        const std::uint32_t m = get(index, n);
        const int t = find(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>((m >> 8) & 0xFF));
        if (t < 0 || kTable[t].pdo != (rx ? 'R' : 'T') || kTable[t].bytes * 8U != (m & 0xFF)) return kAbortNotMappable;
        bits += m & 0xFF;
      }
      if (bits > 64) return kAbortPdoLength;
    } else {
      if (get(index, 0) != 0) return kAbortUnsupported;
      const int t = find(static_cast<std::uint16_t>(v >> 16), static_cast<std::uint8_t>((v >> 8) & 0xFF));
      if (t < 0 || kTable[t].pdo != (rx ? 'R' : 'T') || kTable[t].bytes * 8U != (v & 0xFF)) return kAbortNotMappable;
    }
  } else if (is_comm(index)) {
    const bool rx = index < 0x1800;
    if (sub == 1) {
      const std::uint32_t cur = get(index, 1);
      if ((v & (1U << 29)) != 0) return kAbortRange;
      if ((cur & kInvalidBit) == 0 && (v & kInvalidBit) == 0 && v != cur) return kAbortRange;
    } else if (sub == 2) {
      const bool ok = v <= 240 || v == 254 || v == 255 || (!rx && (v == 252 || v == 253));
      if (!ok) return kAbortRange;
    }
  } else if (index == 0x1017) {
    next_hb_us_ = now_us + static_cast<std::int64_t>(v) * 1000;
  } else if (index == 0x1016) {
    master_seen_us_ = -1;
    comm_lost_ = false;
  }
  values_[static_cast<std::size_t>(k)] = v;
  return 0;
}

// ---------------------------------------------------------------------------------------------------
// Plant and timers
// ---------------------------------------------------------------------------------------------------
void SimIoNode::update_inputs() {
  std::array<std::uint8_t, 2> in{};
  const auto set = [&](int bit, bool on) {
    if (on) in[static_cast<std::size_t>(bit / 8)] |= static_cast<std::uint8_t>(1U << (bit % 8));
  };
  set(kInPistonAExt, piston_[0] >= 1.0);
  set(kInPistonARet, piston_[0] <= 0.0);
  set(kInPistonBExt, piston_[1] >= 1.0);
  set(kInPistonBRet, piston_[1] <= 0.0);
  const double x = plant_.helix_rad * config_.helix_lead_m / (2.0 * 3.14159265358979323846);
  set(kInShuttleLeft, x <= config_.selvedge_window_m);
  set(kInShuttleRight, x >= config_.width_m - config_.selvedge_window_m);
  set(kInEstopOk, !plant_.estop_open);
  set(kInStart, plant_.button_start);
  set(kInPause, plant_.button_pause);
  set(kInAck, plant_.button_ack);
  set(kInKnotted, plant_.row_knotted);
  in_ = in;
  value(0x6000, 1) = in[0];
  value(0x6000, 2) = in[1];
  // Load cell: a narrow pulse around the crank angle at which the beater meets the fell.
  const double two_pi = 2.0 * 3.14159265358979323846;
  double d = std::fmod(plant_.crank_rad - config_.fell_crank_rad, two_pi);
  if (d > two_pi / 2) d -= two_pi;
  if (d < -two_pi / 2) d += two_pi;
  const double c = std::cos(d);
  const double force = c > 0.0 ? config_.beat_peak_n * std::pow(c, 32.0) : 0.0;
  const double counts = std::clamp(std::round(force / config_.load_cell_n_per_count), -32768.0, 32767.0);
  analog_ = static_cast<std::int16_t>(counts);
  value(0x6401, 1) = static_cast<std::uint16_t>(analog_);
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
  // Pistons follow their valve coils (as the outputs really are, error state included).
  const std::uint8_t out = outputs(0);
  const bool valve[2] = {((out >> kOutValveA) & 1U) != 0, ((out >> kOutValveB) & 1U) != 0};
  for (std::size_t i = 0; i < 2; ++i) {
    const double step = dt / config_.piston_travel_s;
    piston_[i] = std::clamp(piston_[i] + (valve[i] ? step : -step), 0.0, 1.0);
  }
  if (plant_.silent) {
    // A silenced node (HIL: the I/O node dies) sends nothing, but its heartbeat timer runs on: a deadline
    // left in the past made the rack's loop spin at real-time priority and starve the master under test.
    const std::int64_t hb_us = static_cast<std::int64_t>(get(0x1017, 0)) * 1000;
    if (hb_us > 0 && now_us >= next_hb_us_) next_hb_us_ = now_us + hb_us;
    return;
  }
  if (boot_at_us_ >= 0 && now_us >= boot_at_us_) {
    boot_at_us_ = -1;
    send(kErrCtl + config_.node_id, 1, {0x00, 0, 0, 0, 0, 0, 0, 0});
    next_hb_us_ = now_us + static_cast<std::int64_t>(get(0x1017, 0)) * 1000;
  }
  if (boot_at_us_ >= 0) return;
  // Event-driven input TPDOs (type 254/255) go out on change.
  const std::array<std::uint8_t, 2> before = in_;
  update_inputs();
  if (nmt_ == 0x05 && in_ != before) {
    for (int k = 0; k < 4; ++k) {
      const auto comm = static_cast<std::uint16_t>(0x1800 + k);
      if (object_exists(comm) && (get(comm, 1) & kInvalidBit) == 0 && get(comm, 2) >= 254) send_tpdo(k);
    }
  }
  const std::uint32_t hb_ms = get(0x1017, 0);
  if (hb_ms != 0 && now_us >= next_hb_us_) {
    send(kErrCtl + config_.node_id, 1, {nmt_, 0, 0, 0, 0, 0, 0, 0});
    next_hb_us_ += static_cast<std::int64_t>(hb_ms) * 1000;
    if (next_hb_us_ <= now_us) next_hb_us_ = now_us + static_cast<std::int64_t>(hb_ms) * 1000;
  }
  // Master heartbeat consumer: silence longer than its time → outputs to their error values, EMCY 0x8130.
  const std::uint32_t consumer = get(0x1016, 1);
  const std::int64_t window_us = static_cast<std::int64_t>(consumer & 0xFFFF) * 1000;
  if (consumer != 0 && window_us > 0 && master_seen_us_ >= 0 && !comm_lost_ &&
      now_us - master_seen_us_ > window_us) {
    comm_lost_ = true;
    value(0x1001, 0) |= 0x11;  // generic + communication
    send(kEmcyBase + config_.node_id, 8, {0x30, 0x81, static_cast<std::uint8_t>(get(0x1001, 0)), 0, 0, 0, 0, 0});
  }
}

std::int64_t SimIoNode::next_deadline_us() const {
  if (!powered_) return std::numeric_limits<std::int64_t>::max();
  std::int64_t t = std::numeric_limits<std::int64_t>::max();
  // Silent: only the plant keeps time (nothing is sent, so no boot-up or heartbeat deadline applies).
  if (plant_.silent) return last_step_us_ + 10'000;
  if (boot_at_us_ >= 0) t = boot_at_us_;
  if (get(0x1017, 0) != 0) t = std::min(t, next_hb_us_);
  // The plant moves continuously: step at least every 10 ms.
  return std::min(t, last_step_us_ + 10'000);
}

}  // namespace loom::sim_can
