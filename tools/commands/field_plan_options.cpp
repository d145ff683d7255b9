#include "commands/field_plan_options.h"

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <tuple>

#include "commands/command_helpers.h"
#include "fieldrig/gps/local_frame.h"

namespace fieldrig::tools {
namespace {

bool parseDouble(std::string_view text, double& out) {
  while (!text.empty() && text.front() == ' ')
    text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ')
    text.remove_suffix(1);
  if (!text.empty() && text.front() == '+')
    text.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return !text.empty() && ec == std::errc() && ptr == text.data() + text.size() &&
         std::isfinite(out);
}

// "LAT,LON" in decimal degrees.
bool parseLatLon(std::string_view text, double& latitude, double& longitude) {
  const std::size_t comma = text.find(',');
  if (comma == std::string_view::npos)
    return false;
  return parseDouble(text.substr(0, comma), latitude) &&
         parseDouble(text.substr(comma + 1), longitude);
}

}  // namespace

void addFieldPlanOptions(CLI::App& command, FieldPlanArgs& args) {
  command.add_option("--row-start", args.row_start, "Start of the first row: LAT,LON")->required();
  command.add_option("--row-end", args.row_end, "End of the first row: LAT,LON")->required();
  command.add_option("--rows", args.plan.rows, "Number of rows")
      ->required()
      ->check(finiteRange(1, kMaxFieldRows));
  command.add_option("--plots", args.plan.plots_per_row, "Plots per row (0: as many as fit)")
      ->capture_default_str()
      ->check(finiteRange(0, kMaxPlotsPerRow));
  command.add_option("--plot-length", args.plan.plot_length_m, "Plot length, m")
      ->required()
      ->check(finiteRange(0.1, 1000.0));
  command.add_option("--alley-length", args.plan.alley_length_m, "Alley length, m")
      ->required()
      ->check(finiteRange(0.0, 1000.0));
  command.add_option("--row-spacing", args.plan.row_spacing_m, "Row spacing, m")
      ->required()
      ->check(finiteRange(0.1, 100.0));
  command
      .add_option("--start-offset", args.plan.start_offset_m,
                  "Distance from the row start to the first plot, m")
      ->capture_default_str()
      ->check(finiteRange(0.0, 10'000.0));
  command.add_flag("--left", args.left,
                   "Further rows lie to the left of the first (default right)");
  command.add_option("--id-prefix", args.plan.id_prefix, "Prefix of the ids <prefix>R<row>P<plot>");
}

core::Result<gps::FieldPlan> resolveFieldPlan(const FieldPlanArgs& args) {
  gps::FieldPlan plan = args.plan;
  if (!parseLatLon(args.row_start, plan.row_start_latitude_deg, plan.row_start_longitude_deg)) {
    return core::Error{"--row-start: '" + args.row_start + "' is not LAT,LON in decimal degrees"};
  }
  if (!parseLatLon(args.row_end, plan.row_end_latitude_deg, plan.row_end_longitude_deg)) {
    return core::Error{"--row-end: '" + args.row_end + "' is not LAT,LON in decimal degrees"};
  }
  plan.rows_to_the_right = !args.left;
  for (const auto& [option, latitude, longitude] :
       {std::tuple{"--row-start", plan.row_start_latitude_deg, plan.row_start_longitude_deg},
        std::tuple{"--row-end", plan.row_end_latitude_deg, plan.row_end_longitude_deg}}) {
    if (std::abs(latitude) > 90 || std::abs(longitude) > 180) {
      return core::Error{std::string(option) +
                         ": latitude must be in [-90, 90] and longitude in [-180, 180]"};
    }
  }
  // A row end on another continent (a swapped sign) would make a drive of days.
  const gps::LocalFrame frame(plan.row_start_latitude_deg, plan.row_start_longitude_deg);
  const gps::EnuPoint end = frame.toLocal(plan.row_end_latitude_deg, plan.row_end_longitude_deg);
  const double row_length_m = std::hypot(end.east_m, end.north_m);
  if (row_length_m > kMaxRowLengthM) {
    return core::Error{"--row-end: " + std::to_string(static_cast<long long>(row_length_m)) +
                       " m from --row-start; a row may be at most " +
                       std::to_string(static_cast<long long>(kMaxRowLengthM)) + " m long"};
  }
  // With --plots 0 the count follows from the row's length: a short --plot-length makes it huge
  // as surely as --rows does.
  double plots_per_row = plan.plots_per_row;
  if (plots_per_row == 0)
    plots_per_row = std::floor(row_length_m / (plan.plot_length_m + plan.alley_length_m));
  if (const double locations = plots_per_row * plan.rows; locations > kMaxFieldLocations) {
    return core::Error{"--rows × --plots: " + std::to_string(static_cast<long long>(locations)) +
                       " locations; a field plan may have at most " +
                       std::to_string(static_cast<long long>(kMaxFieldLocations))};
  }
  return plan;
}

}  // namespace fieldrig::tools
