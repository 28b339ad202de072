// Test helper: prints the COMMAND events of one loom in an LCM log (lcm-logger's file), one line each:
//   COMMAND <word> station=<station> accepted=<0|1> state=<state> who=<who> reply=<reply>
// so script tests can check the audit events serve put on the wire. Decoded by the generated type
// through LCM's own log reader. Usage: telemetry_command_log <lcmlog> <loom id>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "loomlcm/command_t.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: telemetry_command_log <lcmlog> <loom id>\n");
    return 2;
  }
  lcm::LogFile log(argv[1], "r");
  if (!log.good()) {
    std::fprintf(stderr, "telemetry_command_log: cannot read %s\n", argv[1]);
    return 2;
  }
  const std::string channel = std::string("LOOM.") + argv[2] + ".COMMAND";
  int bad = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel != channel) continue;
    loomlcm::command_t m;
    if (m.decode(ev->data, 0, static_cast<int>(ev->datalen)) < 0) {
      ++bad;
      continue;
    }
    std::printf("COMMAND %s station=%s accepted=%d state=%s who=%s reply=%s\n", m.word.c_str(),
                m.station.c_str(), m.accepted ? 1 : 0, m.state.c_str(), m.who.c_str(), m.reply.c_str());
  }
  if (bad > 0) std::fprintf(stderr, "telemetry_command_log: %d COMMAND events did not decode\n", bad);
  return bad > 0 ? 1 : 0;
}
