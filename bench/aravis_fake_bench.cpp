// Whole run of the aravis driver against arv-fake-gv-camera-0.8 on the loopback (real GigE
// Vision over UDP): N software-triggered frames, each triggered once the previous one arrived
// (the fake serves at most one trigger per 40 ms frame period). Prints one JSON line: frames/s,
// lost and corrupt frames, the slowest trigger() call.
//
//   aravis_fake_bench [COUNT=200] [WIDTH=1624] [HEIGHT=1224] [LOST_PER_THOUSAND=0]
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/drivers/aravis/aravis_camera.h"

namespace {

using namespace std::chrono_literals;
using fieldrig::drivers::AravisCamera;

int run(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 200;
  const auto width = static_cast<std::uint32_t>(argc > 2 ? std::atoi(argv[2]) : 1624);
  const auto height = static_cast<std::uint32_t>(argc > 3 ? std::atoi(argv[3]) : 1224);
  const std::string loss = argc > 4 ? argv[4] : "0";
  if (std::string(FIELDRIG_ARV_FAKE_GV_CAMERA).empty()) {
    std::fprintf(stderr, "arv-fake-gv-camera-0.8 not installed (package aravis-tools)\n");
    return 1;
  }

  std::vector<std::string> args = {FIELDRIG_ARV_FAKE_GV_CAMERA, "-i", "lo", "-r", loss};
  const pid_t fake = fork();
  if (fake == 0) {
    std::vector<char*> argv_fake;
    for (auto& arg : args)
      argv_fake.push_back(arg.data());
    argv_fake.push_back(nullptr);
    execv(argv_fake[0], argv_fake.data());
    _exit(127);
  }

  int rc = 0;
  {
    AravisCamera camera;
    fieldrig::drivers::CameraConfig config;
    config.id = "127.0.0.1";
    config.format = fieldrig::core::PixelFormat::kMono8;
    config.width = width;
    config.height = height;
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    auto configured = camera.configure(config);
    while (!configured.ok() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(100ms);
      configured = camera.configure(config);
    }
    const auto pool = fieldrig::core::FramePool::create(16, std::size_t{width} * height);
    std::mutex mutex;
    std::condition_variable changed;
    std::size_t frames = 0;  // guarded by mutex
    if (!configured.ok()) {
      std::fprintf(stderr, "%s\n", configured.error().message.c_str());
      rc = 1;
    } else if (!pool) {
      std::fprintf(stderr, "%s\n", pool.error().message.c_str());
      rc = 1;
    } else if (auto started = camera.start(**pool,
                                           [&](fieldrig::core::Frame&&) {
                                             std::lock_guard lock(mutex);
                                             ++frames;
                                             changed.notify_all();
                                           });
               !started.ok()) {
      std::fprintf(stderr, "%s\n", started.error().message.c_str());
      rc = 1;
    } else {
      std::chrono::nanoseconds slowest{0};
      const auto begin = std::chrono::steady_clock::now();
      for (int i = 1; i <= count; ++i) {
        std::unique_lock lock(mutex);
        const std::size_t before = frames;
        lock.unlock();
        const auto t0 = std::chrono::steady_clock::now();
        camera.trigger(static_cast<std::uint64_t>(i));
        slowest = std::max(slowest, std::chrono::steady_clock::now() - t0);
        lock.lock();
        changed.wait_for(lock, 500ms, [&] { return frames > before; });
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
      camera.stop();
      const auto s = camera.stats();
      std::printf(
          "{\"bench\":\"aravis_fake_gv\",\"width\":%u,\"height\":%u,\"lost_per_thousand\":\"%s\","
          "\"triggers\":%d,\"frames\":%llu,\"corrupt\":%llu,\"lost\":%llu,\"failed\":%llu,"
          "\"frames_per_s\":%.2f,\"mb_per_s\":%.1f,\"slowest_trigger_call_us\":%.1f,"
          "\"stream_failures\":%llu,\"stream_underruns\":%llu}\n",
          width, height, loss.c_str(), count, static_cast<unsigned long long>(s.frames_delivered),
          static_cast<unsigned long long>(s.frames_corrupt),
          static_cast<unsigned long long>(s.frames_lost),
          static_cast<unsigned long long>(s.triggers_failed),
          static_cast<double>(s.frames_delivered) / seconds,
          static_cast<double>(s.frames_delivered) * width * height / seconds / 1e6,
          std::chrono::duration<double, std::micro>(slowest).count(),
          static_cast<unsigned long long>(s.stream_failures),
          static_cast<unsigned long long>(s.stream_underruns));
    }
  }
  kill(fake, SIGTERM);
  waitpid(fake, nullptr, 0);
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  return run(argc, argv);
}
