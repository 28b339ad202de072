// The JOB and CARPET channels: the carpet job queue, the current job's progress, its ETA and the yarn
// left, and the knot map of its design — for the weaver's panel (loomlcm::job_t, loomlcm::carpet_t on
// <prefix>.<id>.JOB / .CARPET). Published by `loomctl serve`'s non-real-time side (arming, the reporter's
// row ends, its poll), never by the loop. Its own lcm_t, like CommandEvents: the service outlives sessions.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "loom/design/design.hpp"
#include "loomlcm/carpet_t.hpp"
#include "loomlcm/job_t.hpp"

typedef struct _lcm_t lcm_t;

namespace loom::telemetry {

// One job of the queue as the panel lists it.
struct JobLine {
  std::uint32_t id = 0;
  std::string design_name;
  std::string state;  // queued, current, carpet_done
  std::uint64_t rows_done = 0, rows_total = 0;
};

// Where the loom stands with its carpet job (plain numbers: the caller reads the queue and magazines).
struct JobReport {
  std::uint32_t job_id = 0;  // 0: no job to show
  std::string state, design_name, design_hash;
  int width = 0, design_rows = 0;
  std::uint64_t rows_done = 0, rows_total = 0;
  int stripe = 0;  // knots per head's stripe (the heads are stock's rows)
  std::uint32_t cycles_done = 0;
  double row_mean_s = -1.0;  // < 0: no whole row of this job timed yet
  std::vector<std::string> slot_colours;
  std::int32_t knots_per_slot = 0;
  std::vector<std::vector<std::int32_t>> stock;  // [head][slot], -1 unknown
  std::vector<JobLine> queue;
  // rows left x the mean whole-row time; < 0 while no row is timed.
  double eta_s() const;
};

// Knots per CARPET band at most: 16 KiB keeps a band well under LCM's 64 KB small message.
inline constexpr std::size_t kCarpetBandKnots = 16384;
// How often the whole knot map goes out again (a panel that joins late).
inline constexpr std::chrono::seconds kCarpetRepeat{10};

// Not RT-safe: allocate. The messages (pure, for tests and the publisher).
loomlcm::job_t to_job(const JobReport& r, const std::string& loom_id, std::int64_t utime);
// The design's knot map in bands of whole rows, each at most kCarpetBandKnots knots (one row per band when
// a row is wider). std::invalid_argument when the palette has more than 256 colours (a byte per knot).
std::vector<loomlcm::carpet_t> to_carpet(const design::Design& d, std::uint32_t job_id,
                                         const std::string& hash, const std::string& loom_id,
                                         std::int64_t utime);

class JobEvents {
 public:
  // Configure-time: opens `lcm_url` ("" = LCM's default). Throws std::invalid_argument when LCM cannot.
  JobEvents(const std::string& lcm_url, const std::string& prefix, const std::string& loom_id);
  ~JobEvents();
  JobEvents(const JobEvents&) = delete;
  JobEvents& operator=(const JobEvents&) = delete;

  // Thread-safe; never throw (a failure is counted). JOB now.
  void publish_job(const JobReport& r) noexcept;
  // The knot map to carry from now on (null: none), sent at once, band by band.
  void set_carpet(std::shared_ptr<const design::Design> d, std::uint32_t job_id,
                  const std::string& hash) noexcept;
  // The knot map again when kCarpetRepeat has passed since it last went out.
  void repeat_carpet() noexcept;
  std::uint64_t published() const;
  std::uint64_t failures() const;

 private:
  template <typename Msg>
  void send(const std::string& channel, const Msg& m);  // caller holds mu_
  void send_carpet();                                   // caller holds mu_

  lcm_t* lcm_ = nullptr;
  std::string job_channel_, carpet_channel_, loom_id_;
  mutable std::mutex mu_;
  std::shared_ptr<const design::Design> design_;
  std::uint32_t job_id_ = 0;
  std::string hash_;
  std::chrono::steady_clock::time_point carpet_sent_{};
  std::uint64_t published_ = 0, failures_ = 0;
};

}  // namespace loom::telemetry
