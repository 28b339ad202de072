// What loom-panel knows about every loom it hears: the latest STATUS, AXES and RT samples, the beats
// of the row being woven and of the row before it, the last rows' time splits and the last faults —
// each bounded, so the panel runs for months in constant memory. Fed by the LCM thread, read by the
// HTTP threads as JSON; one mutex guards it (nothing here is real-time).
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "loomlcm/axes_t.hpp"
#include "loomlcm/beat_t.hpp"
#include "loomlcm/carpet_t.hpp"
#include "loomlcm/design_t.hpp"
#include "loomlcm/fault_t.hpp"
#include "loomlcm/job_t.hpp"
#include "loomlcm/knots_t.hpp"
#include "loomlcm/row_t.hpp"
#include "loomlcm/rt_stats_t.hpp"
#include "loomlcm/status_t.hpp"
#include "loomlcm/weaver_request_t.hpp"

namespace loom::panel {

struct HallLimits {
  std::size_t looms = 256;                // loom ids kept; more are counted as ignored
  std::size_t rows_kept = 20;             // row summaries per loom in its JSON (the page's table)
  std::size_t rows_report = 500;          // row summaries per loom for the row report download (rows.csv)
  std::size_t faults_kept = 50;           // faults per loom
  std::size_t beats_per_row = 512;        // beats kept per row (the firmware caps a row at 256)
  std::size_t weaver_requests_kept = 20;  // weaver requests per loom (knotting heads)
  std::size_t knots_per_row = 4096;       // knots of a row shown (a wider one is cut, and says so)
  std::size_t jobs_listed = 200;          // jobs of a loom's queue listed (the newest; more are counted)
  // Knots of a carpet's knot map kept per loom (a 1.2 x 1.8 m carpet is 194,400): a bigger design is not
  // drawn, and the page says so.
  std::size_t carpet_knots = 2'000'000;
  // > 0: a message stamped (utime, the publisher's wall clock) longer ago than this is a recording being
  // replayed onto this group (lcm-logplayer); it is kept apart under "<id>~replay" and marked, never mixed
  // into the live loom of that id. 0: every message is live (a log read through file://).
  double replay_after_s = 0.0;
  // The scope strip: each loom's AXES samples (the panel decodes at most 10 a second of a live loom) over
  // the last scope_window_s of loop time, at most scope_samples of them, 32 axes each.
  double scope_window_s = 30.0;
  std::size_t scope_samples = 300;
};

// The suffix that keeps a replayed loom apart: '~' is not a loom id character, so no live loom has it.
inline constexpr const char* kReplaySuffix = "~replay";

// The only way the panel turns JSON into text: any string that is not valid UTF-8 (a design palette
// name saved in cp1252, a spoofed LCM packet) has its bad bytes replaced by U+FFFD instead of throwing
// (nlohmann's type_error 316 would end the HTTP handler's thread and, uncaught, the panel).
std::string json_text(const nlohmann::json& j);

class Hall {
 public:
  using Clock = std::chrono::steady_clock;
  // `wall_now_us`: the wall clock, microseconds since the epoch (tests give their own); null = the system's.
  explicit Hall(HallLimits limits = {}, std::function<std::int64_t()> wall_now_us = nullptr);

  // LCM thread. Each records the message under its loom id and bumps the version.
  void on_status(const loomlcm::status_t& m);
  void on_axes(const loomlcm::axes_t& m);
  void on_rt(const loomlcm::rt_stats_t& m);
  void on_beat(const loomlcm::beat_t& m);
  void on_fault(const loomlcm::fault_t& m);
  void on_row(const loomlcm::row_t& m);
  void on_design(const loomlcm::design_t& m);
  void on_knots(const loomlcm::knots_t& m);
  void on_weaver(const loomlcm::weaver_request_t& m);
  void on_job(const loomlcm::job_t& m);
  void on_carpet(const loomlcm::carpet_t& m);

  // HTTP threads. The hall: every loom heard, one summary object each. A loom: everything kept, or
  // nullopt when that id was never heard.
  nlohmann::json hall_json() const;
  std::optional<nlohmann::json> loom_json(const std::string& id) const;
  // The scope strip of one axis: loop times and that axis' position, velocity and following error (SI,
  // as sent), oldest first, with every axis name; nullopt when the loom was never heard. An unknown axis
  // gives empty traces.
  // The row report: every row summary kept (the newest rows_report) as CSV with a header line, wall-clock
  // time (UTC) and loop time first, SI units in the column names; nullopt when the loom was never heard.
  std::optional<std::string> rows_csv(const std::string& id) const;
  std::optional<nlohmann::json> scope_json(const std::string& id, const std::string& axis) const;
  // The current job's knot map as CARPET brought it: width, height, palette, and every knot as two hex
  // digits (its palette index), bottom row first; rows not heard yet are "ff". nullopt when the loom was
  // never heard or no map came.
  std::optional<nlohmann::json> carpet_json(const std::string& id) const;
  // Changes so far; wait_for_change returns the version once it differs from `seen` (or at timeout).
  std::uint64_t version() const;
  std::uint64_t wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout) const;
  std::size_t ignored_looms() const;

 private:
  struct Beat {
    int index = 0;
    double x_m = 0.0, force_n = 0.0;
    bool measured = false, in_band = false;
  };
  struct BeatRow {
    int row = 0;
    std::vector<Beat> beats;
  };
  struct ScopeSample {
    double time_s = 0.0;
    std::vector<std::array<float, 3>> axes;  // position, velocity, following error, in `scope_names` order
  };
  // A knot map assembled from CARPET bands of one design (its hash): a new hash starts it afresh.
  struct Carpet {
    std::string hash, name;
    std::int32_t job_id = 0, width = 0, height = 0;
    std::vector<std::string> codes;
    std::vector<std::int32_t> rgb;
    std::vector<std::uint8_t> knots;  // width x height, 0xFF = not heard
    std::vector<bool> have;           // per design row
    std::size_t rows_heard = 0;
    bool too_big = false;
  };
  struct Loom {
    Clock::time_point heard{};
    std::vector<std::string> scope_names;  // the axes of the samples kept (a new set starts the strip afresh)
    std::deque<ScopeSample> scope;
    bool replay = false;          // kept under "<id>~replay": stamped older than replay_after_s
    double recorded_s_ago = 0.0;  // a replay: the latest message's age
    std::optional<loomlcm::status_t> status;
    std::optional<loomlcm::axes_t> axes;
    std::optional<loomlcm::rt_stats_t> rt;
    BeatRow current, previous;
    double band_min_n = 80.0, band_max_n = 100.0;
    std::deque<loomlcm::row_t> rows;
    std::deque<loomlcm::fault_t> faults;
    std::optional<loomlcm::design_t> design;       // the weaver's next row (looms weaving a design)
    std::optional<loomlcm::knots_t> knots;         // the knotting heads' progress (looms with heads)
    std::deque<loomlcm::weaver_request_t> weaver;  // the last requests made of the weaver
    std::optional<loomlcm::job_t> job;             // the carpet job queue and progress (serve's JOB)
    Carpet carpet;                                 // the job's knot map (CARPET bands)
    std::uint64_t beats_seen = 0, beats_in_band = 0, faults_seen = 0;
  };
  Loom* loom(const std::string& id);  // nullptr when over the loom limit; caller holds mu_
  // The live loom `id`, or its replay when `utime` is older than the limit; caller holds mu_.
  Loom* loom(const std::string& id, std::int64_t utime);
  void changed();                                                  // caller holds mu_
  void add_scope_sample(Loom& l, const loomlcm::axes_t& m) const;  // caller holds mu_
  static nlohmann::json summary(const std::string& id, const Loom& l, Clock::time_point now);
  nlohmann::json knots_json(const loomlcm::knots_t& m) const;

  HallLimits limits_;
  std::function<std::int64_t()> wall_now_us_;
  mutable std::mutex mu_;
  mutable std::condition_variable cv_;
  std::map<std::string, Loom> looms_;
  std::uint64_t version_ = 0;
  std::size_t ignored_ = 0;
};

}  // namespace loom::panel
