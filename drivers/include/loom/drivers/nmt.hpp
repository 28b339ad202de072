// CiA 301 network management on the wire: NMT commands (master → nodes), SYNC, and the NMT error-control
// frame every node produces (boot-up and heartbeat). Pure encoders/decoders, shared by the master and the
// simulated drive node so both ends speak from the same facts.
#pragma once

#include <cstdint>
#include <optional>

#include "loom/drivers/can_frame.hpp"

namespace loom::drivers {

enum class NmtCommand : std::uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

// States a node reports in its error-control frame (0x700 + id, 1 byte).
enum class NmtState : std::uint8_t {
  kBootUp = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};
// RT-safe (static string).
const char* nmt_state_name(NmtState s) noexcept;

// RT-safe. NMT command for one node (1..127) or all nodes (0).
CanFrame make_nmt(NmtCommand command, std::uint8_t node) noexcept;
struct NmtMessage {
  NmtCommand command;
  std::uint8_t node;  // 0 = all nodes
};
// RT-safe. nullopt unless id 0x000, DLC 2 and a known command specifier.
std::optional<NmtMessage> parse_nmt(const CanFrame& frame) noexcept;

// RT-safe. SYNC without counter (0x1019 = 0): id 0x080, DLC 0.
CanFrame make_sync() noexcept;
bool is_sync(const CanFrame& frame) noexcept;

// RT-safe. Heartbeat / boot-up frame of `node`.
CanFrame make_heartbeat(std::uint8_t node, NmtState state) noexcept;
struct Heartbeat {
  std::uint8_t node;
  NmtState state;
};
// RT-safe. nullopt unless id 0x701..0x77F, DLC 1 and a known state (toggle bit 7 is ignored).
std::optional<Heartbeat> parse_heartbeat(const CanFrame& frame) noexcept;

}  // namespace loom::drivers
