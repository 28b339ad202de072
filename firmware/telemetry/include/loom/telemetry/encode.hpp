// Snapshot → LCM message conversion, kept pure (no LCM handle, no clock) so field mapping is testable
// on its own. The caller stamps `utime`; everything else comes from the snapshot.
#pragma once

#include <cstdint>
#include <string>

#include "loom/design/design.hpp"
#include "loom/telemetry/snapshot.hpp"
#include "loomlcm/axes_t.hpp"
#include "loomlcm/beat_t.hpp"
#include "loomlcm/design_t.hpp"
#include "loomlcm/fault_t.hpp"
#include "loomlcm/knots_t.hpp"
#include "loomlcm/row_t.hpp"
#include "loomlcm/rt_stats_t.hpp"
#include "loomlcm/status_t.hpp"
#include "loomlcm/weaver_request_t.hpp"

namespace loom::sequencer {
class KnotProgram;
}

namespace loom::telemetry {

// RT-safe. Loop time tick * period_ns in seconds.
double loop_time_s(const Snapshot& s) noexcept;

// Not RT-safe (allocates strings): publisher thread only. Each fills every field of its message.
// Axis names come from the machine's layout (the snapshot carries slots).
loomlcm::status_t to_status(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                            const hal::AxisLayout& axes = hal::core_axis_layout());
loomlcm::axes_t to_axes(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                        const hal::AxisLayout& axes = hal::core_axis_layout());
// `dropped` and `backlog` come from the ring, which knows about snapshots the loop never got to send.
loomlcm::rt_stats_t to_rt_stats(const Snapshot& s, const std::string& loom_id, std::int64_t utime,
                                std::uint64_t dropped, std::uint64_t backlog,
                                std::uint64_t dropped_events = 0);

// Not RT-safe (allocates strings): publisher thread only. One message per event of that kind.
loomlcm::beat_t to_beat(const Event& e, const std::string& loom_id, std::int64_t utime);
loomlcm::fault_t to_fault(const Event& e, const std::string& loom_id, std::int64_t utime,
                          const hal::AxisLayout& axes = hal::core_axis_layout());
loomlcm::row_t to_row(const Event& e, const std::string& loom_id, std::int64_t utime);
// Not RT-safe: publisher thread only. The design's row to knot after `rows_done` design rows, with the
// row knotted last (when any) and the two after it.
loomlcm::design_t to_design(const design::Design& d, std::uint64_t rows_done, const std::string& loom_id,
                            std::int64_t utime);
// Not RT-safe: publisher thread only. The knotting heads' progress in `s` (KNOTS), the knots and colours
// from `program` (the machine's design as magazine slots).
loomlcm::knots_t to_knots(const Snapshot& s, const sequencer::KnotProgram& program,
                          const std::string& loom_id, std::int64_t utime);
// Not RT-safe: publisher thread only. A weaver request event (WEAVER), worded with `program`'s colours
// (null: colour "" and the text without them).
loomlcm::weaver_request_t to_weaver_request(const Event& e, const sequencer::KnotProgram* program,
                                            const std::string& loom_id, std::int64_t utime);
// The FAULT message's kind field for an event's fault kind: "first", "diagnosis", "device".
const char* fault_kind_name(Event::FaultKind k) noexcept;

}  // namespace loom::telemetry
