// The field-plan options shared by `map generate` and `sim drive`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/gps/field_plan.h"

namespace fieldrig::tools {

// A breeding field is tens of rows of tens to hundreds of plots: these bounds leave room for the
// largest while keeping a typo (--rows 2000000000) from running for hours.
inline constexpr int kMaxFieldRows = 1000;
inline constexpr int kMaxPlotsPerRow = 10'000;
inline constexpr double kMaxFieldLocations = 100'000;
inline constexpr double kMaxRowLengthM = 10'000;

struct FieldPlanArgs {
  std::string row_start;  // "LAT,LON"
  std::string row_end;
  gps::FieldPlan plan;
  bool left = false;
};

// Adds --row-start, --row-end, --rows, --plots, --plot-length, --alley-length, --row-spacing,
// --start-offset, --left and --id-prefix to `command`, bound to `args`.
void addFieldPlanOptions(CLI::App& command, FieldPlanArgs& args);

// The plan with the row ends parsed; the error names the option that is wrong, also when the
// plan would hold more than kMaxFieldLocations locations.
core::Result<gps::FieldPlan> resolveFieldPlan(const FieldPlanArgs& args);

}  // namespace fieldrig::tools
