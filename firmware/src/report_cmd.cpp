// See report_cmd.hpp.
#include "report_cmd.hpp"

#include <cstdio>
#include <string>

#include "loom/firmware/serve/commands.hpp"
#include "loom/firmware/session.hpp"
#include "loom/record/production_record.hpp"
#include "loom/record/report_format.hpp"

namespace loom::firmware {

struct ReportArgs {
  std::string state_dir = serve::ServeArgs{}.state_dir;
  std::string format = "text";
  std::string what;  // "job" (the one report so far)
  std::uint32_t id = 0;
  std::uint32_t weaving = 0;  // 0: the job's latest
};

ReportCommands::ReportCommands(CLI::App& app) : args_(std::make_unique<ReportArgs>()) {
  ReportArgs& a = *args_;
  report_ = app.add_subcommand("report", "production reports from the state directory's record (read-only)");
  report_
      ->add_option("what", a.what, "job: one carpet job's times by machine state, rows, knots, yarn, faults")
      ->required()
      ->check(CLI::IsMember({"job"}));
  report_->add_option("job", a.id, "the job's number (loomctl job list)")
      ->required()
      ->check(CLI::Range(1u, 4294967295u));
  report_->add_option("--weaving", a.weaving, "which weaving of a job started over (default: its latest)")
      ->check(CLI::Range(1u, 4294967295u));
  report_->add_option("--format", a.format, "text | csv | json")
      ->check(CLI::IsMember({"text", "csv", "json"}));
  report_->add_option("--state-dir", a.state_dir, "the service's state directory (default /var/lib/loomctl)");
}

ReportCommands::~ReportCommands() = default;

std::optional<int> ReportCommands::run() const {
  if (!report_->parsed()) return std::nullopt;
  const ReportArgs& a = *args_;
  try {
    const auto r = record::read_job_report(record::ProductionRecord::path_in(a.state_dir), a.id, a.weaving);
    if (!r && a.weaving != 0) {
      std::fprintf(stderr, "loomctl report: --weaving %u: job %u has no such weaving in %s\n", a.weaving,
                   a.id, record::ProductionRecord::path_in(a.state_dir).c_str());
      return kExitBadInput;
    }
    if (!r) {
      std::fprintf(stderr, "loomctl report: job %u has no production record in %s (never started?)\n", a.id,
                   record::ProductionRecord::path_in(a.state_dir).c_str());
      return kExitBadInput;
    }
    const std::string out = a.format == "csv"    ? record::report_csv(*r)
                            : a.format == "json" ? record::report_json(*r)
                                                 : record::report_text(*r);
    std::fputs(out.c_str(), stdout);
    return 0;
  } catch (const record::RecordError& e) {
    std::fprintf(stderr, "loomctl report: %s\n", e.what());
    return kExitBadInput;
  }
}

}  // namespace loom::firmware
