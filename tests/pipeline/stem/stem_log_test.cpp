// The CSV log of measurements: round trip (quoting included), repeat numbering, mean and SD of
// repeats, removing a session's last row, and errors that name the file, line and field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "fieldrig/stem/measurement_log.h"
#include "support/temp_dir.h"

namespace fieldrig::stem {
namespace {

MeasurementRecord record(const std::string& label, double diameter, int repeat) {
  MeasurementRecord r;
  r.session = "2026-07-01_plot, north";
  r.set_index = 3;
  r.trigger_id = 17;
  r.head = "bottom";
  r.stem_label = label;
  r.points = {cv::Point2d(1.25, 2.5), cv::Point2d(3, 4), cv::Point2d(5, 6), cv::Point2d(7, 8.75)};
  r.disparity_px = 161.234;
  r.ncc = 0.9312;
  r.diameter_mm = diameter;
  r.time = "2026-07-01T12:00:00.000Z";
  r.repeat = repeat;
  return r;
}

TEST(StemLog, RoundTripsThroughTheCsvFile) {
  testing_support::ScopedTempDir dir("stem_log_round_trip");
  const auto file = dir / "stem.csv";
  ASSERT_TRUE(appendMeasurement(file, record("row 4 \"tall\"", 14.5, 1)).ok());
  ASSERT_TRUE(appendMeasurement(file, record("row 4 \"tall\"", 15.5, 2)).ok());
  auto records = readMeasurementLog(file);
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), 2u);
  const MeasurementRecord& r = (*records)[1];
  EXPECT_EQ(r.session, "2026-07-01_plot, north");
  EXPECT_EQ(r.stem_label, "row 4 \"tall\"");
  EXPECT_EQ(r.set_index, 3u);
  EXPECT_EQ(r.trigger_id, 17u);
  EXPECT_EQ(r.head, "bottom");
  EXPECT_DOUBLE_EQ(r.points[3].y, 8.75);
  EXPECT_DOUBLE_EQ(r.disparity_px, 161.234);
  EXPECT_DOUBLE_EQ(r.ncc, 0.9312);
  EXPECT_DOUBLE_EQ(r.diameter_mm, 15.5);
  EXPECT_EQ(r.repeat, 2);
  EXPECT_EQ(r.time, "2026-07-01T12:00:00.000Z");
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, csvHeader());
}

// A label typed with a line break is written quoted across two lines; the rows after it, and the
// undo of the last one, must still read (before, the file was read one physical line per row).
TEST(StemLog, ALabelWithLineBreaksRoundTripsAndTheRowsAfterItStayReadable) {
  testing_support::ScopedTempDir dir("stem_log_line_break");
  const auto file = dir / "stem.csv";
  const std::string labels[] = {"row 3\nstem 7", "a\r\nb, \"c\"\n", "\t tab"};
  for (const std::string& label : labels)
    ASSERT_TRUE(appendMeasurement(file, record(label, 14.5, 1)).ok());
  ASSERT_TRUE(appendMeasurement(file, record("plain", 15.5, 1)).ok());
  auto records = readMeasurementLog(file);
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), 4u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_EQ((*records)[i].stem_label, labels[i]);
  EXPECT_EQ((*records)[3].stem_label, "plain");
  EXPECT_DOUBLE_EQ((*records)[3].diameter_mm, 15.5);

  auto removed = removeLastMeasurement(file, record("", 0, 1).session);
  ASSERT_TRUE(removed.ok()) << removed.error().message;
  ASSERT_TRUE(removed->has_value());
  EXPECT_EQ((*removed)->stem_label, "plain");
  removed = removeLastMeasurement(file, record("", 0, 1).session);
  ASSERT_TRUE(removed.ok()) << removed.error().message;
  EXPECT_EQ((*removed)->stem_label, labels[2]);
  records = readMeasurementLog(file);
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), 2u);
  EXPECT_EQ((*records)[1].stem_label, labels[1]);
}

// A damaged row after a multi-line one is named by the line it starts on; a quoted field the file
// ends inside is named too.
TEST(StemLog, ErrorsNameTheLineARecordStartsOn) {
  testing_support::ScopedTempDir dir("stem_log_record_lines");
  const auto file = dir / "stem.csv";
  std::string bad = toCsvRow(record("b", 10.0, 1));
  bad.replace(bad.find("161.234"), 7, "sixteen");
  // Line 1 header, lines 2-4 one record (two line breaks in its label), line 5 the bad record.
  std::ofstream(file) << csvHeader() << '\n'
                      << toCsvRow(record("a\nb\nc", 10.0, 1)) << '\n'
                      << bad << '\n';
  auto damaged = readMeasurementLog(file);
  ASSERT_FALSE(damaged.ok());
  EXPECT_NE(damaged.error().message.find("stem.csv:5: field 'disparity_px'"), std::string::npos)
      << damaged.error().message;

  std::ofstream(file) << csvHeader() << '\n' << toCsvRow(record("a", 10.0, 1)) << "\n\"open";
  auto unterminated = readMeasurementLog(file);
  ASSERT_FALSE(unterminated.ok());
  EXPECT_NE(unterminated.error().message.find("stem.csv:3: unterminated quoted field"),
            std::string::npos)
      << unterminated.error().message;
}

TEST(StemLog, NumbersRepeatsPerStemAndSummarizesMeanAndSd) {
  std::vector<MeasurementRecord> records{record("a", 10.0, 1), record("b", 20.0, 1),
                                         record("a", 12.0, 2), record("a", 14.0, 3)};
  EXPECT_EQ(nextRepeat(records, records[0].session, "a"), 4);
  EXPECT_EQ(nextRepeat(records, records[0].session, "b"), 2);
  EXPECT_EQ(nextRepeat(records, records[0].session, "c"), 1);
  EXPECT_EQ(nextRepeat(records, "another session", "a"), 1);
  const std::vector<StemSummary> summary = summarizeRepeats(records);
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary[0].stem_label, "a");
  EXPECT_EQ(summary[0].count, 3);
  EXPECT_DOUBLE_EQ(summary[0].mean_mm, 12.0);
  EXPECT_DOUBLE_EQ(summary[0].sd_mm, 2.0);  // sample SD of 10, 12, 14
  EXPECT_EQ(summary[1].count, 1);
  EXPECT_DOUBLE_EQ(summary[1].sd_mm, 0.0);
}

TEST(StemLog, RemovingTheLastRowTakesOnlyThatSessionsLastRow) {
  testing_support::ScopedTempDir dir("stem_log_remove_last");
  const auto file = dir / "stem.csv";
  auto in_session = [](const std::string& session, const std::string& label, double diameter,
                       int repeat) {
    MeasurementRecord r = record(label, diameter, repeat);
    r.session = session;
    return r;
  };
  ASSERT_TRUE(appendMeasurement(file, in_session("north", "a", 10.0, 1)).ok());
  ASSERT_TRUE(appendMeasurement(file, in_session("south", "b", 20.0, 1)).ok());
  ASSERT_TRUE(appendMeasurement(file, in_session("north", "a", 12.0, 2)).ok());
  ASSERT_TRUE(appendMeasurement(file, in_session("south", "c", 30.0, 1)).ok());

  auto removed = removeLastMeasurement(file, "north");
  ASSERT_TRUE(removed.ok()) << removed.error().message;
  ASSERT_TRUE(removed->has_value());
  EXPECT_DOUBLE_EQ((*removed)->diameter_mm, 12.0);
  EXPECT_EQ((*removed)->repeat, 2);
  auto records = readMeasurementLog(file);
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), 3u);
  EXPECT_DOUBLE_EQ((*records)[0].diameter_mm, 10.0);
  EXPECT_DOUBLE_EQ((*records)[1].diameter_mm, 20.0);
  EXPECT_DOUBLE_EQ((*records)[2].diameter_mm, 30.0);
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, csvHeader());
  EXPECT_EQ(testing_support::tempFilesBeside(file), 0u) << "the temporary file is left";

  ASSERT_TRUE(removeLastMeasurement(file, "north")->has_value());
  auto none = removeLastMeasurement(file, "north");
  ASSERT_TRUE(none.ok()) << none.error().message;
  EXPECT_FALSE(none->has_value());
  EXPECT_EQ(readMeasurementLog(file)->size(), 2u) << "the other session's rows stay";

  auto absent = removeLastMeasurement(dir / "absent.csv", "north");
  ASSERT_TRUE(absent.ok()) << absent.error().message;
  EXPECT_FALSE(absent->has_value());
  EXPECT_FALSE(std::filesystem::exists(dir / "absent.csv"));
}

TEST(StemLog, AppendsToAFileNamedRelativeToTheWorkingFolder) {
  testing_support::ScopedTempDir dir("stem_log_relative");
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(dir.path());
  const auto appended = appendMeasurement("stem.csv", record("a", 10.0, 1));
  const auto removed = removeLastMeasurement("stem.csv", record("a", 10.0, 1).session);
  std::filesystem::current_path(before);
  ASSERT_TRUE(appended.ok()) << appended.error().message;
  ASSERT_TRUE(removed.ok()) << removed.error().message;
  EXPECT_TRUE(removed->has_value());
  EXPECT_TRUE(readMeasurementLog(dir / "stem.csv")->empty());
}

TEST(StemLog, AMissingFileIsAnEmptyLogAndABadFieldIsNamed) {
  testing_support::ScopedTempDir dir("stem_log_errors");
  auto empty = readMeasurementLog(dir / "absent.csv");
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());
  const auto file = dir / "bad.csv";
  std::string row = toCsvRow(record("a", 10.0, 1));
  row.replace(row.find("161.234"), 7, "sixteen");
  std::ofstream(file) << csvHeader() << '\n' << row << '\n';
  auto bad = readMeasurementLog(file);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("bad.csv:2:"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("disparity_px"), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace fieldrig::stem
