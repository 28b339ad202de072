// The offline CLIs stream their CSV (issue 13: `--samples 10000000` held 1.7–2.7 GB): the peak
// resident memory of a run must not grow with the number of rows. Each CLI runs as a child process
// at 5e4 and 5e5 samples, stdout to /dev/null, and wait4() reports its peak RSS; an
// implementation that keeps every row (≥ 100 bytes each) would grow by ≥ 45 MB between them.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "sanitizer.hpp"

namespace {

struct Run {
  int status = -1;
  long max_rss_kb = 0;
};

Run run_child(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd >= 0) dup2(null_fd, STDOUT_FILENO);
    execv(args[0], args.data());
    _exit(127);
  }
  Run r;
  rusage ru{};
  if (pid > 0 && wait4(pid, &r.status, 0, &ru) == pid) r.max_rss_kb = ru.ru_maxrss;
  return r;
}

void expect_constant_memory(std::vector<std::string> argv, const std::string& samples_flag) {
  LOOM_SKIP_MEMORY_FOOTPRINT_UNDER_ASAN();
  argv.push_back(samples_flag);
  argv.push_back("50000");
  const Run small = run_child(argv);
  argv.back() = "500000";
  const Run large = run_child(argv);
  ASSERT_TRUE(WIFEXITED(small.status) && WEXITSTATUS(small.status) == 0) << argv[1];
  ASSERT_TRUE(WIFEXITED(large.status) && WEXITSTATUS(large.status) == 0) << argv[1];
  // Growth allowed: allocator noise and the bounded output buffer (1 MiB); keeping the 450 000 extra
  // rows (≥ 100 bytes each) would add ≥ 45 MB.
  EXPECT_LT(large.max_rss_kb - small.max_rss_kb, 12 * 1024)
      << argv[1] << ": peak RSS " << small.max_rss_kb << " kB at 5e4 samples, " << large.max_rss_kb
      << " kB at 5e5";
}

TEST(CliStreaming, LoomKinFourbarRunsInConstantMemory) {
  expect_constant_memory({LOOM_KIN_EXE, "fourbar", "--ground", "0.213", "--crank", "0.058", "--coupler",
                          "0.189", "--rocker", "0.232"},
                         "--samples");
}

TEST(CliStreaming, LoomKinNeedleRunsInConstantMemory) {
  expect_constant_memory({LOOM_KIN_EXE, "needle"}, "--samples");
}

TEST(CliStreaming, LoomDynamicsBeatupRunsInConstantMemory) {
  expect_constant_memory({LOOM_DYNAMICS_EXE, "beatup", "--crank-rad-s", "15.5"}, "--samples");
}

}  // namespace
