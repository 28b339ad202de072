// Lookups into the fault table.
#include "loom/sequencer/faults.hpp"

namespace loom::sequencer {

std::uint16_t fault_code(Fault f) {
  switch (f) {
#define LOOM_FAULT_CODE(id, code, name, text) \
  case Fault::id:                             \
    return code;
    LOOM_FAULT_TABLE(LOOM_FAULT_CODE)
#undef LOOM_FAULT_CODE
  }
  return 0xFFFF;
}

const char* fault_name(Fault f) {
  switch (f) {
#define LOOM_FAULT_NAME(id, code, name, text) \
  case Fault::id:                             \
    return name;
    LOOM_FAULT_TABLE(LOOM_FAULT_NAME)
#undef LOOM_FAULT_NAME
  }
  return "?";
}

const char* fault_text(Fault f) {
  switch (f) {
#define LOOM_FAULT_TEXT(id, code, name, text) \
  case Fault::id:                             \
    return text;
    LOOM_FAULT_TABLE(LOOM_FAULT_TEXT)
#undef LOOM_FAULT_TEXT
  }
  return "?";
}

}  // namespace loom::sequencer
