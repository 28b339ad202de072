// What the person at the loom does about each fault: one sentence per fault, beside the fault table's
// own code, name and text. The README's fault table is generated from both (loom-doc-tables), and the
// build fails when a fault has no recovery (the switch in fault_recovery.cpp has no default).
#pragma once

#include "loom/sequencer/faults.hpp"

namespace loom::sequencer {

// Never null. Every fault already stopped motion, kept the counters and lit the red lamp; this says
// what to fix before acknowledging and starting again.
const char* fault_recovery(Fault f);

}  // namespace loom::sequencer
