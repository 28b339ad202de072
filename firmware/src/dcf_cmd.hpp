// `loomctl dcf --config FILE --out DIR`: a DCF (CiA 306) per node that names its EDS, carrying the values
// the loom configures on it, for the builder's other CANopen tools. Moves nothing.
#pragma once

#include <string>

namespace loom::firmware {

struct DcfArgs {
  std::string config, out;
};

// Exit code: 0 written, 2 bad input (a config error, no node with an EDS, a node whose EDS lacks what the
// loom needs, or a folder that cannot be written: nothing is written then).
int run_dcf(const DcfArgs& a);

}  // namespace loom::firmware
