// `loomctl dcf`: every node with an EDS written out as a DCF — the description with the values the loom
// configures as ParameterValues (drivers::eds::write_dcf) — one file per node, named after its table.
// All nodes are checked before the first file is written, so a refusal leaves nothing half-done.
#include "dcf_cmd.hpp"

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "loom/config/config.hpp"
#include "loom/config/eds_nodes.hpp"
#include "loom/firmware/session.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::firmware {

namespace {

// "axes.carriage" → "axes_carriage.dcf".
std::string file_name(const std::string& key) {
  std::string s = key;
  for (char& ch : s) {
    if (ch == '.') ch = '_';
  }
  return s + ".dcf";
}

}  // namespace

int run_dcf(const DcfArgs& a) {
  namespace eds = drivers::eds;
  try {
    const LoomConfig c = a.config.empty() ? default_loom_config() : load_loom_config(a.config);
    const std::vector<EdsNode> nodes = eds_nodes(c);
    if (nodes.empty()) {
      std::fprintf(stderr,
                   "loomctl: dcf: %s names no EDS (axes.<name>.eds, io.eds, io_modules.<name>.eds): there is "
                   "nothing to describe\n",
                   c.source.c_str());
      return kExitBadInput;
    }
    int refused = 0;
    for (const EdsNode& n : nodes) {
      if (n.check.ok()) continue;
      ++refused;
      for (const eds::Finding& f : n.check.findings) {
        if (f.level == eds::Level::kError)
          std::fprintf(stderr, "%s\n", eds::format(n.eds, n.needs, f).c_str());
      }
    }
    if (refused > 0) {
      std::fprintf(stderr, "loomctl: dcf: %d node(s) lack what the loom needs (above); no DCF written\n",
                   refused);
      return kExitBadInput;
    }
    std::vector<std::pair<std::string, std::string>> files;
    for (const EdsNode& n : nodes) {
      files.emplace_back((std::filesystem::path(a.out) / file_name(n.key)).string(), dcf_text(c, n));
    }
    std::error_code ec;
    std::filesystem::create_directories(a.out, ec);
    if (ec) {
      std::fprintf(stderr, "loomctl: dcf: --out %s: cannot create the folder: %s\n", a.out.c_str(),
                   ec.message().c_str());
      return kExitBadInput;
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      state::write_file_durably(files[i].first, files[i].second);
      std::printf("%s: %s (node %u on bus %u), %zu configured values\n", files[i].first.c_str(),
                  nodes[i].key.c_str(), nodes[i].node_id, nodes[i].bus, nodes[i].writes.size());
    }
    return 0;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "loomctl: %s\n", e.what());
    return kExitBadInput;
  } catch (const state::DurableWriteError& e) {
    std::fprintf(stderr, "loomctl: dcf: %s\n", e.what());
    return kExitBadInput;
  }
}

}  // namespace loom::firmware
