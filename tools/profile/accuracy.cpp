// Errors are measured at the phases of a Weyl sequence (j·φ_golden mod 1 in the 64-bit fixed-point
// fraction): evenly spread, never aligned with any table's knots, and the same points for every
// table so rows compare like with like. Velocity and acceleration errors are the phase derivatives'
// errors times the profile's phase rate (and its square), i.e. in SI per second.
#include "accuracy.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

namespace loom::profile {

namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;  // 2^64 / golden ratio

struct Config {
  motion::Interp interp;
  motion::Precision precision;
  std::size_t size;
};

double microseconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::vector<std::size_t> default_sizes() {
  std::vector<std::size_t> s;
  for (std::size_t n = 64; n <= 65536; n *= 2) s.push_back(n);
  return s;
}

std::string csv_line(const AccuracyRow& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s,%s,%zu,%s,%.6g,%.6g,%.6g,%.6g,%.4g,%.4g,%zu", r.profile.c_str(),
                r.interp.c_str(), r.table_size, r.precision.c_str(), r.max_pos_err, r.max_vel_err,
                r.max_acc_err, r.rms_pos_err, r.lookup_ns, r.build_us, r.bytes);
  return buf;
}

std::vector<AccuracyRow> measure_accuracy(const Catalogue& cat, const AccuracyOptions& opt) {
  const std::vector<std::size_t> sizes = opt.sizes.empty() ? default_sizes() : opt.sizes;
  std::vector<AccuracyRow> rows;
  std::vector<std::unique_ptr<motion::PhaseTable>> tables;  // alive until timed
  std::vector<TimedCase> cases;

  for (const ReportProfile& prof : cat.profiles) {
    if (opt.progress)
      std::fprintf(stderr, "loom-profile: %s: exact reference at %zu phases\n", prof.name.c_str(),
                   opt.check_points);
    std::vector<std::uint64_t> fracs(opt.check_points);
    std::vector<motion::PhaseExact> truth(opt.check_points);
    for (std::size_t j = 0; j < opt.check_points; ++j) {
      fracs[j] = kGolden * (j + 1);
      const motion::Phase at{0, fracs[j]};
      truth[j] = prof.exact(at.frac_rad());  // the whole function, rise included
    }
    // The closed form, timed like a lookup.
    rows.push_back({.profile = prof.name, .interp = "exact", .table_size = 0, .precision = "double"});
    cases.push_back({prof.name + "/exact", [f = prof.closed_form](benchmark::State& st) {
                       std::uint64_t x = 0;
                       for (auto _ : st) {
                         x += kGolden;
                         benchmark::DoNotOptimize(f(motion::Phase{0, x}.frac_rad()));
                       }
                     }});
    for (motion::Precision prec : {motion::Precision::kDouble, motion::Precision::kFloat}) {
      for (motion::Interp interp :
           {motion::Interp::kLinear, motion::Interp::kCubic, motion::Interp::kQuintic}) {
        for (std::size_t n : sizes) {
          const motion::TableSpec spec{.size = n, .interp = interp, .precision = prec, .rise = prof.rise};
          // Build time: the best of a few builds (one for the big tables, which take milliseconds).
          double build_us = INFINITY;
          std::unique_ptr<motion::PhaseTable> table;
          for (int rep = 0; rep < (n <= 4096 ? 5 : 1); ++rep) {
            const auto t0 = std::chrono::steady_clock::now();
            auto t = std::make_unique<motion::PhaseTable>(spec, prof.exact);
            build_us = std::min(build_us, microseconds_since(t0));
            table = std::move(t);
          }
          AccuracyRow r{.profile = prof.name,
                        .interp = motion::interp_name(interp),
                        .table_size = n,
                        .precision = motion::precision_name(prec),
                        .build_us = build_us,
                        .bytes = table->bytes()};
          double sum_sq = 0.0;
          for (std::size_t j = 0; j < fracs.size(); ++j) {
            const motion::PhaseSample s = table->at(motion::Phase{0, fracs[j]});
            const double ep = std::abs(s.value - truth[j].value);
            r.max_pos_err = std::max(r.max_pos_err, ep);
            r.max_vel_err = std::max(r.max_vel_err, std::abs(s.d1 - truth[j].d1) * prof.phase_rate);
            r.max_acc_err =
                std::max(r.max_acc_err, std::abs(s.d2 - truth[j].d2) * prof.phase_rate * prof.phase_rate);
            sum_sq += ep * ep;
          }
          r.rms_pos_err = std::sqrt(sum_sq / static_cast<double>(fracs.size()));
          rows.push_back(r);
          const motion::PhaseTable* tp = table.get();
          cases.push_back({prof.name + "/" + r.interp + "/" + std::to_string(n) + "/" + r.precision,
                           [tp](benchmark::State& st) {
                             std::uint64_t x = 0;
                             for (auto _ : st) {
                               x += kGolden;
                               benchmark::DoNotOptimize(tp->at(motion::Phase{0, x}));
                             }
                           }});
          tables.push_back(std::move(table));
        }
      }
    }
  }
  if (opt.progress)
    std::fprintf(stderr, "loom-profile: timing %zu lookups with Google Benchmark\n", cases.size());
  const std::vector<double> ns = time_cases(cases, opt.timing);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].lookup_ns = ns[i];
  return rows;
}

}  // namespace loom::profile
