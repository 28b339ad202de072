// The golden dump. Everything is sampled through the same RT lookups the loop uses (tables by
// fixed-point phase, moves by time), so a change in a kernel, a table default or a limit shows up.
// Numbers use 15 significant digits; the golden diff compares them with a tolerance, not as text.
#include "dump.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "loom/motion/angles.hpp"

namespace loom::profile {

namespace {

class CsvFile {
 public:
  CsvFile(const std::string& dir, const char* name, const char* header) : path_(dir + "/" + name) {
    f_ = std::fopen(path_.c_str(), "w");
    if (!f_) throw std::runtime_error(path_ + ": cannot write");
    std::fprintf(f_, "%s\n", header);
  }
  ~CsvFile() {
    if (f_) std::fclose(f_);
  }
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;

  void row(std::initializer_list<double> values) {
    bool first = true;
    for (double v : values) {
      std::fprintf(f_, first ? "%.15g" : ",%.15g", v);
      first = false;
    }
    std::fputc('\n', f_);
  }
  void key(const char* k, double v) { std::fprintf(f_, "%s,%.15g\n", k, v); }
  void key(const char* k, const char* v) { std::fprintf(f_, "%s,%s\n", k, v); }
  void finish() {
    const bool ok = std::ferror(f_) == 0;
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (!ok || rc != 0) throw std::runtime_error(path_ + ": write failed");
  }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
};

void write_facts(const motion::ProfileSet& p, const std::string& dir) {
  using motion::crank_law_name;
  const motion::ProfileSpec& s = p.spec();
  const motion::WarpWindow& w = p.beatup().warp();
  const motion::CarriagePeaks& c = p.carriage_peaks();
  const motion::ShedSpec& sh = p.shed();
  CsvFile f(dir, "profile_set.csv", "key,value");
  f.key("width_m", s.width_m);
  f.key("beater_width_m", s.beater_width_m);
  f.key("overlap_m", s.overlap_m);
  f.key("beats_per_row", p.beats_per_row());
  f.key("pitch_m", p.pitch_m());
  f.key("carriage_travel_m", p.carriage_travel_m());
  f.key("park_crank_angle_rad", p.beatup().park_crank_angle());
  f.key("rocker_swing_rad", p.beatup().dead_centres().swing);
  f.key("warp_enter_rad", w.enter);
  f.key("warp_fell_rad", w.fell);
  f.key("warp_exit_rad", w.exit);
  f.key("clear_window_rad", w.clear());
  f.key("crank_law", crank_law_name(s.crank_law.kind));
  f.key("crank_ratio_max", p.crank_law().max_ratio());
  f.key("crank_ratio_min", p.crank_law().min_ratio());
  f.key("crank_sweep_duration_s", p.crank_sweep().duration());
  f.key("crank_sweep_ramp_rad", p.crank_sweep().ramp_distance());
  f.key("cam_window_start_rad", p.cam().window_start());
  f.key("cam_window_length_rad", p.cam().window_length());
  f.key("cam_steps", p.cam().steps());
  f.key("carriage_peak_speed_m_s", c.speed_m_s);
  f.key("carriage_peak_accel_m_s2", c.accel_m_s2);
  f.key("carriage_peak_jerk_m_s3", c.jerk_m_s3);
  f.key("carriage_step_time_s", c.step_time_s);
  f.key("carriage_max_crank_speed_rad_s", c.max_crank_speed_rad_s);
  f.key("pick_turns", s.width_m / s.helix_lead_m);
  f.key("pick_duration_s", p.pick().duration());
  f.key("pick_peak_speed_rad_s", p.pick().peak_velocity());
  f.key("helix_accel_limit_rad_s2", p.helix_accel_limit());
  f.key("shuttle_accel_limit_m_s2", p.shuttle_accel_limit_m_s2());
  f.key("shed_piston_travel_s", sh.piston_travel_s);
  f.key("shed_confirm_from_s", sh.earliest_fraction * sh.piston_travel_s);
  f.key("shed_release_timeout_s", sh.release_timeout_s);
  f.key("shed_timeout_s", sh.timeout_s);
  f.key("shed_debounce_s", sh.debounce_s);
  f.key("shed_settle_s", sh.settle_s);
  f.key("table_size", static_cast<double>(s.table_size));
  f.key("table_interp", motion::interp_name(s.table_interp));
  f.key("table_precision", motion::precision_name(s.table_precision));
  f.key("table_bytes", static_cast<double>(p.table_bytes()));
  f.finish();
}

void write_tables(const motion::ProfileSet& p, const std::string& dir) {
  constexpr int kRows = 720;  // every half degree
  CsvFile r(dir, "rocker.csv", "crank_phase_deg,rocker_rad,drocker_dphase,d2rocker_dphase2");
  CsvFile c(dir, "crank_law.csv", "master_phase_deg,crank_phase_rad,dcrank_dmaster,d2crank_dmaster2");
  for (int i = 0; i < kRows; ++i) {
    const motion::Phase at = motion::Phase::from_turns(static_cast<double>(i) / kRows);
    const motion::PhaseSample s = p.rocker().at(at);
    r.row({360.0 * i / kRows, s.value, s.d1, s.d2});
    const motion::CrankSample k = p.crank_at(at);
    c.row({360.0 * i / kRows, k.phase, k.d1, k.d2});
  }
  r.finish();
  c.finish();
}

void write_moves(const motion::ProfileSet& p, double period_s, const std::string& dir) {
  // One row's beat sweep, every 10th tick: master (the sweep move), crank (through the law), beater
  // and carriage (the cam on the crank phase).
  CsvFile b(dir, "beat_sweep.csv", "t_s,master_rad,crank_rad,rocker_rad,carriage_m");
  const motion::JerkMove& sweep = p.crank_sweep();
  for (long k = 0;; k += 10) {
    const double t = static_cast<double>(k) * period_s;
    const motion::Phase master = motion::Phase::from_rad(sweep.at(t).position);
    const double crank = p.crank_at(master).phase;
    b.row({t, master.to_rad(), crank, p.rocker_at(master).value, p.cam().at(crank).position});
    if (t >= sweep.duration()) break;
  }
  b.finish();
  CsvFile k(dir, "pick.csv", "t_s,helix_rad,helix_rad_s,helix_rad_s2,shuttle_m_s2");
  const double per_rad = p.spec().helix_lead_m / motion::kTwoPi;
  for (long i = 0;; i += 5) {
    const double t = static_cast<double>(i) * period_s;
    const motion::MoveSample m = p.pick().at(t);
    k.row({t, m.position, m.velocity, m.acceleration, m.acceleration * per_rad});
    if (t >= p.pick().duration()) break;
  }
  k.finish();
}

}  // namespace

void write_dump(const motion::ProfileSet& set, double period_s, const std::string& dir) {
  write_facts(set, dir);
  write_tables(set, dir);
  write_moves(set, period_s, dir);
}

}  // namespace loom::profile
