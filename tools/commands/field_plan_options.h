// The field-plan options shared by `map generate` and `sim drive`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/gps/field_plan.h"

namespace fieldrig::tools {

struct FieldPlanArgs {
  std::string row_start;  // "LAT,LON"
  std::string row_end;
  gps::FieldPlan plan;
  bool left = false;
};

// Adds --row-start, --row-end, --rows, --plots, --plot-length, --alley-length, --row-spacing,
// --start-offset, --left and --id-prefix to `command`, bound to `args`.
void addFieldPlanOptions(CLI::App& command, FieldPlanArgs& args);

// The plan with the row ends parsed; the error names the option that is wrong.
core::Result<gps::FieldPlan> resolveFieldPlan(const FieldPlanArgs& args);

}  // namespace fieldrig::tools
