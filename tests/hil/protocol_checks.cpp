// The HIL protocol checks. Each expectation is a CiA 301/402 fact (COB-IDs, NMT/SDO command bytes,
// statusword masks, controlword values: CiA 301 / CiA 402); each failure names the log line
// and the frame, so a red test says what the bus showed.
#include "protocol_checks.hpp"

#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <sstream>

namespace loom::hil {

namespace {

using Index = std::optional<std::size_t>;

constexpr std::uint8_t kNmtStart = 0x01;
constexpr std::uint8_t kNmtResetNode = 0x81;
constexpr std::uint16_t kCwEnableOperation = 0x000F;

std::uint32_t cob(std::uint32_t base, int node) {
  return base + static_cast<std::uint32_t>(node);
}

bool standard(const Frame& f) {
  return !f.extended && !f.error_frame && !f.rtr;
}

bool is_nmt(const Frame& f, std::uint8_t command, int node) {
  return standard(f) && f.id == 0x000 && f.len == 2 && f.data[0] == command &&
         (f.data[1] == 0 || f.data[1] == node);
}
bool is_heartbeat(const Frame& f, int node) {
  return standard(f) && f.id == cob(0x700, node) && f.len == 1;
}
bool is_sync(const Frame& f) {
  return standard(f) && f.id == 0x080 && f.len <= 1;
}
bool is_sdo(const Frame& f, std::uint32_t base, int node, std::uint16_t index, std::uint8_t sub) {
  return standard(f) && f.id == cob(base, node) && f.len == 8 && f.u16(1) == index && f.data[3] == sub;
}
bool is_rpdo(const Frame& f, int node) {
  return standard(f) && f.id == cob(0x200, node);
}
bool is_tpdo(const Frame& f, int node) {
  return standard(f) && f.id == cob(0x180, node);
}

// Controlword the master sent to `node` in this frame: RPDO1, or an SDO download to 0x6040.
std::optional<std::uint16_t> controlword(const Frame& f, int node, const PdoLayout& l) {
  if (is_rpdo(f, node) && f.len >= l.controlword_at + 2) return f.u16(l.controlword_at);
  if (is_sdo(f, 0x600, node, 0x6040, 0) && f.data[0] == 0x2B) return f.u16(4);
  return std::nullopt;
}
std::optional<std::int32_t> target(const Frame& f, int node, const PdoLayout& l) {
  if (is_rpdo(f, node) && f.len >= l.target_at + 4) return f.i32(l.target_at);
  return std::nullopt;
}
std::optional<std::uint16_t> statusword(const Frame& f, int node, const PdoLayout& l) {
  if (is_tpdo(f, node) && f.len >= l.statusword_at + 2) return f.u16(l.statusword_at);
  return std::nullopt;
}

Index find_from(const std::vector<Frame>& fs, std::size_t from,
                const std::function<bool(const Frame&)>& pred) {
  for (std::size_t i = from; i < fs.size(); ++i) {
    if (pred(fs[i])) return i;
  }
  return std::nullopt;
}

std::string hex(std::uint32_t v, int width) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", width, v);
  return buf;
}

// "line 12 (+0.123 s) 601#2F60600008000000": what a reader can grep for in the log.
std::string show(const std::vector<Frame>& fs, std::size_t i) {
  const Frame& f = fs[i];
  char head[64];
  std::snprintf(head, sizeof head, "line %zu (+%.3f s) %03X#", f.line,
                static_cast<double>(f.t_us - fs.front().t_us) * 1e-6, static_cast<unsigned>(f.id));
  std::string s = head;
  for (std::size_t b = 0; b < f.len; ++b) {
    char byte[3];
    std::snprintf(byte, sizeof byte, "%02X", static_cast<unsigned>(f.data[b]));
    s += byte;
  }
  return s;
}

CheckResult fail(CheckResult r, std::string why) {
  r.ok = false;
  r.failure = std::move(why);
  return r;
}

std::string node_tag(int node) {
  return "node " + std::to_string(node) + ": ";
}

// Statusword decoding per CiA 402 (mask → value).
bool ready_or_switched_on(std::uint16_t sw) {
  return (sw & 0x6FU) == 0x21U || (sw & 0x6FU) == 0x23U;
}
bool operation_enabled(std::uint16_t sw) {
  return (sw & 0x6FU) == 0x27U;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Summary
// ---------------------------------------------------------------------------------------------------
TrafficSummary summarize(const std::vector<Frame>& frames) {
  TrafficSummary s;
  s.total = frames.size();
  if (!frames.empty()) {
    s.span_s = static_cast<double>(frames.back().t_us - frames.front().t_us) * 1e-6;
  }
  for (const Frame& f : frames) {
    if (f.error_frame) {
      ++s.error_frames;
      continue;
    }
    if (f.extended) {
      ++s.other;
      continue;
    }
    const std::uint32_t fn = f.id & 0x780U;  // function code (upper 4 bits of the 11-bit id)
    const std::uint32_t node = f.id & 0x7FU;
    if (f.id == 0x000)
      ++s.nmt;
    else if (f.id == 0x080)
      ++s.sync;
    else if (fn == 0x080 && node != 0)
      ++s.emcy;
    else if ((fn == 0x180 || fn == 0x280 || fn == 0x380 || fn == 0x480) && node != 0)
      ++s.tpdo;
    else if ((fn == 0x200 || fn == 0x300 || fn == 0x400 || fn == 0x500) && node != 0)
      ++s.rpdo;
    else if (fn == 0x580 && node != 0)
      ++s.sdo_reply;
    else if (fn == 0x600 && node != 0)
      ++s.sdo_request;
    else if (fn == 0x700 && node != 0)
      ++s.heartbeat;
    else
      ++s.other;
  }
  return s;
}

std::string describe(const TrafficSummary& s) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(2);
  o << s.total << " frames in " << s.span_s << " s: nmt=" << s.nmt << " sync=" << s.sync << " rpdo=" << s.rpdo
    << " tpdo=" << s.tpdo << " sdo_request=" << s.sdo_request << " sdo_reply=" << s.sdo_reply
    << " heartbeat=" << s.heartbeat << " emcy=" << s.emcy << " other=" << s.other
    << " error_frames=" << s.error_frames;
  return o.str();
}

// ---------------------------------------------------------------------------------------------------
// Start-up and cyclic exchange
// ---------------------------------------------------------------------------------------------------
CheckResult check_weave_protocol(const std::vector<Frame>& fs, const std::vector<int>& nodes,
                                 const PdoLayout& l) {
  CheckResult r;
  if (fs.empty()) return fail(r, "the log holds no frames");
  for (const int n : nodes) {
    const std::string tag = node_tag(n);
    const Index reset = find_from(fs, 0, [&](const Frame& f) { return is_nmt(f, kNmtResetNode, n); });
    if (!reset) return fail(r, tag + "no NMT reset-node (000#8100 or 000#81 with the node id)");

    const Index boot =
        find_from(fs, *reset + 1, [&](const Frame& f) { return is_heartbeat(f, n) && f.data[0] == 0x00; });
    if (!boot)
      return fail(r, tag + "no boot-up " + hex(cob(0x700, n), 3) + " [00] after the NMT reset at " +
                         show(fs, *reset));

    const Index mode_dl = find_from(fs, *boot + 1, [&](const Frame& f) {
      return is_sdo(f, 0x600, n, 0x6060, 0) && f.data[0] == 0x2F && f.data[4] == 8;
    });
    if (!mode_dl)
      return fail(r, tag + "no SDO download 0x6060:00 = 8 (cs 0x2F) after the boot-up at " + show(fs, *boot));
    const Index mode_ack =
        find_from(fs, *mode_dl + 1, [&](const Frame& f) { return is_sdo(f, 0x580, n, 0x6060, 0); });
    if (!mode_ack) return fail(r, tag + "no SDO reply to the 0x6060 download at " + show(fs, *mode_dl));
    if (fs[*mode_ack].data[0] != 0x60) {
      return fail(r, tag + "0x6060 download not acknowledged with 0x60 (abort " +
                         hex(fs[*mode_ack].u32(4), 8) + "?) at " + show(fs, *mode_ack));
    }

    const Index mode_ul = find_from(fs, *mode_ack + 1, [&](const Frame& f) {
      return is_sdo(f, 0x600, n, 0x6061, 0) && f.data[0] == 0x40;
    });
    if (!mode_ul)
      return fail(
          r, tag + "no SDO upload of 0x6061:00 (cs 0x40) after the mode was set at " + show(fs, *mode_ack));
    const Index mode_up =
        find_from(fs, *mode_ul + 1, [&](const Frame& f) { return is_sdo(f, 0x580, n, 0x6061, 0); });
    if (!mode_up) return fail(r, tag + "no SDO reply to the 0x6061 upload at " + show(fs, *mode_ul));
    // Expedited upload reply: ccs 2 (0x40) with the expedited bit (0x02); size bits may vary.
    if ((fs[*mode_up].data[0] & 0xE2U) != 0x42U) {
      return fail(r, tag + "0x6061 upload not answered expedited (cs 0x4F/0x43…) at " + show(fs, *mode_up));
    }
    if (fs[*mode_up].data[4] != 8) {
      return fail(r, tag + "0x6061 reads " + std::to_string(fs[*mode_up].data[4]) + ", not 8 (CSP), at " +
                         show(fs, *mode_up));
    }

    const Index start = find_from(fs, *mode_up + 1, [&](const Frame& f) { return is_nmt(f, kNmtStart, n); });
    if (!start)
      return fail(r, tag + "no NMT start (000#0100 or with the node id) after 0x6061 was confirmed at " +
                         show(fs, *mode_up));

    const Index first_sync = find_from(fs, *start + 1, is_sync);
    if (!first_sync) return fail(r, tag + "no SYNC (080) after the NMT start at " + show(fs, *start));
    const Index first_tpdo = find_from(fs, *start + 1, [&](const Frame& f) { return is_tpdo(f, n); });
    if (!first_tpdo) return fail(r, tag + "no TPDO " + hex(cob(0x180, n), 3) + " after the NMT start");
    if (*first_tpdo < *first_sync) {
      return fail(r, tag + "synchronous TPDO before any SYNC: " + show(fs, *first_tpdo));
    }
    std::size_t syncs = 0, rpdos = 0, tpdos = 0;
    for (std::size_t i = *start + 1; i < fs.size(); ++i) {
      syncs += is_sync(fs[i]) ? 1U : 0U;
      rpdos += is_rpdo(fs[i], n) ? 1U : 0U;
      tpdos += is_tpdo(fs[i], n) ? 1U : 0U;
    }
    // Every SYNC carries one RPDO and one TPDO per node in CSP; allow 10 % for VM scheduling gaps.
    if (10 * rpdos < 9 * syncs || 10 * tpdos < 9 * syncs) {
      return fail(r, tag + std::to_string(syncs) + " SYNCs but " + std::to_string(rpdos) + " RPDOs and " +
                         std::to_string(tpdos) + " TPDOs after the NMT start (expected one each per SYNC)");
    }

    const Index enable = find_from(fs, *start + 1, [&](const Frame& f) {
      return controlword(f, n, l) == std::optional<std::uint16_t>(kCwEnableOperation);
    });
    if (!enable) return fail(r, tag + "controlword 0x000F (enable operation) never sent after the NMT start");
    Index last_sw;
    for (std::size_t i = *start + 1; i < *enable; ++i) {
      if (statusword(fs[i], n, l)) last_sw = i;
    }
    if (!last_sw)
      return fail(r, tag + "0x000F sent before any statusword was received: " + show(fs, *enable));
    const std::uint16_t sw_before = *statusword(fs[*last_sw], n, l);
    if (!ready_or_switched_on(sw_before)) {
      return fail(r, tag + "0x000F sent on statusword " + hex(sw_before, 4) +
                         " (not Ready to switch on / Switched on): " + show(fs, *enable) + " after " +
                         show(fs, *last_sw));
    }
    if (const auto t = target(fs[*enable], n, l); t && fs[*last_sw].len >= l.position_at + 4) {
      const std::int32_t actual = fs[*last_sw].i32(l.position_at);
      const std::int64_t jump = static_cast<std::int64_t>(*t) - actual;
      if (jump > 2 || jump < -2) {
        return fail(r, tag + "first enabled target " + std::to_string(*t) + " is not the reported position " +
                           std::to_string(actual) + " (a jump on enable): " + show(fs, *enable));
      }
    }
    const Index op = find_from(fs, *enable, [&](const Frame& f) {
      const auto sw = statusword(f, n, l);
      return sw && operation_enabled(*sw);
    });
    if (!op)
      return fail(r, tag + "statusword never reached Operation enabled (&0x6F = 0x27) after 0x000F at " +
                         show(fs, *enable));

    r.notes.push_back(
        tag + "reset " + show(fs, *reset) + " → boot-up line " + std::to_string(fs[*boot].line) +
        " → 0x6060=8 line " + std::to_string(fs[*mode_dl].line) + "/" + std::to_string(fs[*mode_ack].line) +
        " → 0x6061=8 line " + std::to_string(fs[*mode_ul].line) + "/" + std::to_string(fs[*mode_up].line) +
        " → NMT start line " + std::to_string(fs[*start].line) + " → SYNC line " +
        std::to_string(fs[*first_sync].line) + " → 0x000F line " + std::to_string(fs[*enable].line) +
        " → Operation enabled line " + std::to_string(fs[*op].line) + "; after start " +
        std::to_string(syncs) + " SYNC, " + std::to_string(rpdos) + " RPDO, " + std::to_string(tpdos) +
        " TPDO");
  }
  return r;
}

// ---------------------------------------------------------------------------------------------------
// Profile position
// ---------------------------------------------------------------------------------------------------
CheckResult check_profile_position(const std::vector<Frame>& fs, const std::vector<int>& nodes,
                                   double inhibit_s, int min_moves, double slack_s, const PdoLayout& l) {
  CheckResult r;
  if (fs.empty()) return fail(r, "the log holds no frames");
  constexpr std::uint16_t kNewSetpoint = 1U << 4;
  constexpr std::uint16_t kSetpointAck = 1U << 12;
  const auto inhibit_100us = static_cast<std::uint32_t>(std::lround(inhibit_s * 1e4));
  for (const int n : nodes) {
    const std::string tag = node_tag(n);
    // Expedited download request 0x2F/0x2B/0x23 (size bits vary) to 0x600+id, and its ack 0x60.
    const Index mode_dl = find_from(fs, 0, [&](const Frame& f) {
      return is_sdo(f, 0x600, n, 0x6060, 0) && (f.data[0] & 0xE3U) == 0x23U && f.data[4] == 1;
    });
    if (!mode_dl) return fail(r, tag + "no SDO download of 0x6060:00 = 1 (profile position)");
    const Index mode_ack = find_from(fs, *mode_dl + 1, [&](const Frame& f) {
      return is_sdo(f, 0x580, n, 0x6060, 0) && f.data[0] == 0x60;
    });
    if (!mode_ack) return fail(r, tag + "0x6060 = 1 not acknowledged after " + show(fs, *mode_dl));
    const Index inhibit_dl = find_from(fs, 0, [&](const Frame& f) {
      return is_sdo(f, 0x600, n, 0x1800, 3) && (f.data[0] & 0xE3U) == 0x23U;
    });
    if (!inhibit_dl) return fail(r, tag + "no SDO download of 0x1800:03 (TPDO1 inhibit time)");
    if (fs[*inhibit_dl].u16(4) != inhibit_100us) {
      return fail(r, tag + "0x1800:03 written " + std::to_string(fs[*inhibit_dl].u16(4)) + ", not " +
                         std::to_string(inhibit_100us) + " (100 µs units): " + show(fs, *inhibit_dl));
    }
    const Index start = find_from(fs, *mode_ack + 1, [&](const Frame& f) { return is_nmt(f, kNmtStart, n); });
    if (!start) return fail(r, tag + "no NMT start after 0x6060 = 1");

    std::size_t syncs = 0, rpdos = 0, tpdos = 0;
    int moves = 0;
    Index last_rpdo, last_tpdo;
    bool pending = false;        // a set-point RPDO not yet released
    std::size_t pending_at = 0;  // its index
    bool acked = false;
    std::size_t syncs_at_last_rpdo = 0;
    std::int64_t min_gap_us = -1;
    for (std::size_t i = *start + 1; i < fs.size(); ++i) {
      const Frame& f = fs[i];
      if (is_sync(f)) {
        ++syncs;
        continue;
      }
      if (const auto sw = statusword(f, n, l)) {
        ++tpdos;
        if (last_tpdo) {
          const std::int64_t gap = f.t_us - fs[*last_tpdo].t_us;
          if (min_gap_us < 0 || gap < min_gap_us) min_gap_us = gap;
          if (static_cast<double>(gap) < (inhibit_s - slack_s) * 1e6) {
            return fail(r, tag + "TPDO1 " + std::to_string(gap) + " µs after the one before (inhibit time " +
                               std::to_string(inhibit_s * 1e3) + " ms): " + show(fs, *last_tpdo) + " then " +
                               show(fs, i));
          }
        }
        last_tpdo = i;
        if (pending && (*sw & kSetpointAck) != 0) acked = true;
        continue;
      }
      const auto cw = controlword(f, n, l);
      const auto tg = target(f, n, l);
      if (!cw || !tg) continue;
      ++rpdos;
      if (last_rpdo) {
        const auto pcw = *controlword(fs[*last_rpdo], n, l);
        const auto ptg = *target(fs[*last_rpdo], n, l);
        if (pcw == *cw && ptg == *tg) {
          return fail(r, tag + "RPDO1 repeated unchanged (profile position sends on change only): " +
                             show(fs, *last_rpdo) + " then " + show(fs, i));
        }
        if (syncs == syncs_at_last_rpdo) {
          return fail(
              r, tag + "two RPDO1s in one SYNC interval: " + show(fs, *last_rpdo) + " then " + show(fs, i));
        }
        const bool rising = (*cw & kNewSetpoint) != 0 && (pcw & kNewSetpoint) == 0;
        const bool falling = (*cw & kNewSetpoint) == 0 && (pcw & kNewSetpoint) != 0;
        if (falling && pending) {
          if (!acked) {
            return fail(
                r, tag + "set-point released (bit 4 falling) before the drive acknowledged it (bit 12): " +
                       show(fs, pending_at) + " then " + show(fs, i));
          }
          if (*tg != *target(fs[pending_at], n, l)) {
            return fail(r, tag + "the release carries another target than its set-point: " + show(fs, i));
          }
          pending = false;
        }
        if (rising) {
          if (pending) {
            return fail(r, tag + "a new set-point before the last one was released: " + show(fs, i));
          }
          pending = true;
          pending_at = i;
          acked = false;
          ++moves;
        }
      } else if ((*cw & kNewSetpoint) != 0) {
        pending = true;
        pending_at = i;
        acked = false;
        ++moves;
      }
      last_rpdo = i;
      syncs_at_last_rpdo = syncs;
    }
    if (moves < min_moves) {
      return fail(r, tag + std::to_string(moves) + " set-points after the NMT start (expected at least " +
                         std::to_string(min_moves) + ")");
    }
    if (4 * rpdos > syncs) {
      return fail(r, tag + std::to_string(rpdos) + " RPDO1s for " + std::to_string(syncs) +
                         " SYNCs: not event-driven (more than one in four)");
    }
    if (tpdos == 0) return fail(r, tag + "no TPDO1 after the NMT start");
    r.notes.push_back(tag + "0x6060=1 line " + std::to_string(fs[*mode_dl].line) +
                      ", 0x1800:03=" + std::to_string(inhibit_100us) + " line " +
                      std::to_string(fs[*inhibit_dl].line) + "; after start " + std::to_string(syncs) +
                      " SYNC, " + std::to_string(rpdos) + " RPDO1 (" + std::to_string(moves) +
                      " set-points, each acknowledged and released), " + std::to_string(tpdos) +
                      " TPDO1, closest two " + std::to_string(min_gap_us) + " µs apart");
  }
  return r;
}

// ---------------------------------------------------------------------------------------------------
// Heartbeat loss
// ---------------------------------------------------------------------------------------------------
CheckResult check_heartbeat_loss(const std::vector<Frame>& fs, const std::vector<int>& nodes,
                                 double heartbeat_s, int periods, const PdoLayout& l, double master_cycle_s) {
  CheckResult r;
  if (fs.empty()) return fail(r, "the log holds no frames");
  const auto limit_us = static_cast<std::int64_t>(heartbeat_s * periods * 1e6 + 0.5);
  for (const int n : nodes) {
    const std::string tag = node_tag(n);
    Index last_hb;
    std::size_t operational_hbs = 0;
    for (std::size_t i = 0; i < fs.size(); ++i) {
      if (!is_heartbeat(fs[i], n)) continue;
      last_hb = i;
      operational_hbs += fs[i].data[0] == 0x05 ? 1U : 0U;
    }
    if (!last_hb) return fail(r, tag + "no heartbeat " + hex(cob(0x700, n), 3) + " in the log");
    if (operational_hbs < 2)
      return fail(r, tag + "fewer than two operational heartbeats (05): the node never ran");
    if (fs[*last_hb].data[0] != 0x05) {
      return fail(r, tag + "last heartbeat before the loss is not operational (05): " + show(fs, *last_hb));
    }

    const Index enable = find_from(fs, 0, [&](const Frame& f) {
      return controlword(f, n, l) == std::optional<std::uint16_t>(kCwEnableOperation);
    });
    if (!enable || *enable > *last_hb) {
      return fail(
          r, tag + "the master had not enabled the node (controlword 0x000F) before its last heartbeat at " +
                 show(fs, *last_hb));
    }
    for (std::size_t i = *enable; i < *last_hb; ++i) {
      const auto cw = controlword(fs[i], n, l);
      if (cw && *cw != kCwEnableOperation) {
        return fail(r, tag + "the master left enable-operation (controlword " + hex(*cw, 4) +
                           ") before the heartbeat stopped: " + show(fs, i));
      }
    }

    const Index fault = find_from(fs, *last_hb + 1, [&](const Frame& f) {
      const auto cw = controlword(f, n, l);
      return cw && *cw != kCwEnableOperation;
    });
    if (!fault) {
      return fail(r, tag + "no quick-stop/disable controlword after the last heartbeat at " +
                         show(fs, *last_hb) + ": the loss was not acted on");
    }
    const std::int64_t latency_us = fs[*fault].t_us - fs[*last_hb].t_us;
    std::size_t cycles = 0;
    for (std::size_t i = *last_hb + 1; i < *fault; ++i) cycles += is_sync(fs[i]) ? 1U : 0U;
    if (master_cycle_s > 0.0) {
      const auto limit_cycles = static_cast<std::size_t>(std::ceil(heartbeat_s * periods / master_cycle_s));
      if (cycles > limit_cycles) {
        return fail(r, tag + "fault reaction " + std::to_string(cycles) +
                           " master cycles (SYNCs) after the last heartbeat, limit " +
                           std::to_string(limit_cycles) + " (" + std::to_string(limit_us / 1000) +
                           " ms of master time; " + std::to_string(latency_us / 1000) +
                           " ms wall): " + show(fs, *last_hb) + " → " + show(fs, *fault));
      }
    } else if (latency_us > limit_us) {
      return fail(r, tag + "fault reaction " + std::to_string(latency_us / 1000) +
                         " ms after the last heartbeat, limit " + std::to_string(limit_us / 1000) +
                         " ms: " + show(fs, *last_hb) + " → " + show(fs, *fault));
    }

    // The target in force when the fault was raised: the fault RPDO's own, else the last one before.
    std::optional<std::int32_t> held;
    for (std::size_t i = 0; i <= *fault; ++i) {
      if (auto t = target(fs[i], n, l)) held = t;
    }
    std::size_t rpdos_after = 0;
    for (std::size_t i = *fault + 1; i < fs.size(); ++i) {
      const auto cw = controlword(fs[i], n, l);
      if (cw && *cw == kCwEnableOperation) {
        return fail(r, tag + "re-enabled (0x000F) after the fault: " + show(fs, i));
      }
      const auto t = target(fs[i], n, l);
      if (!t) continue;
      ++rpdos_after;
      if (held && *t != *held) {
        return fail(r, tag + "RPDO after the fault commands target " + std::to_string(*t) +
                           " instead of the held " + std::to_string(*held) + ": " + show(fs, i));
      }
    }
    char ms[32];
    std::snprintf(ms, sizeof ms, "%.1f ms", static_cast<double>(latency_us) * 1e-3);
    r.notes.push_back(tag + "last heartbeat " + show(fs, *last_hb) + "; fault controlword " +
                      hex(*controlword(fs[*fault], n, l), 4) + " " + show(fs, *fault) + " after " + ms +
                      " (limit " + std::to_string(limit_us / 1000) + " ms), " + std::to_string(cycles) +
                      " master cycles; " + std::to_string(rpdos_after) +
                      " RPDOs after it, all holding the target");
  }
  return r;
}

}  // namespace loom::hil

// ---------------------------------------------------------------------------------------------------
// I/O node and fault reactions (written from CiA 301/401 byte layouts, not the master's codec)
// ---------------------------------------------------------------------------------------------------
namespace loom::hil {

namespace {
std::string at_line(const Frame& f) {
  return "line " + std::to_string(f.line);
}
}  // namespace

CheckResult check_io_traffic(const std::vector<Frame>& frames, int io_node, bool second_switches) {
  CheckResult r;
  const auto rpdo = static_cast<std::uint32_t>(0x200 + io_node);
  const auto tpdo = static_cast<std::uint32_t>(0x180 + io_node);
  const auto analog = static_cast<std::uint32_t>(0x280 + io_node);
  int n_out = 0, n_in = 0, n_an = 0;
  std::uint8_t out_seen = 0, in_seen = 0, second_seen = 0;
  bool loaded = false;
  std::string second_wrong;  // the first input TPDO whose second switches are missing or disagree
  for (const Frame& f : frames) {
    if (f.error_frame || f.rtr || f.extended) continue;
    if (f.id == rpdo && f.len >= 1) {
      ++n_out;
      out_seen |= f.data[0];
    } else if (f.id == tpdo && f.len >= 1) {
      ++n_in;
      in_seen |= f.data[0];
      if (second_switches && second_wrong.empty()) {
        if (f.len < 3) {
          second_wrong = "an input TPDO of " + std::to_string(f.len) + " byte(s) at log line " +
                         std::to_string(f.line) + ": no 0x6000:03 (second switches)";
        } else if ((f.data[2] & 0x3F) != (f.data[0] & 0x3F)) {
          char buf[128];
          std::snprintf(buf, sizeof buf,
                        "second switches 0x%02X disagree with first switches 0x%02X at log line %zu",
                        f.data[2] & 0x3F, f.data[0] & 0x3F, f.line);
          second_wrong = buf;
        }
      }
      if (f.len >= 3) second_seen |= f.data[2];
    } else if (f.id == analog && f.len >= 2) {
      ++n_an;
      loaded = loaded || static_cast<std::int16_t>(f.u16(0)) > 0;
    }
  }
  r.notes.push_back("I/O node " + std::to_string(io_node) + ": " + std::to_string(n_out) + " output RPDOs, " +
                    std::to_string(n_in) + " input TPDOs, " + std::to_string(n_an) + " load-cell TPDOs");
  const char* const in_names[] = {"piston A extended",  "piston A retracted", "piston B extended",
                                  "piston B retracted", "shuttle at left",    "shuttle at right",
                                  "e-stop chain closed"};
  std::string missing;
  if ((out_seen & 1) == 0) missing += ", valve A on";
  if ((out_seen & 2) == 0) missing += ", valve B on";
  for (int b = 0; b < 7; ++b) {
    if ((in_seen & (1 << b)) == 0) missing += std::string(", ") + in_names[b];
  }
  if (!loaded) missing += ", a load-cell force > 0";
  if (second_switches) {
    for (int b = 0; b < 6; ++b) {
      if ((second_seen & (1 << b)) == 0) missing += std::string(", ") + in_names[b] + " (second switch)";
    }
  }
  if (!missing.empty()) {
    r.ok = false;
    r.failure = "never seen on the bus: " + missing.substr(2);
  } else if (!second_wrong.empty()) {
    r.ok = false;
    r.failure = second_wrong;
  }
  return r;
}

namespace {
bool pdo_bit(const Frame& f, int bit) {
  const auto byte = static_cast<std::size_t>(bit / 8);
  return bit >= 0 && byte < f.len && ((f.data[byte] >> (bit % 8)) & 1U) != 0;
}
}  // namespace

CheckResult check_knotting(const std::vector<Frame>& frames, int io_node, const KnottingWiring& w) {
  CheckResult r;
  const std::size_t heads = w.gripper_bits.size();
  if (heads == 0 || w.cutter_bits.size() != heads || w.yarn_bits.size() != heads ||
      w.selector_nodes.size() != heads) {
    r.ok = false;
    r.failure = "the wiring needs one gripper, cutter and yarn-present bit and one selector node per head";
    return r;
  }
  const auto rpdo = static_cast<std::uint32_t>(0x200 + io_node);
  const auto tpdo = static_cast<std::uint32_t>(0x180 + io_node);
  const auto carriage = static_cast<std::uint32_t>(0x200 + w.carriage_node);
  struct Head {
    bool gripper = false, cutter = false, yarn = false, selector_known = false;
    bool awaiting_knot = false;  // a cut whose knot the switch has not shown yet
    int cuts = 0, knots = 0, selector_moves = 0;
    std::int32_t selector_target = 0;
  };
  std::vector<Head> h(heads);
  bool carriage_known = false;
  std::int32_t carriage_target = 0;
  int carriage_steps = 0;
  const auto fail = [&](const Frame& f, const std::string& what) {
    if (!r.ok) return;
    r.ok = false;
    r.failure = what + " (log line " + std::to_string(f.line) + ")";
  };
  const auto any_gripper = [&] {
    for (const Head& x : h) {
      if (x.gripper) return true;
    }
    return false;
  };
  for (const Frame& f : frames) {
    if (f.error_frame || f.rtr || f.extended) continue;
    if (f.id == rpdo && f.len >= 1) {
      for (std::size_t k = 0; k < heads; ++k) {
        const bool gripper = pdo_bit(f, w.gripper_bits[k]);
        const bool cutter = pdo_bit(f, w.cutter_bits[k]);
        const std::string head = "head " + std::to_string(k + 1);
        if (cutter && !h[k].cutter) {
          if (!gripper) fail(f, head + "'s cutter fired with its gripper open");
          if (h[k].awaiting_knot)
            fail(f, head + " cut again before the yarn-present switch showed its last knot");
          ++h[k].cuts;
          h[k].awaiting_knot = true;
        }
        h[k].gripper = gripper;
        h[k].cutter = cutter;
      }
    } else if (f.id == tpdo && f.len >= 1) {
      for (std::size_t k = 0; k < heads; ++k) {
        const bool yarn = pdo_bit(f, w.yarn_bits[k]);
        if (yarn && !h[k].yarn && h[k].awaiting_knot) {
          ++h[k].knots;
          h[k].awaiting_knot = false;
        }
        h[k].yarn = yarn;
      }
    } else if (f.id == carriage && f.len >= 6) {
      const auto target = static_cast<std::int32_t>(f.u32(2));
      if (carriage_known && target != carriage_target) {
        if (any_gripper()) fail(f, "the carriage moved while a gripper was closed");
        ++carriage_steps;
      }
      carriage_known = true;
      carriage_target = target;
    } else if (f.len >= 6) {
      for (std::size_t k = 0; k < heads; ++k) {
        if (f.id != static_cast<std::uint32_t>(0x200 + w.selector_nodes[k])) continue;
        const auto target = static_cast<std::int32_t>(f.u32(2));
        if (h[k].selector_known && target != h[k].selector_target) {
          if (h[k].gripper)
            fail(f, "head " + std::to_string(k + 1) + "'s selector turned under its closed gripper");
          ++h[k].selector_moves;
        }
        h[k].selector_known = true;
        h[k].selector_target = target;
      }
    }
  }
  for (std::size_t k = 0; k < heads; ++k) {
    const std::string head = "head " + std::to_string(k + 1);
    r.notes.push_back(head + ": " + std::to_string(h[k].cuts) + " cuts, " + std::to_string(h[k].knots) +
                      " knots seen by its yarn-present switch, selector target changed in " +
                      std::to_string(h[k].selector_moves) + " RPDOs");
    if (!r.ok) continue;
    if (h[k].cuts != w.knots_per_head || h[k].knots != w.knots_per_head) {
      r.ok = false;
      r.failure = head + ": " + std::to_string(h[k].cuts) + " cuts and " + std::to_string(h[k].knots) +
                  " knots seen, expected " + std::to_string(w.knots_per_head) + " of each";
    } else if (h[k].selector_moves == 0) {
      r.ok = false;
      r.failure = head + "'s selector never turned (the stripe has more than one colour)";
    }
  }
  r.notes.push_back("carriage target changed in " + std::to_string(carriage_steps) +
                    " RPDOs, none with a gripper closed");
  return r;
}

CheckResult check_emcy_stop(const std::vector<Frame>& frames, const std::vector<int>& nodes, int emcy_node) {
  CheckResult r;
  std::size_t k = 0;
  for (; k < frames.size(); ++k) {
    const Frame& f = frames[k];
    if (!f.error_frame && f.id == static_cast<std::uint32_t>(0x80 + emcy_node) && f.len == 8 && f.u16(0) != 0)
      break;
  }
  if (k == frames.size()) {
    r.ok = false;
    r.failure = "no EMCY with a non-zero code from node " + std::to_string(emcy_node);
    return r;
  }
  const Frame& emcy = frames[k];
  char buf[200];
  std::snprintf(buf, sizeof(buf), "EMCY 0x%04X from node %d at %s", emcy.u16(0), emcy_node,
                at_line(emcy).c_str());
  r.notes.push_back(buf);
  // The master reads the bus, ticks, then sends SYNC and the RPDOs. An EMCY that lands after the read is
  // seen by the next cycle: the RPDOs of the cycle in progress (up to the second SYNC after the EMCY)
  // were decided before it and may still enable; every RPDO1 after that SYNC must stop the drive.
  std::size_t deadline = k + 1;
  for (int syncs = 0; deadline < frames.size(); ++deadline) {
    if (const Frame& f = frames[deadline]; is_sync(f) && ++syncs == 2) break;
  }
  if (deadline == frames.size()) {
    r.ok = false;
    r.failure = "the log ends less than two SYNCs after the EMCY: the reaction cannot be judged";
    return r;
  }
  std::snprintf(buf, sizeof(buf), "one cycle to react: the second SYNC after the EMCY at %s (%.1f ms later)",
                at_line(frames[deadline]).c_str(),
                static_cast<double>(frames[deadline].t_us - emcy.t_us) * 1e-3);
  r.notes.push_back(buf);
  for (int node : nodes) {
    const Frame* first_stop = nullptr;  // the reaction: this node's first quick stop / disable after the EMCY
    bool judged = false;
    for (std::size_t j = k + 1; j < frames.size(); ++j) {
      const Frame& f = frames[j];
      if (f.error_frame || f.id != static_cast<std::uint32_t>(0x200 + node) || f.len < 2) continue;
      const std::uint16_t cw = f.u16(0);
      const bool stop = (cw & 0x0F) == 0x02 || (cw & 0x02) == 0;
      if (stop && first_stop == nullptr) first_stop = &f;
      if (j < deadline) continue;  // the cycle in progress: decided before the EMCY could be read
      if (!judged) {
        judged = true;
        if (!stop) {
          r.ok = false;
          std::snprintf(buf, sizeof(buf),
                        "node %d: first RPDO1 of the next cycle at %s (%.1f ms after the EMCY): controlword "
                        "0x%04X is not "
                        "quick stop (0x0002) or disable voltage",
                        node, at_line(f).c_str(), static_cast<double>(f.t_us - emcy.t_us) * 1e-3, cw);
          r.failure = buf;
          return r;
        }
      } else if ((cw & 0x0F) == 0x0F) {
        r.ok = false;
        std::snprintf(buf, sizeof(buf), "node %d re-enabled after the EMCY at %s (controlword 0x%04X)", node,
                      at_line(f).c_str(), cw);
        r.failure = buf;
        return r;
      }
    }
    if (!judged) {
      r.ok = false;
      r.failure = "no RPDO1 to node " + std::to_string(node) + " in the cycle after the EMCY";
      return r;
    }
    int syncs = 0;  // which cycle after the EMCY stopped the drive (1 = the first SYNC after it)
    for (const Frame* f = &emcy; f != first_stop; ++f) syncs += is_sync(*f) ? 1 : 0;
    std::snprintf(buf, sizeof(buf), "node %d: quick stop at %s, %.1f ms after the EMCY, in cycle %d after it",
                  node, at_line(*first_stop).c_str(),
                  static_cast<double>(first_stop->t_us - emcy.t_us) * 1e-3, syncs);
    r.notes.push_back(buf);
  }
  return r;
}

CheckResult check_feedback_lag(const std::vector<Frame>& frames, const std::vector<int>& nodes,
                               int max_cycles_late) {
  CheckResult r;
  char buf[200];
  for (int node : nodes) {
    int outstanding = 0;  // SYNCs since this node's last TPDO1
    std::size_t tpdos = 0, late = 0;
    int worst = 0;
    const Frame* worst_at = nullptr;
    for (const Frame& f : frames) {
      if (is_sync(f)) {
        ++outstanding;
      } else if (!f.error_frame && f.id == static_cast<std::uint32_t>(0x180 + node)) {
        ++tpdos;
        const int behind = outstanding - 1;  // cycles late: 0 when it answers the SYNC right before it
        if (behind > 0) ++late;
        if (behind > worst) worst = behind, worst_at = &f;
        outstanding = 0;
      }
    }
    if (tpdos == 0) {
      std::snprintf(buf, sizeof(buf), "node %d: no TPDO1 in the log", node);
      if (r.ok) r.ok = false, r.failure = buf;
    } else if (late == 0) {
      std::snprintf(buf, sizeof(buf), "node %d: %zu TPDO1s, each answering the SYNC right before it", node,
                    tpdos);
    } else {
      std::snprintf(buf, sizeof(buf),
                    "node %d: %zu TPDO1s, %zu of them late (worst %d cycle(s) behind, at %s)", node, tpdos,
                    late, worst, at_line(*worst_at).c_str());
    }
    r.notes.push_back(buf);
    if (worst > max_cycles_late && r.ok) {
      r.ok = false;
      r.failure = std::string(buf) + ": more than " + std::to_string(max_cycles_late) + " cycle(s) late";
    }
  }
  return r;
}

CheckResult check_master_loss(const std::vector<Frame>& frames, const std::vector<int>& nodes, int master,
                              double consumer_s, double slack_s) {
  CheckResult r;
  const Frame* last_hb = nullptr;
  for (const Frame& f : frames) {
    if (!f.error_frame && f.id == static_cast<std::uint32_t>(0x700 + master) && f.len == 1) last_hb = &f;
  }
  if (last_hb == nullptr) {
    r.ok = false;
    r.failure = "the master (node " + std::to_string(master) + ") never sent a heartbeat";
    return r;
  }
  r.notes.push_back("last master heartbeat at " + at_line(*last_hb));
  for (int node : nodes) {
    const Frame* emcy = nullptr;
    for (const Frame& f : frames) {
      if (f.line > last_hb->line && !f.error_frame && f.id == static_cast<std::uint32_t>(0x80 + node) &&
          f.len == 8 && f.u16(0) == 0x8130) {
        emcy = &f;
        break;
      }
    }
    if (emcy == nullptr) {
      r.ok = false;
      r.failure = "node " + std::to_string(node) + " sent no EMCY 0x8130 after the master's last heartbeat";
      return r;
    }
    const double dt = static_cast<double>(emcy->t_us - last_hb->t_us) * 1e-6;
    char buf[128];
    std::snprintf(buf, sizeof(buf), "node %d: EMCY 0x8130 %.0f ms after the last master heartbeat (%s)", node,
                  dt * 1e3, at_line(*emcy).c_str());
    r.notes.push_back(buf);
    if (dt > consumer_s + slack_s) {
      r.ok = false;
      r.failure = std::string(buf) + ": later than the consumer time + slack";
      return r;
    }
  }
  return r;
}

}  // namespace loom::hil
