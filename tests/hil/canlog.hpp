// Reading `candump -L` logs: the HIL tests judge what crossed the bus from can-utils' own record, not
// from anything loomctl reports about itself. Plain data plus a line parser that names what is wrong.
// Everything here is test tooling (configure-time only in RT terms: it allocates freely).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace loom::hil {

// One classic CAN frame as candump -L logged it.
struct Frame {
  std::int64_t t_us = 0;  // candump's timestamp, microseconds since the epoch
  std::uint32_t id = 0;   // 11-bit (or 29-bit when `extended`)
  bool extended = false;
  bool rtr = false;
  bool error_frame = false;  // CAN_ERR_FLAG set: not a bus frame, a controller report
  std::uint8_t len = 0;      // data bytes, 0..8
  std::array<std::uint8_t, 8> data{};
  std::size_t line = 0;  // 1-based line in the log, for messages

  // Little-endian fields as CANopen lays them out. Callers check `len` first.
  std::uint16_t u16(std::size_t at) const;
  std::int32_t i32(std::size_t at) const;
  std::uint32_t u32(std::size_t at) const;
};

// Parses one line such as "(1700000000.123456) vcan0 701#00". Returns nothing and sets `error` (which
// names the offending part) when the line is not a classic-CAN candump -L record.
std::optional<Frame> parse_candump_line(std::string_view line, std::string& error);

// Reads a whole log; blank lines are skipped. On the first bad line returns false with
// "line N: <why>" in `error`.
bool read_candump_log(std::istream& in, std::vector<Frame>& frames, std::string& error);

}  // namespace loom::hil
