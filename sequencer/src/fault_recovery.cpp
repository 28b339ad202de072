// One recovery per fault. No default case: with -Wswitch (in -Wall) and LOOM_WERROR a new fault in
// LOOM_FAULT_TABLE does not build until it says here what the operator does about it.
#include "loom/sequencer/fault_recovery.hpp"

namespace loom::sequencer {

const char* fault_recovery(Fault f) {
  switch (f) {
    case Fault::kNone:
      return "nothing to do";
    case Fault::kEStop:
      return "find why the chain opened, close it, ack, start";
    case Fault::kStopRequested:
      return "ack, start";
    case Fault::kDriveFault:
    case Fault::kDriveEmcy:
      return "read the drive's code (device code in the FAULT line), fix the cause, ack (the drives get a "
             "fault reset)";
    case Fault::kEnableTimeout:
      return "check the drive's power stage, its enable input and its own fault display; ack, start";
    case Fault::kHeartbeatLost:
    case Fault::kLinkFault:
    case Fault::kStaleFeedback:
      return "check cabling, node power and bus termination; ack when the bus is back (`loomctl ctl status` "
             "shows `link=` "
             "while something is missing; an early ack is refused)";
    case Fault::kLoopStall:
      return "check the controller's load and real-time set-up (and the bus); ack";
    case Fault::kNonFiniteFeedback:
    case Fault::kEncoderJump:
      return "check the encoder and its cable (a runaway simulated crank, e.g. absurd friction, also ends "
             "here); ack";
    case Fault::kLoadCellFault:
      return "check the load cell and its amplifier; ack";
    case Fault::kShedTimeout:
    case Fault::kShedNotReleased:
    case Fault::kAirLost:
      return "check air pressure, the valves, a jammed frame and the end sensors; ack";
    case Fault::kSensorDiscrepancy:
      return "one switch of the named sensor is stuck, loose or miswired: `loomctl commission --io-once` "
             "shows both; fix it, ack";
    case Fault::kShedSensorEarly:
    case Fault::kShedSensorConflict:
      return "a stuck or miswired reed switch: check it before acknowledging";
    case Fault::kShedSensorLate:
      return "a frame dragging or stuck on its way (air, seal, guide), or a sensor claiming an arrival: "
             "check, ack";
    case Fault::kShuttleLost:
    case Fault::kShuttleNotArrived:
    case Fault::kShuttleSlipped:
    case Fault::kShuttleSensorEarly:
    case Fault::kShuttleSensorConflict:
      return "clear the shed by hand, put the shuttle at the selvedge the counters expect, check the carrier "
             "magnet "
             "and the arrival sensors; ack";
    case Fault::kShuttleSideMismatch:
    case Fault::kCountersInconsistent:
      return "check the last weft in the cloth, correct the counters file (or the shuttle), then start";
    case Fault::kCountersNotSaved:
      return "free the disk or fix the directory. `serve`: ack writes the counters it holds, then re-arms "
             "from them. "
             "`weave` (exit 3): write its FAULT line's counts into the counters file before the next run";
    case Fault::kLoopOverrun:
      return "find what starves the loop thread (CPU isolation, other real-time load); ack";
    case Fault::kKnotServoLag:
      return "look at the head's linkage and gripper for yarn or a jam, turn it freely by hand with the "
             "drive off; ack "
             "(the knot being tied is asked of the weaver, never tied twice)";
    case Fault::kShedLost:
      return "check the air supply, the valves and both frames' end sensors (a switch that lets go reads "
             "like a frame "
             "that moved); ack (the knot being tied is asked of the weaver)";
    case Fault::kCarriageNotAtKnot:
      return "look along the carriage's rail for a jam or a stiff spot and at its drive's following error "
             "and feedback delay (the FAULT line names the knot, how far off it was and the tolerance); "
             "ack (no knot was tied there: the cycle had not started)";
    case Fault::kSelectorJam:
      return "clear the head's colour magazine (a yarn end caught between slots), check it indexes freely; "
             "ack";
    case Fault::kYarnSensorStuck:
      return "look at the knot position: a knot already there was tied before (leave it, the counters are "
             "wrong: check "
             "them); no knot there: the head's yarn-present switch is stuck or miswired; ack";
    case Fault::kHomingFailed:
      return "check the named axis' home switch or index pulse, its cabling and that nothing blocks its "
             "travel; "
             "`axes.<name>.homing_timeout_s` must cover the run; ack, start (homing runs again at arming)";
    case Fault::kAxisUnreferenced:
      return "ack, start: an axis with a homing run homes again at arming; an absolute axis "
             "(`referencing = \"absolute\"`) that lost its reference needs its encoder and calibration "
             "checked";
    case Fault::kCarriageInWarp:
    case Fault::kPickWithoutShed:
    case Fault::kShedWithShuttle:
    case Fault::kGripperInWarp:
    case Fault::kKnotNotClear:
    case Fault::kSelectorWithYarn:
      return "the interlocks refused a motion (a sequencer bug would end here): report it with the run's "
             "report; ack";
  }
  return "?";
}

}  // namespace loom::sequencer
