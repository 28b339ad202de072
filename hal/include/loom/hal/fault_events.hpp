// Device-fault events: a port raises AxisFeedback::fault_raised / LinkStatus::fault_raised on the read
// in which a device's fault report begins (or, for an axis, its code changes), so the loop reports each
// once without keeping the devices' last reports itself. Each port keeps one edge per axis and one for its
// link, beside the record the fault latches in, and applies it to what its read hands out (a value a
// read leaves untouched, e.g. a lost frame's, is the same report: no new event).
#pragma once

#include <cstdint>

#include "loom/hal/types.hpp"

namespace loom::hal {

// RT-safe. The axis reports a fault: the drive says Fault or Fault reaction active, or the port lost it.
inline bool axis_faulted(const AxisFeedback& a) noexcept {
  return a.fault || a.state == DriveState::kFault || a.state == DriveState::kFaultReactionActive;
}

// One axis' fault report, from one read to the next.
class AxisFaultEdge {
 public:
  // RT-safe. Sets fb.fault_raised: faulted now, and healthy on the last read or with another code.
  void raise(AxisFeedback& fb) noexcept {
    const bool faulted = axis_faulted(fb);
    fb.fault_raised = faulted && (!faulted_ || fb.fault_code != code_);
    faulted_ = faulted;
    code_ = faulted ? fb.fault_code : 0;
  }

 private:
  bool faulted_ = false;
  std::uint16_t code_ = 0;
};

// The link's fault report: an event when it begins (a later code on a faulted link is not a new one).
class LinkFaultEdge {
 public:
  // RT-safe. Sets link.fault_raised.
  void raise(LinkStatus& link) noexcept {
    link.fault_raised = link.link_fault && !faulted_;
    faulted_ = link.link_fault;
  }

 private:
  bool faulted_ = false;
};

}  // namespace loom::hal
