// `fieldrig session info DIR [--verify]`, run as the built binary on sessions written here.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "recording/test_helpers.h"
#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace testing_support;

void writeSession(const fs::path& session) {
  SessionWriter writer;
  ASSERT_TRUE(writer.open(session, SessionInfo{}));
  SyntheticRig rig(kWidth, kHeight);
  writeSets(writer, rig, 10, 4);
  rig.fill(14);
  FrameSetRecord incomplete = rig.record(14, "plot2");
  incomplete.complete = false;
  incomplete.frames[1].status = FrameStatus::kMissing;
  incomplete.frames[1].pixels = {};
  ASSERT_TRUE(writer.write(incomplete).ok());
}

TEST(SessionCliTest, InfoPrintsOneJsonSummary) {
  ScopedTempDir tmp("session_cli_info");
  const fs::path session = tmp / "s";
  writeSession(session);
  const auto run = runFieldrig({"session", "info", session.string()}, tmp.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const Json summary = Json::parse(run.out_lines[0]);
  EXPECT_EQ(summary["sets"], 5);
  EXPECT_EQ(summary["frames"], 30);
  EXPECT_EQ(summary["frames_not_ok"], 1);
  EXPECT_EQ(summary["complete"], 4);
  EXPECT_EQ(summary["incomplete"], 1);
  // SyntheticRig: day 20000 after 1970 is 2024-10-04; trigger k fires at k × 100 ms.
  EXPECT_EQ(summary["first_trigger_time"], "2024-10-04T00:00:01.000Z");
  EXPECT_EQ(summary["last_trigger_time"], "2024-10-04T00:00:01.400Z");
  EXPECT_TRUE(summary["torn_line"].is_null());
  EXPECT_GT(summary["bytes"].get<std::uint64_t>(), 29u * (40u * 30u));
  EXPECT_FALSE(summary.contains("verified"));
}

TEST(SessionCliTest, VerifyPassesOnAWholeSessionAndReportsATornLine) {
  ScopedTempDir tmp("session_cli_verify");
  const fs::path session = tmp / "s";
  writeSession(session);
  appendText(session / "index.jsonl", "{\"set\": 5, \"trig");
  const auto run = runFieldrig({"session", "info", session.string(), "--verify"}, tmp.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json summary = Json::parse(run.out_lines.at(0));
  EXPECT_EQ(summary["sets"], 5);
  EXPECT_EQ(summary["torn_line"]["line"], 6);
  EXPECT_EQ(summary["verified"]["ok"], true);
  EXPECT_EQ(summary["verified"]["frames_checked"], 29);
}

TEST(SessionCliTest, VerifyFailsNamingTheFileWithACorruptedByte) {
  ScopedTempDir tmp("session_cli_damage");
  const fs::path session = tmp / "s";
  writeSession(session);
  const fs::path frame = session / "frames" / "000002_3_middle_right.pgm";
  std::string pgm = readWholeFile(frame);
  pgm[pgm.size() / 2] = static_cast<char>(pgm[pgm.size() / 2] ^ 0x80);
  writeText(frame, pgm);

  // Without --verify the summary does not read the frames.
  EXPECT_EQ(runFieldrig({"session", "info", session.string()}, tmp.path()).exit_code, 0);

  const auto run = runFieldrig({"session", "info", session.string(), "--verify"}, tmp.path());
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find(frame.string()), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("damaged"), std::string::npos) << run.err;
  const Json summary = Json::parse(run.out_lines.at(0));
  EXPECT_EQ(summary["verified"]["ok"], false);
  ASSERT_EQ(summary["verified"]["problems"].size(), 1u);
}

TEST(SessionCliTest, UnreadableSessionIsBadInputNamingTheFileAndLine) {
  ScopedTempDir tmp("session_cli_bad");
  const fs::path session = tmp / "s";
  writeSession(session);
  std::vector<std::string> lines = splitLines(readWholeFile(session / "index.jsonl"));
  lines[1] = "not json";
  std::string text;
  for (const std::string& line : lines)
    text += line + "\n";
  writeText(session / "index.jsonl", text);
  const auto run = runFieldrig({"session", "info", session.string()}, tmp.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(run.out_lines.empty());
  EXPECT_NE(run.err.find((session / "index.jsonl").string() + ":2:"), std::string::npos) << run.err;

  const auto absent = runFieldrig({"session", "info", (tmp / "absent").string()}, tmp.path());
  EXPECT_EQ(absent.exit_code, 2);
  EXPECT_NE(absent.err.find("session.json"), std::string::npos) << absent.err;
}

}  // namespace
}  // namespace fieldrig::recording
