// SessionReader on damaged sessions: errors name the file and the line; verify() names the frame
// file that is missing, cut short or altered.
#include <gtest/gtest.h>

#include "recording/test_helpers.h"
#include "support/temp_dir.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using testing_support::readWholeFile;
using testing_support::ScopedTempDir;
using testing_support::splitLines;
using testing_support::SyntheticRig;

void writeSession(const fs::path& session, std::uint64_t sets) {
  SessionWriter writer;
  ASSERT_TRUE(writer.open(session, SessionInfo{}));
  SyntheticRig rig(kWidth, kHeight);
  writeSets(writer, rig, 1, sets);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SessionReaderTest, SyntaxErrorInSessionJsonNamesFileAndLine) {
  ScopedTempDir tmp("reader_bad_session");
  const fs::path session = tmp / "s";
  writeSession(session, 1);
  writeText(session / "session.json",
            "{\n  \"format\": \"fieldrig-session\",\n  \"format_version\": 1,,\n}\n");
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, (session / "session.json").string() + ":3:"))
      << reader.error().message;
  // The writer refuses to reopen it too, with the same place.
  SessionWriter writer;
  core::Result<OpenReport> opened = writer.open(session, SessionInfo{});
  ASSERT_FALSE(opened);
  EXPECT_TRUE(contains(opened.error().message, "session.json:3:")) << opened.error().message;
}

TEST(SessionReaderTest, SessionJsonOfAnotherKindIsRefused) {
  ScopedTempDir tmp("reader_not_session");
  const fs::path session = tmp / "s";
  writeSession(session, 1);
  writeText(session / "session.json", "{\"format\": \"something else\"}\n");
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, "session.json")) << reader.error().message;
  EXPECT_TRUE(contains(reader.error().message, "format")) << reader.error().message;
}

TEST(SessionReaderTest, BadIndexLineNamesFileAndLine) {
  ScopedTempDir tmp("reader_bad_index");
  const fs::path session = tmp / "s";
  writeSession(session, 3);
  const fs::path index = session / "index.jsonl";
  std::vector<std::string> lines = splitLines(readWholeFile(index));
  ASSERT_EQ(lines.size(), 3u);

  // Not JSON at all on line 2.
  writeText(index, lines[0] + "\n{\"set\": 1, garbage\n" + lines[2] + "\n");
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, index.string() + ":2:")) << reader.error().message;

  // Valid JSON, but a field missing on line 3.
  std::string no_trigger = lines[2];
  const std::size_t at = no_trigger.find("\"trigger_id\"");
  ASSERT_NE(at, std::string::npos);
  no_trigger.replace(at, std::string("\"trigger_id\"").size(), "\"trigger\"");
  writeText(index, lines[0] + "\n" + lines[1] + "\n" + no_trigger + "\n");
  reader = SessionReader::open(session);
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, index.string() + ":3:")) << reader.error().message;
  EXPECT_TRUE(contains(reader.error().message, "trigger_id")) << reader.error().message;

  // A frame file outside the session folder, relative or absolute.
  for (const std::string outside : {"../../etc/passwd", "/etc/passwd"}) {
    std::string escaping = lines[1];
    const std::size_t file_at = escaping.find("\"file\":\"");
    ASSERT_NE(file_at, std::string::npos) << escaping;
    const std::size_t value_at = file_at + std::string("\"file\":\"").size();
    escaping.replace(value_at, escaping.find('"', value_at) - value_at, outside);
    writeText(index, lines[0] + "\n" + escaping + "\n" + lines[2] + "\n");
    reader = SessionReader::open(session);
    ASSERT_FALSE(reader) << outside;
    EXPECT_TRUE(contains(reader.error().message, index.string() + ":2:")) << reader.error().message;
    EXPECT_TRUE(contains(reader.error().message, "outside the session folder"))
        << reader.error().message;
  }

  // Set numbers out of order (line 2 repeated).
  writeText(index, lines[0] + "\n" + lines[1] + "\n" + lines[1] + "\n");
  reader = SessionReader::open(session);
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, index.string() + ":3:")) << reader.error().message;
}

TEST(SessionReaderTest, MissingFolderIsAnErrorNamingTheFile) {
  ScopedTempDir tmp("reader_absent");
  core::Result<SessionReader> reader = SessionReader::open(tmp / "nothing");
  ASSERT_FALSE(reader);
  EXPECT_TRUE(contains(reader.error().message, "session.json")) << reader.error().message;
}

TEST(SessionReaderTest, VerifyNamesAlteredTruncatedAndMissingFrames) {
  ScopedTempDir tmp("reader_verify");
  const fs::path session = tmp / "s";
  writeSession(session, 3);
  {
    core::Result<SessionReader> reader = SessionReader::open(session);
    ASSERT_TRUE(reader) << reader.error().message;
    const VerifyReport report = reader->verify();
    EXPECT_TRUE(report.ok());
    EXPECT_EQ(report.frames_checked, 18u);
  }
  const fs::path altered = session / "frames" / "000000_1_bottom_right.pgm";
  const fs::path truncated = session / "frames" / "000001_2_middle_left.pgm";
  const fs::path missing = session / "frames" / "000002_5_top_right.pgm";
  {
    // One pixel byte changed, size and header intact: only the CRC can tell.
    std::string pgm = readWholeFile(altered);
    pgm[pgm.size() - 7] = static_cast<char>(pgm[pgm.size() - 7] ^ 0x01);
    writeText(altered, pgm);
    fs::resize_file(truncated, fs::file_size(truncated) - 10);
    fs::remove(missing);
  }
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  const VerifyReport report = reader->verify();
  ASSERT_EQ(report.problems.size(), 3u);
  EXPECT_TRUE(contains(report.problems[0], altered.string())) << report.problems[0];
  EXPECT_TRUE(contains(report.problems[0], "CRC-32")) << report.problems[0];
  EXPECT_TRUE(contains(report.problems[1], truncated.string())) << report.problems[1];
  EXPECT_TRUE(contains(report.problems[2], missing.string())) << report.problems[2];
}

TEST(SessionReaderTest, HeaderThatDisagreesWithTheIndexIsNamed) {
  ScopedTempDir tmp("reader_header");
  const fs::path session = tmp / "s";
  writeSession(session, 1);
  const fs::path file = session / "frames" / "000000_0_bottom_left.pgm";
  std::string pgm = readWholeFile(file);
  pgm.replace(0, 9, "P5\n30 40\n");  // same size, transposed
  writeText(file, pgm);
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  const VerifyReport report = reader->verify();
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_TRUE(contains(report.problems[0], file.string())) << report.problems[0];
  EXPECT_TRUE(contains(report.problems[0], "30x40")) << report.problems[0];
}

// An index line whose file size is not the file's, with whole pixels: verify said ok.
TEST(SessionReaderTest, AFileSizeThatDisagreesWithTheIndexIsNamed) {
  ScopedTempDir tmp("reader_file_bytes");
  const fs::path session = tmp / "s";
  writeSession(session, 1);
  const fs::path index = session / "index.jsonl";
  const std::string text = readWholeFile(index);
  const auto at = text.find("\"file_bytes\":");
  ASSERT_NE(at, std::string::npos);
  const auto end = text.find(',', at);
  writeText(index, text.substr(0, at) + "\"file_bytes\":1000000000000000" + text.substr(end));
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  const VerifyReport report = reader->verify();
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_TRUE(contains(report.problems[0], "bytes, the index says 1000000000000000"))
      << report.problems[0];
}

}  // namespace
}  // namespace fieldrig::recording

namespace fieldrig::recording {
namespace {

TEST(SessionReaderTest, WriterRefusesToReopenOnABadIndexAndChangesNothing) {
  ScopedTempDir tmp("reader_refused_reopen");
  const fs::path session = tmp / "s";
  writeSession(session, 2);
  const fs::path index = session / "index.jsonl";
  const std::vector<std::string> lines = splitLines(readWholeFile(index));
  writeText(index, "{}\n" + lines[1] + "\n");
  const std::string description = readWholeFile(session / "session.json");
  SessionWriter writer;
  core::Result<OpenReport> opened = writer.open(session, SessionInfo{});
  ASSERT_FALSE(opened);
  EXPECT_TRUE(contains(opened.error().message, index.string() + ":1:")) << opened.error().message;
  EXPECT_FALSE(writer.isOpen());
  EXPECT_EQ(readWholeFile(session / "session.json"), description);
  EXPECT_EQ(readWholeFile(index), "{}\n" + lines[1] + "\n");
}

}  // namespace
}  // namespace fieldrig::recording
