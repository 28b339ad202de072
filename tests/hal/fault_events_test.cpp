// The device-fault events a port raises (hal/fault_events.hpp), over hand-written report sequences: an
// axis' event on the read its fault report begins or changes its code, none while it stands or is
// cleared; the link's when its report begins.
#include "loom/hal/fault_events.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace loom::hal {
namespace {

struct Report {
  DriveState state;
  bool fault;
  std::uint16_t code;
  bool event;  // expected
};

TEST(AxisFaultEdge, RaisesWhenAReportBeginsOrChangesItsCode) {
  const std::vector<Report> reads = {
      {DriveState::kOperationEnabled, false, 0, false},
      {DriveState::kOperationEnabled, false, 0x8611, false},  // an EMCY alone: not a fault report
      {DriveState::kFaultReactionActive, false, 0, true},     // the drive's state is a fault report
      {DriveState::kFault, false, 0, false},                  // same report, same code
      {DriveState::kFault, false, 0x2310, true},              // its EMCY's code follows
      {DriveState::kFault, true, 0x2310, false},
      {DriveState::kSwitchOnDisabled, false, 0, false},     // cleared
      {DriveState::kSwitchOnDisabled, true, 0x8130, true},  // the port lost the node
      {DriveState::kSwitchOnDisabled, true, 0x8130, false},
      {DriveState::kSwitchOnDisabled, false, 0x8130, false},  // cleared (a code without a fault)
      {DriveState::kSwitchOnDisabled, true, 0x8130, true},    // the same code again is a new report
  };
  AxisFaultEdge edge;
  for (std::size_t k = 0; k < reads.size(); ++k) {
    AxisFeedback fb;
    fb.state = reads[k].state;
    fb.fault = reads[k].fault;
    fb.fault_code = reads[k].code;
    fb.fault_raised = !reads[k].event;  // whatever the last read left: the edge sets it
    edge.raise(fb);
    EXPECT_EQ(fb.fault_raised, reads[k].event) << "read " << k;
  }
}

TEST(LinkFaultEdge, RaisesWhenTheLinkReportBegins) {
  struct Link {
    bool fault;
    std::uint16_t code;
    bool event;
  };
  const std::vector<Link> reads = {{false, 0, false},     {true, 0x8130, true}, {true, 0x8140, false},
                                   {true, 0x8140, false}, {false, 0, false},    {true, 0x8140, true}};
  LinkFaultEdge edge;
  for (std::size_t k = 0; k < reads.size(); ++k) {
    LinkStatus link;
    link.link_fault = reads[k].fault;
    link.link_fault_code = reads[k].code;
    link.fault_raised = !reads[k].event;
    edge.raise(link);
    EXPECT_EQ(link.fault_raised, reads[k].event) << "read " << k;
  }
}

}  // namespace
}  // namespace loom::hal
