// Journald-friendly logging: one write(2) per line so lines from different threads never interleave.
#include "loom/firmware/serve/journal.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace loom::firmware::serve {

bool journal_prefix_enabled() {
  static const bool enabled = [] {
    if (const char* v = std::getenv("LOOM_LOG_PREFIX")) return std::strcmp(v, "0") != 0;
    return std::getenv("JOURNAL_STREAM") != nullptr;
  }();
  return enabled;
}

std::string journal_line(Severity s, const std::string& text, bool prefix) {
  if (prefix) return "<" + std::to_string(static_cast<int>(s)) + ">" + text;
  switch (s) {
    case Severity::kErr:
      return "ERROR: " + text;
    case Severity::kWarning:
      return "WARNING: " + text;
    default:
      return text;
  }
}

void log(Severity s, const char* fmt, ...) {
  char buf[1024];
  va_list ap;
  va_start(ap, fmt);
  const int n = std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  std::string text(buf, n < 0 ? 0 : std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buf - 1));
  // One event, one line: a newline inside a message would split it into two journal entries.
  for (char& c : text) {
    if (c == '\n') c = ' ';
  }
  std::string line = journal_line(s, text, journal_prefix_enabled()) + "\n";
  std::fflush(stdout);  // keep order with anything printed through stdio
  const char* p = line.data();
  std::size_t left = line.size();
  while (left > 0) {
    const ssize_t w = ::write(STDOUT_FILENO, p, left);
    if (w <= 0) break;
    p += w;
    left -= static_cast<std::size_t>(w);
  }
}

}  // namespace loom::firmware::serve
