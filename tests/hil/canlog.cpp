// Parser for `candump -L` lines. The format is can-utils' log format (lib.c: "(sec.usec) iface
// ID#DATA", ID with 3 hex digits for standard and 8 for extended/error frames, "R" for remote).
// Strict on purpose: a line we cannot read is reported, never skipped, so a check cannot pass on less.
#include "canlog.hpp"

#include <charconv>
#include <sstream>

namespace loom::hil {

namespace {

constexpr std::uint32_t kErrFlag = 0x20000000U;  // CAN_ERR_FLAG in linux/can.h
constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_hex_u32(std::string_view s, std::uint32_t& out) {
  if (s.empty() || s.size() > 8) return false;
  std::uint32_t v = 0;
  for (char c : s) {
    const int h = hex_value(c);
    if (h < 0) return false;
    v = (v << 4U) | static_cast<std::uint32_t>(h);
  }
  out = v;
  return true;
}

// "(1700000000.123456)" → microseconds. candump always prints six fraction digits.
bool parse_timestamp(std::string_view s, std::int64_t& t_us) {
  if (s.size() < 3 || s.front() != '(' || s.back() != ')') return false;
  s = s.substr(1, s.size() - 2);
  const auto dot = s.find('.');
  if (dot == std::string_view::npos || s.size() - dot - 1 != 6) return false;
  std::int64_t sec = 0;
  std::int64_t usec = 0;
  const auto* sb = s.data();
  auto r1 = std::from_chars(sb, sb + dot, sec);
  auto r2 = std::from_chars(sb + dot + 1, sb + s.size(), usec);
  if (r1.ec != std::errc{} || r1.ptr != sb + dot || r2.ec != std::errc{} || r2.ptr != sb + s.size()) {
    return false;
  }
  t_us = sec * 1'000'000 + usec;
  return true;
}

}  // namespace

std::uint16_t Frame::u16(std::size_t at) const {
  return static_cast<std::uint16_t>(data[at] | (data[at + 1] << 8U));
}

std::uint32_t Frame::u32(std::size_t at) const {
  return static_cast<std::uint32_t>(data[at]) | (static_cast<std::uint32_t>(data[at + 1]) << 8U) |
         (static_cast<std::uint32_t>(data[at + 2]) << 16U) |
         (static_cast<std::uint32_t>(data[at + 3]) << 24U);
}

std::int32_t Frame::i32(std::size_t at) const {
  return static_cast<std::int32_t>(u32(at));
}

std::optional<Frame> parse_candump_line(std::string_view line, std::string& error) {
  std::istringstream words{std::string(line)};
  std::string stamp;
  std::string iface;
  std::string record;
  std::string extra;
  if (!(words >> stamp >> iface >> record) || (words >> extra)) {
    error = "expected '(seconds.micros) iface ID#DATA', got '" + std::string(line) + "'";
    return std::nullopt;
  }
  Frame f;
  if (!parse_timestamp(stamp, f.t_us)) {
    error = "bad timestamp '" + stamp + "'";
    return std::nullopt;
  }
  const auto hash = record.find('#');
  if (hash == std::string::npos) {
    error = "no '#' in frame '" + record + "'";
    return std::nullopt;
  }
  const std::string_view id_text = std::string_view(record).substr(0, hash);
  std::string_view payload = std::string_view(record).substr(hash + 1);
  if (!payload.empty() && payload.front() == '#') {
    error = "CAN FD frame '" + record + "' (the loom bus is classic CAN)";
    return std::nullopt;
  }
  std::uint32_t raw_id = 0;
  if ((id_text.size() != 3 && id_text.size() != 8) || !parse_hex_u32(id_text, raw_id)) {
    error = "bad CAN id '" + std::string(id_text) + "' (3 or 8 hex digits)";
    return std::nullopt;
  }
  f.extended = id_text.size() == 8;
  f.error_frame = f.extended && (raw_id & kErrFlag) != 0;
  f.id = f.extended ? (raw_id & kEffMask) : raw_id;
  if (!f.extended && f.id > 0x7FFU) {
    error = "standard CAN id '" + std::string(id_text) + "' above 0x7FF";
    return std::nullopt;
  }
  if (!payload.empty() && (payload.front() == 'R' || payload.front() == 'r')) {
    f.rtr = true;
    return f;
  }
  if (payload.size() % 2 != 0 || payload.size() > 16) {
    error = "bad data '" + std::string(payload) + "' (0 to 8 bytes as hex pairs)";
    return std::nullopt;
  }
  for (std::size_t i = 0; i < payload.size() / 2; ++i) {
    const int hi = hex_value(payload[2 * i]);
    const int lo = hex_value(payload[2 * i + 1]);
    if (hi < 0 || lo < 0) {
      error = "bad data '" + std::string(payload) + "' (not hex)";
      return std::nullopt;
    }
    f.data[i] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  f.len = static_cast<std::uint8_t>(payload.size() / 2);
  return f;
}

bool read_candump_log(std::istream& in, std::vector<Frame>& frames, std::string& error) {
  std::string text;
  std::size_t number = 0;
  while (std::getline(in, text)) {
    ++number;
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::string why;
    auto f = parse_candump_line(text, why);
    if (!f) {
      error = "line " + std::to_string(number) + ": " + why;
      return false;
    }
    f->line = number;
    frames.push_back(*f);
  }
  return true;
}

}  // namespace loom::hil
