// One line per event for the service's log. Under systemd (JOURNAL_STREAM set: stdout goes to the
// journal) each line starts with the sd-daemon severity prefix "<N>" that journald turns into the
// entry's priority; in a terminal the prefix is left out and warnings and errors say so in words.
// Non-RT: called from the reporter and control threads, never from the loop.
#pragma once

#include <cstdarg>
#include <string>

#include "loom/firmware/severity.hpp"

namespace loom::firmware::serve {

using loom::firmware::Severity;

// Whether lines carry the "<N>" prefix: true when JOURNAL_STREAM is set (or LOOM_LOG_PREFIX=1),
// false when LOOM_LOG_PREFIX=0. Decided once, at the first line.
bool journal_prefix_enabled();

// The exact line written for a message (without the newline): "<N>text" or "text"/"WARNING: text".
std::string journal_line(Severity s, const std::string& text, bool prefix);

// Writes one line to stdout and flushes it (thread-safe: a single write per line).
void log(Severity s, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

}  // namespace loom::firmware::serve
