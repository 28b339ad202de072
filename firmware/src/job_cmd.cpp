// See job_cmd.hpp. Reading verbs (list, show) only read; changing verbs take the state directory's lock
// (the one serve holds), so the queue has one writer, and refuse while serve runs (serve changes it then:
// loomctl ctl job ...).
#include "job_cmd.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <string>

#include "loom/config/config.hpp"
#include "loom/firmware/serve/commands.hpp"
#include "loom/firmware/serve/state_lock.hpp"
#include "loom/firmware/session.hpp"
#include "loom/job/job_queue.hpp"
#include "loom/job/job_text.hpp"
#include "loom/job/yarn_stock.hpp"

namespace loom::firmware {

struct JobArgs {
  std::string verb;  // add, list, show, remove, start-over
  std::string what;  // add: the design file; show, remove, start-over: the job
  std::string state_dir = serve::ServeArgs{}.state_dir;  // serve's default: one place says it
  std::string config;
  job::JobLength length;
  std::uint32_t id = 0;
  CLI::Option *config_opt = nullptr, *rows = nullptr, *metres = nullptr, *repeat = nullptr;
};

namespace {

bool is_dir(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// The command line's shape per verb (CLI11 checked each option's value): `what` present when needed,
// a job number where one is meant, the length and loom options only with add.
std::optional<std::string> misuse(JobArgs& a) {
  const bool add = a.verb == "add", list = a.verb == "list";
  if (!add) {
    for (const CLI::Option* o : {a.config_opt, a.rows, a.metres, a.repeat}) {
      if (o->count() > 0) return o->get_name() + ": only with job add";
    }
  }
  if (list)
    return a.what.empty() ? std::nullopt
                          : std::optional<std::string>("job list takes no argument, not " + a.what);
  if (a.what.empty())
    return "job " + a.verb + " needs " + (add ? "the design file" : "the job's number (loomctl job list)");
  if (add) return std::nullopt;
  std::uint64_t id = 0;
  const bool digits = a.what.size() <= 10 && a.what.find_first_not_of("0123456789") == std::string::npos;
  if (digits) id = std::stoull(a.what);
  if (!digits || id < 1 || id > UINT32_MAX)
    return "job " + a.verb + " " + a.what + ": not a job number (1, 2, ...)";
  a.id = static_cast<std::uint32_t>(id);
  return std::nullopt;
}

int run_verb(const JobArgs& a) {
  if (!is_dir(a.state_dir)) {
    std::fprintf(stderr, "loomctl job: --state-dir %s: not a directory\n", a.state_dir.c_str());
    return kExitBadInput;
  }
  const std::string path = job::JobQueue::path_in(a.state_dir);
  if (a.verb == "list") {
    std::fputs(job::list_text(job::JobQueue::load(path).jobs(), path).c_str(), stdout);
    return 0;
  }
  if (a.verb == "show") {
    std::fputs(job::show_text(job::JobQueue::load(path).job(a.id)).c_str(), stdout);
    return 0;
  }
  // Changing verbs: the queue's one writer is whoever holds the state directory.
  std::unique_ptr<serve::StateDirLock> lock;
  try {
    lock = std::make_unique<serve::StateDirLock>(a.state_dir, "loomctl-job", "");
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr,
                 "loomctl job: the job queue was not changed: %s (while serve runs, it keeps the queue: "
                 "loomctl ctl job %s ...)\n",
                 e.what(), a.verb.c_str());
    return kExitBadInput;
  }
  job::JobQueue q = job::JobQueue::load(path);
  if (a.verb == "add") {
    const LoomConfig loom = a.config.empty() ? default_loom_config() : load_loom_config(a.config);
    const job::Job& j = q.add(a.what, loom, a.length);
    std::printf("added job %u: %s (sha256 %s), %llu rows, queued\n", j.id, j.design_name.c_str(),
                j.sha256.c_str(), static_cast<unsigned long long>(j.length_rows));
  } else if (a.verb == "remove") {
    q.remove(a.id);
    std::printf("removed job %u\n", a.id);
  } else if (a.verb == "start-over") {
    q.start_over(a.id);
    const job::Job& j = q.job(a.id);
    std::printf("job %u starts over at row 1 (%s, weaving %u)\n", a.id, job::job_state_name(j.state),
                j.weaving);
  }
  return 0;
}

}  // namespace

JobCommands::JobCommands(CLI::App& app) : args_(std::make_unique<JobArgs>()) {
  JobArgs& a = *args_;
  job_ = app.add_subcommand("job",
                            "the carpet job queue in the state directory (a job is started at the machine)");
  job_->add_option("verb", a.verb,
                   "add DESIGN: queue a carpet job (a design fitted to the loom, its length, its yarn map)\n"
                   "list: every job (number, state, design, hash, progress)\n"
                   "show N: one job in full, and whether its design file is unchanged\n"
                   "remove N: take a job out of the queue (not the current one)\n"
                   "start-over N: weave a job again from row 1")
      ->required()
      ->check(CLI::IsMember({"add", "list", "show", "remove", "start-over"}));
  job_->add_option("what", a.what,
                   "add: the design file (CSV or PNG); show, remove, start-over: the job's number");
  job_->add_option("--state-dir", a.state_dir, "the service's state directory (default /var/lib/loomctl)");
  a.config_opt =
      job_->add_option("--config", a.config,
                       "add: the loom config (TOML) whose knots per row and magazines the design must fit; "
                       "default: embedded default loom");
  a.rows =
      job_->add_option("--rows", a.length.rows, "add: the carpet's length in rows (default: the design once)")
          ->check(CLI::Range(1ull, 4294967295ull));
  a.metres = job_->add_option("--metres", a.length.metres,
                              "add: the carpet's length in metres, at the loom's rows_per_dm")
                 ->check(CLI::Range(1e-6, 1e6));
  a.repeat = job_->add_option("--repeat", a.length.repeats, "add: weave the design this many times")
                 ->check(CLI::Range(1u, 1000000u));
  a.rows->excludes(a.metres)->excludes(a.repeat);
  a.metres->excludes(a.repeat);
}

JobCommands::~JobCommands() = default;

std::optional<int> JobCommands::run() const {
  if (!job_->parsed()) return std::nullopt;
  if (const auto why = misuse(*args_)) {
    std::fprintf(stderr, "loomctl job: %s\n", why->c_str());
    return kExitBadInput;
  }
  try {
    return run_verb(*args_);
  } catch (const ConfigError& e) {  // the queue's file, the design, the config, a refused change
    std::fprintf(stderr, "loomctl job: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {  // a write that failed (the old queue stays)
    std::fprintf(stderr, "loomctl job: %s\n", e.what());
    return 1;
  }
}

}  // namespace loom::firmware
