// Any CAN frame a bus can deliver, drawn from the fuzzer's input: data, remote or error frame, any
// standard id (an error frame's id holds its error class bits), any length, any bytes. Shared by the
// harnesses that feed a port frame by frame, so they consume their input the same way.
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include <cstdint>

#include "loom/drivers/can_frame.hpp"

namespace loom::fuzz {

inline drivers::CanFrame any_frame(FuzzedDataProvider& in) {
  drivers::CanFrame f;
  f.flags = in.ConsumeIntegral<std::uint8_t>() & (drivers::CanFrame::kError | drivers::CanFrame::kRtr);
  f.id = f.is_error() ? in.ConsumeIntegral<std::uint32_t>()
                      : in.ConsumeIntegral<std::uint16_t>() & drivers::kMaxStandardId;
  f.dlc = in.ConsumeIntegralInRange<std::uint8_t>(0, 8);
  for (auto& b : f.data) b = in.ConsumeIntegral<std::uint8_t>();
  return f;
}

}  // namespace loom::fuzz
