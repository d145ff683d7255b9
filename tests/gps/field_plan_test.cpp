#include "fieldrig/gps/field_plan.h"

#include <gtest/gtest.h>
#include <GeographicLib/Geodesic.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "support/field_plans.h"

namespace fieldrig::gps {
namespace {

using testing_support::fieldPlan;
using testing_support::LatLon;

const GeographicLib::Geodesic& wgs84() {
  return GeographicLib::Geodesic::WGS84();
}

// `metres` from `start` on the geodesic of `azimuth_deg`, by GeographicLib's Direct: the row ends
// are computed independently of the code under test.
LatLon along(LatLon start, double azimuth_deg, double metres) {
  LatLon end;
  wgs84().Direct(start.latitude_deg, start.longitude_deg, azimuth_deg, metres, end.latitude_deg,
                 end.longitude_deg);
  return end;
}

double distance(const ImagingLocation& a, const ImagingLocation& b) {
  double metres = 0;
  wgs84().Inverse(a.latitude_deg, a.longitude_deg, b.latitude_deg, b.longitude_deg, metres);
  return metres;
}

// Azimuth (degrees true, [0, 360)) of the geodesic from a to b, at a.
double azimuth(double lat1, double lon1, double lat2, double lon2) {
  double metres = 0, azimuth1 = 0, azimuth2 = 0;
  wgs84().Inverse(lat1, lon1, lat2, lon2, metres, azimuth1, azimuth2);
  return azimuth1 < 0 ? azimuth1 + 360 : azimuth1;
}

double angleDifference(double a, double b) {
  double d = std::fmod(std::fabs(a - b), 360.0);
  return d > 180 ? 360 - d : d;
}

// Four rows of ~80 m running roughly north-east near Ames, Iowa: start and end are 80 m apart on
// the azimuth 40 degrees. Five 10-foot plots (the paper's) from 2 m after the row start, 1 m
// alleys, 90-inch rows.
FieldPlan amesPlan() {
  const LatLon start{42.0105, -93.7452};
  FieldPlan plan = fieldPlan(start, along(start, 40.0, 80.0), 4, 3.048, 2.0);
  plan.plots_per_row = 5;
  plan.id_prefix = "S1-";
  return plan;
}

const ImagingLocation& byId(const LocationMap& map, const std::string& id) {
  const ImagingLocation* location = map.find(id);
  EXPECT_NE(location, nullptr) << id;
  static const ImagingLocation kNone;
  return location ? *location : kNone;
}

TEST(FieldPlan, CountsIdsAndDrivingOrder) {
  auto map = generateLocations(amesPlan());
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 20u);
  EXPECT_EQ(map->metadataColumns(), (std::vector<std::string>{"row", "plot", "range"}));
  // Serpentine driving: row 1 up the field, row 2 back down, …
  const std::vector<std::string> expected_order = {
      "S1-R01P01", "S1-R01P02", "S1-R01P03", "S1-R01P04", "S1-R01P05", "S1-R02P05", "S1-R02P04",
      "S1-R02P03", "S1-R02P02", "S1-R02P01", "S1-R03P01", "S1-R03P02", "S1-R03P03", "S1-R03P04",
      "S1-R03P05", "S1-R04P05", "S1-R04P04", "S1-R04P03", "S1-R04P02", "S1-R04P01"};
  for (std::size_t i = 0; i < expected_order.size(); ++i) {
    EXPECT_EQ(map->locations()[i].id, expected_order[i]) << i;
  }
  // row, plot (unique in the field), range (position along the field).
  EXPECT_EQ(byId(*map, "S1-R01P01").metadata, (std::vector<std::string>{"1", "1", "1"}));
  EXPECT_EQ(byId(*map, "S1-R02P04").metadata, (std::vector<std::string>{"2", "9", "4"}));
  EXPECT_EQ(byId(*map, "S1-R04P05").metadata, (std::vector<std::string>{"4", "20", "5"}));
}

TEST(FieldPlan, PlotCentresAlongTheRow) {
  const FieldPlan plan = amesPlan();
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  // The first centre is start_offset + plot/2 = 2 + 1.524 = 3.524 m from the row start, on the
  // row's line (azimuth 40 degrees).
  const ImagingLocation& first = byId(*map, "S1-R01P01");
  double metres = 0, azimuth1 = 0, azimuth2 = 0;
  wgs84().Inverse(plan.row_start_latitude_deg, plan.row_start_longitude_deg, first.latitude_deg,
                  first.longitude_deg, metres, azimuth1, azimuth2);
  EXPECT_NEAR(metres, 3.524, 1e-3);
  EXPECT_NEAR(azimuth1, 40.0, 1e-3);
  // Consecutive plots in every row are plot + alley = 4.048 m apart.
  for (int row = 1; row <= 4; ++row) {
    for (int plot = 1; plot < 5; ++plot) {
      const std::string a = "S1-R0" + std::to_string(row) + "P0" + std::to_string(plot);
      const std::string b = "S1-R0" + std::to_string(row) + "P0" + std::to_string(plot + 1);
      EXPECT_NEAR(distance(byId(*map, a), byId(*map, b)), 4.048, 1e-3) << a << " " << b;
    }
  }
  // The last plot centre: 2 + 4 * 4.048 + 1.524 = 19.716 m from the start.
  const ImagingLocation& last = byId(*map, "S1-R01P05");
  wgs84().Inverse(plan.row_start_latitude_deg, plan.row_start_longitude_deg, last.latitude_deg,
                  last.longitude_deg, metres, azimuth1, azimuth2);
  EXPECT_NEAR(metres, 19.716, 1e-3);
}

TEST(FieldPlan, RowsAreSpacedToTheRight) {
  const FieldPlan plan = amesPlan();
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  for (int row = 1; row < 4; ++row) {
    for (int plot = 1; plot <= 5; ++plot) {
      const ImagingLocation& a =
          byId(*map, "S1-R0" + std::to_string(row) + "P0" + std::to_string(plot));
      const ImagingLocation& b =
          byId(*map, "S1-R0" + std::to_string(row + 1) + "P0" + std::to_string(plot));
      EXPECT_NEAR(distance(a, b), 2.286, 1e-3);
      // To the right of travel along azimuth 40 is azimuth 130.
      EXPECT_NEAR(azimuth(a.latitude_deg, a.longitude_deg, b.latitude_deg, b.longitude_deg), 130.0,
                  0.01);
    }
  }
  // Row 4 is three spacings from row 1.
  EXPECT_NEAR(distance(byId(*map, "S1-R01P03"), byId(*map, "S1-R04P03")), 3 * 2.286, 1e-3);
}

TEST(FieldPlan, RowsToTheLeft) {
  FieldPlan plan = amesPlan();
  plan.rows_to_the_right = false;
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  const ImagingLocation& a = byId(*map, "S1-R01P02");
  const ImagingLocation& b = byId(*map, "S1-R02P02");
  EXPECT_NEAR(distance(a, b), 2.286, 1e-3);
  EXPECT_NEAR(azimuth(a.latitude_deg, a.longitude_deg, b.latitude_deg, b.longitude_deg), 310.0,
              0.01);
}

TEST(FieldPlan, SerpentineHeadings) {
  auto map = generateLocations(amesPlan());
  ASSERT_TRUE(map.ok()) << map.error().message;
  for (const ImagingLocation& location : map->locations()) {
    ASSERT_TRUE(location.heading_deg.has_value()) << location.id;
    const bool odd_row = location.metadata[0] == "1" || location.metadata[0] == "3";
    EXPECT_NEAR(*location.heading_deg, odd_row ? 40.0 : 220.0, 1e-3) << location.id;
  }
}

TEST(FieldPlan, HeadingWrapsAroundNorth) {
  // A row driven due south (azimuth 180): the way back is 0, never 360.
  const LatLon start{-33.9, 18.4};
  FieldPlan plan = fieldPlan(start, along(start, 180.0, 20.0), 2);
  plan.plots_per_row = 1;
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 2u);
  EXPECT_NEAR(*map->locations()[0].heading_deg, 180.0, 1e-3);
  EXPECT_LT(angleDifference(*map->locations()[1].heading_deg, 0.0), 1e-3);
  EXPECT_GE(*map->locations()[1].heading_deg, 0.0);
  EXPECT_LT(*map->locations()[1].heading_deg, 360.0);
}

TEST(FieldPlan, AsManyPlotsAsFit) {
  FieldPlan plan = amesPlan();
  plan.plots_per_row = 0;
  plan.rows = 1;
  // 80 m row, offset 2: n plots need 2 + 3.048 n + (n - 1) = 1 + 4.048 n <= 80 -> n = 19.
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->size(), 19u);
  EXPECT_NE(map->find("S1-R01P19"), nullptr);
  EXPECT_EQ(map->find("S1-R01P20"), nullptr);
}

TEST(FieldPlan, PlotsFillingTheRowExactlyFit) {
  const LatLon start{10.0, 20.0};
  FieldPlan plan = fieldPlan(start, along(start, 90.0, 15.0), 1, 4.0, 0.0);
  plan.plots_per_row = 3;  // 3 * 4 + 2 * 1 = 14 <= 15
  EXPECT_TRUE(generateLocations(plan).ok());
  plan.start_offset_m = 1.0;  // 15: exactly the row
  EXPECT_TRUE(generateLocations(plan).ok());
  plan.start_offset_m = 1.01;  // 15.01: one centimetre too long
  auto too_long = generateLocations(plan);
  ASSERT_FALSE(too_long.ok());
  EXPECT_EQ(
      too_long.error().message.rfind("field plan: field 'plots_per_row': 3 plots need 15.01 m", 0),
      0u)
      << too_long.error().message;
}

TEST(FieldPlan, IdsPadToTheWidestNumber) {
  const LatLon start{10.0, 20.0};
  FieldPlan plan = fieldPlan(start, along(start, 0.0, 500.0), 101, 1.0);
  plan.plots_per_row = 3;
  plan.alley_length_m = 0.0;
  plan.row_spacing_m = 1.0;
  auto map = generateLocations(plan);
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->size(), 303u);
  EXPECT_EQ(map->locations()[0].id, "R001P01");
  EXPECT_NE(map->find("R101P03"), nullptr);
}

std::string planError(const FieldPlan& plan) {
  auto map = generateLocations(plan);
  EXPECT_FALSE(map.ok());
  return map.ok() ? std::string() : map.error().message;
}

// One field of amesPlan() made wrong, and the error it must give: the whole message, or (where
// the rest quotes computed numbers) how it starts.
struct WrongField {
  std::function<void(FieldPlan&)> spoil;
  std::string message;
  bool whole = true;
};

TEST(FieldPlan, ErrorsNameTheField) {
  const std::vector<WrongField> cases{
      {[](FieldPlan& p) { p.rows = 0; }, "field plan: field 'rows': must be at least 1, got 0"},
      {[](FieldPlan& p) { p.plots_per_row = -1; }, "field plan: field 'plots_per_row':", false},
      {[](FieldPlan& p) { p.plot_length_m = 0; },
       "field plan: field 'plot_length_m': must be positive, got 0"},
      {[](FieldPlan& p) { p.alley_length_m = -0.5; },
       "field plan: field 'alley_length_m': must be zero or positive, got -0.5"},
      {[](FieldPlan& p) { p.row_spacing_m = 0; },
       "field plan: field 'row_spacing_m': must be positive, got 0"},
      {[](FieldPlan& p) { p.start_offset_m = -1; },
       "field plan: field 'start_offset_m': must be zero or positive, got -1"},
      {[](FieldPlan& p) {
         p.row_end_latitude_deg = p.row_start_latitude_deg;
         p.row_end_longitude_deg = p.row_start_longitude_deg;
       },
       "field plan: field 'row_end': the row end coincides", false},
      {[](FieldPlan& p) { p.row_start_latitude_deg = 91; },
       "field plan: field 'row_start': latitude 91 is outside [-90, 90]"},
      {[](FieldPlan& p) { p.row_end_longitude_deg = std::nan(""); },
       "field plan: field 'row_end': longitude", false},
      {[](FieldPlan& p) { p.plots_per_row = 20; },  // 1 + 4.048 * 20 = 81.96 > 80
       "field plan: field 'plots_per_row': 20 plots need 81.96 m", false},
      {[](FieldPlan& p) {
         p.plots_per_row = 0;
         p.plot_length_m = 100;
       },
       "field plan: field 'plot_length_m': not even one plot", false},
  };
  for (const WrongField& wrong : cases) {
    FieldPlan plan = amesPlan();
    wrong.spoil(plan);
    const std::string error = planError(plan);
    if (wrong.whole) {
      EXPECT_EQ(error, wrong.message);
    } else {
      EXPECT_EQ(error.rfind(wrong.message, 0), 0u) << error;
    }
  }
}

TEST(FieldPlan, GeneratedMapRoundTripsThroughCsv) {
  auto map = generateLocations(amesPlan());
  ASSERT_TRUE(map.ok()) << map.error().message;
  auto reread = LocationMap::parse(map->toCsv(), "generated.csv");
  ASSERT_TRUE(reread.ok()) << reread.error().message;
  ASSERT_EQ(reread->size(), map->size());
  for (std::size_t i = 0; i < map->size(); ++i) {
    EXPECT_EQ(reread->locations()[i].latitude_deg, map->locations()[i].latitude_deg);
    EXPECT_EQ(reread->locations()[i].longitude_deg, map->locations()[i].longitude_deg);
    EXPECT_EQ(reread->locations()[i].heading_deg, map->locations()[i].heading_deg);
  }
}

}  // namespace
}  // namespace fieldrig::gps
