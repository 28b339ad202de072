// Only the loop thread runs at SCHED_FIFO: while a real-time run is going (real clock, telemetry
// publishing through LCM on its own thread, the caller's thread as reporter), an observer reads every
// thread's scheduling policy from /proc/self/task/*/stat and finds the loop thread ("loom-rt") at
// SCHED_FIFO and every other thread at SCHED_OTHER. setup_realtime() must leave the process' policy
// alone (it used to switch the whole process to SCHED_FIFO, and threads started later inherited it).
// Without the privilege for SCHED_FIFO (not root, no RLIMIT_RTPRIO) the test still checks that the
// loop thread is created with explicit attributes and falls back visibly, and that nothing else is
// real-time; it prints which case it ran.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "loom/config/config.hpp"
#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"

using namespace loom;

namespace {

struct TaskInfo {
  std::string comm;
  int policy = -1;
};

// Field 41 of /proc/<pid>/task/<tid>/stat is the scheduling policy (man 5 proc); comm is in parens.
std::map<int, TaskInfo> read_tasks() {
  std::map<int, TaskInfo> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream f(e.path() / "stat");
    std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const auto open = s.find('('), close = s.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;
    TaskInfo t;
    t.comm = s.substr(open + 1, close - open - 1);
    std::istringstream rest(s.substr(close + 2));
    std::string field;
    for (int i = 3; i <= 41 && rest >> field; ++i) {
      if (i == 41) t.policy = std::stoi(field);
    }
    out[std::stoi(e.path().filename().string())] = t;
  }
  return out;
}

}  // namespace

TEST(RtThreads, SetupRealtimeLeavesTheProcessAtSchedOther) {
  const firmware::RtSetup rt = firmware::setup_realtime(80, 1u << 20);
  std::printf("setup_realtime: memory_locked=%d fifo=%d %s\n", rt.memory_locked, rt.fifo,
              rt.problems.c_str());
  EXPECT_EQ(sched_getscheduler(0), SCHED_OTHER);
  int policy = -1;
  std::thread([&] {
    sched_param sp{};
    pthread_getschedparam(pthread_self(), &policy, &sp);
  }).join();
  EXPECT_EQ(policy, SCHED_OTHER) << "a thread started after setup_realtime inherited a real-time policy";
}

TEST(RtThreads, OnlyTheLoopThreadIsSchedFifo) {
  const firmware::RtSetup rt = firmware::setup_realtime(80, 1u << 20);
  firmware::LoomConfig cfg = firmware::default_loom_config();
  cfg.telemetry.lcm_url = "memq://";
  firmware::MachineOptions mo;
  mo.rows = 1;
  mo.telemetry = true;
  mo.lossless_telemetry = false;
  firmware::Machine m(cfg, firmware::default_scene(), mo, {});
  ASSERT_NE(m.telemetry(), nullptr);

  const pid_t reporter_tid = gettid();
  std::atomic<bool> stop{false};
  std::mutex mu;
  std::map<int, TaskInfo> seen_while_running;
  bool saw_loop = false;
  std::thread observer([&] {
    while (!stop.load()) {
      auto tasks = read_tasks();
      bool loop_present = false;
      for (const auto& [tid, t] : tasks) loop_present = loop_present || t.comm == "loom-rt";
      if (loop_present) {
        std::lock_guard<std::mutex> lock(mu);
        seen_while_running = tasks;
        saw_loop = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  firmware::RunOptions o;
  o.period_s = cfg.sequencer.period_s;
  o.realtime = true;
  o.fifo_priority = 80;
  o.max_ticks = 250;  // half a second at 2 ms
  m.sequencer().request_start();
  const firmware::RunResult res =
      firmware::run_loop(m.loop(), m.sequencer(), o, [](const firmware::RunEvent&) {});
  stop.store(true);
  observer.join();
  m.telemetry()->stop();

  ASSERT_TRUE(saw_loop) << "the observer never saw the loop thread";
  std::printf("case: %s\n",
              rt.fifo ? "SCHED_FIFO granted" : "SCHED_FIFO not granted (checking the fallback)");
  int others = 0;
  for (const auto& [tid, t] : seen_while_running) {
    std::printf("  tid %d %-16s policy %d%s\n", tid, t.comm.c_str(), t.policy,
                tid == reporter_tid ? " (reporter)" : "");
    if (t.comm == "loom-rt") {
      EXPECT_EQ(t.policy, rt.fifo ? SCHED_FIFO : SCHED_OTHER);
    } else {
      ++others;
      EXPECT_EQ(t.policy, SCHED_OTHER) << t.comm << " (tid " << tid << ") is not SCHED_OTHER";
    }
  }
  EXPECT_GE(others, 3) << "expected the reporter, the LCM publisher and the observer beside the loop";
  EXPECT_TRUE(seen_while_running.count(reporter_tid) == 1);
  if (rt.fifo) {
    EXPECT_EQ(res.loop_policy, SCHED_FIFO);
    EXPECT_EQ(res.loop_priority, 80);
    EXPECT_FALSE(res.fifo_refused);
  } else {
    EXPECT_TRUE(res.fifo_refused) << "the refusal must be reported, not hidden";
    EXPECT_EQ(res.loop_policy, SCHED_OTHER);
  }
  EXPECT_EQ(res.ticks, 250);
  EXPECT_GT(res.wake_latency_max_ns, 0);
}

TEST(RtThreads, RequiredFifoThatIsRefusedIsAnErrorNotASilentFallback) {
  // Asking for a CPU that does not exist makes pthread_create fail whatever the privileges: the runner
  // must refuse to run and say why.
  firmware::LoomConfig cfg = firmware::default_loom_config();
  firmware::MachineOptions mo;
  mo.telemetry = false;
  firmware::Machine m(cfg, firmware::default_scene(), mo, {});
  firmware::RunOptions o;
  o.realtime = true;
  o.max_ticks = 10;
  o.require_fifo = true;
  o.cpu = 1000;
  const firmware::RunResult res =
      firmware::run_loop(m.loop(), m.sequencer(), o, [](const firmware::RunEvent&) {});
  EXPECT_EQ(res.end, firmware::RunResult::End::kError);
  EXPECT_NE(res.error.find("CPU 1000"), std::string::npos) << res.error;
  EXPECT_EQ(res.ticks, 0);
}
