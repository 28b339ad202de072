// The report's conclusions: the default per profile (the exact closed form when it fits the lookup
// budget, else the cheapest table meeting the accuracy bounds, then the least memory), float32
// against double, what each order costs at a few sizes, and the whole ProfileSet's build time — as
// a README-ready markdown block.
#pragma once

#include <string>
#include <vector>

#include "accuracy.hpp"
#include "catalogue.hpp"

namespace loom::profile {

struct Choice {
  const AccuracyRow* row = nullptr;  // null when nothing meets the requirement
  std::string why;
};

// The per-lookup budget of the target: a tick samples several profiles and must stay cheap.
inline constexpr double kLookupBudgetNs = 20.0;

// The default for `prof`: its exact closed form when that fits the lookup budget (no table, no
// error); otherwise among tables (of one precision when `precision` is not empty, which also
// leaves the closed form out) meeting its position, velocity and acceleration bounds: those within
// 10 % + 0.3 ns (timing noise) of the fastest, preferring 10x margin on position, then fewest bytes,
// then the smallest acceleration error.
Choice choose_default(const ReportProfile& prof, const std::vector<AccuracyRow>& rows,
                      const std::string& precision = "");

struct BuildTimes {
  double constant_us = 0.0;  // default loom, constant crank law: best of 20 builds
  double elliptic_us = 0.0;  // the same with the elliptic law (one more table)
  std::size_t table_bytes = 0;
  std::string tables;  // "1024-knot cubic double"
};
BuildTimes measure_build_times();

std::string choice_label(const AccuracyRow& r);  // "cubic 1024 double" or "closed form"
std::string summary_markdown(const Catalogue& cat, const std::vector<AccuracyRow>& rows,
                             const BuildTimes& build);

}  // namespace loom::profile
