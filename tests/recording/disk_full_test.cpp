// A full disk stops the recording cleanly: the write that fails says why, leaves no temporary
// file or half index line behind, and every set written before stays whole.
//
// Two real mechanisms: a 2 MiB tmpfs mounted for the test (ENOSPC; needs CAP_SYS_ADMIN, skipped
// without it), and RLIMIT_FSIZE in a forked child with SIGXFSZ ignored (EFBIG; needs nothing),
// which fails either a frame file or the index file itself, depending on the limit.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <functional>

#include "recording/test_helpers.h"
#include "support/temp_dir.h"
#include "support/tmpfs_mount.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using testing_support::ScopedTempDir;
using testing_support::SyntheticRig;

using testing_support::TmpfsMount;

// What must hold after the writer stopped at a full disk with `ok_sets` sets written.
void expectWholeSessionOf(const fs::path& session, std::uint64_t ok_sets) {
  EXPECT_EQ(countTempFiles(session), 0);
  EXPECT_EQ(countFiles(session / kFramesDir), 6 * ok_sets);
  core::Result<SessionReader> reader = SessionReader::open(session);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_FALSE(reader->tornLine());
  EXPECT_EQ(reader->sets().size(), ok_sets);
  const VerifyReport report = reader->verify();
  EXPECT_TRUE(report.ok()) << (report.problems.empty() ? "" : report.problems[0]);
}

TEST(DiskFullTest, TmpfsFullStopsCleanlyKeepingEveryWrittenSet) {
  for (FsyncPolicy policy : {FsyncPolicy::kNone, FsyncPolicy::kPerSet, FsyncPolicy::kPerFrame}) {
    SCOPED_TRACE(std::string(toString(policy)));
    ScopedTempDir tmp("rec_tmpfs");
    TmpfsMount mount(tmp / "small", "2m");
    if (!mount.mounted())
      GTEST_SKIP() << "cannot mount a tmpfs here (" << mount.error() << "); the RLIMIT_FSIZE "
                   << "tests below cover the same paths with EFBIG";
    const fs::path session = tmp / "small" / "s";
    SessionWriter writer;
    ASSERT_TRUE(writer.open(session, SessionInfo{}, WriterOptions{policy}));
    SyntheticRig rig(100, 100);
    std::uint64_t ok_sets = 0;
    WriteOutcome outcome;
    for (std::uint64_t trigger = 0; trigger < 1000; ++trigger) {
      rig.fill(trigger);
      outcome = writer.write(rig.record(trigger, std::nullopt));
      if (!outcome.ok())
        break;
      ++ok_sets;
    }
    ASSERT_EQ(outcome.status, WriteStatus::kDiskFull) << outcome.message;
    EXPECT_NE(outcome.message.find(std::strerror(ENOSPC)), std::string::npos) << outcome.message;
    EXPECT_GT(ok_sets, 5u);
    EXPECT_TRUE(writer.stopped());
    ASSERT_TRUE(writer.alarm());
    EXPECT_EQ(*writer.alarm(), outcome.message);
    // Stopped means stopped: nothing more is attempted, even if space came back.
    EXPECT_EQ(writer.write(rig.record(5000, std::nullopt)).status, WriteStatus::kStopped);
    expectWholeSessionOf(session, ok_sets);
  }
}

// Runs `body` in a forked child whose files may grow to `limit_bytes` at most, SIGXFSZ ignored so
// that an oversize write fails with EFBIG instead of killing it. Returns the child's exit code.
int runWithFileSizeLimit(rlim_t limit_bytes, const std::function<int()>& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const rlimit limit{limit_bytes, limit_bytes};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0)
      ::_exit(250);
    ::signal(SIGXFSZ, SIG_IGN);
    ::_exit(body());
  }
  int status = 0;
  if (pid < 0 || ::waitpid(pid, &status, 0) != pid)
    return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(DiskFullTest, FrameLargerThanTheFileLimitFailsWithoutLeavingItsTemporaryFile) {
  ScopedTempDir tmp("rec_fsize_frame");
  const fs::path session = tmp / "s";
  // Exit codes: 0 as expected; 1x which step went wrong.
  const int code = runWithFileSizeLimit(64 * 1024, [&] {
    SessionWriter writer;
    if (!writer.open(session, SessionInfo{}))
      return 10;
    SyntheticRig small(kWidth, kHeight);
    for (std::uint64_t trigger = 0; trigger < 3; ++trigger) {
      small.fill(trigger);
      if (!writer.write(small.record(trigger, std::nullopt)).ok())
        return 11;
    }
    SyntheticRig large(300, 300);  // 90 kB a frame, over the 64 KiB limit
    large.fill(3);
    const WriteOutcome outcome = writer.write(large.record(3, std::nullopt));
    if (outcome.status != WriteStatus::kDiskFull)
      return 12;
    if (outcome.message.find(std::strerror(EFBIG)) == std::string::npos ||
        outcome.message.find("000003_0_bottom_left.pgm") == std::string::npos)
      return 13;
    return writer.write(small.record(4, std::nullopt)).status == WriteStatus::kStopped ? 0 : 14;
  });
  ASSERT_EQ(code, 0);
  expectWholeSessionOf(session, 3);
}

TEST(DiskFullTest, IndexReachingTheFileLimitIsCutBackToWholeLines) {
  ScopedTempDir tmp("rec_fsize_index");
  const fs::path session = tmp / "s";
  // Frames of 1.2 kB fit; the index (about 2.4 kB a line) reaches 8 KiB on its fourth line, which
  // the kernel writes in part before refusing the rest. Exit code: the sets written, or 100+.
  const int code = runWithFileSizeLimit(8 * 1024, [&] {
    SessionWriter writer;
    if (!writer.open(session, SessionInfo{}, WriterOptions{FsyncPolicy::kPerSet}))
      return 100;
    SyntheticRig rig(kWidth, kHeight);
    for (std::uint64_t trigger = 0; trigger < 50; ++trigger) {
      rig.fill(trigger);
      const WriteOutcome outcome = writer.write(rig.record(trigger, "plot"));
      if (!outcome.ok()) {
        const bool index_named = outcome.message.find("index.jsonl") != std::string::npos;
        return outcome.status == WriteStatus::kDiskFull && index_named ? static_cast<int>(trigger)
                                                                       : 101;
      }
    }
    return 102;
  });
  ASSERT_GT(code, 0);
  ASSERT_LT(code, 100);
  expectWholeSessionOf(session, static_cast<std::uint64_t>(code));
  EXPECT_LE(fs::file_size(session / kIndexFile), 8u * 1024u);
}

}  // namespace
}  // namespace fieldrig::recording
