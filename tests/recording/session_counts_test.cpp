// SessionReader's summary of a session, as `fieldrig session info` prints it: the index counted
// (complete sets, frames not ok) and the bytes the folder holds.
#include <gtest/gtest.h>

#include "recording/test_helpers.h"
#include "support/temp_dir.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using testing_support::ScopedTempDir;
using testing_support::SyntheticRig;

TEST(SessionCountsTest, CountsIncompleteSetsAndFramesNotOk) {
  ScopedTempDir tmp("reader_counts");
  const fs::path session = tmp / "s";
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}));
    SyntheticRig rig(kWidth, kHeight);
    writeSets(writer, rig, 1, 2);
    rig.fill(3);
    FrameSetRecord incomplete = rig.record(3, locationFor(3));
    incomplete.complete = false;
    incomplete.frames[4].status = FrameStatus::kMissing;
    incomplete.frames[4].pixels = {};
    ASSERT_TRUE(writer.write(incomplete).ok());
  }
  const core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  const SessionCounts counts = reader->counts();
  EXPECT_EQ(counts.sets, 3U);
  EXPECT_EQ(counts.complete_sets, 2U);
  EXPECT_EQ(counts.frames, 18U);
  EXPECT_EQ(counts.frames_not_ok, 1U);
}

TEST(SessionCountsTest, BytesOnDiskAreEveryFileBelowTheFolder) {
  ScopedTempDir tmp("reader_bytes");
  const fs::path session = tmp / "s";
  {
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}));
    SyntheticRig rig(kWidth, kHeight);
    writeSets(writer, rig, 1, 2);
  }
  const core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  std::uint64_t expected = 0;
  for (const auto& entry : fs::recursive_directory_iterator(session)) {
    if (entry.is_regular_file())
      expected += entry.file_size();
  }
  EXPECT_GT(expected, 12U * kWidth * kHeight);  // twelve frames at least
  EXPECT_EQ(reader->bytesOnDisk(), expected);
  fs::create_directories(session / "notes");
  writeText(session / "notes" / "operator.txt", "rain at 14:00\n");
  EXPECT_EQ(reader->bytesOnDisk(), expected + 14);
}

}  // namespace
}  // namespace fieldrig::recording
