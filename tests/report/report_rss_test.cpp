// Constant memory over a long run (issue: a loom weaving for a month): the same path loomctl takes —
// the machine on the ideal scene without telemetry, the runner, each completed row streamed to the
// report — and the process's resident set (VmRSS) after 10,000 rows within 1 MB of what it was after 100.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/report/run_report.hpp"
#include "sanitizer.hpp"

using namespace loom;

namespace {
long vm_rss_kb() {
  std::ifstream f("/proc/self/status");
  std::string key;
  long kb = -1;
  while (f >> key) {
    if (key == "VmRSS:") {
      f >> kb;
      break;
    }
    std::getline(f, key);
  }
  return kb;
}
}  // namespace

TEST(ReportMemory, RssIsFlatOverTenThousandRows) {
  LOOM_SKIP_MEMORY_FOOTPRINT_UNDER_ASAN();
  constexpr std::uint32_t kRows = 10000;
  firmware::LoomConfig cfg = firmware::default_loom_config();
  // The default 2 ms period: 10,000 rows are ~38 M ticks of the ideal simulator.
  firmware::Scene scene = firmware::default_scene();
  scene.spec.effects = {"ideal", "beat_contact"};  // forces measured, so every row carries its beats
  firmware::MachineOptions opt;
  opt.rows = kRows;
  opt.telemetry = false;
  firmware::Machine m(cfg, scene, opt, {});
  const auto dir = std::filesystem::temp_directory_path() / ("loom_report_rss_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  report::RunHeader h;
  h.loom_id = cfg.loom_id;
  h.scene = "ideal";
  h.period_s = cfg.sequencer.period_s;
  report::ReportWriter w(dir.string(), h);

  long rss_at_100 = -1, rss_at_last = -1, rss_at_end = -1;
  std::uint32_t picks_before = 0;
  m.sequencer().request_start();
  firmware::RunOptions ro;
  ro.period_s = cfg.sequencer.period_s;
  const firmware::RunResult res =
      firmware::run_loop(m.loop(), m.sequencer(), ro, [&](const firmware::RunEvent& e) {
        if (e.kind != firmware::RunEvent::Kind::kRowDone) return;
        w.add_row(e.row, e.counters.picks - picks_before, static_cast<double>(e.tick) * ro.period_s);
        picks_before = e.counters.picks;
        if (e.counters.rows == 100) rss_at_100 = vm_rss_kb();
        if (e.counters.rows == kRows) rss_at_last = vm_rss_kb();
      });
  ASSERT_EQ(m.sequencer().counters().rows, kRows);
  report::RunEnd end;
  end.counters = m.sequencer().counters();
  end.machine_s = static_cast<double>(res.ticks) * ro.period_s;
  w.finish(end);
  rss_at_end = vm_rss_kb();
  std::printf(
      "VmRSS after 100 rows %ld kB, after %u rows %ld kB, after the report %ld kB (rows.jsonl %ju bytes)\n",
      rss_at_100, kRows, rss_at_last, rss_at_end,
      static_cast<std::uintmax_t>(std::filesystem::file_size(dir / "rows.jsonl")));
  ASSERT_GT(rss_at_100, 0);
  EXPECT_LE(rss_at_last - rss_at_100, 1024) << "resident memory grew with the rows";
  // Writing summary.json and the plots streams the rows back: bounded too.
  EXPECT_LE(rss_at_end - rss_at_100, 1024) << "the report's end pass grew with the rows";
  EXPECT_EQ(w.rows(), kRows);
  std::filesystem::remove_all(dir);
}
