#include "fieldrig/daemon/daemon.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <thread>
#include <tuple>
#include <utility>

#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/interruptible_input.h"
#include "fieldrig/core/logging.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/acquisition.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/daemon/link_status.h"
#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/daemon/session_view.h"
#include "fieldrig/daemon/status_server.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/gps/local_frame.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/serial_nmea_source.h"
#include "fieldrig/gps/serial_trigger_chain.h"
#include "fieldrig/gps/trigger_replay.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/sim/nmea_player.h"
#include "fieldrig/sim/sim_camera.h"
#include "fieldrig/stereo/preprocess.h"
#include "service_notifier.h"

namespace fieldrig::daemon {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

constexpr auto kHousekeepingPeriod = std::chrono::milliseconds{200};
constexpr double kGpsLostAfterS = 1.0;  // ten missed 10 Hz epochs
constexpr std::size_t kAlarmsKept = 100;
constexpr double kSpeedWarnRatio = 0.8;  // amber at 80 % of what the cameras can keep up with
constexpr auto kFinishTimeout = std::chrono::seconds{10};
constexpr int kThumbnailWidth = 240;  // pixels: six fit a phone's width in two rows

// A location's state on the page, one character each in the status's locations.states.
constexpr char kPending = kLocationPending, kTriggered = kLocationTriggered,
               kRecorded = kLocationRecorded, kProcessed = kLocationProcessed,
               kMissed = kLocationMissed, kIncomplete = kLocationIncomplete;

struct RowCounts {
  std::uint64_t locations = 0, fired = 0, late = 0, missed = 0;
};

// Folders a start created, deepest first: those still empty are removed when it ends before the
// session was opened.
struct FoldersIfStartFails {
  std::vector<fs::path> folders;
  bool started = false;
  FoldersIfStartFails() = default;
  FoldersIfStartFails(const FoldersIfStartFails&) = delete;
  FoldersIfStartFails& operator=(const FoldersIfStartFails&) = delete;
  ~FoldersIfStartFails() {
    if (started)
      return;
    for (const fs::path& folder : folders) {
      std::error_code not_empty;  // a folder that holds something stays
      fs::remove(folder, not_empty);
    }
  }
};

// Resident memory now and at its peak, MB (Linux: /proc/self/statm and getrusage).
std::pair<double, double> memoryMb() {
  double rss = 0;
  std::ifstream statm("/proc/self/statm");
  std::size_t pages_total = 0, pages_resident = 0;
  if (statm >> pages_total >> pages_resident)
    rss = static_cast<double>(pages_resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / 1e6;
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return {rss, static_cast<double>(usage.ru_maxrss) / 1e3};
}

std::string nowIso() {
  return core::formatIso8601(core::UtcTime{std::chrono::duration_cast<core::Nanoseconds>(
                                 std::chrono::system_clock::now().time_since_epoch())},
                             3);
}

// The fastest the tractor may drive before two locations of a row come closer in time than the
// cameras' minimum trigger interval: the shortest spacing between neighbouring locations of a row
// (maps list a row's locations in order; without a row column, all are one row) over that
// interval. Linear in the map's size: season maps hold 100,000 locations.
double maxSpeedFor(const gps::LocationMap& map, double min_trigger_interval_s) {
  if (map.size() < 2 || min_trigger_interval_s <= 0)
    return 0;
  const auto& columns = map.metadataColumns();
  const auto row_column = std::find(columns.begin(), columns.end(), "row");
  const gps::LocalFrame frame(map.locations().front().latitude_deg,
                              map.locations().front().longitude_deg);
  auto rowOf = [&](const gps::ImagingLocation& location) {
    if (row_column == columns.end())
      return std::string();
    const auto c = static_cast<std::size_t>(row_column - columns.begin());
    return c < location.metadata.size() ? location.metadata[c] : std::string();
  };
  double shortest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < map.size(); ++i) {
    const auto& a = map.locations()[i - 1];
    const auto& b = map.locations()[i];
    if (rowOf(a) != rowOf(b))
      continue;
    const gps::EnuPoint pa = frame.toLocal(a.latitude_deg, a.longitude_deg);
    const gps::EnuPoint pb = frame.toLocal(b.latitude_deg, b.longitude_deg);
    const double spacing = std::hypot(pa.east_m - pb.east_m, pa.north_m - pb.north_m);
    if (spacing > 0)
      shortest = std::min(shortest, spacing);
  }
  return std::isfinite(shortest) ? shortest / min_trigger_interval_s : 0;
}

class Daemon {
 public:
  explicit Daemon(const DaemonOptions& options) : options_(options), config_(options.config) {
    watchLifeSignals();
  }

  int run() {
    if (options_.check_only) {
      const int failed = checkStart();
      if (failed == kExitOk)
        std::cout << sourceName() << ": ok" << std::endl;
      return failed;
    }
    if (const int failed = prepare(); failed != kExitOk)
      return failed;
    if (takeLifeSignals()) {
      // Asked to stop while starting: nothing is triggered, the session is closed as usual.
      spdlog::info("a stop signal during start-up: closing the session");
      stopped_by_signal_ = true;
      return finish();
    }
    const fs::path& nmea =
        options_.mode == Mode::kReplay ? config_.replay.nmea : fs::path(config_.gps.serial.device);
    std::error_code ec;
    const bool device = fs::is_character_file(nmea, ec);
    if (replaysInVirtualTime()) {
      runVirtualTime();
    } else {
      runLive(nmea, /*play_file=*/!device);
    }
    return finish();
  }

 private:
  // The runs' own signal_sets (each with its run's way to stop) live only while they run, and
  // asio puts back the default action of a signal when the last set holding it goes: a SIGTERM
  // during start-up or while closing, after the NMEA ended, killed the daemon with the results
  // behind the recording. This set holds the three signals for the daemon's whole life; its
  // io_context is only polled, where a signal can be acted on.
  void watchLifeSignals() {
    life_signals_.async_wait([this](const boost::system::error_code& error, int number) {
      if (error)
        return;
      if (number == SIGHUP) {
        core::setupLogging(config_.log.level, config_.log.file.string());
        spdlog::info("SIGHUP: log reopened");
      } else {
        life_stop_signals_ = true;
      }
      watchLifeSignals();
    });
  }
  // True when SIGINT or SIGTERM came since the last call (SIGHUP reopens the log here too).
  bool takeLifeSignals() {
    life_io_.restart();
    life_io_.poll();
    return std::exchange(life_stop_signals_, false);
  }

  // The session the sim cameras replay must be one, and the run must not record into it (it
  // appended its sets to the session it was replaying).
  int checkReplayedSession() const {
    const bool replays_session = config_.cameras.rig.driver == "sim" &&
                                 !config_.replay.session.empty() && checksReplayInputs();
    if (!replays_session)
      return kExitOk;
    const auto replayed = recording::SessionReader::open(config_.replay.session);
    if (!replayed) {
      spdlog::error("{}: {}", whereIs("replay.session"), replayed.error().message);
      return kExitBadInput;
    }
    if (replayed->sets().empty()) {
      spdlog::error("{}: {}: no sets recorded to replay", whereIs("replay.session"),
                    config_.replay.session.string());
      return kExitBadInput;
    }
    std::error_code source_error, target_error;
    const fs::path source = fs::weakly_canonical(config_.replay.session, source_error);
    const fs::path target = fs::weakly_canonical(config_.recording.dir, target_error);
    const bool inside =
        std::mismatch(source.begin(), source.end(), target.begin(), target.end()).first ==
        source.end();
    if (!source_error && !target_error && inside) {
      spdlog::error("{}: {}: inside the session being replayed ({}): record elsewhere",
                    whereIs("recording.dir"), config_.recording.dir.string(),
                    config_.replay.session.string());
      return kExitBadInput;
    }
    return kExitOk;
  }

  // The path itself, or the nearest folder above it that exists, when that is not a folder
  // (creating the folders would fail): nullopt when the path can be a folder.
  static std::optional<fs::path> fileOnTheWay(const fs::path& path) {
    std::error_code ec;
    for (fs::path at = fs::absolute(path, ec); !ec; at = at.parent_path()) {
      const fs::file_status status = fs::status(at, ec);
      if (status.type() == fs::file_type::not_found) {
        ec.clear();
        if (at == at.parent_path())
          break;
        continue;
      }
      if (ec)
        break;
      return fs::is_directory(status) ? std::nullopt : std::optional<fs::path>(at);
    }
    return std::nullopt;
  }

  // Replay of a file (not a device) in GPS time, as fast as the pipeline takes it.
  bool replaysInVirtualTime() const {
    std::error_code ec;
    return !options_.check_only && options_.mode == Mode::kReplay &&
           !fs::is_character_file(config_.replay.nmea, ec) && !config_.replay.realtime;
  }

  // Run mode's and replay mode's own inputs. --check-config knows no mode: it checks the inputs
  // of each mode that the configuration names.
  bool checksRunInputs() const {
    return options_.check_only ? !config_.gps.serial.device.empty() : options_.mode == Mode::kRun;
  }
  bool checksReplayInputs() const {
    return options_.check_only ? !config_.replay.nmea.empty() : options_.mode == Mode::kReplay;
  }

  // Everything in the configuration that can be refused without writing anything: the map, the
  // NMEA input, calibration and processing, the folders and the status address. The start runs
  // it first, and --check-config runs only it, so the two never disagree.
  int checkStart() {
    if (config_.map.empty()) {
      spdlog::error("{}: map: no imaging-location map configured", sourceName());
      return kExitBadInput;
    }
    auto map = gps::LocationMap::load(config_.map);
    if (!map) {
      spdlog::error("{}", map.error().message);
      return kExitBadInput;
    }
    if (map->empty()) {
      spdlog::error("{}: the map has no locations", config_.map.string());
      return kExitBadInput;
    }
    map_ = std::move(*map);
    frame_.emplace(map_.locations().front().latitude_deg, map_.locations().front().longitude_deg);
    location_states_.assign(map_.size(), kPending);
    const std::vector<std::string> rows = locationRows(map_);
    for (std::size_t i = 0; i < map_.size(); ++i) {
      location_rows_[map_.locations()[i].id] = rows[i];
      ++rows_[rows[i]].locations;
    }
    map_json_ = mapJson();
    max_speed_mps_ = maxSpeedFor(map_, config_.gps.triggers.planner.min_trigger_interval_s);

    if (options_.check_only && config_.replay.nmea.empty() && config_.gps.serial.device.empty()) {
      spdlog::error(
          "{}: gps.serial.device: neither the receiver's serial port (run) nor "
          "replay.nmea (replay) is configured",
          sourceName());
      return kExitBadInput;
    }
    if (options_.mode == Mode::kReplay && config_.replay.nmea.empty() && !options_.check_only) {
      spdlog::error("{}: replay.nmea: replay needs an NMEA file or device", sourceName());
      return kExitBadInput;
    }
    if (options_.mode == Mode::kRun && config_.gps.serial.device.empty() && !options_.check_only) {
      spdlog::error("{}: gps.serial.device: run needs the receiver's serial port", sourceName());
      return kExitBadInput;
    }
    if (checksReplayInputs()) {
      std::error_code ec;
      if (!fs::exists(config_.replay.nmea, ec)) {
        spdlog::error("{}: {}: no such file or device", whereIs("replay.nmea"),
                      config_.replay.nmea.string());
        return kExitBadInput;
      }
      if (fs::is_directory(config_.replay.nmea, ec)) {
        spdlog::error("{}: {}: a folder, not an NMEA file or device", whereIs("replay.nmea"),
                      config_.replay.nmea.string());
        return kExitBadInput;
      }
      if (!fs::is_character_file(config_.replay.nmea, ec)) {
        if (replaysInVirtualTime()) {
          // Opened now, so that an unreadable file is refused before the session is created; a
          // FIFO opens without waiting for its writer.
          auto input = core::InterruptibleInput::open(config_.replay.nmea);
          if (!input) {
            spdlog::error("{}: {}", whereIs("replay.nmea"), input.error().message);
            return kExitBadInput;
          }
          replay_input_ = std::move(*input);
        } else if (::access(config_.replay.nmea.c_str(), R_OK) != 0) {
          // Not opened: a check opening a FIFO would let its writer in and then leave it with a
          // broken pipe; the real-time player opens the file itself.
          const int error = errno;
          spdlog::error("{}: {}: cannot be read: {}", whereIs("replay.nmea"),
                        config_.replay.nmea.string(), std::strerror(error));
          return kExitBadInput;
        }
      }
    }
    // A device must be a serial port: /dev/null would be opened again and again for ever.
    for (const auto& [checked, key, nmea_input] :
         {std::tuple{checksReplayInputs(), "replay.nmea", config_.replay.nmea},
          std::tuple{checksRunInputs(), "gps.serial.device",
                     fs::path(config_.gps.serial.device)}}) {
      std::error_code ec;
      if (!checked || !fs::is_character_file(nmea_input, ec))
        continue;
      if (auto serial = gps::checkSerialDevice(nmea_input.string()); !serial) {
        spdlog::error("{}: {}", whereIs(key), serial.error().message);
        return kExitBadInput;
      }
    }
    if (config_.recording.dir.empty()) {
      spdlog::error("{}: recording.dir: no session folder configured", sourceName());
      return kExitBadInput;
    }
    if (const auto file = fileOnTheWay(config_.recording.dir)) {
      spdlog::error("{}: {}: {} is not a folder", whereIs("recording.dir"),
                    config_.recording.dir.string(), file->string());
      return kExitBadInput;
    }
    if (const int failed = checkReplayedSession(); failed != kExitOk)
      return failed;
    sim::addSimCamera(drivers::CameraRegistry::instance());  // drivers/ knows nothing of sim/
    if (auto rig =
            drivers::Rig::checkOptions(config_.cameras.rig, drivers::CameraRegistry::instance());
        !rig) {
      spdlog::error("{}: cameras: {}", sourceName(), rig.error().message);
      return kExitBadInput;
    }
    if (config_.pipeline.enabled) {
      if (config_.calibration.empty()) {
        spdlog::error(
            "{}: calibration: processing needs the calibration folder (or set "
            "pipeline.enabled: false)",
            sourceName());
        return kExitBadInput;
      }
      auto rig = cloud::loadRigCalibration(config_.calibration);
      if (!rig) {
        spdlog::error("{}", rig.error().message);
        return kExitBadInput;
      }
      if (auto cameras = checkCalibratedHeadsHaveCameras(*rig, config_.cameras.layout); !cameras) {
        spdlog::error("{}: {} (calibration {})", sourceName(), cameras.error().message,
                      config_.calibration.string());
        return kExitBadInput;
      }
      pipeline::ProcessorOptions processor_options;
      processor_options.cloud = config_.pipeline.cloud;
      processor_options.traits = config_.pipeline.traits;
      auto processor = pipeline::PlotProcessor::create(*rig, processor_options);
      if (!processor) {
        spdlog::error("{}", processor.error().message);
        return kExitBadInput;
      }
      processor_.emplace(std::move(*processor));
      if (const auto file =
              config_.outputs.dir.empty() ? std::nullopt : fileOnTheWay(config_.outputs.dir)) {
        spdlog::error("{}: {}: {} is not a folder", whereIs("outputs.dir"),
                      config_.outputs.dir.string(), file->string());
        return kExitBadInput;
      }
    }
    if (config_.status.enabled) {
      boost::system::error_code error;
      boost::asio::ip::make_address(config_.status.address, error);
      if (error) {
        spdlog::error("{}: '{}': not an IP address", whereIs("status.address"),
                      config_.status.address);
        return kExitBadInput;
      }
    }
    return kExitOk;
  }

  // Everything that can fail on bad input, before anything is written (checkStart, the status
  // port, the cameras, the results and session folders), then the start.
  int prepare() {
    if (const int failed = checkStart(); failed != kExitOk)
      return failed;
    AcquisitionOptions acquisition;
    acquisition.rig = config_.cameras.rig;
    acquisition.layout = config_.cameras.layout;
    if (options_.mode == Mode::kReplay && acquisition.rig.driver == "sim" &&
        !config_.replay.session.empty()) {
      for (auto& camera : acquisition.rig.cameras)
        camera.options["session"] = config_.replay.session.string();
      warnAboutTheReplayedSession();
    }
    acquisition.session_dir = config_.recording.dir;
    acquisition.writer = config_.recording.writer;
    acquisition.processing_queue_sets = std::max<std::size_t>(1, config_.pipeline.queue_sets);
    acquisition.on_recorded = [this](const std::string& location_id, bool complete) {
      std::lock_guard lock(health_mutex_);
      if (char* state = locationState(location_id)) {
        if (!complete)
          *state = kIncomplete;
        else if (*state == kTriggered)
          *state = kRecorded;
      }
    };
    acquisition.session.configuration = {
        {"recorded_by", "fieldrigd"},
        {"mode", options_.mode == Mode::kRun ? "run" : "replay"},
        {"config_file", config_.source.string()},
        {"driver", acquisition.rig.driver},
        {"nmea",
         options_.mode == Mode::kRun ? config_.gps.serial.device : config_.replay.nmea.string()},
        {"replayed_session", config_.replay.session.string()}};
    acquisition.session.map_file = config_.map;
    if (!config_.calibration.empty()) {
      std::error_code ec;
      acquisition.session.calibration.push_back(
          {"calib_dir", fs::absolute(config_.calibration, ec).string()});
    }
    // Results are opened before the session, so that a results folder that cannot be used
    // leaves nothing written.
    const fs::path results_dir =
        config_.outputs.dir.empty() ? config_.recording.dir / "results" : config_.outputs.dir;
    ResultsOptions results_options;
    results_options.csv = config_.outputs.csv;
    results_options.geojson = config_.outputs.geojson;
    results_options.jsonl = config_.outputs.jsonl;
    // The folders opening the results creates (recording.dir/results, and recording.dir itself
    // on a first start) are removed again, when still empty, if the start fails below: a failed
    // start leaves nothing written.
    FoldersIfStartFails new_folders;
    std::error_code absolute_error, missing;
    const fs::path results_absolute = fs::absolute(results_dir, absolute_error).lexically_normal();
    // Only what is not there at all (a dangling link to an unmounted disk is there, and stays).
    for (fs::path folder = results_absolute;
         !absolute_error && folder.has_relative_path() &&
         fs::symlink_status(folder, missing).type() == fs::file_type::not_found;
         folder = folder.parent_path())
      new_folders.folders.push_back(folder);
    if (processor_) {
      auto results = ResultsWriter::open(results_dir, results_options);
      if (!results) {
        spdlog::error("{}", results.error().message);
        return kExitBadInput;
      }
      results_ = std::move(*results);
    }
    // The status port is taken before the session is opened: a port in use leaves nothing written.
    if (config_.status.enabled) {
      StatusServerOptions status_options;
      status_options.map_json = map_json_;
      status_options.more_routes = [this](const std::string& path) { return thumbnail(path); };
      status_options.clock_fields = {"/time", "/uptime_s", "/gps/fix_age_s",
                                     "/disk", "/memory",   "/processing/last_latency_ms"};
      auto server = StatusServer::start(
          config_.status.address, config_.status.port, [this] { return snapshot(); },
          std::move(status_options));
      if (!server) {
        spdlog::error("{}, {}: {}", whereIs("status.address"), whereIs("status.port"),
                      server.error().message);
        return kExitBadInput;
      }
      status_ = std::move(*server);
      // An IPv6 address is bracketed in a URL (http://[::1]:8080/).
      const std::string host = config_.status.address.find(':') == std::string::npos
                                   ? config_.status.address
                                   : "[" + config_.status.address + "]";
      const std::string url = "http://" + host + ":" + std::to_string(status_->port()) + "/status";
      spdlog::info("status on {}", url);
      std::cerr << Json{{"status_url", url}}.dump() << std::endl;
    }
    auto created = Acquisition::create(acquisition, drivers::CameraRegistry::instance());
    if (!created) {
      spdlog::error("{}", created.error().message);
      return kExitBadInput;
    }
    acquisition_ = std::move(*created);
    acquisition_ready_ = true;
    new_folders.started = true;
    Acquisition::ProcessSet process;
    if (processor_)
      process = [this](const core::FrameSet& set) { processSet(set); };
    if (auto started = acquisition_->start(process); !started) {
      spdlog::error("{}", started.error().message);
      return kExitRuntime;
    }
    started_at_ = Clock::now();
    spdlog::info("fieldrigd: {} mode, map {} ({} locations), session {}",
                 options_.mode == Mode::kRun ? "run" : "replay", config_.map.string(), map_.size(),
                 config_.recording.dir.string());
    return kExitOk;
  }

  std::string sourceName() const {
    return config_.source.empty() ? std::string("configuration") : config_.source.string();
  }

  // Where a value came from, for an error about it: the command-line flag that overrode it, or
  // the configuration file and key ("--nmea", "run.yaml: replay.nmea").
  std::string whereIs(const std::string& key) const {
    if (const auto flag = options_.flags_for_keys.find(key); flag != options_.flags_for_keys.end())
      return flag->second;
    return sourceName() + ": " + key;
  }

  // The sim cameras replay the recorded session's sets in order and wrap around when they run
  // out, so a session with fewer sets than the map has locations gives later plots earlier plots'
  // frames, and a torn last index line drops a set unseen: both are said before the run.
  void warnAboutTheReplayedSession() const {
    const auto replayed = recording::SessionReader::open(config_.replay.session);
    if (!replayed)
      return;  // the sim cameras refuse it at start, naming the problem
    const std::size_t sets = replayed->sets().size();
    if (const auto& torn = replayed->tornLine()) {
      spdlog::warn(
          "{} {}: index.jsonl:{}: torn last line ({} bytes) left out: {} sets "
          "are replayed",
          whereIs("replay.session"), config_.replay.session.string(), torn->line, torn->bytes,
          sets);
    }
    if (!map_.empty() && sets < map_.size()) {
      spdlog::warn(
          "{} {}: {} sets for the map's {} locations: from trigger {} on, "
          "the sim cameras replay earlier sets' frames again (those plots' traits are "
          "not their own)",
          whereIs("replay.session"), config_.replay.session.string(), sets, map_.size(), sets + 1);
    }
  }

  // ---- GPS/trigger thread -------------------------------------------------------------------

  void onTrigger(const core::TriggerEvent& event) {
    if (recording_stopped_alarmed_ == false && acquisition_->stats().recording_stopped) {
      recording_stopped_alarmed_ = true;
      alarm("recording_stopped", acquisition_->stats().alarm, "");
    }
    const bool accepted = acquisition_->trigger(event);
    std::lock_guard lock(health_mutex_);
    ++triggers_;
    RowCounts& row = rows_[rowOf(event.location_id)];
    ++row.fired;
    if (event.status == core::TriggerStatus::kLate) {
      ++late_;
      ++row.late;
    }
    if (!accepted)
      ++refused_;
    last_trigger_ = event;
    if (char* state = locationState(event.location_id)) {
      *state = kTriggered;
      current_row_ = rowOf(event.location_id);
    }
  }

  void onPlannerAlarm(const gps::PlannerAlarm& planner_alarm) {
    const bool missed = planner_alarm.kind == gps::AlarmKind::kMissed;
    {
      std::lock_guard lock(health_mutex_);
      if (missed) {
        ++missed_;
        ++rows_[rowOf(planner_alarm.location_id)].missed;
        missed_locations_.push_back(planner_alarm.location_id);
        if (char* state = locationState(planner_alarm.location_id)) {
          *state = kMissed;
          current_row_ = rowOf(planner_alarm.location_id);
        }
      } else if (planner_alarm.kind == gps::AlarmKind::kTooFast) {
        ++too_fast_;
      } else if (planner_alarm.kind == gps::AlarmKind::kPositionJump) {
        ++position_jumps_;
      } else if (planner_alarm.kind == gps::AlarmKind::kTimeJump) {
        ++time_jumps_;
      }
    }
    alarm(std::string(gps::toString(planner_alarm.kind)), planner_alarm.message,
          planner_alarm.location_id);
  }

  void onFix(const core::GpsFix& fix) {
    std::lock_guard lock(health_mutex_);
    ++fixes_;
    last_fix_ = fix;
    if (fix.valid)
      last_valid_fix_at_ = Clock::now();
  }

  void onSerial(const gps::SerialStatus& status) {
    {
      std::lock_guard lock(health_mutex_);
      serial_state_ = std::string(gps::toString(status.event));
    }
    if (status.event == gps::SerialEvent::kLost)
      alarm("serial_lost", status.device + ": " + status.message, "");
    else if (status.event == gps::SerialEvent::kOpened)
      spdlog::info("serial {} opened", status.device);
  }

  // Every kHousekeepingPeriod on the GPS thread: GPS loss and recovery, service status.
  void housekeeping() {
    std::optional<double> age;
    bool lost_now = false, recovered = false;
    {
      std::lock_guard lock(health_mutex_);
      if (last_valid_fix_at_)
        age = std::chrono::duration<double>(Clock::now() - *last_valid_fix_at_).count();
      const bool lost = !age || *age > kGpsLostAfterS;
      if (lost && !gps_lost_ && (age || Clock::now() - started_at_ > std::chrono::seconds{5})) {
        gps_lost_ = true;
        lost_now = true;
      } else if (!lost && gps_lost_) {
        gps_lost_ = false;
        recovered = true;
      }
    }
    if (lost_now) {
      alarm("gps_lost",
            age ? "no valid fix for " + std::to_string(*age).substr(0, 4) +
                      " s: no triggers until fixes return; locations passed meanwhile are missed"
                : "no valid fix yet: check the receiver's cable and its RTK status",
            "");
    }
    if (recovered)
      alarm("gps_recovered", "valid fixes again: triggering resumes", "");
    if (!recording_stopped_alarmed_ && acquisition_->stats().recording_stopped) {
      recording_stopped_alarmed_ = true;
      alarm("recording_stopped", acquisition_->stats().alarm, "");
    }
    if (Clock::now() - last_status_notify_ > std::chrono::seconds{1}) {
      last_status_notify_ = Clock::now();
      const AcquisitionStats stats = acquisition_->stats();
      notifier_.status("triggers " + std::to_string(acquisition_->triggered()) + ", recorded " +
                       std::to_string(stats.sets_recorded) + ", processed " +
                       std::to_string(stats.sets_processed) + (gps_lost_ ? ", GPS LOST" : ""));
    }
  }

  // Virtual time: the planner in GPS time, every trigger once the pipeline has room.
  void runVirtualTime() {
    boost::asio::io_context control;
    boost::asio::signal_set signals(control, SIGINT, SIGTERM, SIGHUP);
    // The input is ended too: a FIFO whose writer stays open would keep the replay reading.
    watchSignals(signals, [this] {
      acquisition_->interruptWaits();
      replay_input_->interrupt();
    });
    if (takeLifeSignals()) {  // came before this run's signal_set (or since, and seen by both)
      spdlog::info("a stop signal before the replay began: closing the session");
      stopped_by_signal_ = true;
      stop_requested_ = true;
      replay_input_->interrupt();
    }
    notifier_.startWatchdog(control);
    std::thread control_thread([&control] { control.run(); });
    // Stopped and joined on every way out: an exception from the replay (std::bad_alloc in a
    // handler) that met a joinable thread would call std::terminate, and the unwinding that
    // closes the session (~Acquisition) would never happen.
    struct StopAndJoin {
      boost::asio::io_context& io;
      std::thread& thread;
      ~StopAndJoin() {
        io.stop();
        if (thread.joinable())
          thread.join();
      }
    } stop_and_join{control, control_thread};
    notifier_.ready();

    // Processing takes as many sets as its queue holds; without processing, half the pool.
    const std::uint64_t room = processor_
                                   ? std::max<std::size_t>(1, config_.pipeline.queue_sets)
                                   : std::max<std::size_t>(1, config_.cameras.rig.pool_sets / 2);
    gps::ReplayHandlers handlers;
    handlers.on_trigger = [&](const core::TriggerEvent& event) {
      if (stop_requested_)
        return;
      acquisition_->waitForRoom(room);  // a stop request (signal) ends the wait too
      // A wait ended by the stop leaves no room: a set triggered now would be skipped by live
      // processing. The set in flight is finished; nothing more is triggered.
      if (stop_requested_)
        return;
      if (event.fix)
        onFix(*event.fix);
      onTrigger(event);
    };
    handlers.on_alarm = [this](const gps::PlannerAlarm& a) { onPlannerAlarm(a); };
    const auto summary =
        gps::replayTriggers(replay_input_->stream(), map_, config_.gps.triggers, handlers);
    if (summary) {
      nmea_stats_ = summary->nmea;
      planner_stats_ = summary->planner;
    } else {
      spdlog::error("{}: {}", sourceName(), summary.error().message);
      run_failed_ = true;
    }
    if (!replay_input_->readError().empty())
      nmea_problem_ = replay_input_->readError();
  }

  // Real time: the serial path of the field, from a device, or from a file played into a pty.
  void runLive(const fs::path& nmea_path, bool play_file) {
    boost::asio::io_context io;
    std::unique_ptr<sim::NmeaPtyPlayer> player;
    gps::SerialOptions serial = config_.gps.serial;
    serial.device = nmea_path.string();
    if (play_file) {
      // Every pause of the capture is played as it was: a GPS outage must look like one.
      auto started = sim::NmeaPtyPlayer::start(nmea_path, sim::NmeaPacing{}, [&io, this] {
        // The file is over: give the last triggers their frames, then end the run.
        boost::asio::post(io, [this] { stop_requested_ = true; });
      });
      if (!started) {
        spdlog::error("{}", started.error().message);
        stop_requested_ = true;
        run_failed_ = true;
        return;
      }
      player = std::move(*started);
      serial.device = player->devicePath();
    }
    gps::LiveTriggerHandlers handlers;
    handlers.on_trigger = [this](const core::TriggerEvent& event, core::SteadyTime) {
      onTrigger(event);
    };
    handlers.on_alarm = [this](const gps::PlannerAlarm& a) { onPlannerAlarm(a); };
    handlers.on_fix = [this](const core::GpsFix& fix) { onFix(fix); };
    auto created = gps::SerialTriggerChain::create(
        io, map_, serial, config_.gps.triggers, handlers,
        [this](const gps::SerialStatus& status) { onSerial(status); });
    if (!created) {
      spdlog::error("{}: gps: {}", sourceName(), created.error().message);
      run_failed_ = true;
      return;
    }
    gps::SerialTriggerChain& chain = *created;
    boost::asio::signal_set signals(io, SIGINT, SIGTERM, SIGHUP);
    auto stop_all = [&] {
      chain.stop();
      io.stop();
    };
    watchSignals(signals, stop_all);
    if (takeLifeSignals()) {  // came before this run's signal_set (or since, and seen by both)
      spdlog::info("a stop signal before the run began: closing the session");
      stopped_by_signal_ = true;
      stop_requested_ = true;
      boost::asio::post(io, stop_all);
    }
    boost::asio::steady_timer housekeeping_timer(io);
    std::function<void()> arm = [&] {
      housekeeping_timer.expires_after(kHousekeepingPeriod);
      housekeeping_timer.async_wait([&](const boost::system::error_code& error) {
        if (error)
          return;
        housekeeping();
        if (stop_requested_) {
          stop_all();
          return;
        }
        arm();
      });
    };
    arm();
    notifier_.startWatchdog(io);
    chain.start();
    notifier_.ready();
    io.run();
    nmea_stats_ = chain.nmeaStats();
    planner_stats_ = chain.plannerStats();
  }

  void watchSignals(boost::asio::signal_set& signals, std::function<void()> on_stop) {
    signals.async_wait(
        [this, &signals, on_stop](const boost::system::error_code& error, int number) {
          if (error)
            return;
          if (number == SIGHUP) {
            core::setupLogging(config_.log.level, config_.log.file.string());
            spdlog::info("SIGHUP: log reopened");
            watchSignals(signals, on_stop);
            return;
          }
          spdlog::info("signal {}: finishing the set in flight, then closing the session", number);
          notifier_.stopping();
          stopped_by_signal_ = true;
          stop_requested_ = true;
          on_stop();
        });
  }

  // ---- processing thread ----------------------------------------------------------------------

  void processSet(const core::FrameSet& set) {
    std::vector<std::string> problems;
    const auto heads =
        headFramesFromFrameSet(set, acquisition_->cameraNames(), processor_->rig(), problems);
    const pipeline::PlotResult result = processor_->process(heads, std::move(problems));
    keepThumbnails(heads, set.trigger_id);
    const core::TriggerEvent& event = set.trigger;
    PlotIdentity identity;
    identity.trigger_id = set.trigger_id;
    if (!event.location_id.empty())
      identity.location_id = event.location_id;
    identity.time =
        core::formatIso8601(event.location_id.empty() ? event.sent_time : event.time, 6);
    placePlot(identity, event.fix, &map_);
    identity.trigger_status =
        event.location_id.empty() ? std::string() : std::string(core::toString(event.status));
    const Json line = plotLine(identity, result);
    if (const std::string failed = results_->add(line); !failed.empty())
      alarm("results_not_written", failed, event.location_id);
    if (options_.print_results)
      std::cout << line.dump() << std::endl;
    const double latency_ms = event.sent_time == core::UtcTime{}
                                  ? 0
                                  : std::chrono::duration<double, std::milli>(
                                        std::chrono::system_clock::now() - event.sent_time)
                                        .count();
    std::lock_guard lock(health_mutex_);
    if (char* state = locationState(event.location_id)) {
      if (*state == kTriggered || *state == kRecorded)
        *state = result.partial ? kIncomplete : kProcessed;
    }
    latencies_ms_.push_back(latency_ms);
    last_latency_ms_ = latency_ms;
    max_latency_ms_ = std::max(max_latency_ms_, latency_ms);
    last_plot_ = Json{{"plot", line.at("plot")},
                      {"status", line.at("traits").at("status")},
                      {"height_m", line.at("traits").at("height_m")},
                      {"width_m", line.at("traits").at("width_m")},
                      {"vvi", line.at("traits").at("vvi")},
                      {"vai", line.at("traits").at("vai")},
                      {"partial", result.partial},
                      {"problems", line.at("problems")}};
  }

  // ---- any thread -----------------------------------------------------------------------------

  void alarm(const std::string& kind, const std::string& message, const std::string& location) {
    spdlog::warn("alarm {}{}: {}", kind, location.empty() ? "" : " at " + location, message);
    std::lock_guard lock(health_mutex_);
    ++alarms_total_;
    alarms_.push_back(Json{{"time", nowIso()},
                           {"kind", kind},
                           {"location", location.empty() ? Json(nullptr) : Json(location)},
                           {"message", message}});
    if (alarms_.size() > kAlarmsKept)
      alarms_.pop_front();
  }

  // The set's images, kThumbnailWidth pixels wide, as JPEG for the page (head by head, left then
  // right): a few milliseconds beside the plot's stereo. An image that cannot be made stays
  // empty (the page shows its place blank).
  void keepThumbnails(const std::vector<cloud::HeadFrames>& heads, std::uint64_t trigger_id) {
    std::vector<std::string> thumbnails;
    for (const cloud::HeadFrames& head : heads) {
      for (const cv::Mat* image : {&head.left, &head.right}) {
        std::string jpeg;
        if (!image->empty()) {
          auto small = stereo::debayerAndScale(*image, head.pixel_format,
                                               kThumbnailWidth / static_cast<double>(image->cols));
          std::vector<std::uint8_t> bytes;
          if (small && cv::imencode(".jpg", *small, bytes, {cv::IMWRITE_JPEG_QUALITY, 80}))
            jpeg.assign(bytes.begin(), bytes.end());
        }
        thumbnails.push_back(std::move(jpeg));
      }
    }
    std::lock_guard lock(thumbnails_mutex_);
    thumbnails_ = std::move(thumbnails);
    thumbnails_set_ = trigger_id;
  }

  // /thumbnail/N.jpg: the last processed set's Nth image (see keepThumbnails).
  std::optional<HttpReply> thumbnail(const std::string& path) const {
    static const std::string prefix = "/thumbnail/";
    if (path.rfind(prefix, 0) != 0 || path.size() != prefix.size() + 5 ||
        path.compare(prefix.size() + 1, 4, ".jpg") != 0 || path[prefix.size()] < '0' ||
        path[prefix.size()] > '9')
      return std::nullopt;
    const auto index = static_cast<std::size_t>(path[prefix.size()] - '0');
    std::lock_guard lock(thumbnails_mutex_);
    if (index >= thumbnails_.size() || thumbnails_[index].empty())
      return HttpReply{boost::beast::http::status::not_found, "text/plain", "no such image\n", {}};
    return HttpReply{boost::beast::http::status::ok, "image/jpeg", thumbnails_[index], {}};
  }

  // The state of a location of the map, or nullptr (a manual trigger, an unknown id). Under
  // health_mutex_.
  char* locationState(const std::string& location_id) {
    const gps::ImagingLocation* location = location_id.empty() ? nullptr : map_.find(location_id);
    if (location == nullptr)
      return nullptr;
    return &location_states_[static_cast<std::size_t>(location - map_.locations().data())];
  }

  // The map's static part for the page (/map): each location's id, row and place in metres
  // east and north of the map's first location, in the map's order (that of
  // locations.states in the status).
  std::string mapJson() const { return cabMapJson(map_, config_.map.string()).dump(); }

  std::string rowOf(const std::string& location_id) const {
    const auto it = location_rows_.find(location_id);
    return it == location_rows_.end() ? "unknown" : it->second;
  }

  Json snapshot() const {
    if (!acquisition_ready_)
      return Json{{"mode", options_.mode == Mode::kRun ? "run" : "replay"}, {"starting", true}};
    const AcquisitionStats stats = acquisition_->stats();
    const std::uint64_t triggered = acquisition_->triggered();
    Json out;
    out["mode"] = options_.mode == Mode::kRun ? "run" : "replay";
    out["time"] = nowIso();
    out["uptime_s"] = std::chrono::duration<double>(Clock::now() - started_at_).count();
    out["session"] = config_.recording.dir.string();
    std::lock_guard lock(health_mutex_);
    Json gps_status;
    gps_status["serial"] = serial_state_;
    gps_status["lost"] = gps_lost_;
    gps_status["fixes"] = fixes_;
    gps_status["fix_age_s"] =
        last_valid_fix_at_
            ? Json(std::chrono::duration<double>(Clock::now() - *last_valid_fix_at_).count())
            : Json(nullptr);
    if (last_fix_) {
      gps_status["valid"] = last_fix_->valid;
      gps_status["quality"] =
          last_fix_->quality ? Json(static_cast<int>(*last_fix_->quality)) : Json(nullptr);
      gps_status["satellites"] =
          last_fix_->satellites ? Json(*last_fix_->satellites) : Json(nullptr);
      gps_status["hdop"] = last_fix_->hdop ? Json(*last_fix_->hdop) : Json(nullptr);
      gps_status["lat"] = last_fix_->latitude_deg;
      gps_status["lon"] = last_fix_->longitude_deg;
      gps_status["course_deg"] =
          last_fix_->course_deg ? Json(*last_fix_->course_deg) : Json(nullptr);
      const gps::EnuPoint p = frame_->toLocal(last_fix_->latitude_deg, last_fix_->longitude_deg);
      gps_status["east_m"] = std::round(p.east_m * 100) / 100;
      gps_status["north_m"] = std::round(p.north_m * 100) / 100;
    }
    out["gps"] = gps_status;
    const double speed = last_fix_ && last_fix_->speed_mps ? *last_fix_->speed_mps : 0.0;
    const double ratio = max_speed_mps_ > 0 ? speed / max_speed_mps_ : 0.0;
    out["speed"] = {{"speed_mps", speed},
                    {"max_speed_mps", max_speed_mps_},
                    {"ratio", ratio},
                    {"level", ratio >= 1.0               ? "over"
                              : ratio >= kSpeedWarnRatio ? "warn"
                                                         : "ok"}};
    Json rows = Json::object();
    for (const auto& [name, row] : rows_) {
      rows[name] = {{"locations", row.locations},
                    {"fired", row.fired},
                    {"late", row.late},
                    {"missed", row.missed}};
    }
    out["triggers"] = {{"fired", triggers_},
                       {"late", late_},
                       {"missed", missed_},
                       {"too_fast", too_fast_},
                       {"position_jumps", position_jumps_},
                       {"time_jumps", time_jumps_},
                       {"refused", refused_},
                       {"locations", map_.size()},
                       {"rows", rows},
                       {"missed_locations", missed_locations_}};
    if (last_trigger_) {
      out["triggers"]["last"] = {{"location", last_trigger_->location_id},
                                 {"time", core::formatIso8601(last_trigger_->time, 3)},
                                 {"status", core::toString(last_trigger_->status)},
                                 // The planner's own 1-sigma uncertainty of this crossing.
                                 {"timing_sigma_s", last_trigger_->timing_sigma_s},
                                 {"along_track_sigma_m", last_trigger_->along_track_sigma_m}};
    }
    // One character per location of the map, in its order (see /map "states"): the page's dots.
    out["locations"] = {{"states", location_states_}, {"current_row", current_row_}};
    out["queues"] = {{"in_flight", acquisition_->inFlight()},
                     {"to_record", triggered > stats.sets_recorded + stats.sets_lost
                                       ? triggered - stats.sets_recorded - stats.sets_lost
                                       : 0}};
    out["sets"] = {{"triggered", triggered},
                   {"recorded", stats.sets_recorded},
                   {"incomplete", stats.rig.incomplete_sets},
                   {"lost", stats.sets_lost},
                   {"skipped_for_processing", stats.sets_skipped_for_processing},
                   {"processed", stats.sets_processed},
                   {"frames_missing", stats.rig.frames_missing},
                   {"frames_dropped", stats.rig.frames_dropped},
                   {"frames_corrupt", stats.rig.frames_corrupt},
                   {"recording_stopped", stats.recording_stopped}};
    out["packets"] = linkStatusJson(acquisition_->linkSummary());
    {
      std::lock_guard thumbnails_lock(thumbnails_mutex_);
      out["thumbnails"] = {{"set", thumbnails_set_}, {"count", thumbnails_.size()}};
    }
    out["processing"] = {{"enabled", processor_.has_value()},
                         {"last_latency_ms", last_latency_ms_},
                         {"max_latency_ms", max_latency_ms_},
                         {"last_plot", last_plot_}};
    Json disk;
    struct statvfs fs_info {};
    if (::statvfs(config_.recording.dir.c_str(), &fs_info) == 0) {
      const double free_bytes = static_cast<double>(fs_info.f_bavail) * fs_info.f_frsize;
      const double elapsed_h =
          std::chrono::duration<double>(Clock::now() - started_at_).count() / 3600.0;
      const double rate = elapsed_h > 0 ? static_cast<double>(stats.bytes_written) / elapsed_h : 0;
      disk["free_bytes"] = free_bytes;
      disk["bytes_written"] = stats.bytes_written;
      disk["bytes_per_hour"] = rate;
      disk["hours_left"] = rate > 0 ? Json(free_bytes / rate) : Json(nullptr);
    }
    out["disk"] = disk;
    const auto [rss_mb, peak_rss_mb] = memoryMb();
    out["memory"] = {{"rss_mb", rss_mb}, {"peak_rss_mb", peak_rss_mb}};
    out["alarms_total"] = alarms_total_;
    out["alarms"] = Json(alarms_);
    return out;
  }

  int finish() {
    notifier_.stopping();
    spdlog::info("fieldrigd: closing the session (the sets in flight are finished and processed)");
    takeLifeSignals();  // the run's own set has seen those already
    acquisition_->finish(kFinishTimeout);
    if (takeLifeSignals()) {
      spdlog::info(
          "a stop signal while closing: the session is closed whole and the results written "
          "first, as they are now");
    }
    if (results_) {
      if (const std::string failed = results_->flush(); !failed.empty())
        alarm("results_not_written", failed, "");
    }
    status_.reset();
    const AcquisitionStats stats = acquisition_->stats();
    Json summary;
    summary["locations"] = map_.size();
    summary["fixes"] = planner_stats_.fixes;
    summary["triggers"] = acquisition_->triggered();
    summary["triggers_late"] = late_;
    summary["missed"] = missed_;
    summary["position_jumps"] = planner_stats_.position_jumps;
    summary["time_jumps"] = planner_stats_.time_jumps;
    summary["sets_recorded"] = stats.sets_recorded;
    summary["sets_incomplete"] = stats.rig.incomplete_sets;
    summary["sets_lost"] = stats.sets_lost;
    summary["sets_processed"] = stats.sets_processed;
    summary["sets_skipped_for_processing"] = stats.sets_skipped_for_processing;
    const LinkSummary link = acquisition_->linkSummary();
    summary["packets_resent"] = link.has_packets ? Json(link.packets_resent) : Json(nullptr);
    summary["packets_missing"] = link.has_packets ? Json(link.packets_missing) : Json(nullptr);
    summary["triggers_merged"] =
        link.counts_merged_triggers ? Json(link.triggers_merged) : Json(nullptr);
    summary["recording_stopped"] = stats.recording_stopped;
    summary["alarms"] = alarms_total_;
    summary["nmea"] = {{"lines", nmea_stats_.lines},
                       {"sentences", nmea_stats_.sentences},
                       {"rejected_sentences", nmea_stats_.rejectedTotal()},
                       {"valid_fixes", planner_stats_.valid_epochs},
                       {"invalid_fixes", planner_stats_.fixes_invalid}};
    // How the run went on this machine (not results: they vary from run to run).
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - started_at_).count();
    summary["elapsed_s"] = elapsed_s;
    summary["sets_per_s"] =
        elapsed_s > 0 ? static_cast<double>(stats.sets_processed) / elapsed_s : 0;
    std::vector<double> latencies = latencies_ms_;
    std::sort(latencies.begin(), latencies.end());
    if (!latencies.empty()) {
      double sum = 0;
      for (double l : latencies)
        sum += l;
      summary["latency_ms"] = {
          {"mean", sum / static_cast<double>(latencies.size())},
          {"p95", latencies[std::min(latencies.size() - 1, latencies.size() * 95 / 100)]},
          {"max", latencies.back()}};
    }
    summary["peak_rss_mb"] = memoryMb().second;
    summary["session"] = config_.recording.dir.string();
    if (results_)
      summary["results"] = results_->dir().string();
    std::cout << Json{{"summary", summary}}.dump() << std::endl;
    if (stats.sets_skipped_for_processing > 0) {
      spdlog::warn(
          "{} sets were recorded but not processed live: `fieldrig process {}` completes "
          "the results (it skips the plots already there)",
          stats.sets_skipped_for_processing, config_.recording.dir.string());
    }
    spdlog::info("fieldrigd: session {} closed", config_.recording.dir.string());
    if (stats.recording_stopped) {
      spdlog::error("recording stopped: {}", stats.alarm);
      return kExitRuntime;
    }
    if (!nmea_problem_.empty()) {
      spdlog::error("{}: {}", whereIs("replay.nmea"), nmea_problem_);
      return kExitRuntime;
    }
    if (run_failed_)
      return kExitRuntime;  // said when it failed; the NMEA was never read
    return judgeReplayedNmea();
  }

  // A replayed file that gave no fix would otherwise end as an empty session with exit 0: said
  // as bad input, with what the lines were. Lines rejected beside good fixes are warned about.
  int judgeReplayedNmea() const {
    if (options_.mode != Mode::kReplay)
      return kExitOk;
    std::string rejected;
    for (std::size_t i = 0; i < gps::kRejectReasonCount; ++i) {
      if (const std::uint64_t count = nmea_stats_.rejected[i]; count > 0) {
        rejected += (rejected.empty() ? "" : ", ") +
                    std::string(gps::toString(static_cast<gps::RejectReason>(i))) + " " +
                    std::to_string(count);
      }
    }
    const std::string lines =
        std::to_string(nmea_stats_.lines) + " lines (" + std::to_string(nmea_stats_.sentences) +
        " sentences with a correct checksum, " + std::to_string(nmea_stats_.rejectedTotal()) +
        " rejected" + (rejected.empty() ? "" : ": " + rejected) + ")" +
        (planner_stats_.fixes > 0 && planner_stats_.valid_epochs == 0
             ? "; every fix invalid (RMC status V or GGA quality 0, or vetoed by the other)"
             : "");
    if (planner_stats_.valid_epochs == 0 && !stopped_by_signal_) {
      spdlog::error("{}: {}: no valid fix in {}: nothing could be triggered",
                    whereIs("replay.nmea"), config_.replay.nmea.string(), lines);
      return kExitBadInput;
    }
    if (planner_stats_.fixes_invalid > 0 && acquisition_->triggered() < map_.size()) {
      // Each invalid fix restarts the track: a receiver flickering between valid and invalid
      // gives fixes but never a track, and no alarm would say why nothing fired.
      spdlog::warn(
          "{}: {}: {} of {} fixes were invalid (each restarts the track, {} restarts): "
          "{} triggers for {} locations",
          whereIs("replay.nmea"), config_.replay.nmea.string(), planner_stats_.fixes_invalid,
          planner_stats_.fixes, planner_stats_.track_restarts, acquisition_->triggered(),
          map_.size());
    }
    if (nmea_stats_.rejectedTotal() > 0) {
      spdlog::warn("{}: {}: sentences rejected: {} in {}", whereIs("replay.nmea"),
                   config_.replay.nmea.string(), nmea_stats_.rejectedTotal(), lines);
    }
    return kExitOk;
  }

  const DaemonOptions& options_;
  const config::Config& config_;
  gps::LocationMap map_;
  std::map<std::string, std::string> location_rows_;
  std::optional<gps::LocalFrame> frame_;  // metres east and north of the map's first location
  std::string map_json_;
  double max_speed_mps_ = 0;
  std::optional<pipeline::PlotProcessor> processor_;  // the processing thread's
  std::unique_ptr<ResultsWriter> results_;            // the processing thread's, then finish()'s
  std::unique_ptr<Acquisition> acquisition_;
  std::atomic<bool> acquisition_ready_{false};  // acquisition_ is set: the status may read it
  std::unique_ptr<StatusServer> status_;
  ServiceNotifier notifier_;
  std::atomic<bool> stop_requested_{false};
  Clock::time_point started_at_ = Clock::now();
  Clock::time_point last_status_notify_{};
  gps::NmeaStats nmea_stats_;
  // Replay in virtual time: the NMEA file, opened by checkStart() and ended early by a signal.
  std::unique_ptr<core::InterruptibleInput> replay_input_;
  std::string nmea_problem_;  // a read error of the replayed file
  std::atomic<bool> stopped_by_signal_{false};
  boost::asio::io_context life_io_;
  boost::asio::signal_set life_signals_{life_io_, SIGINT, SIGTERM, SIGHUP};
  bool life_stop_signals_ = false;  // of life_io_'s handler, run by takeLifeSignals()
  bool run_failed_ = false;         // the GPS input could not be started: exit 3
  gps::TriggerStats planner_stats_;

  // Health: written by the GPS and processing threads, read by the status thread.
  mutable std::mutex health_mutex_;
  std::map<std::string, RowCounts> rows_;
  std::uint64_t triggers_ = 0, late_ = 0, missed_ = 0, too_fast_ = 0, refused_ = 0, fixes_ = 0;
  std::uint64_t position_jumps_ = 0, time_jumps_ = 0;
  std::vector<std::string> missed_locations_;
  std::string location_states_;  // one of kPending… per location of the map, in its order
  std::string current_row_;      // the row of the latest trigger or missed location
  std::optional<core::GpsFix> last_fix_;
  std::optional<Clock::time_point> last_valid_fix_at_;
  std::optional<core::TriggerEvent> last_trigger_;
  bool gps_lost_ = false;
  std::atomic<bool> recording_stopped_alarmed_{false};
  std::string serial_state_ = "not opened";
  double last_latency_ms_ = 0, max_latency_ms_ = 0;
  std::vector<double> latencies_ms_;  // trigger sent → plot written, per processed set
  Json last_plot_ = nullptr;
  std::deque<Json> alarms_;
  // The last processed set's images for the page: written by processing, read by the status.
  mutable std::mutex thumbnails_mutex_;
  std::vector<std::string> thumbnails_;
  std::uint64_t thumbnails_set_ = 0;
  std::uint64_t alarms_total_ = 0;
};

}  // namespace

int runDaemon(const DaemonOptions& options) {
  Daemon daemon(options);
  return daemon.run();
}

}  // namespace fieldrig::daemon
