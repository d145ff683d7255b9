// The per-plot report: GeoJSON parsed back (RFC 7946 structure, [lon, lat], traits as
// properties, null where the status makes a trait meaningless) and CSV columns.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "fieldrig/traits/plot_report.h"

namespace fieldrig::traits {
namespace {

std::vector<PlotRecord> twoPlots() {
  PlotRecord ok;
  ok.plot_id = "P-0101";
  ok.lat_deg = 42.0231;
  ok.lon_deg = -93.7754;
  ok.time = "2014-08-05T15:04:05Z";
  ok.traits.status = TraitsStatus::kOk;
  ok.traits.height_m = 2.31;
  ok.traits.width_m = 0.84;
  ok.traits.vvi = 0.42;
  ok.traits.vai = 2.7;
  ok.traits.total_area_m2 = 3.1;
  ok.traits.ega_m2 = 1.15;
  ok.traits.quality.area_computed = true;
  ok.traits.quality.valid_slices = 17;
  ok.traits.quality.slices = 20;
  PlotRecord empty;
  empty.plot_id = "P-0102, east";  // a comma must survive the CSV
  empty.lat_deg = 42.0232;
  empty.lon_deg = -93.7750;
  empty.time = "2014-08-05T15:04:09Z";
  empty.traits.status = TraitsStatus::kNoPlants;
  empty.traits.message = "ground only";
  return {ok, empty};
}

TEST(PlotReport, GeoJsonParsesBackWithLonLatAndTraits) {
  const nlohmann::json geo = nlohmann::json::parse(formatGeoJson(twoPlots()));
  EXPECT_EQ(geo.at("type"), "FeatureCollection");
  ASSERT_EQ(geo.at("features").size(), 2U);
  const nlohmann::json& first = geo["features"][0];
  EXPECT_EQ(first.at("type"), "Feature");
  EXPECT_EQ(first.at("geometry").at("type"), "Point");
  const nlohmann::json& coordinates = first["geometry"]["coordinates"];
  ASSERT_EQ(coordinates.size(), 2U);
  EXPECT_DOUBLE_EQ(coordinates[0].get<double>(), -93.7754);  // longitude first
  EXPECT_DOUBLE_EQ(coordinates[1].get<double>(), 42.0231);
  const nlohmann::json& p = first.at("properties");
  EXPECT_EQ(p.at("plot_id"), "P-0101");
  EXPECT_EQ(p.at("status"), "ok");
  EXPECT_DOUBLE_EQ(p.at("height_m").get<double>(), 2.31);
  EXPECT_DOUBLE_EQ(p.at("vai").get<double>(), 2.7);
  EXPECT_EQ(p.at("valid_slices").get<int>(), 17);

  const nlohmann::json& second = geo["features"][1]["properties"];
  EXPECT_EQ(second.at("status"), "no_plants");
  EXPECT_TRUE(second.at("height_m").is_null());
  EXPECT_TRUE(second.at("vvi").is_null());
}

TEST(PlotReport, CsvHasOneRowPerPlotWithQuotedFields) {
  std::istringstream csv(formatCsv(twoPlots()));
  std::string header, row1, row2, extra;
  std::getline(csv, header);
  std::getline(csv, row1);
  std::getline(csv, row2);
  EXPECT_FALSE(std::getline(csv, extra));
  EXPECT_EQ(header.rfind("plot_id,lat,lon,time,status,height_m,width_m,vvi,vai", 0), 0U);
  EXPECT_EQ(row1.rfind("P-0101,42.0231,-93.7754,2014-08-05T15:04:05Z,ok,2.31,0.84,0.42,2.7", 0),
            0U);
  EXPECT_EQ(row2.rfind("\"P-0102, east\",42.0232,-93.775,2014-08-05T15:04:09Z,no_plants,,,,", 0),
            0U);
}

TEST(PlotReport, ResultJsonCarriesQualityAndNoNaN) {
  TraitsResult r;
  r.status = TraitsStatus::kOk;
  r.height_m = 1.0;
  r.quality.points_in = 10;
  r.slices.resize(2);
  const nlohmann::ordered_json j = traitsToJson(r);
  for (const char* key : {"height_m", "width_m", "vvi", "vai", "total_volume_m3", "total_area_m2",
                          "ega_m2", "valid_slices", "slices", "quality"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["quality"]["points_in"], 10);
  EXPECT_EQ(j["slices"].size(), 2U);
}

}  // namespace
}  // namespace fieldrig::traits
