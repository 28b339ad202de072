// Little-endian field access for CANopen payloads (CiA 301 transmits every multi-byte value LSB first).
// Kept explicit rather than memcpy-ing host integers so the codecs are correct on any host byte order.
#pragma once

#include <cstddef>
#include <cstdint>

namespace loom::drivers {

// RT-safe.
inline std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
// RT-safe.
inline std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
// RT-safe. Two's complement reinterpretation (well defined since C++20).
inline std::int32_t get_i32(const std::uint8_t* p) noexcept {
  return static_cast<std::int32_t>(get_u32(p));
}
inline std::int16_t get_i16(const std::uint8_t* p) noexcept {
  return static_cast<std::int16_t>(get_u16(p));
}

// RT-safe.
inline void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v & 0xFF);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
// RT-safe.
inline void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (std::size_t i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFF);
}
inline void put_i32(std::uint8_t* p, std::int32_t v) noexcept {
  put_u32(p, static_cast<std::uint32_t>(v));
}
inline void put_i16(std::uint8_t* p, std::int16_t v) noexcept {
  put_u16(p, static_cast<std::uint16_t>(v));
}

}  // namespace loom::drivers
