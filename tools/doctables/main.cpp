// loom-doc-tables: the READMEs' generated tables, printed as Markdown from the code's own tables — the
// config keys from firmware::config_keys() (the table the config reader reads with) and the faults from
// LOOM_FAULT_TABLE with sequencer::fault_recovery(). tools/doctables/regen.sh puts them into the
// READMEs; the CTest readme.generated_tables fails when a committed table differs from this output.
#include <cstdio>
#include <cstring>
#include <string>

#include "loom/config/config.hpp"
#include "loom/sequencer/fault_recovery.hpp"
#include "loom/sequencer/faults.hpp"

namespace {

// A table cell: '|' would end the cell, a newline the row.
std::string cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

void print_config_keys() {
  std::printf("| key | class | range |\n|---|---|---|\n");
  for (const auto& k : loom::firmware::config_keys()) {
    std::printf("| `%s` | %s | %s |\n", cell(k.path).c_str(), k.klass, cell(k.range).c_str());
  }
}

void print_faults() {
  using loom::sequencer::Fault;
  std::printf("| code | fault | meaning | recovery |\n|---|---|---|---|\n");
  const auto row = [](Fault f) {
    if (f == Fault::kNone) return;
    std::printf("| 0x%04X | `%s` | %s | %s |\n", loom::sequencer::fault_code(f),
                loom::sequencer::fault_name(f), cell(loom::sequencer::fault_text(f)).c_str(),
                cell(loom::sequencer::fault_recovery(f)).c_str());
  };
#define LOOM_DOC_FAULT_ROW(id, code, name, text) row(Fault::id);
  LOOM_FAULT_TABLE(LOOM_DOC_FAULT_ROW)
#undef LOOM_DOC_FAULT_ROW
}

int usage(std::FILE* out, int code) {
  std::fprintf(
      out,
      "loom-doc-tables: the READMEs' generated tables as Markdown, from the code's own tables\n"
      "Usage: loom-doc-tables SUBCOMMAND\n\n"
      "Subcommands:\n"
      "  config-keys  every config key with its class and range (firmware::config_keys)\n"
      "  faults       every fault: code, name, meaning, recovery (LOOM_FAULT_TABLE, fault_recovery)\n\n"
      "tools/doctables/regen.sh BUILD_DIR writes them into the READMEs between their markers.\n");
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0))
    return usage(stdout, 0);
  if (argc != 2) return usage(stderr, 2);
  const std::string what = argv[1];
  if (what == "config-keys") {
    print_config_keys();
  } else if (what == "faults") {
    print_faults();
  } else {
    std::fprintf(stderr, "loom-doc-tables: unknown subcommand '%s' (has: config-keys faults)\n",
                 what.c_str());
    return 2;
  }
  return std::fflush(stdout) == 0 ? 0 : 1;
}
