// `fieldrig map generate` (locations from a field plan) and `fieldrig map record` (the operator
// drives the field once and marks each imaging location).
//
// Threading of `map record`: everything runs on the one thread that runs the io_context. The
// NMEA input (serial port, FIFO, or a regular file paced by a timer), stdin (Enter marks), and
// the signals (SIGUSR1 marks, SIGINT/SIGTERM stop) are all asynchronous operations on that
// io_context, so their handlers never run concurrently and the recorder's state (latest fixes,
// the map, the output file) needs no lock.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "commands/commands.h"
#include "commands/field_plan_options.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/local_frame.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/nmea_parser.h"
#include "fieldrig/gps/serial_nmea_source.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;
namespace asio = boost::asio;

// ---------------------------------------------------------------------------------------------
// map generate

struct GenerateOptions {
  FieldPlanArgs field;
  std::string out;
};

int runGenerate(const GenerateOptions& options) {
  const auto plan = resolveFieldPlan(options.field);
  if (!plan) {
    std::cerr << "fieldrig map generate: " << plan.error().message << '\n';
    return kExitBadInput;
  }
  auto map = gps::generateLocations(*plan);
  if (!map) {
    std::cerr << "fieldrig map generate: " << map.error().message << '\n';
    return kExitBadInput;
  }
  auto saved = map->save(options.out);
  if (!saved) {
    std::cerr << "fieldrig map generate: " << saved.error().message << '\n';
    return kExitRuntime;
  }
  Json summary;
  summary["out"] = options.out;
  summary["locations"] = map->size();
  summary["rows"] = plan->rows;
  summary["plots_per_row"] = map->size() / static_cast<std::size_t>(plan->rows);
  std::cout << summary.dump() << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------------------------------------
// map record

struct RecordOptions {
  std::string nmea;
  std::string out;
  unsigned baud = 115200;
  std::string id_prefix = "P";
  long start_id = 1;
  bool start_id_given = false;
  bool realtime = true;
};

// A mark needs a fix received this recently; older means the receiver or the link stalled and
// the position no longer says where the tractor is.
constexpr std::chrono::seconds kMaxFixAge{2};
// Below this ground speed the receiver's course over ground is not a direction of travel.
constexpr double kMinCourseSpeedMps = 0.3;  // as the trigger planner's minimum speed
// Fixes kept for the heading fallback (bearing from an earlier fix).
constexpr std::chrono::seconds kFixHistory{10};
// Without an RMC course, the heading is the bearing from the latest earlier fix at least this
// far away: over one 10 Hz step (20 cm at 2 m/s) 1-2 cm of RTK noise would swing it by degrees.
constexpr double kMinBearingBaseM = 1.0;
// A regular file is paced by its GPS times, but a gap in the log (receiver off for lunch) is
// shortened to this so a replay never sits idle.
constexpr std::chrono::seconds kMaxReplayGap{5};

const std::vector<std::string>& recordMetadataColumns() {
  static const std::vector<std::string> columns = {"time", "speed_mps", "quality"};
  return columns;
}

// The output map: appended to (and flushed to disk) one line per mark.
class MapFile {
 public:
  ~MapFile() {
    if (fd_ >= 0)
      ::close(fd_);
  }

  // Opens `path` for appending; an existing non-empty file must be a recording map (same
  // header), whose locations are loaded into `map`. Returns an error message on failure.
  std::optional<std::string> open(const std::string& path, gps::LocationMap& map) {
    path_ = path;
    std::error_code error;
    const bool exists = std::filesystem::exists(path, error);
    const bool has_content = exists && std::filesystem::file_size(path, error) > 0;
    bool needs_newline = false;
    if (has_content) {
      auto existing = gps::LocationMap::load(path);
      if (!existing)
        return existing.error().message;
      const std::string expected = map.csvHeader().substr(0, map.csvHeader().size() - 1);
      std::ifstream in(path, std::ios::binary);
      const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      const std::string header = firstRecordLine(text);
      if (header != expected || existing->metadataColumns() != map.metadataColumns()) {
        return path + ": its header '" + header + "' is not the recording header '" + expected +
               "'; give another --out";
      }
      for (const gps::ImagingLocation& location : existing->locations()) {
        auto added = map.add(location);
        if (!added)
          return path + ": " + added.error().message;
      }
      // A run killed mid-line cannot leave a partial last line (lines are written whole), but a
      // hand-edited file may lack the final newline.
      needs_newline = !text.empty() && text.back() != '\n';
    }
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0)
      return path + ": cannot open for writing: " + std::strerror(errno);
    if (needs_newline) {
      if (auto bad = append("\n"))
        return bad;
    }
    if (!has_content) {
      if (auto bad = append(map.csvHeader()))
        return bad;
    }
    return std::nullopt;
  }

  // Writes `text` and forces it to disk: a mark must survive the tractor's power being cut.
  std::optional<std::string> append(std::string_view text) {
    while (!text.empty()) {
      const ssize_t written = ::write(fd_, text.data(), text.size());
      if (written < 0) {
        if (errno == EINTR)
          continue;
        return path_ + ": write failed: " + std::strerror(errno);
      }
      text.remove_prefix(static_cast<std::size_t>(written));
    }
    if (::fdatasync(fd_) != 0 && errno != EINVAL) {
      return path_ + ": sync failed: " + std::strerror(errno);
    }
    return std::nullopt;
  }

 private:
  static std::string firstRecordLine(const std::string& text) {
    std::size_t pos = 0;
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
      pos = 3;
    while (pos < text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string::npos)
        end = text.size();
      std::string line = text.substr(pos, end - pos);
      while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
        line.pop_back();
      const std::size_t first = line.find_first_not_of(" \t");
      if (first != std::string::npos && line[first] != '#')
        return line;
      pos = end + 1;
    }
    return {};
  }

  std::string path_;
  int fd_ = -1;
};

// Turns fixes into marks. Owned by the io thread.
class MapRecorder {
 public:
  MapRecorder(const RecordOptions& options, std::chrono::sys_days fallback_date)
      : options_(options),
        map_(recordMetadataColumns()),
        assembler_(fallback_date),
        parser_([this](const gps::Sentence& sentence) { onSentence(sentence, stamp_); }) {}

  std::optional<std::string> open() {
    if (auto bad = file_.open(options_.out, map_))
      return bad;
    existing_ = map_.size();
    next_number_ = options_.start_id_given ? options_.start_id : highestNumber() + 1;
    return std::nullopt;
  }

  std::size_t existing() const { return existing_; }
  std::size_t marks() const { return map_.size() - existing_; }
  bool failed() const { return failed_; }

  // Raw bytes (file or FIFO), received at `stamp`.
  void feed(std::string_view bytes, const core::ReceptionStamp& stamp) {
    stamp_ = stamp;
    parser_.feed(bytes);
  }
  void flush() { parser_.flush(); }

  void onSentence(const gps::Sentence& sentence, const core::ReceptionStamp& stamp) {
    const std::optional<core::GpsFix> fix = assembler_.add(sentence, stamp);
    if (!fix)
      return;
    // The assembler refines an epoch sentence by sentence: replace, don't append.
    if (!recent_.empty() && recent_.back().time == fix->time)
      recent_.pop_back();
    if (fix->valid)
      recent_.push_back(*fix);
    while (!recent_.empty() && stamp.steady - recent_.front().received.steady > kFixHistory) {
      recent_.pop_front();
    }
  }

  // Marks the current position; `trigger` says what asked ("enter", "sigusr1").
  void mark(std::string_view trigger) {
    const auto now = std::chrono::steady_clock::now();
    if (recent_.empty()) {
      std::cerr << "fieldrig map record: mark (" << trigger
                << ") refused: no valid fix yet; nothing written\n";
      return;
    }
    const core::GpsFix& fix = recent_.back();
    const auto age = now - fix.received.steady;
    if (age > kMaxFixAge) {
      std::cerr << "fieldrig map record: mark (" << trigger << ") refused: the latest valid fix is "
                << core::toSeconds(age) << " s old; nothing written\n";
      return;
    }

    gps::ImagingLocation location;
    while (map_.find(options_.id_prefix + std::to_string(next_number_)) != nullptr)
      ++next_number_;
    location.id = options_.id_prefix + std::to_string(next_number_++);
    location.latitude_deg = fix.latitude_deg;
    location.longitude_deg = fix.longitude_deg;
    std::string heading_source = "none";
    // At a standstill (operators stop on the spot to mark it) receivers report course 0 or a
    // stale value: a course counts only while moving.
    if (fix.course_deg && *fix.course_deg >= 0 && *fix.course_deg < 360 && fix.speed_mps &&
        *fix.speed_mps >= kMinCourseSpeedMps) {
      location.heading_deg = fix.course_deg;
      heading_source = "course";
    } else if (auto bearing = trackBearing()) {
      location.heading_deg = bearing;
      heading_source = "track";
    } else {
      std::cerr << "fieldrig map record: " << location.id
                << ": no course and no earlier fix 1 m away; written without heading\n";
    }
    char speed[32] = "";
    if (fix.speed_mps)
      std::snprintf(speed, sizeof speed, "%.3f", *fix.speed_mps);
    location.metadata = {core::formatIso8601(fix.time, 3), speed,
                         fix.quality ? std::to_string(static_cast<int>(*fix.quality)) : ""};

    const std::string line = map_.csvLine(location);
    auto added = map_.add(location);
    if (!added) {
      std::cerr << "fieldrig map record: mark refused: " << added.error().message << '\n';
      return;
    }
    if (auto bad = file_.append(line)) {
      std::cerr << "fieldrig map record: " << *bad << '\n';
      failed_ = true;
      return;
    }

    Json out;
    out["id"] = location.id;
    out["lat"] = location.latitude_deg;
    out["lon"] = location.longitude_deg;
    out["heading_deg"] = location.heading_deg ? Json(*location.heading_deg) : Json(nullptr);
    out["heading_source"] = heading_source;
    out["time"] = location.metadata[0];
    out["speed_mps"] = fix.speed_mps ? Json(*fix.speed_mps) : Json(nullptr);
    out["quality"] = fix.quality ? Json(static_cast<int>(*fix.quality)) : Json(nullptr);
    out["fix_age_s"] = core::toSeconds(age);
    out["trigger"] = trigger;
    std::cout << out.dump() << std::endl;  // one line at once: a reader may be waiting on it
  }

 private:
  long highestNumber() const {
    long highest = 0;
    for (const gps::ImagingLocation& location : map_.locations()) {
      const std::string& id = location.id;
      if (id.size() <= options_.id_prefix.size() ||
          id.compare(0, options_.id_prefix.size(), options_.id_prefix) != 0) {
        continue;
      }
      long number = 0;
      const char* begin = id.data() + options_.id_prefix.size();
      const auto [ptr, ec] = std::from_chars(begin, id.data() + id.size(), number);
      if (ec == std::errc() && ptr == id.data() + id.size())
        highest = std::max(highest, number);
    }
    return highest;
  }

  std::optional<double> trackBearing() const {
    const core::GpsFix& latest = recent_.back();
    const gps::LocalFrame frame(latest.latitude_deg, latest.longitude_deg);
    for (auto it = recent_.rbegin() + 1; it != recent_.rend(); ++it) {
      const gps::EnuPoint earlier = frame.toLocal(it->latitude_deg, it->longitude_deg);
      // The vector from the earlier fix to the latest one (at the local frame's origin).
      if (std::hypot(earlier.east_m, earlier.north_m) >= kMinBearingBaseM) {
        return gps::bearingDegrees(-earlier.east_m, -earlier.north_m);
      }
    }
    return std::nullopt;
  }

  RecordOptions options_;
  gps::LocationMap map_;
  MapFile file_;
  gps::FixAssembler assembler_;
  gps::NmeaParser parser_;
  core::ReceptionStamp stamp_{};
  std::deque<core::GpsFix> recent_;  // valid fixes of the last kFixHistory, oldest first
  std::size_t existing_ = 0;
  long next_number_ = 1;
  bool failed_ = false;
};

// Replays a regular file: at its GPS times (realtime) or as fast as the io loop allows.
class FileReplay {
 public:
  FileReplay(asio::io_context& io, std::ifstream in, bool realtime, MapRecorder& recorder,
             std::function<void()> on_end)
      : io_(io),
        in_(std::move(in)),
        realtime_(realtime),
        recorder_(recorder),
        on_end_(std::move(on_end)),
        timer_(io) {}

  void start() {
    deadline_ = std::chrono::steady_clock::now();
    asio::post(io_, [this] { pump(); });
  }

 private:
  void pump() {
    if (!realtime_) {
      // A chunk per turn of the loop, so that marks and signals are still served in between.
      std::array<char, 65536> chunk{};
      in_.read(chunk.data(), chunk.size());
      const auto count = static_cast<std::size_t>(in_.gcount());
      if (count == 0)
        return end();
      recorder_.feed(std::string_view(chunk.data(), count), core::ReceptionStamp::now());
      asio::post(io_, [this] { pump(); });
      return;
    }
    while (true) {
      if (!pending_) {
        std::string line;
        if (!std::getline(in_, line))
          return end();
        pending_ = std::move(line);
        pending_time_ = timeOf(*pending_);
      }
      if (pending_time_) {
        if (!last_time_ || *pending_time_ < *last_time_) {
          // The first timed line, or time going back (a new log appended): no wait.
          last_time_ = pending_time_;
        } else if (*pending_time_ > *last_time_) {
          deadline_ += std::min<std::chrono::steady_clock::duration>(*pending_time_ - *last_time_,
                                                                     kMaxReplayGap);
          last_time_ = pending_time_;
          timer_.expires_at(deadline_);
          timer_.async_wait([this](const boost::system::error_code& error) {
            if (!error)
              pump();
          });
          return;
        }
      }
      *pending_ += '\n';
      recorder_.feed(*pending_, core::ReceptionStamp::now());
      pending_.reset();
    }
  }

  // The GPS time of a line, from a private parser and assembler (the recorder's see the bytes
  // only when they are due).
  std::optional<core::UtcTime> timeOf(std::string_view line) {
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    const gps::Sentence sentence = gps::NmeaParser::parseLine(line);
    const auto fix = scan_assembler_.add(sentence, core::ReceptionStamp{});
    if (!fix)
      return std::nullopt;
    return fix->time;
  }

  void end() {
    recorder_.flush();
    on_end_();
  }

  asio::io_context& io_;
  std::ifstream in_;
  bool realtime_;
  MapRecorder& recorder_;
  std::function<void()> on_end_;
  asio::steady_timer timer_;
  gps::FixAssembler scan_assembler_;
  std::optional<std::string> pending_;  // the next line, read but not yet due
  std::optional<core::UtcTime> pending_time_;
  std::optional<core::UtcTime> last_time_;
  std::chrono::steady_clock::time_point deadline_{};
};

// Reads a FIFO (or anything else that can be polled) as it arrives.
class StreamReplay {
 public:
  StreamReplay(asio::io_context& io, int fd, MapRecorder& recorder, std::function<void()> on_end)
      : stream_(io, fd), recorder_(recorder), on_end_(std::move(on_end)) {}

  void start() {
    stream_.async_read_some(
        asio::buffer(buffer_), [this](const boost::system::error_code& error, std::size_t bytes) {
          if (bytes > 0) {
            recorder_.feed(std::string_view(buffer_.data(), bytes), core::ReceptionStamp::now());
          }
          if (error) {
            recorder_.flush();
            on_end_();
            return;
          }
          start();
        });
  }

 private:
  asio::posix::stream_descriptor stream_;
  MapRecorder& recorder_;
  std::function<void()> on_end_;
  std::array<char, 4096> buffer_{};
};

// Enter on stdin: one mark per line.
class StdinMarks {
 public:
  StdinMarks(asio::io_context& io, MapRecorder& recorder)
      : flags_(::fcntl(STDIN_FILENO, F_GETFL)), stdin_(io), recorder_(recorder) {
    boost::system::error_code error;
    stdin_.assign(STDIN_FILENO, error);
    if (error) {
      std::cerr << "fieldrig map record: stdin cannot be read (" << error.message()
                << "); mark with SIGUSR1\n";
    }
  }

  ~StdinMarks() {
    // stdin is not ours to close, and Asio made it non-blocking: a shell sharing the terminal
    // would otherwise inherit that.
    if (stdin_.is_open())
      stdin_.release();
    if (flags_ >= 0)
      ::fcntl(STDIN_FILENO, F_SETFL, flags_);
  }

  void start() {
    if (!stdin_.is_open())
      return;
    stdin_.async_read_some(asio::buffer(buffer_),
                           [this](const boost::system::error_code& error, std::size_t bytes) {
                             for (std::size_t i = 0; i < bytes; ++i) {
                               if (buffer_[i] == '\n')
                                 recorder_.mark("enter");
                             }
                             // At end of stdin (closed pipe, /dev/null) SIGUSR1 still marks.
                             if (!error)
                               start();
                           });
  }

 private:
  int flags_;
  asio::posix::stream_descriptor stdin_;
  MapRecorder& recorder_;
  std::array<char, 256> buffer_{};
};

int runRecord(const RecordOptions& options) {
  const char* kName = "fieldrig map record: ";
  std::error_code fs_error;
  const auto status = std::filesystem::status(options.nmea, fs_error);
  const auto type = status.type();
  if (fs_error ||
      (type != std::filesystem::file_type::character &&
       type != std::filesystem::file_type::regular && type != std::filesystem::file_type::fifo)) {
    std::cerr << kName << "--nmea " << options.nmea << ": not a serial device, FIFO or file"
              << (fs_error ? " (" + fs_error.message() + ")" : std::string()) << '\n';
    return kExitBadInput;
  }
  const bool live = type != std::filesystem::file_type::regular;
  // GGA alone carries no date; live, today's date is the right guess until an RMC says.
  const auto today = std::chrono::floor<std::chrono::days>(std::chrono::system_clock::now());
  MapRecorder recorder(options, live ? today : std::chrono::sys_days{});
  if (auto bad = recorder.open()) {
    std::cerr << kName << *bad << '\n';
    return kExitBadInput;
  }

  asio::io_context io;
  auto stop = [&io] { io.stop(); };

  std::unique_ptr<gps::SerialNmeaSource> serial;
  std::unique_ptr<FileReplay> file;
  std::unique_ptr<StreamReplay> stream;
  std::string input_kind;
  // Signals first: a mark sent while a FIFO open still waits for its writer must not kill us.
  asio::signal_set signals(io, SIGUSR1, SIGINT, SIGTERM);
  std::function<void(const boost::system::error_code&, int)> on_signal =
      [&](const boost::system::error_code& error, int number) {
        if (error)
          return;
        if (number == SIGUSR1) {
          recorder.mark("sigusr1");
          signals.async_wait(on_signal);
        } else {
          stop();
        }
      };
  signals.async_wait(on_signal);
  if (type == std::filesystem::file_type::character) {
    input_kind = "serial device";
    gps::SerialOptions serial_options;
    serial_options.device = options.nmea;
    serial_options.baud = options.baud;
    try {
      serial = std::make_unique<gps::SerialNmeaSource>(
          io, serial_options,
          [&recorder](const gps::Sentence& sentence, const core::ReceptionStamp& stamp) {
            recorder.onSentence(sentence, stamp);
          },
          [kName](const gps::SerialStatus& s) {
            if (s.event == gps::SerialEvent::kOpened) {
              std::cerr << kName << s.device << " open\n";
            } else {
              std::cerr << kName << s.device << ": " << s.message << "; retrying in "
                        << s.retry_in.count() << " ms\n";
            }
          });
    } catch (const std::invalid_argument& error) {
      std::cerr << kName << error.what() << '\n';
      return kExitBadInput;
    }
  } else if (type == std::filesystem::file_type::fifo) {
    input_kind = "FIFO";
    // Blocks until a writer opens the FIFO, which is what a reader of a FIFO wants.
    const int fd = ::open(options.nmea.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
      std::cerr << kName << options.nmea << ": cannot open: " << std::strerror(errno) << '\n';
      return kExitBadInput;
    }
    stream = std::make_unique<StreamReplay>(io, fd, recorder, stop);
  } else {
    input_kind = options.realtime ? "file, paced by its GPS times" : "file, as fast as possible";
    std::ifstream in(options.nmea, std::ios::binary);
    if (!in) {
      std::cerr << kName << options.nmea << ": cannot open: " << std::strerror(errno) << '\n';
      return kExitBadInput;
    }
    file = std::make_unique<FileReplay>(io, std::move(in), options.realtime, recorder, stop);
  }

  StdinMarks marks(io, recorder);
  marks.start();

  std::cerr << kName << "reading " << options.nmea << " (" << input_kind << "), appending to "
            << options.out << " (" << recorder.existing() << " locations already there); mark "
            << "with Enter or kill -USR1 " << ::getpid() << ", stop with Ctrl-C" << std::endl;
  if (serial)
    serial->start();
  if (file)
    file->start();
  if (stream)
    stream->start();
  // Stop after a failed write too: marks that cannot be kept must not look accepted.
  while (!io.stopped()) {
    io.run_one();
    if (recorder.failed())
      io.stop();
  }
  if (serial)
    serial->stop();

  std::cerr << kName << recorder.marks() << " marks written to " << options.out << '\n';
  return recorder.failed() ? kExitRuntime : kExitOk;
}

}  // namespace

void registerMapCommand(CLI::App& app, int& exit_code) {
  CLI::App* map = app.add_subcommand("map", "Imaging-location maps");
  map->require_subcommand(1);

  CLI::App* generate =
      map->add_subcommand("generate", "Write a map of plot centres from a field plan");
  auto g = std::make_shared<GenerateOptions>();
  addFieldPlanOptions(*generate, g->field);
  generate->add_option("--out", g->out, "Map file to write")->required();
  generate->callback([g, &exit_code] { exit_code = runGenerate(*g); });

  CLI::App* record = map->add_subcommand(
      "record", "Drive the field and mark imaging locations with Enter or SIGUSR1");
  auto r = std::make_shared<RecordOptions>();
  record->add_option("--nmea", r->nmea, "Serial device, FIFO or NMEA file")->required();
  record->add_option("--out", r->out, "Map file to write or continue")->required();
  record->add_option("--baud", r->baud, "Serial baud rate")->capture_default_str();
  record->add_option("--id-prefix", r->id_prefix, "Prefix of the ids <prefix><number>")
      ->capture_default_str();
  CLI::Option* start_id = record->add_option(
      "--start-id", r->start_id,
      "First id number (default: one past the highest in the existing map, or 1); "
      "numbers already used are skipped");
  record->add_flag("--realtime,!--no-realtime", r->realtime,
                   "Replay a file at the pace of its GPS times (default) or as fast as possible");
  record->callback([r, start_id, &exit_code] {
    r->start_id_given = start_id->count() > 0;
    exit_code = runRecord(*r);
  });
}

}  // namespace fieldrig::tools
