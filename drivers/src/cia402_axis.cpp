// CiA 402 axis profile (see cia402_axis.hpp): SDO configuration at bring-up, and the per-tick
// exchange. The RT half touches only fixed fields; every fault it detects is latched here or in the
// master's NodeSupervisor and reported through hal::AxisFeedback, never thrown or logged.
#include "loom/drivers/cia402_axis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "loom/drivers/can_axis_port.hpp"
#include "loom/drivers/cob_id.hpp"
#include "loom/drivers/emcy.hpp"
#include "loom/drivers/pdo.hpp"
#include "loom/drivers/sdo.hpp"
#include "loom/drivers/sdo_client.hpp"

namespace loom::drivers {

using hal::AxisRequest;
using hal::DriveState;

namespace {
constexpr std::uint16_t kConsumerHeartbeat = 0x1016;
}  // namespace

void Cia402Axis::setup(const CanAxisConfig& a, const CanAxisPortConfig& port) {
  sdo_cfg_ =
      SdoSettings{port.cycle_period_s, port.heartbeat_producer_s, port.master_node_id, port.master_consumer_s,
                  port.tpdo2,          port.tpdo2_every_n_sync};
  label_ = "node " + std::to_string(a.node_id) + " (" + a.name + ")";
  node_ = a.node_id;
  bus_ = a.bus;
  description_ = a.description;
  timing_ = NodeTiming{a.boot_timeout_s > 0.0 ? a.boot_timeout_s : port.boot_timeout_s,
                       a.operational_timeout_s > 0.0 ? a.operational_timeout_s : port.operational_timeout_s,
                       port.heartbeat_consumer_s};
  cycle_period_s_ = port.cycle_period_s;
  tpdo2_wanted_ = port.tpdo2;
  counts_per_unit_ = a.counts_per_unit;
  rated_effort_ = a.rated_effort;
  ferror_min_ = a.ferror_min;
  ferror_k_s_ = a.ferror_k_s;
  homing_method_ = a.homing_method;
  home_offset_counts_ = static_cast<std::int32_t>(std::llround(a.home_offset * a.counts_per_unit));
  homing_speed_ = a.homing_speed;
  homing_accel_ = a.homing_accel;
  mode_ = a.mode;
  run_mode_ = mode_ == DriveMode::kProfilePosition ? od::kModeProfilePosition : od::kModeCsp;
  profile_velocity_ = a.profile_velocity;
  profile_acceleration_ = a.profile_acceleration;
  profile_jerk_ = a.profile_jerk;
  tpdo_inhibit_s_ = port.profile_tpdo_inhibit_s;
  tpdo_event_timer_s_ = port.profile_tpdo_event_timer_s;
  state_timeout_s_ = port.state_timeout_s;
  // A still PP axis' data stays current while its event-timer TPDO keeps coming: one event period, plus
  // half of one for the drive's and the bus' timing.
  fresh_ticks_ = static_cast<hal::Tick>(std::ceil(1.5 * tpdo_event_timer_s_ / cycle_period_s_ - 1e-9));
  bring_up_started();
}

void Cia402Axis::bring_up_started() {
  up_ = false;
  notes_.clear();
  position_ = PositionUnwrapper{};
  last_target_counts_ = 0;
  statusword_ = 0;
  state_ = DriveState::kUnknown;
  tracker_ = Cia402Tracker{};
  refreshed_ = hal::kNeverTick;
  last_position_si_ = velocity_ = effort_ = 0.0;
  last_cmd_si_ = cmd_velocity_ = 0.0;
  cmd_valid_ = ferror_fault_ = false;
  ferror_high_water_ = 0.0;
  has_consumer_ = has_tpdo2_ = false;
  // After every bring-up (a reset-node, a boot-up) an incremental encoder's count means nothing.
  referenced_ = homing_method_ == 0;
  homing_error_ = homing_commanded_ = false;
  mode_display_ = run_mode_;
  sent_any_ = false;
  last_sent_ = CanFrame{};
  last_cmd_target_ = 0.0;
  pp_have_ = pp_pending_ = pp_moving_ = false;
  pp_target_ = 0;
  pp_wait_ticks_ = pp_limit_ticks_ = 0;
  pp_fault_ = 0;
  pp_since_ = 0;
  still_ = false;
}

void Cia402Axis::brought_up(CanBus& /*bus*/) {
  up_ = true;
}

// ---------------------------------------------------------------------------------------------------
// Bring-up (configure-time only): the profile's part, between boot-up and NMT start
// ---------------------------------------------------------------------------------------------------
Status Cia402Axis::configure_profile(SdoClient& sdo) {
  const std::uint8_t node = node_;
  const std::string who = label_ + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };

  // The drive must offer the mode before we select it.
  Result<std::uint32_t> modes = sdo.read(node, od::kSupportedDriveModes, 0);
  if (!modes) return fail(modes.status());
  const bool pp = mode_ == DriveMode::kProfilePosition;
  if (pp && (modes.value() & od::kSupportsPpBit) == 0) {
    char buf[160];
    std::snprintf(buf, sizeof(buf),
                  "drive_mode = \"profile\" but the drive does not support profile position (0x6502 = "
                  "0x%08X, bit 0 clear)",
                  modes.value());
    return Status::error(who + buf);
  }
  if (!pp && (modes.value() & od::kSupportsCspBit) == 0) {
    char buf[128];
    std::snprintf(buf, sizeof(buf),
                  "the drive does not support cyclic synchronous position (0x6502 = 0x%08X, bit 7 clear)",
                  modes.value());
    return Status::error(who + buf);
  }
  if (homing_method_ != 0) {
    if (Status s = configure_homing(sdo, modes.value()); !s) return s;
  }
  if (Status s = sdo.write(node, od::kModesOfOperation, 0, static_cast<std::uint8_t>(run_mode_), 1); !s) {
    return fail(s);
  }
  Result<std::uint32_t> display = sdo.read(node, od::kModesOfOperationDisplay, 0);
  if (!display) return fail(display.status());
  const auto shown = static_cast<std::int8_t>(display.value() & 0xFF);
  if (shown != run_mode_) {
    return Status::error(who + "0x6061 (modes of operation display) reads " + std::to_string(shown) +
                         (pp ? " after writing 1 (profile position) to 0x6060"
                             : " after writing 8 (cyclic synchronous position) to 0x6060"));
  }
  if (pp) {
    if (Status s = configure_profile_position(sdo); !s) return s;
  }

  const auto producer_ms = static_cast<std::uint32_t>(std::lround(sdo_cfg_.heartbeat_producer_s * 1e3));
  if (Status s = sdo.write(node, od::kHeartbeatProducer, 0, producer_ms, 2); !s) return fail(s);

  const InterpolationPeriod ip = *encode_interpolation_period(sdo_cfg_.cycle_period_s);
  if (Status s = sdo.write(node, od::kInterpolationPeriod, 1, ip.value, 1); !s) return fail(s);
  if (Status s = sdo.write(node, od::kInterpolationPeriod, 2, static_cast<std::uint8_t>(ip.index), 1); !s) {
    return fail(s);
  }

  // The master's heartbeat watched by the drive (optional object: used when present, noted when absent).
  if (sdo_cfg_.master_node_id != 0) {
    const std::uint32_t v = (static_cast<std::uint32_t>(sdo_cfg_.master_node_id) << 16) |
                            static_cast<std::uint32_t>(std::lround(sdo_cfg_.master_consumer_s * 1e3));
    if (Status s = sdo.write(node, kConsumerHeartbeat, 1, v, 4); !s) {
      if (sdo.last_abort() != sdo_abort::kNoObject && sdo.last_abort() != sdo_abort::kNoSubIndex)
        return fail(s);
      notes_.push_back(who +
                       "0x1016 (consumer heartbeat time) absent: the drive will not stop by itself if the "
                       "master dies");
    } else {
      has_consumer_ = true;
    }
  }

  if (Status s = configure_pdos(sdo); !s) return s;

  // Seed the state machine and the first target from the drive, so enabling never jumps.
  Result<std::uint32_t> sw = sdo.read(node, od::kStatusword, 0);
  if (!sw) return fail(sw.status());
  Result<std::uint32_t> pos = sdo.read(node, od::kPositionActual, 0);
  if (!pos) return fail(pos.status());
  statusword_ = static_cast<std::uint16_t>(sw.value());
  state_ = decode_statusword(statusword_);
  position_.reset(static_cast<std::int32_t>(pos.value()));
  last_target_counts_ = position_.value();
  last_position_si_ = counts_to_si(position_.value(), counts_per_unit_);
  return Status::ok();
}

Status Cia402Axis::configure_pdos(SdoClient& sdo) {
  const bool homed = homing_method_ != 0;
  const std::uint8_t node = node_;
  const std::string who = label_ + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };
  // A module with a fixed mapping refuses writes with read-only (0x06010002) or unsupported access.
  const auto fixed_code = [&] {
    return sdo.last_abort() == sdo_abort::kReadOnly || sdo.last_abort() == sdo_abort::kUnsupportedAccess;
  };
  const auto read_map = [&](std::uint16_t map, std::array<std::uint32_t, 8>& e) -> Result<std::uint32_t> {
    Result<std::uint32_t> n = sdo.read(node, map, 0);
    if (!n) return n;
    if (n.value() > 8)
      return Status::error(describe_object(map, 0) + " = " + std::to_string(n.value()) + " (> 8)");
    for (std::uint32_t k = 0; k < n.value(); ++k) {
      Result<std::uint32_t> v = sdo.read(node, map, static_cast<std::uint8_t>(k + 1));
      if (!v) return v.status();
      e[k] = v.value();
    }
    return n;
  };
  // PDO mapping (CiA 301 re-map procedure): invalidate, clear count, write entries, set count, set
  // transmission type, validate. When the drive's mapping is fixed, read it back and accept it only if it
  // is exactly the layout the RT codec packs (pdo.hpp); otherwise refuse, naming what is missing.
  struct PdoPlan {
    std::uint16_t comm;
    std::uint16_t map;
    std::uint32_t cob_id;
    const PdoMapEntry* entries;
    std::uint8_t n_entries;
    std::uint8_t transmission_type;
    bool optional;  // used when the drive has it, noted when absent (TPDO2: velocity and torque)
  };
  // Profile position: RPDO1 and TPDO1 event-driven (255); TPDO1 with its inhibit time and event timer.
  const bool pp = mode_ == DriveMode::kProfilePosition;
  const std::uint8_t pdo1_type = pp ? od::kTransmissionEvent : 1;
  const PdoPlan plans[] = {
      {od::kRpdoComm, od::kRpdoMap, cob::rpdo(1, node),
       homed ? kRpdo1HomingMapping.data() : kRpdo1Mapping.data(), static_cast<std::uint8_t>(homed ? 3 : 2),
       pdo1_type, false},
      {od::kTpdoComm, od::kTpdoMap, cob::tpdo(1, node),
       homed ? kTpdo1HomingMapping.data() : kTpdo1Mapping.data(), static_cast<std::uint8_t>(homed ? 3 : 2),
       pdo1_type, false},
      {static_cast<std::uint16_t>(od::kTpdoComm + 1), static_cast<std::uint16_t>(od::kTpdoMap + 1),
       cob::tpdo(2, node), sdo_cfg_.tpdo2 ? kTpdo2Mapping.data() : nullptr,
       static_cast<std::uint8_t>(sdo_cfg_.tpdo2 ? 2 : 0), sdo_cfg_.tpdo2_every_n_sync, true},
      {static_cast<std::uint16_t>(od::kTpdoComm + 2), 0, cob::tpdo(3, node), nullptr, 0, 0, true},
      {static_cast<std::uint16_t>(od::kTpdoComm + 3), 0, cob::tpdo(4, node), nullptr, 0, 0, true},
  };
  for (const PdoPlan& p : plans) {
    // A node configured from its EDS (only what differs is written): a PDO that already carries exactly
    // the layout is not re-mapped (no invalidate, no clear).
    // (A PP drive's TPDO1 gets its inhibit time, which may change only while the PDO is invalid.)
    bool mapped = false;
    if (sdo.skips_unchanged() && p.entries != nullptr && !(pp && p.comm == od::kTpdoComm)) {
      std::array<std::uint32_t, 8> e{};
      Result<std::uint32_t> n = read_map(p.map, e);
      mapped = n && n.value() == p.n_entries;
      for (std::uint8_t k = 0; mapped && k < p.n_entries; ++k)
        mapped = e[k] == encode_map_entry(p.entries[k]);
    }
    if (!mapped) {
      if (Status s = sdo.write(node, p.comm, 1, p.cob_id | od::kPdoInvalidBit, 4); !s) {
        if (sdo.last_abort() == sdo_abort::kNoObject && p.optional) {
          // Nothing to disable; a wanted optional PDO the drive lacks is reported.
          if (p.entries != nullptr) {
            notes_.push_back(who + describe_object(p.comm, 1) +
                             " absent: no velocity/torque PDO, velocity is derived from positions");
          }
          continue;
        }
        if (!fixed_code()) return fail(s);
        if (p.entries == nullptr) continue;  // cannot disable a fixed PDO: the master ignores its frames
      }
      if (p.entries == nullptr) continue;
      bool fixed = false;
      if (Status s = sdo.write(node, p.map, 0, 0, 1); !s) {
        if (!fixed_code()) return fail(s);
        fixed = true;
      }
      if (!fixed) {
        for (std::uint8_t k = 0; k < p.n_entries; ++k) {
          if (Status s =
                  sdo.write(node, p.map, static_cast<std::uint8_t>(k + 1), encode_map_entry(p.entries[k]), 4);
              !s) {
            return fail(s);
          }
        }
        if (Status s = sdo.write(node, p.map, 0, p.n_entries, 1); !s) return fail(s);
      } else {
        std::array<std::uint32_t, 8> e{};
        Result<std::uint32_t> n = read_map(p.map, e);
        if (!n) return fail(n.status());
        bool same = n.value() == p.n_entries;
        for (std::uint8_t k = 0; same && k < p.n_entries; ++k) same = e[k] == encode_map_entry(p.entries[k]);
        if (!same) {
          std::string missing;
          for (std::uint8_t k = 0; k < p.n_entries; ++k) {
            char buf[48];
            std::snprintf(buf, sizeof(buf), "%s0x%04X (%s, %u bits) at entry %u", missing.empty() ? "" : ", ",
                          p.entries[k].index, object_name(p.entries[k].index), p.entries[k].bits, k + 1U);
            if (k >= n.value() || e[k] != encode_map_entry(p.entries[k])) missing += buf;
          }
          if (p.optional) {
            notes_.push_back(who + describe_object(p.map, 0) + " is fixed and lacks " + missing +
                             ": velocity is derived from positions");
            continue;
          }
          return Status::error(who + describe_object(p.map, 0) +
                               " is read-only and does not carry what the "
                               "master needs: missing " +
                               missing);
        }
        notes_.push_back(who + describe_object(p.map, 0) + " is fixed (read-only); read back and accepted");
      }
    }
    if (Status s = sdo.write(node, p.comm, 2, p.transmission_type, 1); !s) {
      if (!fixed_code()) return fail(s);
      Result<std::uint32_t> t = sdo.read(node, p.comm, 2);
      if (!t) return fail(t.status());
      const bool event = t.value() == 254 || t.value() == 255;
      if (p.transmission_type == od::kTransmissionEvent && !event) {
        return Status::error(
            who + describe_object(p.comm, 2) + " = " + std::to_string(t.value()) +
            " cannot be changed and is not event-driven (254/255), as profile position needs");
      }
      if (p.transmission_type != od::kTransmissionEvent && (t.value() < 1 || t.value() > 240)) {
        return Status::error(who + describe_object(p.comm, 2) + " = " + std::to_string(t.value()) +
                             " cannot be changed and is not synchronous (1..240)");
      }
    }
    if (pp && p.comm == od::kTpdoComm) {
      const auto inhibit = static_cast<std::uint32_t>(std::lround(tpdo_inhibit_s_ * 1e4));    // 100 µs
      const auto timer = static_cast<std::uint32_t>(std::lround(tpdo_event_timer_s_ * 1e3));  // ms
      if (Status s = sdo.write(node, p.comm, od::kPdoInhibitSub, inhibit, 2); !s) return fail(s);
      if (Status s = sdo.write(node, p.comm, od::kPdoEventTimerSub, timer, 2); !s) return fail(s);
    }
    if (Status s = sdo.write(node, p.comm, 1, p.cob_id, 4); !s) {
      if (!fixed_code()) return fail(s);
      Result<std::uint32_t> c = sdo.read(node, p.comm, 1);
      if (!c) return fail(c.status());
      if ((c.value() & od::kPdoInvalidBit) != 0 || (c.value() & 0x7FF) != p.cob_id) {
        return Status::error(who + describe_object(p.comm, 1) + " cannot be set to the pre-defined COB-ID");
      }
    }
    if (p.comm == od::kTpdoComm + 1) has_tpdo2_ = true;
  }
  return Status::ok();
}

// Profile position: the drive's own profile, from the limits the sequencer plans the axis' moves with
// (in counts), and its shape as the drive offers it: jerk-limited when it takes 3, else a linear ramp.
Status Cia402Axis::configure_profile_position(SdoClient& sdo) {
  const std::string who = label_ + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };
  if (!(profile_velocity_ > 0.0) || !(profile_acceleration_ > 0.0)) {
    return Status::error(who + "profile position needs the axis' speed and acceleration limits (0x6081, " +
                         "0x6083): none were given");
  }
  const auto counts = [&](double si) {
    const double c = std::min(si * counts_per_unit_, 4294967295.0);
    return std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::llround(c)));
  };
  if (Status s = sdo.write(node_, od::kProfileVelocity, 0, counts(profile_velocity_), 4); !s) return fail(s);
  if (Status s = sdo.write(node_, od::kProfileAcceleration, 0, counts(profile_acceleration_), 4); !s)
    return fail(s);
  if (Status s = sdo.write(node_, od::kProfileDeceleration, 0, counts(profile_acceleration_), 4); !s)
    return fail(s);
  const auto jerk_limited = static_cast<std::uint16_t>(od::kProfileJerkLimited);
  if (Status s = sdo.write(node_, od::kMotionProfileType, 0, jerk_limited, 2); !s) {
    const std::uint32_t abort = sdo.last_abort();
    if (abort != sdo_abort::kNoObject && abort != sdo_abort::kValueRange && abort != sdo_abort::kValueTooHigh)
      return fail(s);
    if (abort != sdo_abort::kNoObject) {
      if (Status l = sdo.write(node_, od::kMotionProfileType, 0,
                               static_cast<std::uint16_t>(od::kProfileLinearRamp), 2);
          !l)
        return fail(l);
    }
    notes_.push_back(who + "0x6086 (motion profile type): no jerk-limited profile offered; the drive runs " +
                     "a linear ramp (trapezoid), no jerk limit");
    profile_jerk_ = 0.0;
  }
  return Status::ok();
}

// The homing run's parameters, in drive units, so the RT path only switches the mode and starts it.
Status Cia402Axis::configure_homing(SdoClient& sdo, std::uint32_t supported_modes) {
  const std::string who = label_ + ": ";
  const auto fail = [&](const Status& s) { return Status::error(who + s.message()); };
  if ((supported_modes & od::kSupportsHomingBit) == 0) {
    char buf[160];
    std::snprintf(
        buf, sizeof(buf),
        "referencing = \"homing\" but the drive does not offer homing mode (0x6502 = 0x%08X, bit 5 clear)",
        supported_modes);
    return Status::error(who + buf);
  }
  const auto counts = [&](double si) {
    return static_cast<std::uint32_t>(std::llround(si * counts_per_unit_));
  };
  if (Status s = sdo.write(node_, od::kHomingMethod, 0, static_cast<std::uint8_t>(homing_method_), 1); !s)
    return fail(s);
  if (Status s = sdo.write(node_, od::kHomeOffset, 0, static_cast<std::uint32_t>(home_offset_counts_), 4);
      !s) {
    return fail(s);
  }
  if (homing_method_ != 37) {  // 37 sets the current position: no travel, no speeds
    const std::uint32_t fast = std::max<std::uint32_t>(1, counts(homing_speed_));
    if (Status s = sdo.write(node_, od::kHomingSpeeds, 1, fast, 4); !s) return fail(s);
    if (Status s = sdo.write(node_, od::kHomingSpeeds, 2, std::max<std::uint32_t>(1, fast / 4), 4); !s)
      return fail(s);
    if (Status s = sdo.write(node_, od::kHomingAcceleration, 0,
                             std::max<std::uint32_t>(1, counts(homing_accel_)), 4);
        !s) {
      return fail(s);
    }
  }
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void Cia402Axis::on_profile_frame(hal::Tick now, const CanFrame& f) noexcept {
  switch (decode_cob_id(f.id).function) {
    case CobFunction::kTpdo1: {
      Tpdo1Mode p{};
      if (homing_method_ == 0) {
        const auto q = unpack_tpdo1(f, node_);
        if (q) p = Tpdo1Mode{q->statusword, q->position_actual, run_mode_};
        if (!q) {
          ++rx_errors_;
          return;
        }
      } else {
        const auto q = unpack_tpdo1_mode(f, node_);
        if (!q) {
          ++rx_errors_;
          return;
        }
        p = *q;
      }
      statusword_ = p.statusword;
      state_ = decode_statusword(p.statusword);
      mode_display_ = p.mode_display;
      if (homing_method_ != 0 && mode_display_ == od::kModeHoming && homing_commanded_) {
        // CiA 402 homing mode: bit 12 homing attained (with bit 10, target reached), bit 13 homing error.
        // An error wins (bits 12 and 13 together are reserved, not a success) and stays latched until
        // acknowledged: the axis is not referenced, and no later "attained" of that run makes it so.
        if ((statusword_ & statusword::kHomingError) != 0) {
          homing_error_ = true;
          referenced_ = false;
        } else if (!referenced_ && !homing_error_ && (statusword_ & statusword::kHomingAttained) != 0 &&
                   (statusword_ & statusword::kTargetReached) != 0) {
          referenced_ = true;
          position_.reset(p.position_actual);  // the count jumped to the home offset: a new origin
          last_position_si_ = counts_to_si(position_.value(), counts_per_unit_);
          refreshed_ = hal::kNeverTick;  // no velocity across the jump
        }
      }
      const double pos = counts_to_si(position_.update(p.position_actual), counts_per_unit_);
      if (!tpdo2_wanted_ && refreshed_ != hal::kNeverTick && now > refreshed_) {
        velocity_ = (pos - last_position_si_) / (static_cast<double>(now - refreshed_) * cycle_period_s_);
      }
      last_position_si_ = pos;
      refreshed_ = now;
      // PP: a drive that says it stands (power stage off, or target reached) sends again only on change.
      const bool can_move = state_ == DriveState::kOperationEnabled ||
                            state_ == DriveState::kQuickStopActive ||
                            state_ == DriveState::kFaultReactionActive;
      still_ = !can_move || (statusword_ & statusword::kTargetReached) != 0;
      if (mode_ == DriveMode::kProfilePosition && still_ && !tpdo2_wanted_) velocity_ = 0.0;
      // Following error against the target commanded before this feedback (LinuxCNC's velocity-scaled rule).
      if (ferror_min_ > 0.0 && cmd_valid_ && state_ == DriveState::kOperationEnabled &&
          mode_display_ == od::kModeCsp) {
        const double err = std::abs(last_cmd_si_ - pos);
        if (err > ferror_high_water_) ferror_high_water_ = err;
        if (err > std::max(ferror_min_, ferror_k_s_ * std::abs(cmd_velocity_))) ferror_fault_ = true;
      }
      return;
    }
    case CobFunction::kTpdo2: {
      const auto p = unpack_tpdo2(f, node_);
      if (!p || !tpdo2_wanted_) {
        ++rx_errors_;
        return;
      }
      velocity_ = static_cast<double>(p->velocity_actual) / counts_per_unit_;
      effort_ = static_cast<double>(p->torque_actual) * rated_effort_ / 1000.0;
      return;
    }
    default:
      return;  // SDO replies to someone else's tool, our own RPDO echo, ...
  }
}

bool Cia402Axis::faulted() const noexcept {
  return supervisor_.link_fault() != 0 || supervisor_.emcy_code() != 0 || ferror_fault_ || pp_fault_ != 0 ||
         state_ == DriveState::kFault || state_ == DriveState::kFaultReactionActive;
}

void Cia402Axis::fill_feedback(hal::Tick now, hal::AxisFeedback& fb, bool bus_off,
                               bool bus_configured) noexcept {
  const bool link_down = bus_off || !bus_configured || !up_;
  const std::uint16_t link_fault = supervisor_.link_fault();
  const std::uint16_t emcy = supervisor_.emcy_code();
  fb.state = state_;
  fb.position = counts_to_si(position_.value(), counts_per_unit_);
  fb.velocity = velocity_;
  fb.effort = effort_;
  fb.refreshed = refreshed_;
  if (mode_ == DriveMode::kProfilePosition && still_ && refreshed_ != hal::kNeverTick && now >= refreshed_ &&
      now - refreshed_ <= fresh_ticks_) {
    // Current now, or, with a set-point on its way, as of the tick it was raised (the drive stood then).
    fb.refreshed = pp_pending_ || pp_moving_ ? std::max(refreshed_, std::min(now, pp_since_)) : now;
  }
  fb.referenced = referenced_;
  fb.homing_error = homing_error_;
  fb.following_error = state_ == DriveState::kOperationEnabled && mode_display_ == od::kModeCsp &&
                       (statusword_ & statusword::kCspFollowingError) != 0;
  const bool in_fault_state = state_ == DriveState::kFault || state_ == DriveState::kFaultReactionActive;
  // An EMCY from a drive that stays enabled is reported by its kind and code alone (the HAL's contract:
  // the sequencer latches drive_emcy and stops every axis, as for a drive fault); `fault` means the drive
  // itself is in Fault (or the link or our own supervision says so).
  const bool drive_fault = in_fault_state || ferror_fault_ || pp_fault_ != 0;
  fb.fault = link_down || link_fault != 0 || drive_fault || tracker_.timed_out;
  if (link_fault != 0) {
    fb.fault_code = link_fault;
    fb.fault_kind = hal::FaultKind::kNodeLost;
  } else if (link_down) {
    fb.fault_code = fault_code::kCommunication;
    fb.fault_kind = bus_off ? hal::FaultKind::kBusOff : hal::FaultKind::kCommunication;
  } else if (emcy != 0) {
    fb.fault_code = emcy;
    fb.fault_kind = in_fault_state ? hal::FaultKind::kDrive : hal::FaultKind::kEmcy;
  } else if (ferror_fault_) {
    fb.fault_code = fault_code::kFollowingError;
    fb.fault_kind = hal::FaultKind::kDrive;
  } else if (pp_fault_ != 0) {
    fb.fault_code = pp_fault_;
    fb.fault_kind = hal::FaultKind::kDrive;
  } else if (tracker_.timed_out) {
    fb.fault_code = fault_code::kStateTimeout;
    fb.fault_kind = hal::FaultKind::kDrive;
  } else {
    fb.fault_code = fault_code::kNone;
    fb.fault_kind = in_fault_state ? hal::FaultKind::kDrive : hal::FaultKind::kNone;
  }
  fault_edge_.raise(fb);
}

// The operator acknowledged (the sequencer requests a fault reset): latches whose cause the master
// itself decided are cleared; a drive still in Fault gets its reset edge through the CiA 402 table.
void Cia402Axis::acknowledge() noexcept {
  ferror_fault_ = false;
  pp_fault_ = 0;
  homing_error_ = false;
  supervisor_.acknowledge(state_ == DriveState::kFault || state_ == DriveState::kFaultReactionActive);
}

bool Cia402Axis::command(hal::Tick now, const hal::AxisCommand& cmd, bool stop_all, bool bus_down,
                         std::uint32_t state_timeout_ticks, CanFrame& rpdo1) noexcept {
  // A drive we cannot supervise (lost, rebooted, bus-off) gets quick stop, never an enable command.
  const bool lost = supervisor_.link_fault() != 0 || bus_down;
  // A homing run is an enabled drive in homing mode (6) with controlword bit 4 set; an absolute axis has
  // nothing to run and is simply enabled.
  const bool homing = cmd.request == AxisRequest::kHome && homing_method_ != 0 && !referenced_;
  const AxisRequest wanted_request = cmd.request == AxisRequest::kHome ? AxisRequest::kEnable : cmd.request;
  const AxisRequest request = lost || (stop_all && wanted_request != AxisRequest::kFaultReset &&
                                       wanted_request != AxisRequest::kDisable)
                                  ? AxisRequest::kQuickStop
                                  : wanted_request;
  const Cia402Step step = cia402_step(state_, request, tracker_, state_timeout_ticks);
  tracker_ = step.next;
  std::uint16_t controlword = step.controlword;
  const std::int8_t mode = homing && request == AxisRequest::kEnable ? od::kModeHoming : run_mode_;
  if (mode == od::kModeHoming && state_ == DriveState::kOperationEnabled &&
      mode_display_ == od::kModeHoming && controlword == controlword::kEnableOperation && !homing_error_) {
    controlword |=
        controlword::kHomingStart;  // the drive starts on its rising edge and runs while it is held
    homing_commanded_ = true;
  }
  if (mode != od::kModeHoming) homing_commanded_ = false;

  const bool running = state_ == DriveState::kOperationEnabled &&
                       step.controlword == controlword::kEnableOperation && mode == run_mode_ &&
                       mode_display_ == run_mode_ && referenced_;
  std::int64_t target = position_.value();
  if (mode_ == DriveMode::kProfilePosition) {
    // The target field is the drive's set-point: it changes only with a new one (bit 4 rising), so an
    // idle axis' RPDO1 stays the same and is not sent.
    controlword |= profile_setpoint(now, cmd, running && mode != od::kModeHoming, state_timeout_ticks);
    target = sent_any_ ? last_target_counts_ : position_.value();
    if ((controlword & controlword::kNewSetpoint) != 0 && mode != od::kModeHoming) target = pp_target_;
  } else {
    // Outside Operation Enabled in CSP the target follows the actual position, so enabling never jumps;
    // an unreferenced axis is never moved (its count means nothing yet).
    const double wanted = cmd.target_position;
    if (running && std::isfinite(wanted)) target = si_to_counts(wanted, counts_per_unit_);
  }
  const double cmd_si = counts_to_si(target, counts_per_unit_);
  cmd_velocity_ = cmd_valid_ ? (cmd_si - last_cmd_si_) / cycle_period_s_ : 0.0;
  last_cmd_si_ = cmd_si;
  cmd_valid_ = true;
  last_target_counts_ = target;
  const CanFrame f = homing_method_ == 0
                         ? pack_rpdo1(node_, Rpdo1{controlword, wire_counts(target)})
                         : pack_rpdo1_mode(node_, Rpdo1Mode{controlword, wire_counts(target), mode});
  rpdo1 = f;
  if (mode_ == DriveMode::kProfilePosition && sent_any_ && f.id == last_sent_.id && f.dlc == last_sent_.dlc &&
      f.data == last_sent_.data) {
    return false;  // nothing changed: an event-driven RPDO is not repeated
  }
  sent_any_ = true;
  last_sent_ = f;
  return true;
}

// The trapezoid (or jerk-limited trapezoid) the drive runs from 0x6081/0x6083/0x6084 over `distance`,
// plus a quarter of it and the state timeout for the drive's start and the last TPDO's way back.
std::uint32_t Cia402Axis::profile_move_ticks(std::int64_t distance_counts) const {
  const double d = std::abs(static_cast<double>(distance_counts)) / counts_per_unit_;
  const double v = profile_velocity_, a = profile_acceleration_;
  double t = d * a >= v * v ? d / v + v / a : 2.0 * std::sqrt(d / a);
  if (profile_jerk_ > 0.0) t += a / profile_jerk_;
  const double limit = 1.25 * t + state_timeout_s_;
  return static_cast<std::uint32_t>(std::ceil(limit / cycle_period_s_));
}

// Profile position's set-point handshake (CiA 402): the target and bit 4 up; the drive acknowledges with
// statusword bit 12; bit 4 down; the drive drops bit 12 and reports target reached with bit 10. The
// set-point is the end of the move the sequencer's per-tick target is on (AxisCommand::move_end) while
// that target moves or has arrived there, else the per-tick target itself (a hold, a stop: never the end
// of a move no longer being played). Returns the bits to OR into the controlword.
std::uint16_t Cia402Axis::profile_setpoint(hal::Tick now, const hal::AxisCommand& cmd, bool running,
                                           std::uint32_t state_timeout_ticks) noexcept {
  const double t = cmd.target_position;
  const bool on_move = std::isfinite(cmd.move_end) && (t != last_cmd_target_ || t == cmd.move_end);
  last_cmd_target_ = t;
  if (!running) {  // quick stop, disable, fault, homing: the drive forgets its set-point
    pp_have_ = pp_pending_ = pp_moving_ = false;
    pp_wait_ticks_ = 0;
    return 0;
  }
  const std::uint16_t handshake = controlword::kNewSetpoint | controlword::kChangeImmediately;
  const bool ack = (statusword_ & statusword::kSetpointAcknowledge) != 0;
  if (pp_pending_) {
    if (!ack) {
      if (++pp_wait_ticks_ > state_timeout_ticks && pp_fault_ == 0)
        pp_fault_ = fault_code::kSetpointNotAcknowledged;
      return handshake;
    }
    pp_pending_ = false;  // acknowledged: release bit 4 in this very tick
    pp_moving_ = true;
    pp_wait_ticks_ = 0;
    return 0;
  }
  if (pp_moving_) {
    if (!ack && (statusword_ & statusword::kTargetReached) != 0) {
      pp_moving_ = false;
    } else if (++pp_wait_ticks_ > pp_limit_ticks_) {
      if (pp_fault_ == 0) pp_fault_ = fault_code::kTargetNotReached;
      pp_moving_ = false;
    }
  }
  const double wanted = on_move ? cmd.move_end : t;
  if (ack || !std::isfinite(wanted)) return 0;  // the drive still shows the last acknowledge
  const std::int64_t w = si_to_counts(wanted, counts_per_unit_);
  if (w == (pp_have_ ? pp_target_ : position_.value())) return 0;
  pp_limit_ticks_ = profile_move_ticks(w - position_.value());
  pp_target_ = w;
  pp_have_ = pp_pending_ = true;
  pp_moving_ = false;
  pp_wait_ticks_ = 0;
  pp_since_ = now;
  ++pp_setpoints_;
  return handshake;
}

}  // namespace loom::drivers
