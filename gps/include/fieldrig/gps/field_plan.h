// Imaging locations generated from a field plan instead of a recorded drive.
//
// The first row runs from `row_start` to `row_end`; further rows lie parallel to it,
// `row_spacing_m` apart, to the right of the first row's direction (or the left). Each row holds
// `plots_per_row` plots of `plot_length_m` separated by alleys of `alley_length_m`, the first
// starting `start_offset_m` after the row start. One location is generated at each plot centre,
// with the heading of serpentine driving: odd rows (0-based) are driven back toward the start.
#pragma once

#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/gps/location_map.h"

namespace fieldrig::gps {

struct FieldPlan {
  double row_start_latitude_deg = 0;
  double row_start_longitude_deg = 0;
  double row_end_latitude_deg = 0;
  double row_end_longitude_deg = 0;
  int rows = 1;
  int plots_per_row = 0;  // 0: as many as fit between row start and end
  double plot_length_m = 3.0;
  double alley_length_m = 1.0;
  double row_spacing_m = 2.286;  // 90 inches, the paper's spacing
  double start_offset_m = 0.0;
  bool rows_to_the_right = true;
  std::string id_prefix;  // ids are <prefix>R<row>P<plot>, 1-based, zero-padded
};

// Locations in driving order with metadata columns row (1-based), plot (1-based and unique in
// the field: (row-1)*plots_per_row + range) and range (1-based position along the field's
// direction, the P number of the id, whichever way the row is driven). Errors name the field
// of the plan that is wrong (e.g. plots that do not fit in the row).
core::Result<LocationMap> generateLocations(const FieldPlan& plan);

}  // namespace fieldrig::gps
