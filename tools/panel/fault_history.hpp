// The loom's persisted fault history (serve's faults.log, read through its control socket with the
// `faults` request) as the panel's JSON: the newest `keep` lines, each split into its wall-clock time,
// kind (fault, ack, overrun_stop, command), name and the rest. What the panel heard on LCM since it
// started is only part of the story; this survives a restart of the panel, of serve and of the board.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace loom::panel {

// `reply`: serve's answer to `faults` ("no faults recorded in PATH" when none). A line that does not look
// like a history line (time kind loom name ...) is kept whole, never dropped or trusted: {"line": ...}.
// Returns {"lines": [{"time", "kind", "name", "detail", "line"}...], "total": n, "shown": k, "note": s}.
nlohmann::json fault_history_json(const std::string& reply, std::size_t keep);

}  // namespace loom::panel
