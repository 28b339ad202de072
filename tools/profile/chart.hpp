// The Pareto chart of the report, written as SVG by hand (no plotting dependency): per profile,
// worst position error against lookup time on log axes, every table a point, the Pareto front
// joined, the accuracy requirement dashed.
#pragma once

#include <string>
#include <vector>

#include "accuracy.hpp"
#include "catalogue.hpp"

namespace loom::profile {

// Rows on neither axis worse than another row: not beaten on both time and error by any single row.
std::vector<const AccuracyRow*> pareto_front(const std::vector<const AccuracyRow*>& rows);

// Configure-time only. The SVG document.
std::string pareto_svg(const Catalogue& cat, const std::vector<AccuracyRow>& rows);

}  // namespace loom::profile
