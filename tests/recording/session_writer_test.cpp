// SessionWriter and SessionReader together on a real filesystem: what is written reads back
// byte for byte, by set index, trigger id and location id; reopening continues; torn lines.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "recording/test_helpers.h"
#include "support/temp_dir.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace testing_support;

SessionInfo testInfo(const fs::path& map_file) {
  SessionInfo info;
  info.configuration = {{"rig", {{"driver", "sim"}, {"cameras", 6}}}, {"rate_hz", 5}};
  info.calibration = {{"head_bottom", "calib/bottom.yaml"}, {"extrinsics", "calib/heads.yaml"}};
  info.map_file = map_file;
  return info;
}

// Every frame of `set` equals what the synthetic rig made for its trigger.
void expectFramesMatch(const SessionReader& reader, const IndexedSet& set, int width, int height) {
  ASSERT_EQ(set.frames.size(), 6u);
  for (const IndexedFrame& frame : set.frames) {
    core::Result<Image> image = reader.loadFrame(frame);
    ASSERT_TRUE(image) << image.error().message;
    EXPECT_EQ(image->width, width);
    EXPECT_EQ(image->height, height);
    EXPECT_EQ(image->pixels, expectedImage(set.trigger_id, frame.camera_index, width, height))
        << "set " << set.set_index << " camera " << frame.camera_index;
  }
}

TEST(SessionWriterTest, RoundTripByIndexTriggerAndLocation) {
  ScopedTempDir tmp("rec_round_trip");
  const fs::path session = tmp / "session";
  // SHA-256("abc") is the FIPS 180-2 example digest.
  writeText(tmp / "map.csv", "abc");
  SyntheticRig rig(kWidth, kHeight);
  {
    SessionWriter writer;
    core::Result<OpenReport> opened = writer.open(session, testInfo(tmp / "map.csv"));
    ASSERT_TRUE(opened) << opened.error().message;
    EXPECT_FALSE(opened->reopened);
    EXPECT_EQ(opened->next_set_index, 0u);
    writeSets(writer, rig, 100, 7);
    EXPECT_EQ(writer.nextSetIndex(), 7u);
  }

  core::Result<SessionReader> opened = SessionReader::open(session);
  ASSERT_TRUE(opened) << opened.error().message;
  const SessionReader& reader = *opened;
  EXPECT_FALSE(reader.tornLine());
  EXPECT_EQ(reader.metadata().software_version, FIELDRIG_VERSION_FOR_TEST);
  EXPECT_EQ(reader.metadata().map_sha256,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(reader.metadata().configuration["rate_hz"], 5);
  ASSERT_EQ(reader.metadata().calibration.size(), 2u);
  EXPECT_EQ(reader.metadata().calibration[1].path, "calib/heads.yaml");
  ASSERT_EQ(reader.sets().size(), 7u);

  for (std::uint64_t k = 0; k < 7; ++k) {
    const IndexedSet* set = reader.bySetIndex(k);
    ASSERT_NE(set, nullptr);
    EXPECT_EQ(set->trigger_id, 100 + k);
    expectFramesMatch(reader, *set, kWidth, kHeight);
  }
  const IndexedSet* by_trigger = reader.byTriggerId(104);
  ASSERT_NE(by_trigger, nullptr);
  EXPECT_EQ(by_trigger->set_index, 4u);
  EXPECT_EQ(reader.byTriggerId(99), nullptr);
  EXPECT_EQ(reader.bySetIndex(7), nullptr);

  // Triggers 100…106 at plots 100 % 3 = 1, 2, 0, 1, 2, 0, 1.
  const std::vector<const IndexedSet*> plot1 = reader.byLocationId("plot1");
  ASSERT_EQ(plot1.size(), 3u);
  EXPECT_EQ(plot1[0]->trigger_id, 100u);
  EXPECT_EQ(plot1[1]->trigger_id, 103u);
  EXPECT_EQ(plot1[2]->trigger_id, 106u);
  EXPECT_TRUE(reader.byLocationId("plot9").empty());

  // Metadata survives the trip.
  const IndexedSet& set = *by_trigger;
  EXPECT_EQ(set.location_id, "plot2");
  ASSERT_TRUE(set.fix);
  EXPECT_DOUBLE_EQ(set.fix->latitude_deg, 40.0 + 1e-6 * 104);
  EXPECT_EQ(set.fix->quality, core::FixQuality::kRtkFixed);
  EXPECT_EQ(set.fix->satellites, 14);
  EXPECT_EQ(set.fix->talker, "GN");
  EXPECT_TRUE(set.complete);
  EXPECT_DOUBLE_EQ(set.skew_us, 12.5);
  EXPECT_EQ(set.frames[3].camera_name, "middle_right");
  EXPECT_EQ(set.frames[3].pixel_format, core::PixelFormat::kBayerRG8);
  EXPECT_EQ(set.frames[3].device_timestamp_ns, 104 * 100'000'000LL + 3);
  EXPECT_EQ(set.frames[3].sequence, 104u);
  EXPECT_EQ(set.frames[3].status, FrameStatus::kOk);
  EXPECT_EQ(set.trigger_time, rig.record(104, std::nullopt).trigger_time);
  EXPECT_EQ(set.fix->time, set.trigger_time - std::chrono::milliseconds{40});

  EXPECT_TRUE(reader.verify().ok());
}

TEST(SessionWriterTest, FramesArePlainPgmFilesNamedBySetAndCamera) {
  ScopedTempDir tmp("rec_pgm");
  SessionWriter writer;
  ASSERT_TRUE(writer.open(tmp / "s", SessionInfo{}));
  SyntheticRig rig(kWidth, kHeight);
  writeSets(writer, rig, 5, 1);
  const std::string pgm = readWholeFile(tmp / "s" / "frames" / "000000_4_top_left.pgm");
  const std::string header = "P5\n40 30\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 40u * 30u);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  EXPECT_EQ(static_cast<std::uint8_t>(pgm[header.size() + 1]),
            testing_support::expectedPixel(5, 4, 1, 0));
  EXPECT_EQ(countTempFiles(tmp / "s"), 0);
  // The index is JSON lines, one per set, naming the files.
  const std::vector<std::string> lines = splitLines(readWholeFile(tmp / "s" / "index.jsonl"));
  ASSERT_EQ(lines.size(), 1u);
  const Json line = Json::parse(lines[0]);
  EXPECT_EQ(line["frames"][4]["file"], "frames/000000_4_top_left.pgm");
  EXPECT_EQ(line["gps"]["valid"], true);
}

TEST(SessionWriterTest, PaddedRowsAreStoredPacked) {
  ScopedTempDir tmp("rec_stride");
  SessionWriter writer;
  ASSERT_TRUE(writer.open(tmp / "s", SessionInfo{}));
  SyntheticRig rig(kWidth, kHeight, 64);  // 24 bytes of 0xEE padding per row
  writeSets(writer, rig, 9, 2);
  core::Result<SessionReader> reader = SessionReader::open(tmp / "s");
  ASSERT_TRUE(reader) << reader.error().message;
  for (const IndexedSet& set : reader->sets())
    expectFramesMatch(*reader, set, kWidth, kHeight);
  EXPECT_TRUE(reader->verify().ok());
}

TEST(SessionWriterTest, MissingAndShortFramesAreRecordedAsData) {
  ScopedTempDir tmp("rec_missing");
  SessionWriter writer;
  ASSERT_TRUE(writer.open(tmp / "s", SessionInfo{}));
  SyntheticRig rig(kWidth, kHeight);
  rig.fill(1);
  FrameSetRecord record = rig.record(1, std::nullopt);
  record.complete = false;
  record.fix.reset();
  record.frames[2].status = FrameStatus::kMissing;
  record.frames[2].reason = "timeout after 200 ms";
  record.frames[2].pixels = {};
  record.frames[5].pixels = record.frames[5].pixels.first(100);  // a truncated buffer
  const WriteOutcome outcome = writer.write(record);
  ASSERT_TRUE(outcome.ok()) << outcome.message;

  core::Result<SessionReader> reader = SessionReader::open(tmp / "s");
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 1u);
  const IndexedSet& set = reader->sets()[0];
  EXPECT_FALSE(set.complete);
  EXPECT_FALSE(set.location_id);
  EXPECT_FALSE(set.fix);
  EXPECT_EQ(set.frames[2].status, FrameStatus::kMissing);
  EXPECT_EQ(set.frames[2].reason, "timeout after 200 ms");
  EXPECT_TRUE(set.frames[2].file.empty());
  EXPECT_EQ(set.frames[5].status, FrameStatus::kCorrupt);
  EXPECT_NE(set.frames[5].reason.find("100 bytes"), std::string::npos) << set.frames[5].reason;
  EXPECT_TRUE(set.frames[5].file.empty());
  EXPECT_FALSE(reader->loadFrame(set.frames[2]));
  EXPECT_TRUE(reader->loadFrame(set.frames[0]));
  EXPECT_EQ(countFiles(tmp / "s" / "frames"), 4u);
  EXPECT_TRUE(reader->verify().ok());
}

TEST(SessionWriterTest, EveryFsyncPolicyWritesTheSameSession) {
  for (FsyncPolicy policy : {FsyncPolicy::kNone, FsyncPolicy::kPerSet, FsyncPolicy::kPerFrame}) {
    SCOPED_TRACE(std::string(toString(policy)));
    ScopedTempDir tmp("rec_policy");
    SessionWriter writer;
    ASSERT_TRUE(writer.open(tmp / "s", SessionInfo{}, WriterOptions{policy}));
    SyntheticRig rig(kWidth, kHeight);
    writeSets(writer, rig, 0, 3);
    core::Result<SessionReader> reader = SessionReader::open(tmp / "s");
    ASSERT_TRUE(reader) << reader.error().message;
    ASSERT_EQ(reader->sets().size(), 3u);
    expectFramesMatch(*reader, reader->sets()[2], kWidth, kHeight);
    EXPECT_EQ(countTempFiles(tmp / "s"), 0);
  }
}

TEST(SessionWriterTest, ReopenContinuesNumberingAndKeepsTheDescription) {
  ScopedTempDir tmp("rec_reopen");
  const fs::path session = tmp / "s";
  SyntheticRig rig(kWidth, kHeight);
  SessionInfo first;
  first.configuration = {{"run", 1}};
  first.start_time = std::chrono::sys_days{std::chrono::year{2026} / 7 / 14};
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, first));
    writeSets(writer, rig, 1, 3);
  }
  {
    SessionWriter writer;
    SessionInfo second;
    second.configuration = {{"run", 2}};
    core::Result<OpenReport> opened = writer.open(session, second);
    ASSERT_TRUE(opened) << opened.error().message;
    EXPECT_TRUE(opened->reopened);
    EXPECT_EQ(opened->next_set_index, 3u);
    EXPECT_FALSE(opened->torn_line);
    // Trigger ids restart with a new run; set indices do not.
    writeSets(writer, rig, 1, 2);
  }
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 5u);
  for (std::uint64_t k = 0; k < 5; ++k)
    EXPECT_EQ(reader->sets()[k].set_index, k);
  EXPECT_EQ(reader->sets()[4].trigger_id, 2u);
  expectFramesMatch(*reader, reader->sets()[4], kWidth, kHeight);
  EXPECT_EQ(reader->metadata().start_time, "2026-07-14T00:00:00.000Z");
  EXPECT_EQ(reader->metadata().configuration["run"], 1);
  ASSERT_EQ(reader->metadata().raw["reopened"].size(), 1u);
  EXPECT_TRUE(reader->verify().ok());
}

// A session reopened with another map than the one it names records that map in its reopening
// and reports it; the same map again records nothing new.
TEST(SessionWriterTest, ReopeningWithAnotherMapRecordsAndReportsIt) {
  ScopedTempDir tmp("rec_reopen_map");
  const fs::path session = tmp / "s";
  const fs::path map = tmp / "map.csv";
  const fs::path other = tmp / "other.csv";
  std::ofstream(map) << "id,lat,lon,heading\nA,42,-93,0\n";
  std::ofstream(other) << "id,lat,lon,heading\nB,43,-93,0\n";
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, testInfo(map)));
  }
  {
    SessionWriter writer;
    core::Result<OpenReport> same = writer.open(session, testInfo(map));
    ASSERT_TRUE(same) << same.error().message;
    EXPECT_FALSE(same->map_changed);
  }
  {
    SessionWriter writer;
    core::Result<OpenReport> changed = writer.open(session, testInfo(other));
    ASSERT_TRUE(changed) << changed.error().message;
    ASSERT_TRUE(changed->map_changed);
    EXPECT_NE(changed->map_changed->find("sets from now on are triggered from " + other.string()),
              std::string::npos)
        << *changed->map_changed;
  }
  {  // the new map again: it is the one in use, nothing new to record
    SessionWriter writer;
    core::Result<OpenReport> again = writer.open(session, testInfo(other));
    ASSERT_TRUE(again) << again.error().message;
    EXPECT_FALSE(again->map_changed);
  }
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  const auto& reopened = reader->metadata().raw["reopened"];
  ASSERT_EQ(reopened.size(), 3u);
  EXPECT_FALSE(reopened[2].contains("map"));
  EXPECT_FALSE(reopened[0].contains("map"));
  EXPECT_EQ(reopened[1].at("map").at("path"), other.string());
  EXPECT_EQ(reader->metadata().map_path, map.string()) << "the session's first map stays";
}

TEST(SessionWriterTest, TornLastLineIsIgnoredReportedAndCutOnReopen) {
  ScopedTempDir tmp("rec_torn");
  const fs::path session = tmp / "s";
  const fs::path index = session / "index.jsonl";
  SyntheticRig rig(kWidth, kHeight);
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}));
    writeSets(writer, rig, 10, 4);
  }
  // What a crash in the middle of the fifth line's write leaves: its first half, no newline.
  const std::vector<std::string> lines = splitLines(readWholeFile(index));
  ASSERT_EQ(lines.size(), 4u);
  const std::string half = lines[3].substr(0, lines[3].size() / 2);
  appendText(index, half);
  const std::size_t whole_size = fs::file_size(index) - half.size();

  {
    core::Result<SessionReader> reader = SessionReader::open(session);
    ASSERT_TRUE(reader) << reader.error().message;
    EXPECT_EQ(reader->sets().size(), 4u);
    ASSERT_TRUE(reader->tornLine());
    EXPECT_EQ(reader->tornLine()->line, 5u);
    EXPECT_EQ(reader->tornLine()->bytes, half.size());
    EXPECT_EQ(reader->tornLine()->offset, whole_size);
    EXPECT_TRUE(reader->verify().ok());
  }
  {
    SessionWriter writer;
    core::Result<OpenReport> opened = writer.open(session, SessionInfo{});
    ASSERT_TRUE(opened) << opened.error().message;
    ASSERT_TRUE(opened->torn_line);
    EXPECT_EQ(opened->torn_line->line, 5u);
    EXPECT_EQ(opened->next_set_index, 4u);
    EXPECT_EQ(fs::file_size(index), whole_size);
    writeSets(writer, rig, 20, 2);
  }
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_FALSE(reader->tornLine());
  ASSERT_EQ(reader->sets().size(), 6u);
  EXPECT_EQ(reader->sets()[4].trigger_id, 20u);
  EXPECT_EQ(reader->sets()[5].set_index, 5u);
  // Still valid JSON lines, every one.
  for (const std::string& line : splitLines(readWholeFile(index)))
    EXPECT_TRUE(Json::accept(line)) << line;
  EXPECT_TRUE(reader->verify().ok());
}

TEST(SessionWriterTest, ReopenRemovesWhatACrashedRunLeftInFrames) {
  ScopedTempDir tmp("rec_leftovers");
  const fs::path session = tmp / "s";
  SyntheticRig rig(kWidth, kHeight);
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}));
    writeSets(writer, rig, 0, 2);
  }
  // A frame being written, and a frame of a set whose index line never came.
  writeText(session / "frames" / "000002_0_bottom_left.pgm.tmp", "P5\n40 30\n255\nxx");
  writeText(session / "frames" / "000002_1_bottom_right.pgm", "P5\n40 30\n255\n");
  SessionWriter writer;
  core::Result<OpenReport> opened = writer.open(session, SessionInfo{});
  ASSERT_TRUE(opened) << opened.error().message;
  EXPECT_EQ(opened->leftovers_removed, 2u);
  EXPECT_EQ(countFiles(session / "frames"), 12u);
}

// Two daemons on one recording folder interleaved their sets in the index (0,1,0,2,…) and
// overwrote each other's frames; the second writer is refused while the first holds the folder.
TEST(SessionWriterTest, ASecondWriterOnTheFolderIsRefusedWhileTheFirstHoldsIt) {
  ScopedTempDir tmp("rec_two_writers");
  const fs::path session = tmp / "s";
  SyntheticRig rig(kWidth, kHeight);
  SessionWriter first;
  ASSERT_TRUE(first.open(session, SessionInfo{}));
  writeSets(first, rig, 0, 1);
  {
    SessionWriter second;
    const core::Result<OpenReport> refused = second.open(session, SessionInfo{});
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("index.jsonl: in use by another writer"),
              std::string::npos)
        << refused.error().message;
  }
  writeSets(first, rig, 1, 1);
  first.close();
  SessionWriter after;
  const core::Result<OpenReport> reopened = after.open(session, SessionInfo{});
  ASSERT_TRUE(reopened) << reopened.error().message;
  EXPECT_EQ(reopened->next_set_index, 2u);
}

// With its index gone (deleted, or a copy without it), a reopening numbered sets from 0 again and
// removed every captured frame as a "leftover"; stray frames in a new folder went the same way.
TEST(SessionWriterTest, FramesTheIndexDoesNotHoldAreKeptAndTheOpeningIsRefused) {
  ScopedTempDir tmp("rec_index_lost");
  const fs::path session = tmp / "s";
  SyntheticRig rig(kWidth, kHeight);
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}));
    writeSets(writer, rig, 0, 3);
  }
  const std::size_t frames = countFiles(session / "frames");
  ASSERT_GT(frames, 0u);
  fs::remove(session / "index.jsonl");
  SessionWriter writer;
  const core::Result<OpenReport> lost = writer.open(session, SessionInfo{});
  ASSERT_FALSE(lost);
  EXPECT_NE(lost.error().message.find("there is no index.jsonl"), std::string::npos)
      << lost.error().message;
  EXPECT_EQ(countFiles(session / "frames"), frames);
  EXPECT_FALSE(fs::exists(session / "index.jsonl")) << "a refused opening created the index";

  // An index that ends two sets early (an older copy put back).
  const fs::path stray = tmp / "stray";
  fs::create_directories(stray / "frames");
  fs::copy_file(session / "frames" / "000002_0_bottom_left.pgm",
                stray / "frames" / "000002_0_bottom_left.pgm");
  const core::Result<OpenReport> stray_frames = writer.open(stray, SessionInfo{});
  ASSERT_FALSE(stray_frames);
  EXPECT_NE(stray_frames.error().message.find("000002_0_bottom_left.pgm: a frame of set 2"),
            std::string::npos)
      << stray_frames.error().message;
  EXPECT_TRUE(fs::exists(stray / "frames" / "000002_0_bottom_left.pgm"));
}

TEST(SessionWriterTest, WriteWithoutASessionIsRefusedWithoutThrowing) {
  SessionWriter writer;
  SyntheticRig rig(4, 4);
  const WriteOutcome outcome = writer.write(rig.record(1, std::nullopt));
  EXPECT_EQ(outcome.status, WriteStatus::kStopped);
  EXPECT_FALSE(outcome.message.empty());
}

TEST(SessionWriterTest, OpenFailsWithTheMapFileNamed) {
  ScopedTempDir tmp("rec_no_map");
  SessionInfo info;
  info.map_file = tmp / "absent.csv";
  SessionWriter writer;
  core::Result<OpenReport> opened = writer.open(tmp / "s", info);
  ASSERT_FALSE(opened);
  EXPECT_NE(opened.error().message.find("absent.csv"), std::string::npos) << opened.error().message;
}

}  // namespace
}  // namespace fieldrig::recording
