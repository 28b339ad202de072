// The accuracy-versus-time measurement behind `loom-profile report`: for each profile, table size,
// interpolation order and precision, the errors against the exact kinematics at a quarter-million
// phases, the build time and the memory, plus the lookup time from Google Benchmark. The closed
// form itself is a row too ("exact"), so a table must beat it to be worth its memory.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "catalogue.hpp"
#include "timing.hpp"

namespace loom::profile {

struct AccuracyRow {
  std::string profile;
  std::string interp;  // linear, cubic, quintic, or exact (the closed form, no table)
  std::size_t table_size = 0;
  std::string precision;  // double, float32
  double max_pos_err = 0.0, max_vel_err = 0.0, max_acc_err = 0.0, rms_pos_err = 0.0;
  double lookup_ns = 0.0;
  double build_us = 0.0;
  std::size_t bytes = 0;
};

struct AccuracyOptions {
  std::vector<std::size_t> sizes;  // default: 64, 128, ..., 65536
  std::size_t check_points = std::size_t{1} << 18;
  TimingOptions timing;
  bool progress = true;  // one line per profile on stderr
};
std::vector<std::size_t> default_sizes();

// Configure-time only (runs for a while: ~30 s with the defaults).
std::vector<AccuracyRow> measure_accuracy(const Catalogue& cat, const AccuracyOptions& opt);

// The exact CSV header of the command-line contract.
inline constexpr const char* kAccuracyHeader =
    "profile,interp,table_size,precision,max_pos_err,max_vel_err,max_acc_err,rms_pos_err,lookup_ns,build_us,"
    "bytes";
std::string csv_line(const AccuracyRow& r);

}  // namespace loom::profile
