// libFuzzer harness: the receive path of drivers::CanIoPort (the master's side of the CiA 401 I/O node)
// fed an arbitrary sequence of frames between its ticks.
//
// Once per process two ports are brought up for real — NMT + SDO against sim_can::SimIoNode over the
// in-memory CAN network of the driver tests — one per wiring:
//   0  the default drivers::IoWiring{}: TPDO1 = 0x6000:01..03 (second channels on bits 16..21), TPDO2 =
//      the load cell 0x6401:01, RPDO1 = 0x6200:01;
//   1  a 32-input wiring with mixed polarities, unwired optional inputs (a button, a second channel), a
//      second channel on bit 30 and one on bit 31: TPDO1 = 0x6000:01..04, no load cell (TPDO2
//      disabled), outputs on 0x6200:01..02;
//   2  the default wiring with two knotting heads: grippers on outputs 8, 9, cutters on 20, 21, yarn-present
//      on inputs 24 (active low) and 25: TPDO1 = 0x6000:01..04, RPDO1 = 0x6200:01..03;
//   3  the second of a loom's two modules (an operator panel: the stack light, the buzzer and the buttons
//      on it, everything else on the first): TPDO1 = 0x6000:01..02, no load cell, RPDO1 = 0x6200:01. The
//      model reads it through a wiring written out by hand (only those signals), so every other signal
//      must read false — the e-stop chain too, which is the first module's — and never be written.
// The first input byte picks the template; each input starts from a copy of it, now on a bus the input
// alone feeds (the simulated node is gone), and plays operations read from the rest with
// FuzzedDataProvider:
//   any frame (any COB-ID, data, error or RTR frame, DLC 0..8);
//   a TPDO1, TPDO2, heartbeat or EMCY of the I/O node with fuzzed contents and (mostly nominal) length;
//   a tick: the frames queued since the last tick through on_frame (as CanAxisPort hands them over),
//   then supervise, read_io, read_analog, write_io with fuzzed outputs;
//   a gap (ticks without a cycle), a run of quiet ticks, acknowledge, a full transmit queue.
// Besides crashes and sanitizer reports it checks, after every frame and every tick, the port against a
// model kept here from the frames alone — the bits are extracted BY HAND from the frame bytes and the
// wiring's bit/polarity, never through the port's own decoding:
//   - a TPDO1 of at least the mapped length is one sample: every input read_io reports (both channels of
//     the safety sensors, buttons, e-stop chain) equals the hand-computed bit, `refreshed` = that tick;
//   - a too-short TPDO1 (and an RTR frame on its COB-ID) changes nothing and counts one rx error;
//   - an unwired input (a second channel, a button) always reads false; before the first TPDO1 every
//     input reads false, the e-stop chain true (no news is not an opened chain), `refreshed` never;
//   - `refreshed` (inputs, analog) never goes backwards;
//   - the load-cell force is finite whenever `beat_force_valid`, and equals gain · counts + offset of
//     the last TPDO2 of at least 2 bytes; no load cell fitted = never valid;
//   - the link fault follows the heartbeat rules (boot-up = 0xFF02, stopped/pre-operational = 0xFF03,
//     silence > 125 ticks = 0x8130) and, once latched, keeps its code: acknowledge() does not clear it
//     (only re-arming, the bring-up, does), while it does clear the last EMCY code;
//   - heard_again; rx_errors; tx_dropped; the RPDO written is the requested outputs by hand — the safe
//     outputs (valves off, red lamp on) while a link fault is latched.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fake_can_network.hpp"
#include "fuzzed_frame.hpp"
#include "loom/drivers/can_io_port.hpp"
#include "loom/drivers/can_network.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/sim_can/sim_io_node.hpp"

namespace {

using namespace loom;

[[noreturn]] __attribute__((format(printf, 1, 2))) void fail(const char* fmt, ...) {
  std::fprintf(stderr, "CanIoPort property violated: ");
  va_list ap;
  va_start(ap, fmt);
  std::vfprintf(stderr, fmt, ap);
  va_end(ap);
  std::fprintf(stderr, "\n");
  std::abort();
}

constexpr int kMaxOps = 512;
constexpr std::size_t kMaxFramesPerTick = 64;  // more are lost, as on a full rx FIFO
constexpr std::uint8_t kNode = 4;
// By hand: the consumer time 0.250 s over the cycle 0.002 s (CanIoConfig defaults).
constexpr hal::Tick kConsumerTicks = 125;
// COB-IDs of the pre-defined connection set for node 4 (CiA 301), by hand.
constexpr std::uint32_t kEmcyId = 0x080 + kNode, kTpdo1Id = 0x180 + kNode, kTpdo2Id = 0x280 + kNode,
                        kTpdo3Id = 0x380 + kNode, kTpdo4Id = 0x480 + kNode, kRpdo1Id = 0x200 + kNode,
                        kHeartbeatId = 0x700 + kNode;

// The port's bus. During bring-up it relays to the simulated node's network; afterwards the port only
// sends (write_io): every frame is kept, and refused while "full".
class FuzzBus final : public drivers::CanBus {
 public:
  drivers::CanBus* relay = nullptr;
  int tx_full = 0;
  drivers::CanFrame last_sent{};
  std::uint32_t sent = 0;

  drivers::SendResult send(const drivers::CanFrame& f) noexcept override {
    if (relay != nullptr) return relay->send(f);
    last_sent = f;
    ++sent;
    if (tx_full > 0) {
      --tx_full;
      return drivers::SendResult::kWouldBlock;
    }
    return drivers::SendResult::kOk;
  }
  bool receive(drivers::CanFrame& f) noexcept override { return relay != nullptr && relay->receive(f); }
  void reset() {
    tx_full = 0;
    sent = 0;
    last_sent = {};
  }
};

// What the harness knows of a template without asking the port: its wiring, the mapped lengths.
struct Layout {
  std::uint8_t input_bytes;   // TPDO1 = 0x6000:01..input_bytes
  bool load_cell;             // TPDO2 = 0x6401:01 (16 bits)
  std::uint8_t output_bytes;  // RPDO1 = 0x6200:01..output_bytes
};

drivers::CanIoConfig wiring_32_bits() {
  drivers::CanIoConfig c;
  drivers::IoWiring& w = c.wiring;
  w.estop_ok = {6, true};
  w.button_start = {24, false};
  w.button_pause = {-1, false};
  w.row_knotted = {15, true};
  w.second[0] = {31, false};
  w.second[1] = {17, true};
  w.second[3] = {-1, false};
  w.second[5] = {30, true};
  w.load_cell_channel = 0;
  w.piston_b_extend = {1, true};
  w.lamp_amber = {12, false};
  w.buzzer = {-1, false};
  return c;
}

// The loom's whole wiring with the panel's signals on module 1, served as module 1.
drivers::CanIoConfig panel_module() {
  drivers::CanIoConfig c;
  drivers::IoWiring& w = c.wiring;
  for (drivers::IoBit* b : {&w.lamp_green, &w.lamp_amber, &w.lamp_red, &w.buzzer, &w.button_start,
                            &w.button_pause, &w.button_ack}) {
    b->module = 1;
  }
  w.button_ack.active_low = true;
  c.module = 1;
  c.name = "panel";
  return c;
}
// By hand: what module 1 of panel_module() carries, nothing else.
drivers::IoWiring panel_model() {
  drivers::IoWiring w;
  for (drivers::IoBit* b : {&w.piston_a_extended, &w.piston_a_retracted, &w.piston_b_extended,
                            &w.piston_b_retracted, &w.shuttle_at_left, &w.shuttle_at_right, &w.estop_ok,
                            &w.row_knotted, &w.piston_a_extend, &w.piston_b_extend}) {
    *b = {};
  }
  for (drivers::IoBit& b : w.second) b = {};
  w.button_ack = {10, true};
  w.load_cell_channel = 0;
  return w;
}

drivers::CanIoConfig two_heads() {
  drivers::CanIoConfig c;
  drivers::IoWiring& w = c.wiring;
  w.heads = 2;
  w.gripper_close = {drivers::IoBit{8, false}, drivers::IoBit{9, false}};
  w.cutter = {drivers::IoBit{20, false}, drivers::IoBit{21, false}};
  w.yarn_present = {drivers::IoBit{24, true}, drivers::IoBit{25, false}};
  return c;
}

struct Template {
  test::FakeCanNetwork net;
  test::FakeCanNetwork::Endpoint& master;
  test::FakeCanNetwork::Endpoint& module_side;
  sim_can::SimIoNode module;
  FuzzBus bus;
  drivers::CanIoPort port;
  Layout layout;
  drivers::IoWiring model_wiring;  // what the model reads the port through (written out by hand)
  std::int64_t now_us = 0;

  // Virtual time for the bring-up: every idle() lets 100 µs pass on the network and the module.
  using Clock = loom::test::RigClock<Template>;

  void advance(std::int64_t dt_us) {
    const std::int64_t end = now_us + dt_us;
    while (now_us < end) {
      now_us = std::min(end, now_us + 100);
      net.set_time(now_us);
      drivers::CanFrame f;
      while (module_side.receive(f)) module.handle(f, now_us);
      module.step(now_us, sim_can::IoPlant{});
    }
  }

  Template(const drivers::CanIoConfig& config, Layout l, const drivers::IoWiring* by_hand = nullptr)
      : master(net.add_endpoint()),
        module_side(net.add_endpoint()),
        module(module_side, sim_can::SimIoConfig{}),
        port(config),
        layout(l),
        model_wiring(by_hand != nullptr ? *by_hand : config.wiring) {
    module.power_on(now_us);
    bus.relay = &master;
    Clock clock(*this);
    // Brought up as every module is, by a network (here of the module alone); afterwards the harness hands
    // the port its frames itself.
    drivers::CanNetwork network(port.master_config(), 1);
    const bool added = network.add(port);
    const drivers::Status s =
        added ? network.configure(bus, clock) : drivers::Status::error("not registered");
    if (!s.is_ok()) {
      std::fprintf(stderr, "bring-up against the simulated I/O node failed: %s\n", s.message().c_str());
      std::abort();
    }
    // The layout the harness assumes is the one on the wire: one SYNC, and the module answers with its
    // TPDO1 (and TPDO2) of the lengths above.
    drivers::CanFrame f;
    while (master.receive(f)) {
    }
    drivers::CanFrame sync;
    sync.id = 0x080;
    (void)master.send(sync);
    advance(1000);
    int tpdo1 = -1, tpdo2 = -1;
    while (master.receive(f)) {
      if (f.is_error() || f.is_rtr()) continue;
      if (f.id == kTpdo1Id) tpdo1 = f.dlc;
      if (f.id == kTpdo2Id) tpdo2 = f.dlc;
    }
    if (tpdo1 != layout.input_bytes || tpdo2 != (layout.load_cell ? 2 : -1)) {
      std::fprintf(stderr,
                   "the module sends TPDO1 with %d bytes and TPDO2 with %d, the harness expects %d and %d\n",
                   tpdo1, tpdo2, layout.input_bytes, layout.load_cell ? 2 : -1);
      std::abort();
    }
    bus.relay = nullptr;
  }
};

// The port as the harness expects it, from the frames alone.
struct Model {
  const drivers::IoWiring* wiring = nullptr;
  Layout layout{};
  std::uint64_t input_word = 0;  // the last accepted TPDO1, little-endian (bit b = sub b/8+1, bit b%8)
  hal::Tick inputs_refreshed = hal::kNeverTick;
  std::int16_t counts = 0;
  hal::Tick analog_refreshed = hal::kNeverTick;
  hal::Tick last_heartbeat = hal::kNeverTick;
  bool booted = false;
  std::uint16_t link_fault = 0;
  std::uint16_t emcy = 0;
  std::uint32_t rx_errors = 0;
  std::uint32_t tx_dropped = 0;

  void frame(hal::Tick now, const drivers::CanFrame& f) {
    if (f.is_error() || (f.id & 0x7F) != kNode) return;  // other nodes' traffic, the bus's own errors
    const bool data = !f.is_rtr();
    switch (f.id) {
      case kTpdo1Id:
        if (data && f.dlc >= layout.input_bytes) {
          input_word = 0;
          for (std::size_t k = 0; k < layout.input_bytes; ++k)
            input_word |= std::uint64_t{f.data[k]} << (8 * k);
          inputs_refreshed = now;
        } else {
          ++rx_errors;  // too short, or a remote request carrying no data
        }
        return;
      case kTpdo2Id:
        if (layout.load_cell && data && f.dlc >= 2) {
          counts = static_cast<std::int16_t>(static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8)));
          analog_refreshed = now;
        } else {
          ++rx_errors;  // short, RTR, or a TPDO the bring-up disabled
        }
        return;
      case kTpdo3Id:
      case kTpdo4Id:
        ++rx_errors;  // disabled by the bring-up
        return;
      case kEmcyId:
        if (data && f.dlc == 8) {
          const auto code = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
          if (code != 0) emcy = code;  // 0x0000 = error reset: the code stays until acknowledged
        } else {
          ++rx_errors;
        }
        return;
      case kHeartbeatId: {
        const int state = f.data[0] & 0x7F;  // bit 7: the node-guarding toggle
        if (!data || f.dlc != 1 || (state != 0x00 && state != 0x04 && state != 0x05 && state != 0x7F)) {
          ++rx_errors;
          return;
        }
        last_heartbeat = now;
        if (state == 0x00) booted = true;
        if (link_fault == 0 && state == 0x00) link_fault = drivers::fault_code::kNodeRebooted;
        if (link_fault == 0 && state != 0x00 && state != 0x05)
          link_fault = drivers::fault_code::kNodeNotOperational;
        return;
      }
      default:
        return;  // SDO, RPDO echoes, ...: not the master's business here
    }
  }
  void supervise(hal::Tick now) {
    if (last_heartbeat == hal::kNeverTick) last_heartbeat = now;
    if (link_fault == 0 && now - last_heartbeat > kConsumerTicks)
      link_fault = drivers::fault_code::kHeartbeatLost;
  }
  bool heard_again(hal::Tick now) const {
    return booted || (last_heartbeat != hal::kNeverTick && now - last_heartbeat <= kConsumerTicks);
  }
  // By hand: the electrical bit `b.bit` of the last sample through the signal's polarity.
  bool input(const drivers::IoBit& b) const {
    if (b.bit < 0) return false;
    if (inputs_refreshed == hal::kNeverTick) return false;
    const bool level = ((input_word >> b.bit) & 1U) != 0;  // b.bit < 64 (validated wiring)
    return b.active_low ? !level : level;
  }
};

struct Checker {
  const drivers::CanIoPort* port = nullptr;
  hal::Tick io_refreshed = hal::kNeverTick;
  hal::Tick analog_refreshed = hal::kNeverTick;
  std::uint16_t latched = 0;

  void expect_input(const char* name, bool got, bool want, const Model& m) const {
    if (got != want) {
      fail("%s = %d, but the TPDO1 of tick %lld (0x%016llX) says %d", name, got,
           static_cast<long long>(m.inputs_refreshed), static_cast<unsigned long long>(m.input_word), want);
    }
  }

  void check(drivers::CanIoPort& p, const Model& m, hal::Tick now) {
    const drivers::IoWiring& w = *m.wiring;
    hal::DigitalInputs io;
    io.refreshed = 12345;  // must be overwritten
    p.read_io(now, hal::AxisFeedbacks{}, io);
    if (io.refreshed < io_refreshed) {
      fail("inputs refreshed went backwards: %lld after %lld", static_cast<long long>(io.refreshed),
           static_cast<long long>(io_refreshed));
    }
    io_refreshed = io.refreshed;
    if (io.refreshed != m.inputs_refreshed) {
      fail("inputs refreshed = %lld, the last TPDO1 accepted came at %lld",
           static_cast<long long>(io.refreshed), static_cast<long long>(m.inputs_refreshed));
    }
    expect_input("piston_a_extended", io.piston_a_extended, m.input(w.piston_a_extended), m);
    expect_input("piston_a_retracted", io.piston_a_retracted, m.input(w.piston_a_retracted), m);
    expect_input("piston_b_extended", io.piston_b_extended, m.input(w.piston_b_extended), m);
    expect_input("piston_b_retracted", io.piston_b_retracted, m.input(w.piston_b_retracted), m);
    expect_input("shuttle_at_left", io.shuttle_at_left, m.input(w.shuttle_at_left), m);
    expect_input("shuttle_at_right", io.shuttle_at_right, m.input(w.shuttle_at_right), m);
    // The chain's module reads it closed before its first TPDO (no news is not an opened chain); a module
    // without it reads false (CanIoModules takes it from the one that has it).
    expect_input("estop_ok", io.estop_ok,
                 w.estop_ok.bit >= 0 && (m.inputs_refreshed == hal::kNeverTick || m.input(w.estop_ok)), m);
    expect_input("button_start", io.button_start, m.input(w.button_start), m);
    expect_input("button_pause", io.button_pause, m.input(w.button_pause), m);
    expect_input("button_ack", io.button_ack, m.input(w.button_ack), m);
    expect_input("row_knotted", io.row_knotted, m.input(w.row_knotted), m);
    static constexpr std::array<const char*, hal::kSafetySensorCount> kSecond{
        "second_channel[0]", "second_channel[1]", "second_channel[2]",
        "second_channel[3]", "second_channel[4]", "second_channel[5]"};
    for (std::size_t i = 0; i < hal::kSafetySensorCount; ++i) {
      if (w.second[i].bit < 0 && io.second_channel[i]) fail("%s is true but not wired", kSecond[i]);
      expect_input(kSecond[i], io.second_channel[i], m.input(w.second[i]), m);
    }
    static constexpr std::array<const char*, hal::kMaxKnottingHeads> kYarn{
        "yarn_present[0]", "yarn_present[1]", "yarn_present[2]",  "yarn_present[3]",
        "yarn_present[4]", "yarn_present[5]", "yarn_present[6]",  "yarn_present[7]",
        "yarn_present[8]", "yarn_present[9]", "yarn_present[10]", "yarn_present[11]"};
    for (std::size_t h = 0; h < hal::kMaxKnottingHeads; ++h) {
      // A head the wiring does not use (or the loom lacks) never reads a knot.
      const bool want = static_cast<int>(h) < w.heads && m.input(w.yarn_present[h]);
      expect_input(kYarn[h], io.yarn_present[h], want, m);
    }

    hal::AnalogInputs a;
    a.beat_force_n = 1.0;  // must be overwritten
    p.read_analog(now, a);
    if (a.beat_force_valid && !std::isfinite(a.beat_force_n))
      fail("beat force %g is valid but not finite", a.beat_force_n);
    if (a.refreshed < analog_refreshed) {
      fail("analog refreshed went backwards: %lld after %lld", static_cast<long long>(a.refreshed),
           static_cast<long long>(analog_refreshed));
    }
    analog_refreshed = a.refreshed;
    const bool valid = m.layout.load_cell && m.analog_refreshed != hal::kNeverTick;
    if (a.beat_force_valid != valid || a.refreshed != m.analog_refreshed) {
      fail("beat force valid = %d refreshed %lld, the model says %d refreshed %lld", a.beat_force_valid,
           static_cast<long long>(a.refreshed), valid, static_cast<long long>(m.analog_refreshed));
    }
    if (valid) {
      const double want = w.load_cell_n_per_count * m.counts + w.load_cell_offset_n;
      if (std::abs(a.beat_force_n - want) > 1e-9 * (1.0 + std::abs(want))) {
        fail("beat force %g N, the TPDO2's %d counts make %g N", a.beat_force_n, m.counts, want);
      }
    }

    const std::uint16_t code = p.link_fault_code();
    if (latched != 0 && code != latched) fail("link fault 0x%04X latched, now 0x%04X", latched, code);
    latched = code;
    if (code != m.link_fault) fail("link fault 0x%04X, the heartbeats say 0x%04X", code, m.link_fault);
    if (p.last_emcy_code() != m.emcy)
      fail("last EMCY code 0x%04X, expected 0x%04X", p.last_emcy_code(), m.emcy);
    if (p.rx_errors() != m.rx_errors) fail("rx errors %u, expected %u", p.rx_errors(), m.rx_errors);
    if (p.heard_again(now) != m.heard_again(now)) {
      fail("heard_again(%lld) = %d, last heartbeat at %lld, booted %d", static_cast<long long>(now),
           p.heard_again(now), static_cast<long long>(m.last_heartbeat), m.booted);
    }
  }
};

// By hand: the RPDO1 bytes for `o` on wiring `w` (bit b of 0x6200:01..08 = byte b/8, bit b%8).
std::array<std::uint8_t, 8> rpdo_bytes(const drivers::IoWiring& w, const hal::DigitalOutputs& o) {
  std::uint64_t word = 0;
  const auto put = [&](const drivers::IoBit& b, bool on) {
    if (b.bit >= 0 && (b.active_low ? !on : on)) word |= std::uint64_t{1} << b.bit;
  };
  put(w.piston_a_extend, o.piston_a_extend);
  put(w.piston_b_extend, o.piston_b_extend);
  put(w.lamp_green, o.lamp_green);
  put(w.lamp_amber, o.lamp_amber);
  put(w.lamp_red, o.lamp_red);
  put(w.buzzer, o.buzzer);
  for (std::size_t h = 0; h < static_cast<std::size_t>(w.heads); ++h) {
    put(w.gripper_close[h], o.gripper_close[h]);
    put(w.cutter[h], o.cutter[h]);
  }
  std::array<std::uint8_t, 8> bytes{};
  for (std::size_t k = 0; k < bytes.size(); ++k) bytes[k] = static_cast<std::uint8_t>(word >> (8 * k));
  return bytes;
}

drivers::CanFrame node_frame(FuzzedDataProvider& in, std::uint32_t id, std::uint8_t nominal_dlc) {
  drivers::CanFrame f;
  f.id = id;
  f.dlc = in.ConsumeBool() ? nominal_dlc : in.ConsumeIntegralInRange<std::uint8_t>(0, 8);
  const auto bytes = in.ConsumeIntegral<std::uint64_t>();  // beyond the DLC too: must never be read
  for (std::size_t k = 0; k < f.data.size(); ++k) f.data[k] = static_cast<std::uint8_t>(bytes >> (8 * k));
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Process lifetime; never freed (libFuzzer exits).
  static const drivers::IoWiring panel = panel_model();
  static Template* const templates[4] = {new Template(drivers::CanIoConfig{}, Layout{3, true, 1}),
                                         new Template(wiring_32_bits(), Layout{4, false, 2}),
                                         new Template(two_heads(), Layout{4, true, 3}),
                                         new Template(panel_module(), Layout{2, false, 1}, &panel)};
  if (size == 0) return 0;
  Template& t = *templates[data[0] % 4];
  FuzzBus& bus = t.bus;
  bus.reset();
  drivers::CanIoPort port = t.port;  // configured, bound to `bus`
  const drivers::IoWiring& wiring = t.model_wiring;

  Model m;
  m.wiring = &wiring;
  m.layout = t.layout;
  Checker c;
  hal::Tick now = 0;
  std::array<drivers::CanFrame, kMaxFramesPerTick> pending{};
  std::size_t n_pending = 0;
  const auto queue = [&](const drivers::CanFrame& f) {
    if (n_pending < pending.size()) pending[n_pending++] = f;
  };

  const auto cycle = [&](const hal::DigitalOutputs& out) {
    for (std::size_t k = 0; k < n_pending; ++k) {
      port.on_frame(now, pending[k]);
      m.frame(now, pending[k]);
      c.check(port, m, now);
    }
    n_pending = 0;
    port.supervise(now);
    m.supervise(now);
    c.check(port, m, now);

    const std::uint32_t sent = bus.sent;
    const bool refused = bus.tx_full > 0;
    port.write_io(now, out);
    if (bus.sent != sent + 1) fail("write_io sent %u frames", bus.sent - sent);
    if (refused) ++m.tx_dropped;
    if (port.tx_dropped() != m.tx_dropped)
      fail("tx dropped %u, expected %u", port.tx_dropped(), m.tx_dropped);
    const drivers::CanFrame& f = bus.last_sent;
    const std::array<std::uint8_t, 8> want =
        rpdo_bytes(wiring, m.link_fault != 0 ? drivers::io_safe_outputs() : out);
    if (f.id != kRpdo1Id || f.dlc != t.layout.output_bytes || f.flags != 0 || f.data != want) {
      fail(
          "write_io sent 0x%03X [%u] %02X %02X %02X (link fault 0x%04X), expected 0x%03X [%u] %02X %02X %02X",
          f.id, f.dlc, f.data[0], f.data[1], f.data[2], m.link_fault, kRpdo1Id, t.layout.output_bytes,
          want[0], want[1], want[2]);
    }
    ++now;
  };

  FuzzedDataProvider in(data + 1, size - 1);
  for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
    switch (in.ConsumeIntegralInRange<int>(0, 9)) {
      case 0: {  // any frame
        const drivers::CanFrame f = fuzz::any_frame(in);
        queue(f);
        break;
      }
      case 1:  // the digital inputs
        queue(node_frame(in, kTpdo1Id, t.layout.input_bytes));
        break;
      case 2:  // the load cell
        queue(node_frame(in, kTpdo2Id, 2));
        break;
      case 3: {  // heartbeat / boot-up: mostly a known state, with or without the toggle bit
        drivers::CanFrame f = node_frame(in, kHeartbeatId, 1);
        if (in.ConsumeBool()) {
          static constexpr std::array<std::uint8_t, 4> kStates{0x00, 0x04, 0x05, 0x7F};
          f.data[0] = static_cast<std::uint8_t>((f.data[0] & 0x80) |
                                                kStates[in.ConsumeIntegralInRange<std::size_t>(0, 3)]);
        }
        queue(f);
        break;
      }
      case 4:  // EMCY
        queue(node_frame(in, kEmcyId, 8));
        break;
      case 5: {  // one RT cycle
        const auto bits = in.ConsumeIntegral<std::uint8_t>();
        hal::DigitalOutputs out;
        out.piston_a_extend = (bits & 0x01) != 0;
        out.piston_b_extend = (bits & 0x02) != 0;
        out.lamp_green = (bits & 0x04) != 0;
        out.lamp_amber = (bits & 0x08) != 0;
        out.lamp_red = (bits & 0x10) != 0;
        out.buzzer = (bits & 0x20) != 0;
        const auto heads = in.ConsumeIntegral<std::uint8_t>();  // every head's signals, used or not
        for (std::size_t h = 0; h < 2; ++h) {
          out.gripper_close[h] = ((heads >> (2 * h)) & 1U) != 0;
          out.cutter[h] = ((heads >> (2 * h + 1)) & 1U) != 0;
        }
        out.gripper_close[5] = (heads & 0x10) != 0;
        out.cutter[11] = (heads & 0x20) != 0;
        cycle(out);
        break;
      }
      case 6:  // ticks without a cycle (a stalled loop)
        now += in.ConsumeIntegralInRange<int>(1, 1000);
        break;
      case 7: {  // quiet cycles: nothing heard (heartbeat consumer)
        const int n = in.ConsumeIntegralInRange<int>(1, 200);
        for (int k = 0; k < n; ++k) cycle(hal::DigitalOutputs{});
        break;
      }
      case 8:  // the operator acknowledges
        port.acknowledge();
        m.emcy = 0;
        c.check(port, m, now);
        break;
      case 9:
        bus.tx_full = in.ConsumeIntegralInRange<int>(0, 8);
        break;
    }
  }
  return 0;
}
