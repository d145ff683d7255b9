#include "fieldrig/gps/field_plan.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "fieldrig/gps/local_frame.h"

namespace fieldrig::gps {
namespace {

// Lengths are checked to this slack so that a plan whose plots fill the row exactly (as typed
// from a plot sheet, with decimal rounding) is not refused for a micrometre.
constexpr double kFitToleranceM = 1e-6;
// Row ends closer than this are the same point: no direction can be taken from them.
constexpr double kMinRowLengthM = 0.01;

core::Error planError(std::string_view field, const std::string& message) {
  return core::Error{"field plan: field '" + std::string(field) + "': " + message};
}

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

int decimalDigits(int value) {
  int digits = 1;
  while (value >= 10) {
    value /= 10;
    ++digits;
  }
  return digits;
}

std::string padded(int value, int width) {
  std::string text = std::to_string(value);
  if (static_cast<int>(text.size()) < width) {
    text.insert(0, static_cast<std::size_t>(width) - text.size(), '0');
  }
  return text;
}

std::optional<core::Error> checkPoint(std::string_view field, double latitude, double longitude) {
  if (!std::isfinite(latitude) || latitude < -90 || latitude > 90) {
    return planError(field, "latitude " + number(latitude) + " is outside [-90, 90]");
  }
  if (!std::isfinite(longitude) || longitude < -180 || longitude > 180) {
    return planError(field, "longitude " + number(longitude) + " is outside [-180, 180]");
  }
  return std::nullopt;
}

}  // namespace

core::Result<LocationMap> generateLocations(const FieldPlan& plan) {
  if (auto bad =
          checkPoint("row_start", plan.row_start_latitude_deg, plan.row_start_longitude_deg)) {
    return *bad;
  }
  if (auto bad = checkPoint("row_end", plan.row_end_latitude_deg, plan.row_end_longitude_deg)) {
    return *bad;
  }
  if (plan.rows < 1)
    return planError("rows", "must be at least 1, got " + std::to_string(plan.rows));
  if (plan.plots_per_row < 0) {
    return planError("plots_per_row", "must be 0 (as many as fit) or more, got " +
                                          std::to_string(plan.plots_per_row));
  }
  if (!std::isfinite(plan.plot_length_m) || plan.plot_length_m <= 0) {
    return planError("plot_length_m", "must be positive, got " + number(plan.plot_length_m));
  }
  if (!std::isfinite(plan.alley_length_m) || plan.alley_length_m < 0) {
    return planError("alley_length_m",
                     "must be zero or positive, got " + number(plan.alley_length_m));
  }
  if (!std::isfinite(plan.row_spacing_m) || plan.row_spacing_m <= 0) {
    return planError("row_spacing_m", "must be positive, got " + number(plan.row_spacing_m));
  }
  if (!std::isfinite(plan.start_offset_m) || plan.start_offset_m < 0) {
    return planError("start_offset_m",
                     "must be zero or positive, got " + number(plan.start_offset_m));
  }

  // The frame is anchored at the row start: the whole field is a few hundred metres across, where
  // the tangent plane departs from the ellipsoid by micrometres (see LocalFrame::toGeodetic).
  const LocalFrame frame(plan.row_start_latitude_deg, plan.row_start_longitude_deg);
  const EnuPoint end = frame.toLocal(plan.row_end_latitude_deg, plan.row_end_longitude_deg);
  const double row_length = std::hypot(end.east_m, end.north_m);
  if (row_length < kMinRowLengthM) {
    return planError(
        "row_end", "the row end coincides with the row start (" + number(row_length) + " m apart)");
  }
  const double along_east = end.east_m / row_length;
  const double along_north = end.north_m / row_length;
  // To the right of travel is the direction turned 90 degrees clockwise: (north, -east).
  const double side = plan.rows_to_the_right ? 1.0 : -1.0;
  const double across_east = side * along_north;
  const double across_north = side * -along_east;

  const double pitch = plan.plot_length_m + plan.alley_length_m;
  const double usable = row_length - plan.start_offset_m;
  int plots = plan.plots_per_row;
  if (plots == 0) {
    // n plots take n*plot + (n-1)*alley.
    plots = static_cast<int>(std::floor((usable + plan.alley_length_m + kFitToleranceM) / pitch));
    if (plots < 1) {
      return planError("plot_length_m", "not even one plot of " + number(plan.plot_length_m) +
                                            " m fits in the row (" + number(row_length) +
                                            " m long, start offset " + number(plan.start_offset_m) +
                                            " m)");
    }
  } else {
    const double needed =
        plan.start_offset_m + plots * plan.plot_length_m + (plots - 1) * plan.alley_length_m;
    if (needed > row_length + kFitToleranceM) {
      return planError("plots_per_row", std::to_string(plots) + " plots need " + number(needed) +
                                            " m but the row is " + number(row_length) + " m long");
    }
  }

  // Headings to a micro-degree: finer is noise of the tangent-plane arithmetic (a due-north row
  // would otherwise read 359.99999999999494) and means nothing to the ±60° travel test.
  const auto tidy = [](double degrees) {
    const double rounded = std::round(degrees * 1e6) / 1e6;
    return rounded >= 360.0 ? rounded - 360.0 : rounded;
  };
  const double forward_heading = tidy(bearingDegrees(along_east, along_north));
  const double backward_heading = tidy(std::fmod(forward_heading + 180.0, 360.0));
  // Ids are zero-padded to the widest number (at least two digits) so that they sort in field
  // order as text.
  const int row_width = std::max(2, decimalDigits(plan.rows));
  const int plot_width = std::max(2, decimalDigits(plots));

  LocationMap map({"row", "plot", "range"});
  for (int row = 0; row < plan.rows; ++row) {
    const bool forward = row % 2 == 0;  // serpentine: odd rows are driven back to the start side
    for (int step = 0; step < plots; ++step) {
      const int range = forward ? step : plots - 1 - step;  // 0-based position along the field
      const double along = plan.start_offset_m + range * pitch + plan.plot_length_m / 2;
      const double across = row * plan.row_spacing_m;
      const EnuPoint centre{along * along_east + across * across_east,
                            along * along_north + across * across_north};
      const GeodeticPoint position = frame.toGeodetic(centre);

      ImagingLocation location;
      location.id =
          plan.id_prefix + "R" + padded(row + 1, row_width) + "P" + padded(range + 1, plot_width);
      location.latitude_deg = position.latitude_deg;
      location.longitude_deg = position.longitude_deg;
      location.heading_deg = forward ? forward_heading : backward_heading;
      location.metadata = {std::to_string(row + 1), std::to_string(row * plots + range + 1),
                           std::to_string(range + 1)};
      auto added = map.add(std::move(location));
      if (!added)
        return core::Error{"field plan: " + added.error().message};
    }
  }
  return map;
}

}  // namespace fieldrig::gps
