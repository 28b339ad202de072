// What `loomctl serve` tells the weaver's panel about the carpet job (telemetry JOB and CARPET): the queue
// and the current job as jobs.txt has them, the knot cycles of the row in progress, the magazines' levels
// as magazines.txt keeps them (the row ends' levels without it), and an ETA from this job's whole rows timed
// so far. Non-RT: arming, the reporter's run events and its poll; the rest it reads from the state directory.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>

#include "loom/firmware/machine.hpp"
#include "loom/firmware/runner.hpp"
#include "loom/telemetry/job_events.hpp"

namespace loom::firmware {

class JobFeed {
 public:
  // Opens LCM; std::invalid_argument when it cannot.
  JobFeed(std::string state_dir, const std::string& lcm_url, const std::string& loom_id);

  // A session armed on `machine`: its knotting heads, the job's design (CARPET), the kept magazine levels.
  void armed(const Machine& machine);
  // After the service handled a run event: a row end (levels, the row's time, the credited rows), knot
  // progress (at most once a second). Never throws.
  void on_event(const RunEvent& e) noexcept;
  // The reporter's poll: JOB again when jobs.txt or magazines.txt changed, and JOB and CARPET again every
  // 10 s. Never throws.
  void poll() noexcept;

 private:
  void publish_locked();  // caller holds mu_
  void read_magazines();  // caller holds mu_

  std::string state_dir_;
  telemetry::JobEvents events_;
  std::mutex mu_;
  telemetry::JobReport report_;  // the loom's side: heads, stripe, stock, knot cycles
  double period_s_ = 0.0;
  std::uint32_t timed_job_ = 0;  // the job whose rows are timed below
  double timed_s_ = 0.0;
  std::uint64_t timed_rows_ = 0;
  std::chrono::steady_clock::time_point progress_sent_{}, job_sent_{};
  std::filesystem::file_time_type queue_mtime_{}, magazines_mtime_{};
  std::string carpet_key_;  // job id and hash of the knot map on CARPET
};

}  // namespace loom::firmware
