// Whole run of the aravis driver against arv-fake-gv-camera-0.8 on the loopback (real GigE
// Vision over UDP): N software-triggered frames, each triggered once the previous one arrived
// (the fake serves at most one trigger per 40 ms frame period). Prints one JSON line: frames/s,
// lost and corrupt frames, the slowest trigger() call.
//
// With RATE_HZ > 0 the triggers follow a clock instead, as `fieldrig acquire` sends them: then a
// busy host bunches them, and what counts is that each trigger still gets its own frame. A
// trigger the camera merged into the previous one shows no frame-id gap. Matched in order, every
// later frame would carry an earlier trigger's id and its trigger-to-frame latency
// (`latency_ms_p50/p99/max`, from the trigger() call of the id the frame carries to its
// reception) would grow by a trigger period per merge; matched by time (the fake stamps with the
// host's clock: `matched_by_time`), the merge is counted (`triggers_merged`, also in `lost`) and
// later frames keep their own ids. `misnumbered`: whole frames whose camera frame id does not
// follow their trigger id (after a merge, every later one: the camera skipped no frame id).
// MIN_TRIGGER_INTERVAL_US sets the driver's pacing (default: the camera's frame period; 0: off).
//
//   aravis_fake_bench [COUNT=200] [WIDTH=1624] [HEIGHT=1224] [LOST_PER_THOUSAND=0] [RATE_HZ=0]
//                     [MIN_TRIGGER_INTERVAL_US]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/drivers/aravis/aravis_camera.h"
#include "support/aravis_fakes.h"
#include "support/collector.h"

namespace {

using namespace std::chrono_literals;
using fieldrig::drivers::AravisCamera;
using fieldrig::testing_support::Collector;
using fieldrig::testing_support::configureWhenUp;
using fieldrig::testing_support::FakeGvCamera;
using fieldrig::testing_support::triggerInStep;

int run(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 200;
  const auto width = static_cast<std::uint32_t>(argc > 2 ? std::atoi(argv[2]) : 1624);
  const auto height = static_cast<std::uint32_t>(argc > 3 ? std::atoi(argv[3]) : 1224);
  const std::string loss = argc > 4 ? argv[4] : "0";
  const double rate_hz = argc > 5 ? std::atof(argv[5]) : 0.0;
  const std::string min_interval = argc > 6 ? argv[6] : "";
  if (std::string(FIELDRIG_ARV_FAKE_GV_CAMERA).empty()) {
    std::fprintf(stderr, "arv-fake-gv-camera-0.8 not installed (package aravis-tools)\n");
    return 1;
  }

  int rc = 0;
  {
    FakeGvCamera fake(loss);
    AravisCamera camera;
    fieldrig::drivers::CameraConfig config;
    config.id = FakeGvCamera::address();
    config.format = fieldrig::core::PixelFormat::kMono8;
    config.width = width;
    config.height = height;
    if (!min_interval.empty())
      config.options["min_trigger_interval_us"] = min_interval;
    const auto configured = configureWhenUp(camera, config, fake);
    const auto pool = fieldrig::core::FramePool::create(16, std::size_t{width} * height);
    // Only the count matters here: each frame's metadata is kept, its buffer goes back at once.
    Collector<fieldrig::core::FrameMetadata> frames;
    if (!configured.ok()) {
      std::fprintf(stderr, "%s\n", configured.error().message.c_str());
      rc = 1;
    } else if (!pool) {
      std::fprintf(stderr, "%s\n", pool.error().message.c_str());
      rc = 1;
    } else if (auto started = camera.start(
                   **pool, frames.sinkKeeping<fieldrig::core::Frame>(
                               [](const fieldrig::core::Frame& frame) { return frame.metadata; }));
               !started.ok()) {
      std::fprintf(stderr, "%s\n", started.error().message.c_str());
      rc = 1;
    } else {
      const auto begin = std::chrono::steady_clock::now();
      std::chrono::nanoseconds slowest{0};
      std::vector<std::chrono::steady_clock::time_point> sent(static_cast<std::size_t>(count) + 1);
      if (rate_hz > 0) {
        const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(1.0 / rate_hz));
        for (int i = 1; i <= count; ++i) {
          std::this_thread::sleep_until(begin + (i - 1) * period);
          const auto before = std::chrono::steady_clock::now();
          sent[static_cast<std::size_t>(i)] = before;
          camera.trigger(static_cast<std::uint64_t>(i));
          slowest = std::max(slowest, std::chrono::steady_clock::now() - before);
        }
        frames.waitFor(static_cast<std::size_t>(count), 2000ms);
      } else {
        slowest = triggerInStep(camera, frames, count, 500ms).slowest;
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
      camera.stop();
      const auto s = camera.stats();
      // Whole frames whose frame id is not as far from the first whole frame's as their trigger
      // id is (16-bit block ids skip 0 when they wrap).
      std::uint64_t misnumbered = 0;
      const fieldrig::core::FrameMetadata* first = nullptr;
      const std::vector<fieldrig::core::FrameMetadata> kept = frames.items();
      for (const auto& m : kept) {
        if (m.status != fieldrig::core::FrameStatus::kOk)
          continue;
        if (first == nullptr)
          first = &m;
        std::uint64_t expected = first->sequence + (m.trigger_id - first->trigger_id);
        while (expected > 0xFFFF)
          expected -= 0xFFFF;
        if (m.sequence != expected)
          ++misnumbered;
      }
      std::vector<double> latency_ms;
      for (const auto& m : kept) {
        if (rate_hz > 0 && m.trigger_id >= 1 && m.trigger_id < sent.size()) {
          latency_ms.push_back(
              std::chrono::duration<double, std::milli>(m.received.steady - sent[m.trigger_id])
                  .count());
        }
      }
      std::sort(latency_ms.begin(), latency_ms.end());
      auto quantile = [&](double q) {
        return latency_ms.empty() ? 0.0
                                  : latency_ms[static_cast<std::size_t>(
                                        q * static_cast<double>(latency_ms.size() - 1))];
      };
      std::printf(
          "{\"bench\":\"aravis_fake_gv\",\"width\":%u,\"height\":%u,\"lost_per_thousand\":\"%s\","
          "\"triggers\":%d,\"frames\":%llu,\"corrupt\":%llu,\"lost\":%llu,\"failed\":%llu,"
          "\"frames_per_s\":%.2f,\"mb_per_s\":%.1f,\"slowest_trigger_call_us\":%.1f,"
          "\"stream_failures\":%llu,\"stream_underruns\":%llu,\"rate_hz\":%.1f,"
          "\"min_trigger_interval_us\":%lld,\"triggers_paced\":%llu,\"triggers_merged\":%llu,"
          "\"matched_by_time\":%llu,\"misnumbered\":%llu,"
          "\"packets_resent\":%llu,\"packets_missing\":%llu,\"latency_ms_p50\":%.1f,"
          "\"latency_ms_p99\":%.1f,\"latency_ms_max\":%.1f}\n",
          width, height, loss.c_str(), count, static_cast<unsigned long long>(s.frames_delivered),
          static_cast<unsigned long long>(s.frames_corrupt),
          static_cast<unsigned long long>(s.frames_lost),
          static_cast<unsigned long long>(s.triggers_failed),
          static_cast<double>(s.frames_delivered) / seconds,
          static_cast<double>(s.frames_delivered) * width * height / seconds / 1e6,
          std::chrono::duration<double, std::micro>(slowest).count(),
          static_cast<unsigned long long>(s.stream_failures),
          static_cast<unsigned long long>(s.stream_underruns), rate_hz,
          static_cast<long long>(s.min_trigger_interval_us),
          static_cast<unsigned long long>(s.triggers_paced),
          static_cast<unsigned long long>(s.triggers_merged),
          static_cast<unsigned long long>(s.frames_matched_by_time),
          static_cast<unsigned long long>(misnumbered),
          static_cast<unsigned long long>(s.packets_resent),
          static_cast<unsigned long long>(s.packets_missing), quantile(0.5), quantile(0.99),
          quantile(1.0));
    }
  }
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  return run(argc, argv);
}
