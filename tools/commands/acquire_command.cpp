// `fieldrig acquire --driver sim|aravis|dc1394 [--camera ID]... --count N --rate HZ --out DIR`:
// triggers N sets in software at the given rate, records them, and prints one JSON summary.
#include <sys/resource.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands/command_helpers.h"
#include "fieldrig/daemon/acquisition.h"
#include "fieldrig/recording/session_format.h"
#include "fieldrig/sim/sim_camera.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct AcquireArgs {
  std::string driver = "sim";
  std::vector<std::string> cameras;
  std::uint64_t count = 10;
  double rate_hz = 5;
  std::string out;
  std::string fsync = "per_set";
  std::uint32_t width = 1624;
  std::uint32_t height = 1224;
  std::string pixel_format = "BayerRG8";
  std::size_t pool_sets = 16;
  int frame_timeout_ms = 500;
  std::vector<std::string> camera_options;  // KEY=VALUE for every camera (sim fault injection…)
};

// Peak resident memory of this process (VmHWM), MB: bounded by the frame pool when nothing is
// allocated per frame.
double peakRssMb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0)
      return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0;
}

double cpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

int runAcquire(const AcquireArgs& args) {
  constexpr std::string_view kName = "fieldrig acquire: ";
  daemon::AcquisitionOptions options;
  options.rig.driver = args.driver;
  options.rig.pool_sets = args.pool_sets;
  options.rig.frame_timeout = std::chrono::milliseconds{args.frame_timeout_ms};
  const auto format = core::parsePixelFormat(args.pixel_format);
  if (!format) {
    return fail(kName, "--pixel-format: '" + args.pixel_format +
                           "' is not one of Mono8, BayerRG8, BayerGR8, BayerGB8, BayerBG8");
  }
  const auto fsync = recording::parseFsyncPolicy(args.fsync);
  if (!fsync)
    return fail(kName, "--fsync: '" + args.fsync + "' is not none, per_set or per_frame");
  options.writer.fsync = *fsync;
  std::vector<std::string> ids = args.cameras;
  if (ids.empty() && args.driver == "sim")
    ids = {"0", "1", "2", "3", "4", "5"};
  if (ids.empty())
    return fail(kName, "--camera: name the cameras of driver '" + args.driver + "'");
  for (const std::string& id : ids) {
    drivers::CameraConfig camera;
    camera.id = id;
    camera.width = args.width;
    camera.height = args.height;
    camera.format = *format;
    for (const std::string& option : args.camera_options) {
      const auto equals = option.find('=');
      if (equals == std::string::npos)
        return fail(kName, "--camera-option: '" + option + "' is not KEY=VALUE");
      camera.options[option.substr(0, equals)] = option.substr(equals + 1);
    }
    options.rig.cameras.push_back(camera);
  }
  options.session_dir = args.out;
  options.session.configuration = {{"driver", args.driver},
                                   {"cameras", ids},
                                   {"width", args.width},
                                   {"height", args.height},
                                   {"pixel_format", args.pixel_format},
                                   {"rate_hz", args.rate_hz},
                                   {"fsync", args.fsync}};

  sim::addSimCamera(drivers::CameraRegistry::instance());  // drivers/ knows nothing of sim/
  auto acquisition = daemon::Acquisition::create(options, drivers::CameraRegistry::instance());
  if (!acquisition)
    return fail(kName, acquisition.error().message);
  if (auto started = (*acquisition)->start(); !started)
    return fail(kName, started.error().message, kExitRuntime);
  const double cpu_before = cpuSeconds();
  const auto begin = std::chrono::steady_clock::now();
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / args.rate_hz));
  for (std::uint64_t i = 0; i < args.count; ++i) {
    std::this_thread::sleep_until(begin + i * period);
    (*acquisition)->trigger();
  }
  (*acquisition)
      ->finish(std::chrono::milliseconds{args.frame_timeout_ms} + std::chrono::seconds{30});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const double cpu = cpuSeconds() - cpu_before;
  const daemon::AcquisitionStats s = (*acquisition)->stats();
  const daemon::LinkSummary link = (*acquisition)->linkSummary();
  // Not known (null) unless some camera's transport has packets (GigE Vision).
  auto packets = [&](std::uint64_t count) {
    return link.has_packets ? Json(count) : Json(nullptr);
  };

  Json summary;
  summary["sets"] = s.sets_recorded;
  summary["sets_lost"] = s.sets_lost;
  summary["triggered"] = (*acquisition)->triggered();
  summary["incomplete"] = s.rig.incomplete_sets;
  summary["frames_lost"] = s.rig.frames_missing + s.rig.frames_dropped;
  summary["frames_corrupt"] = s.rig.frames_corrupt;
  summary["max_skew_us"] = static_cast<double>(s.rig.max_skew_ns) / 1000.0;
  summary["skew_flagged"] = s.rig.skew_flagged;
  summary["packets_resent"] = packets(link.packets_resent);
  summary["packets_missing"] = packets(link.packets_missing);
  // A frame lost without a missing packet: the camera merged its trigger into an earlier one.
  summary["triggers_merged"] =
      link.counts_merged_triggers ? Json(link.triggers_merged) : Json(nullptr);
  summary["mb_per_s"] = static_cast<double>(s.bytes_written) / 1e6 / seconds;
  summary["sets_per_s"] = static_cast<double>(s.sets_recorded) / seconds;
  summary["cpu_ms_per_set"] =
      s.sets_recorded ? cpu * 1000.0 / static_cast<double>(s.sets_recorded) : 0.0;
  summary["seconds"] = seconds;
  summary["pool_mb"] = static_cast<double>((*acquisition)->poolBytes()) / 1e6;
  summary["peak_rss_mb"] = peakRssMb();
  summary["out"] = args.out;
  if (s.recording_stopped)
    summary["alarm"] = s.alarm;
  return printJsonLine(summary, s.recording_stopped ? kExitRuntime : kExitOk);
}

}  // namespace

void registerAcquireCommand(CLI::App& app, int& exit_code) {
  const auto [cmd, args] = addSubcommand(
      app, "acquire", "Trigger N sets in software at a rate, record them, print a JSON summary",
      exit_code, runAcquire);
  cmd->add_option("--driver", args->driver, "camera driver")->capture_default_str();
  cmd->add_option("--camera", args->cameras,
                  "camera id, once per camera in rig order (sim: default 0-5)");
  cmd->add_option("--count", args->count, "sets to trigger")
      ->required()
      ->check(finiteRange<std::uint64_t>(1, 10'000'000));
  cmd->add_option("--rate", args->rate_hz, "trigger rate, Hz")
      ->required()
      ->check(finiteRange(0.01, 1000.0));
  cmd->add_option("--out", args->out, "session folder (created, or continued)")->required();
  cmd->add_option("--fsync", args->fsync, "none, per_set or per_frame")->capture_default_str();
  // The largest machine-vision sensors are about 14k pixels wide; the pool's own budget check
  // refuses a rig whose frames, times the sets, do not fit in memory.
  cmd->add_option("--width", args->width, "frame width")
      ->capture_default_str()
      ->check(finiteRange<std::uint32_t>(1, 16384));
  cmd->add_option("--height", args->height, "frame height")
      ->capture_default_str()
      ->check(finiteRange<std::uint32_t>(1, 16384));
  cmd->add_option("--pixel-format", args->pixel_format, "GenICam pixel format")
      ->capture_default_str();
  // Far below Boost.Lockfree's 65,535 free-list nodes even with a frame per camera per set.
  cmd->add_option("--pool-sets", args->pool_sets, "frame buffers allocated, in sets")
      ->capture_default_str()
      ->check(finiteRange<std::size_t>(1, 1024));
  cmd->add_option("--frame-timeout-ms", args->frame_timeout_ms,
                  "a set leaves incomplete this long after its trigger")
      ->capture_default_str()
      ->check(finiteRange(1, 60'000));
  cmd->add_option("--camera-option", args->camera_options,
                  "KEY=VALUE for every camera (sim: drop_every, corrupt_every, delay_ms…)");
}

}  // namespace fieldrig::tools
