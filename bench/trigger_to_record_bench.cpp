// Whole-run benchmark of the frame path's hand-offs with six sim cameras: how long a trigger
// takes to come out as a FrameSet, and what an idle started rig costs. Prints a Markdown table.
//
//   trigger_to_record_bench [TRIGGERS] [INTERVAL_MS] [IDLE_S]
//
// - rig: Rig::trigger() → the rig's SetSink (the rig thread grouped the six frames);
// - acquisition: Acquisition::trigger() → the processing thread holding the set (rig thread,
//   then the consumer queue; the recorder's queue is the same kind of hop, beside it);
// - idle CPU: user + system time of the whole process (CLOCK_PROCESS_CPUTIME_ID) over IDLE_S
//   seconds of a started rig, then of a started acquisition with processing, with no trigger,
//   as % of a core.
//
// Triggers are paced every INTERVAL_MS (default 10, 300 triggers) so that each set travels
// alone; frames are 160×120 so that the sim cameras' pixel filling stays small next to the
// hand-offs. The source uses only the Rig's and the Acquisition's public interface, so the same
// file builds against older trees for a before/after comparison in one run.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/daemon/acquisition.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/sim/sim_camera.h"

#include "process_cpu.h"
#include "support/sim_cameras.h"

namespace {

namespace fs = std::filesystem;
using namespace fieldrig;
using Clock = std::chrono::steady_clock;

drivers::RigOptions sixSimCameras() {
  drivers::RigOptions options = testing_support::sixSimCameras(160, 120);
  options.frame_timeout = std::chrono::milliseconds{500};
  options.pool_sets = 32;
  return options;
}

struct Latencies {
  std::vector<double> us;  // one per whole set that arrived
  std::size_t expected = 0;
  std::uint64_t incomplete = 0;  // sets that left the rig incomplete: a frame missing or dropped
  std::uint64_t frames_missing = 0;  // none before the rig's timeout
  std::uint64_t frames_dropped = 0;  // no free buffer in the pool
  std::uint64_t skipped = 0;         // sets the consumer never saw (its queue was full)
};

// The latency of a whole set, from when its trigger was sent (`sent[trigger id]`).
void recordLatency(Latencies& latencies, const std::vector<Clock::time_point>& sent,
                   const core::FrameSet& set) {
  if (set.complete() && set.trigger_id < sent.size()) {
    latencies.us.push_back(
        std::chrono::duration<double, std::micro>(Clock::now() - sent[set.trigger_id]).count());
  }
}

// Triggers 1 … sent.size() - 1, `interval` apart, noting in `sent` when each was fired.
template <typename Fire>
void triggerAtInterval(std::vector<Clock::time_point>& sent, std::chrono::milliseconds interval,
                       Fire fire) {
  const Clock::time_point start = Clock::now() + interval;
  for (std::size_t i = 1; i < sent.size(); ++i) {
    std::this_thread::sleep_until(start + static_cast<int>(i) * interval);
    sent[i] = Clock::now();
    fire(static_cast<int>(i));
  }
}

void printRow(const char* path, Latencies latencies) {
  std::vector<double>& v = latencies.us;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    if (v.empty())
      return 0.0;
    const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
    return v[std::min(i, v.size() - 1)];
  };
  std::printf("| %s | %zu/%zu | %.0f | %.0f | %.0f | %llu (%llu missing, %llu dropped) | %llu |\n",
              path, v.size(), latencies.expected, at(0.5), at(0.99), at(1.0),
              static_cast<unsigned long long>(latencies.incomplete),
              static_cast<unsigned long long>(latencies.frames_missing),
              static_cast<unsigned long long>(latencies.frames_dropped),
              static_cast<unsigned long long>(latencies.skipped));
}

// Sleeps `seconds` with the given parts started and idle; returns the process's CPU share.
double idleCpuPercent(double seconds) {
  const double cpu_start = fieldrig::bench::processCpuSeconds();
  const Clock::time_point start = Clock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  return 100.0 * (fieldrig::bench::processCpuSeconds() - cpu_start) / wall;
}

Latencies rigLatency(int triggers, std::chrono::milliseconds interval) {
  auto rig = drivers::Rig::create(sixSimCameras(), drivers::CameraRegistry::instance());
  if (!rig) {
    std::fprintf(stderr, "%s\n", rig.error().message.c_str());
    std::exit(1);
  }
  std::vector<Clock::time_point> sent(static_cast<std::size_t>(triggers) + 1);
  Latencies latencies;
  latencies.expected = static_cast<std::size_t>(triggers);
  latencies.us.reserve(latencies.expected);
  // The sink runs on the rig thread; `sent[id]` was written before trigger(id) pushed the id.
  if (!(*rig)->start([&](core::FrameSet&& set) { recordLatency(latencies, sent, set); })) {
    std::exit(1);
  }
  triggerAtInterval(sent, interval, [&](int i) { (*rig)->trigger(static_cast<std::uint64_t>(i)); });
  std::this_thread::sleep_for(std::chrono::milliseconds{600});  // the last sets' timeout
  (*rig)->stop();
  latencies.incomplete = (*rig)->stats().incomplete_sets;
  latencies.frames_missing = (*rig)->stats().frames_missing;
  latencies.frames_dropped = (*rig)->stats().frames_dropped;
  return latencies;
}

std::unique_ptr<daemon::Acquisition> makeAcquisition(const fs::path& dir) {
  daemon::AcquisitionOptions options;
  options.rig = sixSimCameras();
  options.session_dir = dir;
  options.writer.fsync = recording::FsyncPolicy::kNone;  // the disk is not what is measured
  options.processing_queue_sets = 4;
  auto acquisition = daemon::Acquisition::create(options, drivers::CameraRegistry::instance());
  if (!acquisition) {
    std::fprintf(stderr, "%s\n", acquisition.error().message.c_str());
    std::exit(1);
  }
  return std::move(*acquisition);
}

Latencies acquisitionLatency(const fs::path& dir, int triggers,
                             std::chrono::milliseconds interval) {
  auto acquisition = makeAcquisition(dir);
  std::vector<Clock::time_point> sent(static_cast<std::size_t>(triggers) + 1);
  Latencies latencies;
  latencies.expected = static_cast<std::size_t>(triggers);
  latencies.us.reserve(latencies.expected);
  // A new session numbers its sets from 1: the i-th trigger is set i.
  if (!acquisition->start(
          [&](const core::FrameSet& set) { recordLatency(latencies, sent, set); })) {
    std::exit(1);
  }
  triggerAtInterval(sent, interval, [&](int) { acquisition->trigger(); });
  acquisition->finish(std::chrono::seconds{10});
  const daemon::AcquisitionStats stats = acquisition->stats();
  latencies.incomplete = stats.rig.incomplete_sets;
  latencies.frames_missing = stats.rig.frames_missing;
  latencies.frames_dropped = stats.rig.frames_dropped;
  latencies.skipped = stats.sets_skipped_for_processing;
  return latencies;
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 300;
  const std::chrono::milliseconds interval{argc > 2 ? std::atoi(argv[2]) : 10};
  const double idle_s = argc > 3 ? std::atof(argv[3]) : 5.0;
  if (triggers <= 0 || interval.count() <= 0 || idle_s <= 0) {
    std::fprintf(stderr, "usage: trigger_to_record_bench [TRIGGERS] [INTERVAL_MS] [IDLE_S]\n");
    return 2;
  }
  sim::addSimCamera(drivers::CameraRegistry::instance());  // drivers/ knows nothing of sim/
  const fs::path root =
      fs::temp_directory_path() / ("trigger_to_record_bench_" + std::to_string(::getpid()));
  fs::create_directories(root);

  std::printf("six sim cameras 160x120, %d triggers every %lld ms\n\n", triggers,
              static_cast<long long>(interval.count()));
  std::printf(
      "| trigger → | whole sets | p50 µs | p99 µs | max µs | incomplete (frames) | skipped |\n"
      "|---|---|---|---|---|---|---|\n");
  printRow("rig sink", rigLatency(triggers, interval));
  printRow("acquisition consumer", acquisitionLatency(root / "latency", triggers, interval));

  std::printf("\n| idle, started | CPU %% of one core over %.0f s |\n|---|---|\n", idle_s);
  {
    auto rig = drivers::Rig::create(sixSimCameras(), drivers::CameraRegistry::instance());
    if (!rig || !(*rig)->start([](core::FrameSet&&) {}))
      return 1;
    std::printf("| rig | %.2f |\n", idleCpuPercent(idle_s));
    (*rig)->stop();
  }
  {
    auto acquisition = makeAcquisition(root / "idle");
    if (!acquisition->start([](const core::FrameSet&) {}))
      return 1;
    std::printf("| acquisition (rig, recorder, processing) | %.2f |\n", idleCpuPercent(idle_s));
    acquisition->finish(std::chrono::seconds{1});
  }
  fs::remove_all(root);
  return 0;
}
