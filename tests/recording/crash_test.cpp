// kill -9 of a recording process, mid-run: afterwards the session opens, every indexed set is
// whole and byte-identical to what was recorded, and a reopening continues its numbering.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <iostream>
#include <random>
#include <thread>

#include "recording/test_helpers.h"
#include "support/cli_process.h"
#include "support/temp_dir.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using testing_support::FieldrigProcess;
using testing_support::ScopedTempDir;

TEST(CrashTest, KillNineMidRunLeavesEveryIndexedSetWhole) {
  ScopedTempDir tmp("rec_kill9");
  const fs::path session = tmp / "s";
  std::mt19937 random(20260714);
  std::uint64_t expected_at_least = 0;
  // Three runs into the same session, killed at a random moment once a few sets are written;
  // each policy once.
  for (const char* policy : {"none", "per_set", "per_frame"}) {
    SCOPED_TRACE(policy);
    {
      FieldrigProcess recorder({session.string(), policy}, tmp.path(), RECORD_FOREVER_BINARY);
      ASSERT_TRUE(recorder.waitForStdoutLines(8, std::chrono::seconds{60})) << recorder.err();
      std::this_thread::sleep_for(std::chrono::microseconds{random() % 20000});
      ASSERT_TRUE(recorder.signal(SIGKILL));
      EXPECT_EQ(recorder.waitExit(), -1);  // died by the signal
      // Only the "set N" lines: a reopening that cuts a torn line says so on stdout (spdlog's
      // default sink), and that line is no set.
      for (const std::string& line : recorder.outLines())
        expected_at_least += line.rfind("set ", 0) == 0 ? 1 : 0;
    }
    // Informational: whether this kill caught a frame or an index line half-written.
    std::cout << policy << ": killed with " << countTempFiles(session)
              << " temporary frame file(s) in place\n";
    core::Result<SessionReader> reader = SessionReader::open(session);
    ASSERT_TRUE(reader) << reader.error().message;
    if (reader->tornLine())
      std::cout << policy << ": torn index line " << reader->tornLine()->line << "\n";
    const auto& sets = reader->sets();
    ASSERT_GE(sets.size(), expected_at_least);
    for (std::uint64_t k = 0; k < sets.size(); ++k) {
      ASSERT_EQ(sets[k].set_index, k);
      ASSERT_EQ(sets[k].frames.size(), 6u);
      for (const IndexedFrame& frame : sets[k].frames) {
        core::Result<Image> image = reader->loadFrame(frame);
        ASSERT_TRUE(image) << image.error().message;
        ASSERT_EQ(image->pixels,
                  expectedImage(sets[k].trigger_id, frame.camera_index, frame.width, frame.height))
            << frame.file;
      }
    }
    const VerifyReport report = reader->verify();
    EXPECT_TRUE(report.ok()) << (report.problems.empty() ? "" : report.problems[0]);
    // The next run starts where the index ends (the helper's output restarts at 0 lines).
    expected_at_least = sets.size();
  }

  // A recorder restarted after the crash continues the numbering and leaves a whole session.
  SessionWriter writer;
  core::Result<OpenReport> opened = writer.open(session, SessionInfo{});
  ASSERT_TRUE(opened) << opened.error().message;
  EXPECT_EQ(opened->next_set_index, expected_at_least);
  EXPECT_EQ(countTempFiles(session), 0);
  testing_support::SyntheticRig rig(kWidth, kHeight);
  writeSets(writer, rig, 1, 1);
  writer.close();
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_FALSE(reader->tornLine());
  EXPECT_EQ(reader->sets().size(), expected_at_least + 1);
  EXPECT_EQ(countFiles(session / kFramesDir), 6 * (expected_at_least + 1));
  EXPECT_TRUE(reader->verify().ok());
}

}  // namespace
}  // namespace fieldrig::recording
