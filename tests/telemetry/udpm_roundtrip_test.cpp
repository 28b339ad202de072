// End to end through real LCM multicast: a Telemetry publisher on udpm (host-only, ttl=0, a port and
// loom id unique to this process) and an independent LCM subscriber with its own handlers. The
// subscriber must see the row count and the sequencer state advance exactly as the run did.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "loom/telemetry/telemetry.hpp"
#include "loomlcm/axes_t.hpp"
#include "loomlcm/status_t.hpp"
#include "synthetic_loom.hpp"

namespace {

using namespace loom::telemetry;
namespace sequencer = loom::sequencer;
using Key = std::tuple<std::string, std::int64_t, std::int64_t, std::int64_t>;  // state, row, pick, beat

// Handlers are static with a context pointer: LCM 1.3.1's member-function subscribe crashes under
// -fsanitize=undefined (the ASan/UBSan preset).
class StatusCollector {
 public:
  static void on_status(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::status_t* m,
                        StatusCollector* self) {
    std::lock_guard lock(self->mu_);
    self->got_.emplace_back(m->state, m->rows_done, m->pick, m->beat);
  }
  static void on_axes(const lcm::ReceiveBuffer*, const std::string&, const loomlcm::axes_t* m,
                      StatusCollector* self) {
    std::lock_guard lock(self->mu_);
    if (m->axes.size() == loom::hal::kCoreAxisCount) ++self->axes_;
  }
  std::vector<Key> got() {
    std::lock_guard lock(mu_);
    return got_;
  }
  int axes() {
    std::lock_guard lock(mu_);
    return axes_;
  }

 private:
  std::mutex mu_;
  std::vector<Key> got_;
  int axes_ = 0;
};

TEST(UdpmRoundTrip, SubscriberSeesRowsAndStatesAdvanceInOrder) {
  const int port = 20000 + static_cast<int>(::getpid() % 20000);
  const std::string url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
  const std::string loom_id = "rt" + std::to_string(::getpid());

  lcm::LCM sub(url);
  ASSERT_TRUE(sub.good()) << "LCM could not open " << url
                          << " (no multicast route? udpm needs one, e.g. ip route add 224.0.0.0/4 dev lo)";
  StatusCollector collector;
  const ChannelNames ch = channel_names(kDefaultChannelPrefix, loom_id);
  sub.subscribeFunction(ch.status, &StatusCollector::on_status, &collector)->setQueueCapacity(100'000);
  sub.subscribeFunction(ch.axes, &StatusCollector::on_axes, &collector)->setQueueCapacity(100'000);
  std::atomic<bool> done{false};
  std::thread receiver([&] {
    while (!done.load()) sub.handleTimeout(50);
  });

  test_support::WeaveScript w;
  constexpr std::int64_t kRows = 12;
  const std::int64_t ticks = w.ticks_for_rows(kRows) + 1;  // the last tick shows row 12 counted
  std::vector<Key> want;
  for (std::int64_t t = 0; t < ticks; ++t) {
    const Snapshot s = test_support::script_snapshot(w, t);
    const Key k{sequencer::state_name(static_cast<sequencer::State>(s.state)), s.row, s.pick, s.beat};
    if (want.empty() || want.back() != k) want.push_back(k);
  }

  PublisherConfig cfg;
  cfg.lcm_url = url;
  cfg.loom_id = loom_id;
  cfg.decimation = {.status_every_n_ticks = 1'000'000, .axes_every_n_ticks = 10, .rt_every_n_ticks = 100};
  Telemetry tel(cfg);
  tel.start();
  for (std::int64_t t = 0; t < ticks; ++t) {
    ASSERT_TRUE(tel.push_waiting(test_support::script_snapshot(w, t)));
    // A loop-like pace (100 µs per tick) keeps bursts well inside the socket buffers.
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  tel.stop();
  EXPECT_EQ(tel.stats().publish_errors, 0u);
  EXPECT_EQ(tel.stats().status, want.size());

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (collector.got().size() < want.size() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  done = true;
  receiver.join();

  const std::vector<Key> got = collector.got();
  EXPECT_EQ(got, want);
  ASSERT_FALSE(got.empty());
  // Rows rise by one at a time from 0 to kRows, never backwards.
  std::int64_t row = 0;
  for (const auto& k : got) {
    ASSERT_TRUE(std::get<1>(k) == row || std::get<1>(k) == row + 1);
    row = std::get<1>(k);
  }
  EXPECT_EQ(row, kRows);
  EXPECT_EQ(collector.axes(), static_cast<int>((ticks + 9) / 10));
}

}  // namespace
