#include "fieldrig/recording/session_writer.h"

#include <dirent.h>
#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>

#include "file_util.h"

namespace fieldrig::recording {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::string nowIso() {
  return core::formatIso8601(
      std::chrono::time_point_cast<core::Nanoseconds>(std::chrono::system_clock::now()), 3);
}

std::string errnoText(int error) {
  return std::strerror(error);
}

WriteStatus statusOf(int error) {
  return error == ENOSPC || error == EDQUOT || error == EFBIG ? WriteStatus::kDiskFull
                                                              : WriteStatus::kIoError;
}

core::Result<Json> newSessionJson(const SessionInfo& info) {
  Json out;
  out["format"] = "fieldrig-session";
  out["format_version"] = kFormatVersion;
  out["software_version"] = softwareVersion();
  out["start_time"] =
      core::formatIso8601(std::chrono::time_point_cast<core::Nanoseconds>(info.start_time), 3);
  out["configuration"] = info.configuration;
  Json calibration = Json::array();
  for (const CalibrationReference& reference : info.calibration)
    calibration.push_back({{"name", reference.name}, {"path", reference.path}});
  out["calibration"] = std::move(calibration);
  if (info.map_file) {
    std::string error;
    const std::string sha = detail::sha256File(*info.map_file, error);
    if (sha.empty())
      return core::Error{"map checksum: " + error};
    out["map"] = {{"path", info.map_file->string()}, {"sha256", sha}};
  } else {
    out["map"] = nullptr;
  }
  out["reopened"] = Json::array();
  return out;
}

// The set number a frame file's name starts with (frameFileName: "000012_3_middle_right.pgm"), or
// none for a name without leading digits. At most 18 digits are read, so that it cannot overflow.
std::optional<std::uint64_t> setNumberOf(const std::string& name) {
  std::uint64_t number = 0;
  std::size_t digits = 0;
  while (digits < name.size() && digits < 18 && name[digits] >= '0' && name[digits] <= '9')
    number = number * 10 + static_cast<std::uint64_t>(name[digits++] - '0');
  if (digits == 0)
    return std::nullopt;
  return number;
}

// A frame file of a later set than the one in flight, or any frame file when there was no index
// at all, means the index does not hold every set captured (lost, or replaced by another): the
// reopening is refused naming it, since removing or overwriting those frames would lose them.
std::string framesBeyondTheIndex(const fs::path& frames_dir, std::uint64_t next_set_index,
                                 bool index_existed) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = entry.path().filename().string();
    const std::optional<std::uint64_t> number = setNumberOf(name);
    if (name.ends_with(".tmp") || !number)
      continue;
    if (!index_existed || *number > next_set_index) {
      return entry.path().string() + ": a frame of set " + std::to_string(*number) + ", but " +
             (index_existed ? "the index ends before set " + std::to_string(next_set_index)
                            : "there is no " + std::string(kIndexFile)) +
             ": the index does not hold every captured set (lost or replaced?); nothing is "
             "changed (restore the index, or record into another folder)";
    }
  }
  return {};
}

// Removes what a crashed run left in frames/: temporary files, and frame files of sets whose
// index line was never written (their numbers are reused now).
std::uint64_t removeLeftovers(const fs::path& frames_dir, std::uint64_t next_set_index) {
  std::uint64_t removed = 0;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = entry.path().filename().string();
    const std::optional<std::uint64_t> number = setNumberOf(name);
    const bool leftover = name.ends_with(".tmp") || (number && *number >= next_set_index);
    if (leftover && fs::remove(entry.path(), ec))
      ++removed;
  }
  return removed;
}

}  // namespace

std::string_view toString(WriteStatus status) {
  switch (status) {
    case WriteStatus::kOk:
      return "ok";
    case WriteStatus::kDiskFull:
      return "disk_full";
    case WriteStatus::kIoError:
      return "io_error";
    case WriteStatus::kStopped:
      return "stopped";
  }
  return "unknown";
}

SessionWriter::~SessionWriter() {
  close();
}

void SessionWriter::close() {
  discardPending(false);
  if (index_fd_ >= 0)
    ::close(index_fd_);
  if (frames_dir_fd_ >= 0)
    ::close(frames_dir_fd_);
  index_fd_ = -1;
  frames_dir_fd_ = -1;
}

core::Result<OpenReport> SessionWriter::open(const fs::path& dir, const SessionInfo& info,
                                             const WriterOptions& options) {
  close();
  alarm_.reset();
  dir_ = dir;
  frames_dir_ = dir / kFramesDir;
  options_ = options;
  bytes_written_ = 0;
  OpenReport report;

  std::error_code ec;
  fs::create_directories(frames_dir_, ec);
  if (ec)
    return core::Error{frames_dir_.string() + ": cannot create: " + ec.message()};

  const fs::path session_path = dir / kSessionFile;
  const fs::path index_path = dir / kIndexFile;
  std::string error;
  Json session;
  if (fs::exists(session_path, ec)) {
    report.reopened = true;
    const std::optional<std::string> text = detail::readWholeFile(session_path, error);
    if (!text)
      return core::Error{error};
    try {
      session = Json::parse(*text);
    } catch (const Json::parse_error& e) {
      return core::Error{session_path.string() + ":" + detail::lineOf(*text, e.byte) + ": " +
                         e.what()};
    }
    if (!session.is_object())
      return core::Error{session_path.string() + ":1: not a JSON object"};
    if (!session.contains("reopened") || !session["reopened"].is_array())
      session["reopened"] = Json::array();
    Json reopening = {{"time", nowIso()}, {"software_version", softwareVersion()}};
    // Sets from here on were triggered from this map: when it is not the one session.json names
    // (a map edited between starts, or another field's), the reopening records it and says so.
    if (info.map_file) {
      const std::string sha = detail::sha256File(*info.map_file, error);
      if (sha.empty())
        return core::Error{"map checksum: " + error};
      // The map in use so far: the last reopening's that recorded one, else the session's own.
      Json recorded = session.contains("map") ? session["map"] : Json();
      for (const Json& earlier : session["reopened"]) {
        if (earlier.is_object() && earlier.contains("map"))
          recorded = earlier["map"];
      }
      const bool same = recorded.is_object() && recorded.contains("sha256") &&
                        recorded["sha256"].is_string() &&
                        recorded["sha256"].get<std::string>() == sha;
      if (!same) {
        reopening["map"] = {{"path", info.map_file->string()}, {"sha256", sha}};
        report.map_changed = session_path.string() + " names the map " +
                             (recorded.is_object() ? recorded.dump() : std::string("null")) +
                             "; sets from now on are triggered from " + info.map_file->string() +
                             " (sha256 " + sha + ")";
      }
    }
    session["reopened"].push_back(std::move(reopening));
  } else {
    // An empty index is what a start that failed before session.json was written leaves.
    if (fs::exists(index_path, ec) && fs::file_size(index_path, ec) > 0)
      return core::Error{index_path.string() + ": an index without " + std::string(kSessionFile)};
    core::Result<Json> fresh = newSessionJson(info);
    if (!fresh)
      return fresh.error();
    session = std::move(fresh.value());
  }
  const bool index_existed = fs::exists(index_path, ec);
  index_fd_ = ::open(index_path.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (index_fd_ < 0)
    return core::Error{index_path.string() + ": cannot open: " + errnoText(errno)};
  // One writer at a time: two daemons on one folder interleaved their sets in the index and
  // overwrote each other's frames. The lock goes with the descriptor (close, or a crash).
  if (::flock(index_fd_, LOCK_EX | LOCK_NB) != 0) {
    const int lock_error = errno;
    close();
    if (!index_existed)
      fs::remove(index_path, ec);
    return core::Error{index_path.string() + ": " +
                       (lock_error == EWOULDBLOCK
                            ? std::string("in use by another writer (a second fieldrigd or "
                                          "fieldrig acquire on this recording folder?)")
                            : "cannot lock: " + errnoText(lock_error))};
  }
  const std::optional<std::string> content = detail::readWholeFile(index_path, error);
  if (!content) {
    close();
    return core::Error{error};
  }
  core::Result<detail::IndexScan> scan = detail::scanIndex(*content, index_path);
  if (!scan) {
    close();
    return scan.error();
  }
  index_size_ = scan->whole_bytes;
  next_set_index_ = scan->sets.empty() ? 0 : scan->sets.back().set_index + 1;
  if (scan->torn_line) {
    // Cut before appending: a new line glued to half an old one would corrupt both.
    report.torn_line = scan->torn_line;
    if (::ftruncate(index_fd_, static_cast<off_t>(index_size_)) != 0 || ::fsync(index_fd_) != 0) {
      const int truncate_error = errno;
      close();
      return core::Error{index_path.string() +
                         ": cannot cut the torn last line: " + errnoText(truncate_error)};
    }
    spdlog::warn("{}:{}: torn last line ({} bytes) cut away", index_path.string(),
                 report.torn_line->line, report.torn_line->bytes);
  }
  if (std::string beyond = framesBeyondTheIndex(frames_dir_, next_set_index_, index_existed);
      !beyond.empty()) {
    close();
    if (!index_existed)
      fs::remove(index_path, ec);
    return core::Error{std::move(beyond)};
  }
  // Only once the index is known to be usable, so that a refused reopening changes nothing.
  if (std::string failure = detail::replaceFileAtomically(session_path, session.dump(2) + "\n");
      !failure.empty()) {
    close();
    return core::Error{failure};
  }
  report.next_set_index = next_set_index_;
  report.leftovers_removed = removeLeftovers(frames_dir_, next_set_index_);

  frames_dir_fd_ = ::open(frames_dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (frames_dir_fd_ < 0) {
    const int open_error = errno;
    close();
    return core::Error{frames_dir_.string() + ": cannot open: " + errnoText(open_error)};
  }
  // The names session.json, index.jsonl and frames/ themselves must survive a power loss too.
  if (const int sync_error = detail::syncDirectory(dir); sync_error != 0) {
    close();
    return core::Error{dir.string() + ": cannot sync: " + errnoText(sync_error)};
  }
  return report;
}

void SessionWriter::discardPending(bool renamed) {
  for (PendingFile& file : pending_) {
    if (file.fd >= 0)
      ::close(file.fd);
    file.fd = -1;
    ::unlink(file.temp_path.c_str());
    if (renamed)
      ::unlink(file.final_path.c_str());
  }
  pending_.clear();
}

WriteOutcome SessionWriter::fail(WriteStatus status, std::string message) {
  spdlog::error("recording stopped ({}): {}", toString(status), message);
  alarm_ = message;
  return {status, 0, std::move(message)};
}

bool SessionWriter::writeFrame(std::uint64_t set_index, const FrameView& frame, IndexedFrame& entry,
                               PendingFile& pending, int& error, std::string& failed_path) {
  entry.file = frameFileName(set_index, frame.camera_index, frame.camera_name);
  pending.final_path = dir_ / entry.file;
  pending.temp_path = pending.final_path;
  pending.temp_path += ".tmp";

  const auto width = static_cast<std::size_t>(frame.width);
  const auto height = static_cast<std::size_t>(frame.height);
  const std::size_t stride = frame.stride > 0 ? static_cast<std::size_t>(frame.stride) : width;
  std::span<const std::uint8_t> pixels = frame.pixels.first(width * height);
  if (stride != width) {
    // Padded rows are packed once here, into a buffer kept from frame to frame.
    row_buffer_.resize(width * height);
    for (std::size_t row = 0; row < height; ++row) {
      std::memcpy(row_buffer_.data() + row * width, frame.pixels.data() + row * stride, width);
    }
    pixels = row_buffer_;
  }
  const std::string header = detail::pgmHeader(frame.width, frame.height);
  entry.crc32 = detail::crc32(pixels);
  entry.file_bytes = header.size() + pixels.size();

  failed_path = pending.temp_path.string();
  pending.fd = ::open(pending.temp_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (pending.fd < 0) {
    error = errno;
    return false;
  }
  error = detail::writeFully(pending.fd, header.data(), header.size());
  if (error == 0)
    error = detail::writeFully(pending.fd, pixels.data(), pixels.size());
  if (error == 0 && options_.fsync == FsyncPolicy::kPerFrame && ::fdatasync(pending.fd) != 0)
    error = errno;
  if (error != 0)
    return false;
  bytes_written_ += entry.file_bytes;
  if (options_.fsync == FsyncPolicy::kPerSet)
    return true;  // synced and renamed with the rest of the set
  if (::close(pending.fd) != 0) {
    pending.fd = -1;
    error = errno;
    return false;
  }
  pending.fd = -1;
  failed_path = pending.final_path.string();
  if (::rename(pending.temp_path.c_str(), pending.final_path.c_str()) != 0) {
    error = errno;
    return false;
  }
  if (options_.fsync == FsyncPolicy::kPerFrame && ::fsync(frames_dir_fd_) != 0) {
    error = errno;
    failed_path = frames_dir_.string();
    return false;
  }
  return true;
}

WriteOutcome SessionWriter::write(const FrameSetRecord& record) {
  if (!isOpen())
    return {WriteStatus::kStopped, 0, "the session writer is not open"};
  if (alarm_)
    return {WriteStatus::kStopped, 0, "recording stopped earlier: " + *alarm_};

  const std::uint64_t set_index = next_set_index_;
  entry_.set_index = set_index;
  entry_.trigger_id = record.trigger_id;
  entry_.location_id = record.location_id;
  entry_.fix = record.fix;
  entry_.trigger_time = record.trigger_time;
  entry_.planned_time = record.planned_time;
  entry_.sent_time = record.sent_time;
  entry_.trigger_status = record.trigger_status;
  entry_.complete = record.complete;
  entry_.skew_us = record.skew_us;
  entry_.frames.resize(record.frames.size());
  pending_.clear();

  for (std::size_t k = 0; k < record.frames.size(); ++k) {
    const FrameView& frame = record.frames[k];
    IndexedFrame& entry = entry_.frames[k];
    entry = IndexedFrame{};
    entry.camera_index = frame.camera_index;
    entry.camera_name = frame.camera_name;
    entry.width = frame.width;
    entry.height = frame.height;
    entry.pixel_format = frame.pixel_format;
    entry.sequence = frame.sequence;
    entry.device_timestamp_ns = frame.device_timestamp_ns;
    entry.host_steady_ns = frame.received.steady.time_since_epoch().count();
    entry.host_system_ns =
        std::chrono::duration_cast<core::Nanoseconds>(frame.received.system.time_since_epoch())
            .count();
    entry.status = frame.status;
    entry.reason = frame.reason;
    if (frame.status == FrameStatus::kMissing || frame.status == FrameStatus::kDropped)
      continue;

    const std::size_t stride = frame.stride > 0 ? static_cast<std::size_t>(frame.stride)
                                                : static_cast<std::size_t>(frame.width);
    const bool sized =
        frame.width > 0 && frame.height > 0 && stride >= static_cast<std::size_t>(frame.width) &&
        frame.pixels.size() >= (static_cast<std::size_t>(frame.height) - 1) * stride +
                                   static_cast<std::size_t>(frame.width);
    if (!sized) {
      // Failure is data: the set is recorded, this frame marked, instead of losing the set.
      entry.status = FrameStatus::kCorrupt;
      entry.reason = "pixel buffer of " + std::to_string(frame.pixels.size()) +
                     " bytes does not hold " + std::to_string(frame.width) + "x" +
                     std::to_string(frame.height) + " with stride " + std::to_string(stride) +
                     (frame.reason.empty() ? "" : "; " + frame.reason);
      continue;
    }
    pending_.emplace_back();
    int error = 0;
    std::string failed_path;
    if (!writeFrame(set_index, frame, entry, pending_.back(), error, failed_path)) {
      discardPending(true);
      return fail(statusOf(error), failed_path + ": " + errnoText(error));
    }
  }

  if (options_.fsync == FsyncPolicy::kPerSet) {
    // Data first, then the names: a renamed file must never point at unwritten blocks.
    for (PendingFile& file : pending_) {
      const bool synced = ::fdatasync(file.fd) == 0;
      const int error = synced ? 0 : errno;
      const bool closed = ::close(file.fd) == 0;
      file.fd = -1;
      if (!synced || !closed) {
        discardPending(true);
        return fail(statusOf(error != 0 ? error : EIO),
                    file.temp_path.string() + ": " + errnoText(error != 0 ? error : EIO));
      }
    }
    for (PendingFile& file : pending_) {
      if (::rename(file.temp_path.c_str(), file.final_path.c_str()) != 0) {
        const int error = errno;
        discardPending(true);
        return fail(statusOf(error), file.final_path.string() + ": " + errnoText(error));
      }
    }
    if (!pending_.empty() && ::fsync(frames_dir_fd_) != 0) {
      const int error = errno;
      discardPending(true);
      return fail(statusOf(error), frames_dir_.string() + ": " + errnoText(error));
    }
  }

  // The commit point: the set exists once its whole line, newline included, is in the index.
  line_ = toIndexLine(entry_);
  line_ += '\n';
  const fs::path index_path = dir_ / kIndexFile;
  if (const int error = detail::writeFully(index_fd_, line_.data(), line_.size()); error != 0) {
    // A partial line would be taken for a torn one by a reader; cut it now and drop the frames
    // so that the folder holds exactly the indexed sets.
    const bool cut = ::ftruncate(index_fd_, static_cast<off_t>(index_size_)) == 0;
    discardPending(true);
    return fail(statusOf(error), index_path.string() + ": " + errnoText(error) +
                                     (cut ? "" : " (and the partial line could not be cut)"));
  }
  pending_.clear();
  index_size_ += line_.size();
  bytes_written_ += line_.size();
  ++next_set_index_;
  if (options_.fsync != FsyncPolicy::kNone && ::fdatasync(index_fd_) != 0) {
    // The line is written (a crash of the process keeps it) but may not survive a power loss.
    const int error = errno;
    WriteOutcome outcome = fail(statusOf(error), index_path.string() + ": " + errnoText(error));
    outcome.set_index = set_index;
    return outcome;
  }
  return {WriteStatus::kOk, set_index, {}};
}

}  // namespace fieldrig::recording
