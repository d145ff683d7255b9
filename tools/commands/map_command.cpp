// `fieldrig map generate` (locations from a field plan) and `fieldrig map record` (the operator
// drives the field once and marks each imaging location): arguments and output. The recorder's
// rules are gps::MapRecorder's, the file is played by sim::NmeaPlayer.
#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/signal_set.hpp>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "commands/command_helpers.h"
#include "commands/field_plan_options.h"
#include "fieldrig/core/durable_file.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/map_recorder.h"
#include "fieldrig/gps/serial_nmea_source.h"
#include "fieldrig/sim/nmea_player.h"

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
  if (!plan)
    return fail("fieldrig map generate: ", plan.error().message);
  auto map = gps::generateLocations(*plan);
  if (!map)
    return fail("fieldrig map generate: ", map.error().message);
  auto saved = map->save(options.out);
  if (!saved)
    return fail("fieldrig map generate: ", saved.error().message);
  Json summary;
  summary["out"] = options.out;
  summary["locations"] = map->size();
  summary["rows"] = plan->rows;
  summary["plots_per_row"] = map->size() / static_cast<std::size_t>(plan->rows);
  return printJsonLine(summary);
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

// A file is paced by its GPS times, but a gap in the log (receiver off for lunch) is shortened
// to this so a replay never sits idle.
constexpr std::chrono::seconds kMaxReplayGap{5};

Json markJson(const gps::RecordedLocation& recorded, std::string_view trigger) {
  const gps::ImagingLocation& location = recorded.location;
  const core::GpsFix& fix = recorded.fix;
  Json out;
  out["id"] = location.id;
  out["lat"] = location.latitude_deg;
  out["lon"] = location.longitude_deg;
  out["heading_deg"] = location.heading_deg ? Json(*location.heading_deg) : Json(nullptr);
  out["heading_source"] = gps::toString(recorded.heading_source);
  out["time"] = location.metadata[0];
  out["speed_mps"] = fix.speed_mps ? Json(*fix.speed_mps) : Json(nullptr);
  out["quality"] = fix.quality ? Json(static_cast<int>(*fix.quality)) : Json(nullptr);
  out["fix_age_s"] = core::toSeconds(recorded.fix_age);
  out["trigger"] = trigger;
  return out;
}

// Enter on stdin: one mark per line.
class StdinMarks {
 public:
  StdinMarks(asio::io_context& io, std::function<void()> on_enter)
      : flags_(::fcntl(STDIN_FILENO, F_GETFL)), stdin_(io), on_enter_(std::move(on_enter)) {
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
                                 on_enter_();
                             }
                             // At end of stdin (closed pipe, /dev/null) SIGUSR1 still marks.
                             if (!error)
                               start();
                           });
  }

 private:
  int flags_;
  asio::posix::stream_descriptor stdin_;
  std::function<void()> on_enter_;
  std::array<char, 256> buffer_{};
};

// Everything runs on the one thread that runs the io_context: the NMEA input (serial port, or a
// file or FIFO played by sim::NmeaPlayer), stdin (Enter marks) and the signals (SIGUSR1 marks,
// SIGINT/SIGTERM stop) are asynchronous operations on it, so the recorder needs no lock.
int runRecord(const RecordOptions& options) {
  const char* kName = "fieldrig map record: ";
  std::error_code fs_error;
  const auto type = std::filesystem::status(options.nmea, fs_error).type();
  if (fs_error ||
      (type != std::filesystem::file_type::character &&
       type != std::filesystem::file_type::regular && type != std::filesystem::file_type::fifo)) {
    std::cerr << kName << "--nmea " << options.nmea << ": not a serial device, FIFO or file"
              << (fs_error ? " (" + fs_error.message() + ")" : std::string()) << '\n';
    return kExitBadInput;
  }
  const bool live = type != std::filesystem::file_type::regular;
  auto existing = gps::openRecordingMap(options.out);
  if (!existing)
    return fail(kName, existing.error().message);
  const std::size_t already_there = existing->size();
  gps::MapRecorderOptions recorder_options;
  recorder_options.id_prefix = options.id_prefix;
  if (options.start_id_given)
    recorder_options.start_id = options.start_id;
  // GGA alone carries no date; live, today's date is the right guess until an RMC says.
  const auto today = std::chrono::floor<std::chrono::days>(std::chrono::system_clock::now());
  gps::MapRecorder recorder(std::move(*existing), recorder_options,
                            live ? today : std::chrono::sys_days{});

  bool failed = false;
  // `trigger` says what asked for the mark ("enter", "sigusr1").
  auto mark = [&](std::string_view trigger) {
    const auto recorded = recorder.mark(std::chrono::steady_clock::now());
    if (!recorded) {
      std::cerr << kName << "mark (" << trigger << ") refused: " << recorded.error().message
                << "; nothing written\n";
      return;
    }
    if (recorded->heading_source == gps::HeadingSource::kNone) {
      std::cerr << kName << recorded->location.id
                << ": no course and no earlier fix 1 m away; written without heading\n";
    }
    // On the disk before it is reported: a mark must survive the tractor's power being cut.
    const std::string line = recorder.map().csvLine(recorded->location);
    if (const std::string bad = core::appendDurably(options.out, line); !bad.empty()) {
      std::cerr << kName << bad << '\n';
      failed = true;
      return;
    }
    std::cout << markJson(*recorded, trigger).dump() << std::endl;  // a reader may be waiting
  };

  asio::io_context io;
  // Signals first: a mark sent while a FIFO open still waits for its writer must not kill us.
  asio::signal_set signals(io, SIGUSR1, SIGINT, SIGTERM);
  std::function<void(const boost::system::error_code&, int)> on_signal =
      [&](const boost::system::error_code& error, int number) {
        if (error)
          return;
        if (number == SIGUSR1) {
          mark("sigusr1");
          signals.async_wait(on_signal);
        } else {
          io.stop();
        }
      };
  signals.async_wait(on_signal);

  std::unique_ptr<gps::SerialNmeaSource> serial;
  std::unique_ptr<sim::NmeaPlayer> player;
  std::string input_kind;
  if (type == std::filesystem::file_type::character) {
    input_kind = "serial device";
    gps::SerialOptions serial_options;
    serial_options.device = options.nmea;
    serial_options.baud = options.baud;
    auto created = gps::SerialNmeaSource::create(
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
    if (!created)
      return fail(kName, created.error().message);
    serial = std::move(*created);
  } else {
    sim::NmeaPacing pacing;
    pacing.realtime = options.realtime;
    pacing.max_gap = kMaxReplayGap;
    input_kind = live               ? "FIFO"
                 : options.realtime ? "file, paced by its GPS times"
                                    : "file, as fast as possible";
    auto opened = sim::NmeaPlayer::open(
        io, options.nmea, pacing,
        [&recorder](std::string_view bytes) { recorder.feed(bytes, core::ReceptionStamp::now()); },
        [&] {
          recorder.flush();
          io.stop();
        });
    if (!opened)
      return fail(kName, opened.error().message);
    player = std::move(*opened);
  }

  StdinMarks marks(io, [&mark] { mark("enter"); });
  marks.start();

  std::cerr << kName << "reading " << options.nmea << " (" << input_kind << "), appending to "
            << options.out << " (" << already_there << " locations already there); mark "
            << "with Enter or kill -USR1 " << ::getpid() << ", stop with Ctrl-C" << std::endl;
  if (serial)
    serial->start();
  if (player)
    player->start();
  // Stop after a failed write too: marks that cannot be kept must not look accepted.
  while (!io.stopped()) {
    io.run_one();
    if (failed)
      io.stop();
  }
  if (serial)
    serial->stop();

  std::cerr << kName << recorder.map().size() - already_there << " marks written to " << options.out
            << '\n';
  return failed ? kExitRuntime : kExitOk;
}

}  // namespace

void registerMapCommand(CLI::App& app, int& exit_code) {
  CLI::App* map = addCommandGroup(app, "map", "Imaging-location maps");

  const auto [generate, g] = addSubcommand(
      *map, "generate", "Write a map of plot centres from a field plan", exit_code, runGenerate);
  addFieldPlanOptions(*generate, g->field);
  generate->add_option("--out", g->out, "Map file to write")->required();

  CLI::App* record = map->add_subcommand(
      "record", "Drive the field and mark imaging locations with Enter or SIGUSR1");
  auto r = std::make_shared<RecordOptions>();
  record->add_option("--nmea", r->nmea, "Serial device, FIFO or NMEA file")->required();
  record->add_option("--out", r->out, "Map file to write or continue")->required();
  record->add_option("--baud", r->baud, "Serial baud rate")
      ->capture_default_str()
      ->check(finiteRange(300u, 4'000'000u));
  record->add_option("--id-prefix", r->id_prefix, "Prefix of the ids <prefix><number>")
      ->capture_default_str();
  CLI::Option* start_id =
      record
          ->add_option("--start-id", r->start_id,
                       "First id number (default: one past the highest in the existing map, or 1); "
                       "numbers already used are skipped")
          ->check(finiteRange(1L, 999'999'999L));
  record->add_flag("--realtime,!--no-realtime", r->realtime,
                   "Replay a file at the pace of its GPS times (default) or as fast as possible");
  record->callback([r, start_id, &exit_code] {
    r->start_id_given = start_id->count() > 0;
    exit_code = runRecord(*r);
  });
}

}  // namespace fieldrig::tools
