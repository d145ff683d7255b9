#include "fieldrig/gps/location_map.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/temp_dir.h"

namespace fieldrig::gps {
namespace {

// Parses `text` expecting failure; returns the message.
std::string parseError(std::string_view text) {
  auto map = LocationMap::parse(text, "field.csv");
  EXPECT_FALSE(map.ok()) << "parsed although invalid:\n" << text;
  return map.ok() ? std::string() : map.error().message;
}

TEST(LocationMapParse, RequiredColumnsOnly) {
  auto map = LocationMap::parse("id,lat,lon\nA1,42.5,-93.25\nA2,-10,170.125\n", "field.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 2u);
  EXPECT_TRUE(map->metadataColumns().empty());
  const ImagingLocation& first = map->locations()[0];
  EXPECT_EQ(first.id, "A1");
  EXPECT_EQ(first.latitude_deg, 42.5);
  EXPECT_EQ(first.longitude_deg, -93.25);
  EXPECT_FALSE(first.heading_deg.has_value());
  EXPECT_TRUE(first.metadata.empty());
  EXPECT_EQ(map->locations()[1].id, "A2");
  EXPECT_EQ(map->locations()[1].latitude_deg, -10.0);
  EXPECT_EQ(map->locations()[1].longitude_deg, 170.125);
}

TEST(LocationMapParse, ColumnsInAnyOrderWithMetadataCommentsAndBlankLines) {
  const std::string text =
      "# field 7, season 2026\n"
      "\n"
      "plot,lon,heading,id,lat,range\n"
      "  # an indented comment\n"
      "101,-93.5,90,P1,42.25,1\n"
      "\n"
      "102,-93.75,270.5,P2,42.125,2\n"
      "#trailing comment\n";
  auto map = LocationMap::parse(text, "field.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->metadataColumns(), (std::vector<std::string>{"plot", "range"}));
  ASSERT_EQ(map->size(), 2u);
  const ImagingLocation* p2 = map->find("P2");
  ASSERT_NE(p2, nullptr);
  EXPECT_EQ(p2->latitude_deg, 42.125);
  EXPECT_EQ(p2->longitude_deg, -93.75);
  ASSERT_TRUE(p2->heading_deg.has_value());
  EXPECT_EQ(*p2->heading_deg, 270.5);
  EXPECT_EQ(p2->metadata, (std::vector<std::string>{"102", "2"}));
  EXPECT_EQ(map->find("P3"), nullptr);
  EXPECT_EQ(map->locations()[0].metadata, (std::vector<std::string>{"101", "1"}));
}

TEST(LocationMapParse, QuotedFieldsCrlfAndEmptyHeading) {
  const std::string text =
      "id,lat,lon,heading,note\r\n"
      "\"P,1\",1.5,2.5,,\"said \"\"hi\"\", left\"\r\n"
      "P2 , 3 , 4 ,10,  spaced  \r\n"
      "P3,5,6,20,\"two\nlines\"\r\n";
  auto map = LocationMap::parse(text, "field.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 3u);
  EXPECT_EQ(map->locations()[0].id, "P,1");
  EXPECT_FALSE(map->locations()[0].heading_deg.has_value());
  EXPECT_EQ(map->locations()[0].metadata[0], "said \"hi\", left");
  // Unquoted fields are trimmed, CR included.
  EXPECT_EQ(map->locations()[1].id, "P2");
  EXPECT_EQ(map->locations()[1].latitude_deg, 3.0);
  EXPECT_EQ(map->locations()[1].metadata[0], "spaced");
  EXPECT_EQ(map->locations()[2].metadata[0], "two\nlines");
}

TEST(LocationMapParse, LineNumbersCountCommentsBlankLinesAndQuotedNewlines) {
  const std::string text =
      "# comment\n"        // 1
      "id,lat,lon,note\n"  // 2
      "\n"                 // 3
      "A,1,2,\"x\n"        // 4
      "y\"\n"              // 5
      "B,abc,2,z\n";       // 6
  EXPECT_EQ(parseError(text), "field.csv:6: field 'lat': 'abc' is not a number");
}

TEST(LocationMapParse, NotANumber) {
  EXPECT_EQ(parseError("id,lat,lon\nA,1,2\nB,1,2x\n"),
            "field.csv:3: field 'lon': '2x' is not a number");
  EXPECT_EQ(parseError("id,lat,lon\nA,,2\n"), "field.csv:2: field 'lat': '' is not a number");
  EXPECT_EQ(parseError("id,lat,lon,heading\nA,1,2,north\n"),
            "field.csv:2: field 'heading': 'north' is not a number");
}

TEST(LocationMapParse, NonFiniteNumbers) {
  EXPECT_EQ(parseError("id,lat,lon\nA,nan,2\n"),
            "field.csv:2: field 'lat': 'nan' is not a finite number");
  EXPECT_EQ(parseError("id,lat,lon\nA,1,inf\n"),
            "field.csv:2: field 'lon': 'inf' is not a finite number");
  EXPECT_EQ(parseError("id,lat,lon\nA,1e999,2\n"),
            "field.csv:2: field 'lat': '1e999' is not a finite number");
}

TEST(LocationMapParse, OutOfRange) {
  EXPECT_EQ(parseError("id,lat,lon\nA,90.5,2\n"),
            "field.csv:2: field 'lat': 90.5 is outside [-90, 90]");
  EXPECT_EQ(parseError("id,lat,lon\nA,-91,2\n"),
            "field.csv:2: field 'lat': -91 is outside [-90, 90]");
  EXPECT_EQ(parseError("id,lat,lon\nA,1,180.25\n"),
            "field.csv:2: field 'lon': 180.25 is outside [-180, 180]");
  EXPECT_EQ(parseError("id,lat,lon,heading\nA,1,2,360\n"),
            "field.csv:2: field 'heading': 360 is outside [0, 360)");
  EXPECT_EQ(parseError("id,lat,lon,heading\nA,1,2,-0.5\n"),
            "field.csv:2: field 'heading': -0.5 is outside [0, 360)");
  // The bounds themselves are inside.
  auto edges = LocationMap::parse("id,lat,lon,heading\nA,90,-180,0\nB,-90,180,359.5\n", "f");
  EXPECT_TRUE(edges.ok()) << edges.error().message;
}

TEST(LocationMapParse, EmptyAndDuplicateIds) {
  EXPECT_EQ(parseError("id,lat,lon\nA,1,2\n,1,2\n"), "field.csv:3: field 'id': empty id");
  EXPECT_EQ(parseError("id,lat,lon\n# c\nP1,1,2\nP12,1,2\nP2,1,2\n\nP12,3,4\n"),
            "field.csv:7: duplicate id 'P12' (first on line 4)");
}

TEST(LocationMapParse, HeaderProblems) {
  EXPECT_EQ(parseError("# only a comment\n\n"),
            "field.csv: no header line (expected at least id,lat,lon)");
  EXPECT_EQ(parseError("# c\nid,lon,plot\nA,1,2\n"),
            "field.csv:2: the header lacks the required column 'lat'");
  EXPECT_EQ(parseError("lat,lon\n1,2\n"), "field.csv:1: the header lacks the required column 'id'");
  EXPECT_EQ(parseError("id,lat\nA,1\n"), "field.csv:1: the header lacks the required column 'lon'");
  EXPECT_EQ(parseError("id,lat,lon,plot,plot\n"),
            "field.csv:1: column 'plot' appears twice in the header");
  EXPECT_EQ(parseError("id,lat,lon,,plot\n"), "field.csv:1: column 4 of the header has no name");
}

TEST(LocationMapParse, WrongNumberOfFields) {
  EXPECT_EQ(parseError("id,lat,lon,plot\nA,1,2,3\nB,1,2\n"),
            "field.csv:3: expected 4 fields as in the header (line 1), found 3");
  EXPECT_EQ(parseError("id,lat,lon\nA,1,2,3\n"),
            "field.csv:2: expected 3 fields as in the header (line 1), found 4");
}

TEST(LocationMapParse, QuotingErrors) {
  EXPECT_EQ(parseError("id,lat,lon,note\nA,1,2,\"open\n"),
            "field.csv:2: field 'note': unterminated quoted field");
  EXPECT_EQ(parseError("id,lat,lon,note\nA,1,2,\"x\"y\n"),
            "field.csv:2: field 'note': text after the closing quote");
  EXPECT_EQ(parseError("id,lat,lon,note\nA,1,2,5'6\"\n"),
            "field.csv:2: field 'note': a quote inside an unquoted field (quote the whole field)");
}

TEST(LocationMapAdd, RejectsDuplicatesBadNumbersAndMetadataCount) {
  LocationMap map({"plot"});
  EXPECT_TRUE(map.add({"A", 1, 2, 45.0, {"7"}}).ok());
  auto duplicate = map.add({"A", 3, 4, std::nullopt, {"8"}});
  ASSERT_FALSE(duplicate.ok());
  EXPECT_EQ(duplicate.error().message, "location 'A': duplicate id");
  auto out_of_range = map.add({"B", 1, 2, 360.0, {"8"}});
  ASSERT_FALSE(out_of_range.ok());
  EXPECT_EQ(out_of_range.error().message, "location 'B': field 'heading': 360 is outside [0, 360)");
  auto metadata = map.add({"C", 1, 2, std::nullopt, {}});
  ASSERT_FALSE(metadata.ok());
  EXPECT_EQ(metadata.error().message, "location 'C': 0 metadata values for 1 metadata columns");
  EXPECT_EQ(map.size(), 1u);
}

TEST(LocationMapWrite, ExactTextOfASmallMap) {
  LocationMap map({"plot", "note"});
  ASSERT_TRUE(map.add({"P1", 42.5, -93.25, 90.0, {"1", ""}}).ok());
  ASSERT_TRUE(map.add({"P,2", 0.1, 0.2, std::nullopt, {"2", "a \"b\""}}).ok());
  ASSERT_TRUE(map.add({"#3", -1, 1, 0.0, {"3", " x"}}).ok());
  EXPECT_EQ(map.toCsv(),
            "id,lat,lon,heading,plot,note\n"
            "P1,42.5,-93.25,90,1,\n"
            "\"P,2\",0.1,0.2,,2,\"a \"\"b\"\"\"\n"
            "\"#3\",-1,1,0,3,\" x\"\n");
}

void expectSameLocations(const LocationMap& a, const LocationMap& b) {
  EXPECT_EQ(a.metadataColumns(), b.metadataColumns());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const ImagingLocation& x = a.locations()[i];
    const ImagingLocation& y = b.locations()[i];
    EXPECT_EQ(x.id, y.id);
    // Exact equality: the text must carry every bit of the double.
    EXPECT_EQ(x.latitude_deg, y.latitude_deg) << x.id;
    EXPECT_EQ(x.longitude_deg, y.longitude_deg) << x.id;
    EXPECT_EQ(x.heading_deg, y.heading_deg) << x.id;
    EXPECT_EQ(x.metadata, y.metadata) << x.id;
  }
}

LocationMap awkwardMap() {
  LocationMap map({"plot", "comment, with comma", "empty"});
  // Values that need all 17 significant digits, and ones with awkward text.
  EXPECT_TRUE(
      map.add({"R01P01", 42.012345678901234, -93.98765432109876, 0.1 + 0.2, {"1", "", ""}}).ok());
  EXPECT_TRUE(map.add({"R01P02", 1.0 / 3.0, -2.0 / 3.0, std::nullopt, {"2", "x\ny", ""}}).ok());
  EXPECT_TRUE(map.add({"  padded ",
                       -89.999999999999986,
                       179.99999999999997,
                       359.99999999999994,
                       {"\"q\"", "#not a comment", " "}})
                  .ok());
  EXPECT_TRUE(map.add({"tiny", 5e-324, -1e-300, 1e-10, {"3", "\r", ""}}).ok());
  return map;
}

TEST(LocationMapWrite, RoundTripsThroughText) {
  const LocationMap original = awkwardMap();
  auto reread = LocationMap::parse(original.toCsv(), "roundtrip.csv");
  ASSERT_TRUE(reread.ok()) << reread.error().message;
  expectSameLocations(original, *reread);
  // And writing again gives the same bytes.
  EXPECT_EQ(reread->toCsv(), original.toCsv());
}

TEST(LocationMapWrite, CsvLinesAppendedToTheHeaderMakeTheSameFile) {
  const LocationMap original = awkwardMap();
  std::string text = original.csvHeader();
  for (const ImagingLocation& location : original.locations())
    text += original.csvLine(location);
  EXPECT_EQ(text, original.toCsv());
}

class LocationMapFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = std::filesystem::temp_directory_path() /
                 ("fieldrig_location_map_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }
  std::filesystem::path directory_;
};

TEST_F(LocationMapFileTest, SaveAndLoadOnDisk) {
  const LocationMap original = awkwardMap();
  const auto path = directory_ / "map.csv";
  auto saved = original.save(path);
  ASSERT_TRUE(saved.ok()) << saved.error().message;
  EXPECT_EQ(testing_support::tempFilesBeside(path), 0u);
  auto loaded = LocationMap::load(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  expectSameLocations(original, *loaded);
}

TEST_F(LocationMapFileTest, LoadErrorsNameThePath) {
  const auto path = directory_ / "bad.csv";
  std::ofstream(path) << "id,lat,lon\nA,1,2\nA,3,4\n";
  auto loaded = LocationMap::load(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error().message, path.string() + ":3: duplicate id 'A' (first on line 2)");

  auto missing = LocationMap::load(directory_ / "missing.csv");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(
      missing.error().message.rfind((directory_ / "missing.csv").string() + ": cannot open", 0), 0u)
      << missing.error().message;
}

TEST_F(LocationMapFileTest, SaveIntoMissingFolderFailsNamingTheFile) {
  LocationMap map;
  const auto path = directory_ / "no" / "such" / "map.csv";
  auto saved = map.save(path);
  ASSERT_FALSE(saved.ok());
  EXPECT_NE(saved.error().message.find(path.string()), std::string::npos) << saved.error().message;
}

TEST_F(LocationMapFileTest, ByteOrderMarkIsIgnored) {
  const auto path = directory_ / "bom.csv";
  std::ofstream(path, std::ios::binary) << "\xEF\xBB\xBFid,lat,lon\r\nA,1,2\r\n";
  auto loaded = LocationMap::load(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  ASSERT_NE(loaded->find("A"), nullptr);
}

}  // namespace
}  // namespace fieldrig::gps
