// The durable-file helpers: what they write, the errors they return, and what a writer killed in
// the middle of its work leaves behind (a child process appends or replaces in a loop and is
// killed with SIGKILL at an arbitrary moment).
#include "fieldrig/core/durable_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "support/file_size_limit.h"
#include "support/temp_dir.h"

namespace fieldrig::core {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing_support::ScopedTempDir;

std::string read(const fs::path& path) {
  std::string error;
  const auto text = readWholeFile(path, error);
  EXPECT_TRUE(text.has_value()) << error;
  return text.value_or("");
}

// Record `index` of the append test: its number, then enough bytes that writing it takes a
// while (so that a kill can land inside a write), then a newline.
std::string appendRecord(int index) {
  char head[32];
  std::snprintf(head, sizeof head, "R%08d ", index);
  return head + std::string(64 * 1024 + (index % 7) * 1000, static_cast<char>('a' + index % 26)) +
         "\n";
}

// Version `index` of the replace test: its number, a large body, and an end mark.
std::string replaceVersion(int index) {
  char head[32];
  std::snprintf(head, sizeof head, "V%08d\n", index);
  return head + std::string(512 * 1024 + (index % 5) * 999, static_cast<char>('a' + index % 26)) +
         "\nEND\n";
}

// Runs `work(i)` for i = 0, 1, … in a child process until it is killed, waits until `ready`
// says the child is well under way, lets it run for `extra`, then kills it with SIGKILL.
template <typename Work, typename Ready>
void killMidWork(Work work, Ready ready, std::chrono::milliseconds extra) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    for (int i = 0;; ++i) {
      if (!work(i).empty())
        ::_exit(1);
    }
  }
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!ready() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  std::this_thread::sleep_for(extra);
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  // Killed, not exited: an exit would mean a write failed, and the test would prove nothing.
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer exited with " << WEXITSTATUS(status);
}

TEST(DurableFileTest, WriteFullyWritesEveryByte) {
  const ScopedTempDir dir("durable_write_fully");
  const fs::path path = dir / "out.bin";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  const std::string text = appendRecord(3);
  EXPECT_EQ(writeFully(fd, text.data(), text.size()), 0);
  ::close(fd);
  EXPECT_EQ(read(path), text);
  EXPECT_EQ(writeFully(-1, "x", 1), EBADF);
}

TEST(DurableFileTest, ReplaceAndAppendWriteWhatTheySayAndNameThePathInErrors) {
  const ScopedTempDir dir("durable_basic");
  const fs::path path = dir / "file.txt";
  EXPECT_EQ(replaceFileAtomically(path, "one\n"), "");
  EXPECT_EQ(read(path), "one\n");
  EXPECT_EQ(replaceFileAtomically(path, "two\n"), "");
  EXPECT_EQ(read(path), "two\n");
  EXPECT_EQ(testing_support::tempFilesBeside(path), 0u);
  EXPECT_EQ(appendDurably(path, "three\n"), "");
  EXPECT_EQ(appendDurably(dir / "new.txt", "first\n"), "");
  EXPECT_EQ(read(path), "two\nthree\n");
  EXPECT_EQ(read(dir / "new.txt"), "first\n");

  const fs::path missing = dir / "no" / "such" / "file.txt";
  EXPECT_NE(replaceFileAtomically(missing, "x").find(missing.parent_path().string()),
            std::string::npos);
  EXPECT_EQ(appendDurably(missing, "x").rfind(missing.string() + ": cannot open", 0), 0u);
  std::string error;
  EXPECT_FALSE(readWholeFile(missing, error).has_value());
  EXPECT_EQ(error.rfind(missing.string() + ": cannot open", 0), 0u) << error;
}

TEST(DurableFileTest, WriteWholeFileReplacesTheContentAndReportsAFullDisk) {
  const ScopedTempDir dir("durable_whole");
  const fs::path path = dir / "image.bin";
  EXPECT_EQ(writeWholeFile(path, "a longer first content"), "");
  EXPECT_EQ(writeWholeFile(path, "short"), "");
  EXPECT_EQ(read(path), "short");
  // /dev/full fails every write with ENOSPC: the disk-full case, without filling a disk.
  const std::string full = writeWholeFile("/dev/full", "bytes that cannot land");
  EXPECT_EQ(full.rfind("/dev/full: cannot write: ", 0), 0u) << full;
  EXPECT_NE(full.find(std::strerror(ENOSPC)), std::string::npos) << full;
  const fs::path missing = dir / "no" / "such" / "file.bin";
  EXPECT_EQ(writeWholeFile(missing, "x").rfind(missing.string() + ": cannot create", 0), 0u);
}

// A write that fails part-way (here a file size limit, as a full disk would) leaves the old
// file whole and no partial one beside it.
TEST(DurableFileTest, AWholeFileWriteThatFailsKeepsTheOldFile) {
  const ScopedTempDir dir("durable_whole_fails");
  const fs::path path = dir / "cloud.ply";
  ASSERT_EQ(writeWholeFile(path, "the old content"), "");
  std::string failed;
  {
    const testing_support::FileSizeLimit limit(64);
    failed = writeWholeFile(path, std::string(4096, 'x'));
  }
  EXPECT_EQ(failed.rfind(path.string() + ": cannot write: ", 0), 0u) << failed;
  EXPECT_NE(failed.find(std::strerror(EFBIG)), std::string::npos) << failed;
  EXPECT_EQ(read(path), "the old content");
  {
    const testing_support::FileSizeLimit limit(64);
    EXPECT_NE(writeWholeFile(dir / "new.ply", std::string(4096, 'x')), "");
  }
  EXPECT_FALSE(fs::exists(dir / "new.ply"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1)
      << "no temporary file is left";
  // A file already named like a temporary one is not touched, and a symbolic link is written
  // through to its target (/dev/stdout is one), not replaced by a file.
  std::ofstream(path.string() + ".tmp") << "someone else's";
  const fs::path link = dir / "link.ply";
  fs::create_symlink(path, link);
  ASSERT_EQ(writeWholeFile(link, "through the link"), "");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(read(path), "through the link");
  ASSERT_EQ(writeWholeFile(path, "new"), "");
  EXPECT_EQ(read(path.string() + ".tmp"), "someone else's");
}

// Files that belong together: when one cannot be written, none is replaced.
TEST(DurableFileTest, FilesReplacedTogetherStayOldWhenOneCannotBeWritten) {
  const ScopedTempDir dir("durable_together");
  const fs::path small = dir / "intrinsics.yml";
  const fs::path large = dir / "extrinsics.yml";
  ASSERT_EQ(replaceFilesTogether({{small, "old small"}, {large, "old large"}}), "");
  EXPECT_EQ(read(small), "old small");
  EXPECT_EQ(read(large), "old large");
  const std::string large_text(4096, 'n');
  std::string failed;
  {
    const testing_support::FileSizeLimit limit(64);  // the small one fits, the large one not
    failed = replaceFilesTogether({{small, "new small"}, {large, large_text}});
  }
  EXPECT_EQ(failed.rfind(large.string() + ": cannot write: ", 0), 0u) << failed;
  EXPECT_EQ(read(small), "old small");
  EXPECT_EQ(read(large), "old large");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2)
      << "no temporary file is left";
  ASSERT_EQ(replaceFilesTogether({{small, "new small"}, {large, large_text}}), "");
  EXPECT_EQ(read(small), "new small");
  EXPECT_EQ(read(large), large_text);
}

TEST(DurableFileTest, AnAppenderKilledMidWriteLeavesEveryEarlierRecordWhole) {
  for (const auto extra : {0ms, 7ms, 23ms, 61ms}) {
    const ScopedTempDir dir("durable_append_kill");
    const fs::path path = dir / "log.txt";
    killMidWork([&](int i) { return appendDurably(path, appendRecord(i)); },
                [&] {
                  std::error_code missing;
                  const auto size = fs::file_size(path, missing);
                  return !missing && size > 4 * appendRecord(0).size();
                },
                extra);
    const std::string text = read(path);
    std::size_t pos = 0;
    int index = 0;
    while (pos < text.size()) {
      const std::string expected = appendRecord(index);
      const std::size_t end = text.find('\n', pos);
      if (end == std::string::npos) {
        // Only the last record may be torn, and then it is a beginning of the record that was
        // being written, never a mix of two.
        EXPECT_EQ(text.compare(pos, std::string::npos, expected, 0, text.size() - pos), 0)
            << "torn record " << index << " is not a prefix of it";
        break;
      }
      ASSERT_EQ(text.compare(pos, end + 1 - pos, expected), 0)
          << "record " << index << " at byte " << pos << " is not whole (kill after "
          << extra.count() << " ms)";
      pos = end + 1;
      ++index;
    }
    EXPECT_GE(index, 4) << "the child had appended at least four records before the kill";
  }
}

// The temporary file has a name of its own: a file already called PATH.tmp was truncated, and a
// link there was followed to its target, by the fixed name an earlier version used.
TEST(DurableFileTest, AReplaceLeavesAFileOrALinkNamedLikeItsTemporaryFileAlone) {
  const ScopedTempDir dir("durable_replace_names");
  const fs::path path = dir / "session.json";
  const fs::path other = dir / "other.txt";
  std::ofstream(other) << "not to be touched";
  fs::create_symlink(other, path.string() + ".tmp");
  ASSERT_EQ(replaceFileAtomically(path, "{}\n"), "");
  EXPECT_EQ(read(path), "{}\n");
  EXPECT_EQ(read(other), "not to be touched");
  EXPECT_TRUE(fs::is_symlink(path.string() + ".tmp"));
  fs::remove(path.string() + ".tmp");
  std::ofstream(path.string() + ".tmp") << "someone else's";
  ASSERT_EQ(replaceFilesTogether({{path, "[]\n"}, {other, "new"}}), "");
  EXPECT_EQ(read(path), "[]\n");
  EXPECT_EQ(read(other), "new");
  EXPECT_EQ(read(path.string() + ".tmp"), "someone else's");
  EXPECT_EQ(testing_support::tempFilesBeside(path), 1u) << "only the decoy PATH.tmp is there";
  EXPECT_EQ(testing_support::tempFilesBeside(other), 0u);
}

// A rename that fails after another went through (a target that became a folder): the first file
// is new, the one that failed is named, and no temporary file of either is left.
TEST(DurableFileTest, FilesReplacedTogetherNameARenameThatFailsAndLeaveNoTemporaryFile) {
  const ScopedTempDir dir("durable_together_rename");
  const fs::path first = dir / "intrinsics.yml";
  const fs::path second = dir / "extrinsics.yml";
  fs::create_directories(second);
  const std::string failed = replaceFilesTogether({{first, "new first"}, {second, "new second"}});
  EXPECT_EQ(failed.rfind(second.string() + ": cannot write: ", 0), 0u) << failed;
  EXPECT_EQ(read(first), "new first");
  EXPECT_TRUE(fs::is_directory(second));
  EXPECT_EQ(testing_support::tempFilesBeside(first), 0u);
  EXPECT_EQ(testing_support::tempFilesBeside(second), 0u);
}

// The new file takes the mode a plain open would give, 0644 less the umask: a crew's umask 077
// keeps its session records private, as it did before the temporary files had names of their own.
TEST(DurableFileTest, AReplacedFileTakesTheUmasksMode) {
  const ScopedTempDir dir("durable_umask");
  const mode_t saved = ::umask(077);
  const std::string replaced = replaceFileAtomically(dir / "session.json", "{}\n");
  const std::string whole = writeWholeFile(dir / "cloud.ply", "ply");
  ::umask(022);
  const std::string replaced_022 = replaceFileAtomically(dir / "plots.jsonl", "{}\n");
  ::umask(saved);
  ASSERT_EQ(replaced, "");
  ASSERT_EQ(whole, "");
  ASSERT_EQ(replaced_022, "");
  const auto mode = [](const fs::path& p) {
    struct stat info {};
    EXPECT_EQ(::stat(p.c_str(), &info), 0) << p;
    return info.st_mode & 0777;
  };
  EXPECT_EQ(mode(dir / "session.json"), 0600U);
  EXPECT_EQ(mode(dir / "cloud.ply"), 0600U);
  EXPECT_EQ(mode(dir / "plots.jsonl"), 0644U);
}

TEST(DurableFileTest, AReplacerKilledMidWriteLeavesTheOldOrTheNewFileNeverAMix) {
  for (const auto extra : {0ms, 5ms, 19ms, 43ms}) {
    const ScopedTempDir dir("durable_replace_kill");
    const fs::path path = dir / "state.txt";
    ASSERT_EQ(replaceFileAtomically(path, replaceVersion(0)), "");
    killMidWork([&](int i) { return replaceFileAtomically(path, replaceVersion(i + 1)); },
                [&] {
                  std::string error;
                  const auto text = readWholeFile(path, error);
                  return text && text->compare(0, 9, "V00000003") >= 0;
                },
                extra);
    const std::string text = read(path);
    int version = -1;
    ASSERT_EQ(std::sscanf(text.c_str(), "V%08d", &version), 1) << text.substr(0, 20);
    EXPECT_GE(version, 3);
    EXPECT_TRUE(text == replaceVersion(version))
        << "version " << version << " is not whole (" << text.size() << " bytes, expected "
        << replaceVersion(version).size() << "; kill after " << extra.count() << " ms)";
  }
}

}  // namespace
}  // namespace fieldrig::core
