// Persists FrameSets into a session folder so that a crash (kill -9, power loss under a fsync
// policy) never leaves an indexed set incomplete, and a full disk stops the recording cleanly.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/recording/frame_set_record.h"
#include "fieldrig/recording/session_format.h"

namespace fieldrig::recording {

struct WriterOptions {
  FsyncPolicy fsync = FsyncPolicy::kPerSet;
};

// What open() found in the folder.
struct OpenReport {
  bool reopened = false;                // the folder held a session already
  std::uint64_t next_set_index = 0;     // the index the next write() gets
  std::optional<TornLine> torn_line;    // cut away from index.jsonl
  std::uint64_t leftovers_removed = 0;  // temporary or unindexed frame files of a crashed run
  // Reopened with another map than session.json names (its "reopened" entry records the new one):
  // what changed, to be said where the run's user sees it.
  std::optional<std::string> map_changed;
};

enum class WriteStatus {
  kOk,
  kDiskFull,  // ENOSPC, EDQUOT or EFBIG: the writer has stopped
  kIoError,   // any other write error: the writer has stopped
  kStopped,   // the writer stopped earlier (or was never opened); nothing was written
};

std::string_view toString(WriteStatus status);

struct WriteOutcome {
  WriteStatus status = WriteStatus::kOk;
  std::uint64_t set_index = 0;  // the set's index when kOk
  std::string message;          // what failed, naming the file, when not kOk
  bool ok() const { return status == WriteStatus::kOk; }
};

// Thread contract: owned by one thread (the recorder thread); every call, queries included, comes
// from that thread. After the first failed write it writes nothing more (stopped(), alarm()):
// the sets already indexed stay whole, the failed set leaves no file behind.
class SessionWriter {
 public:
  SessionWriter() = default;
  ~SessionWriter();
  SessionWriter(const SessionWriter&) = delete;
  SessionWriter& operator=(const SessionWriter&) = delete;

  // Creates `dir` (and its parents) as a new session, or reopens the session already there:
  // its session.json is kept (the reopening is appended to it), a torn last index line is cut
  // away, leftover files of a crashed run are removed and numbering continues after the last
  // indexed set. An error names the file (and line) that prevents recording.
  core::Result<OpenReport> open(const std::filesystem::path& dir, const SessionInfo& info,
                                const WriterOptions& options = {});

  // Writes the set's frames, then its index line. Never throws; on failure the writer stops and
  // says why. Frames whose pixels are shorter than width/height/stride require are recorded as
  // corrupt without an image rather than refused, so that the set's line is still written.
  WriteOutcome write(const FrameSetRecord& record);

  // Closes the files; the session stays valid (it is valid after every write()).
  void close();

  bool isOpen() const { return index_fd_ >= 0; }
  bool stopped() const { return alarm_.has_value(); }
  const std::optional<std::string>& alarm() const { return alarm_; }  // why it stopped
  std::uint64_t nextSetIndex() const { return next_set_index_; }
  std::uint64_t bytesWritten() const { return bytes_written_; }  // this opening, all files
  const std::filesystem::path& dir() const { return dir_; }

 private:
  struct PendingFile {
    int fd = -1;
    std::filesystem::path temp_path;
    std::filesystem::path final_path;
  };

  WriteOutcome fail(WriteStatus status, std::string message);
  // Writes one frame to its temporary file; the file stays open in `pending` for kPerSet.
  bool writeFrame(std::uint64_t set_index, const FrameView& frame, IndexedFrame& entry,
                  PendingFile& pending, int& error, std::string& failed_path);
  void discardPending(bool renamed);

  std::filesystem::path dir_;
  std::filesystem::path frames_dir_;
  WriterOptions options_;
  int index_fd_ = -1;
  int frames_dir_fd_ = -1;
  std::uint64_t index_size_ = 0;  // bytes of whole lines in index.jsonl
  std::uint64_t next_set_index_ = 0;
  std::uint64_t bytes_written_ = 0;
  std::optional<std::string> alarm_;

  // Reused from set to set so that the steady state allocates nothing per frame.
  std::vector<PendingFile> pending_;
  std::vector<std::uint8_t> row_buffer_;
  IndexedSet entry_;
  std::string line_;
};

}  // namespace fieldrig::recording
