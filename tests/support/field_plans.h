// The field plans the tests and benchmarks drive over, built one way: what varies between them
// (where the rows lie, how many, the plot length and the offset of the first plot) is given, the
// rest is the paper's field (1 m alleys, 90-inch rows to the right). A test changes a field of the
// returned plan where its assertions depend on it. withFieldPlan gives the same plan to the
// `fieldrig map generate` and `fieldrig sim drive` commands.
#pragma once

#include <charconv>
#include <string>
#include <utility>
#include <vector>

#include "fieldrig/gps/field_plan.h"

namespace fieldrig::testing_support {

struct LatLon {
  double latitude_deg = 0;
  double longitude_deg = 0;
};

// `rows` serpentine rows, the first from `start` to `end`, of `plot_length_m` plots with 1 m
// alleys, as many as fit after `start_offset_m`; further rows 2.286 m to the right.
inline gps::FieldPlan fieldPlan(LatLon start, LatLon end, int rows, double plot_length_m = 3.0,
                                double start_offset_m = 0.0) {
  gps::FieldPlan plan;
  plan.row_start_latitude_deg = start.latitude_deg;
  plan.row_start_longitude_deg = start.longitude_deg;
  plan.row_end_latitude_deg = end.latitude_deg;
  plan.row_end_longitude_deg = end.longitude_deg;
  plan.rows = rows;
  plan.plots_per_row = 0;
  plan.plot_length_m = plot_length_m;
  plan.alley_length_m = 1.0;
  plan.row_spacing_m = 2.286;  // 90 inches
  plan.start_offset_m = start_offset_m;
  plan.rows_to_the_right = true;
  return plan;
}

// The shortest text that reads back as `value` ("42.0105", "3"): the command gets exactly the
// plan's numbers.
inline std::string planNumber(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

// `command` (e.g. {"sim", "drive"}), then every option of `plan` as
// tools/commands/field_plan_options.cpp reads them, then `more`.
inline std::vector<std::string> withFieldPlan(std::vector<std::string> command,
                                              const gps::FieldPlan& plan,
                                              const std::vector<std::string>& more = {}) {
  std::vector<std::string> args = std::move(command);
  args.insert(
      args.end(),
      {"--row-start",
       planNumber(plan.row_start_latitude_deg) + "," + planNumber(plan.row_start_longitude_deg),
       "--row-end",
       planNumber(plan.row_end_latitude_deg) + "," + planNumber(plan.row_end_longitude_deg),
       "--rows", std::to_string(plan.rows), "--plots", std::to_string(plan.plots_per_row),
       "--plot-length", planNumber(plan.plot_length_m), "--alley-length",
       planNumber(plan.alley_length_m), "--row-spacing", planNumber(plan.row_spacing_m),
       "--start-offset", planNumber(plan.start_offset_m)});
  if (!plan.rows_to_the_right)
    args.push_back("--left");
  if (!plan.id_prefix.empty())
    args.insert(args.end(), {"--id-prefix", plan.id_prefix});
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

}  // namespace fieldrig::testing_support
