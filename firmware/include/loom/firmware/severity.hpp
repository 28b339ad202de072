// How much a message matters, as syslog and sd-daemon number it: the service's journal lines carry it
// as their "<N>" prefix, and a console command turns errors and warnings into words.
#pragma once

namespace loom::firmware {

enum class Severity : int { kErr = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };

}  // namespace loom::firmware
