// Aravis' own fakes for the aravis driver's test and benchmark: arv-fake-gv-camera-0.8 speaking
// GigE Vision on the loopback (FakeGvCamera), a camera configured once the fake is up, and frames
// triggered one after another. The including target defines FIELDRIG_ARV_FAKE_GV_CAMERA: the
// fake's path, empty when aravis-tools is missing.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/drivers/camera.h"
#include "support/collector.h"

namespace fieldrig::testing_support {

// arv-fake-gv-camera-0.8 on the loopback, started by the constructor and killed by the destructor.
class FakeGvCamera {
 public:
  // The fake binds the GigE Vision control port on lo's 127.0.0.1 (it refuses loopback addresses
  // that lo does not carry, such as 127.0.0.2): a file lock keeps tests run in parallel (ctest -j),
  // and the benchmark, from starting two at once. Bounded: after kLockWait the caller goes on and
  // fails visibly. `lost_per_thousand`: the fake's packet loss (-r), none when empty.
  explicit FakeGvCamera(const std::string& lost_per_thousand = {}) {
    lock_ = ::open("/tmp/fieldrig-arv-fake-gv-camera.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    const auto deadline = std::chrono::steady_clock::now() + kLockWait;
    while (lock_ >= 0 && ::flock(lock_, LOCK_EX | LOCK_NB) != 0 &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds{50});
    }
    std::vector<std::string> args = {FIELDRIG_ARV_FAKE_GV_CAMERA, "-i", "lo"};
    if (!lost_per_thousand.empty()) {
      args.push_back("-r");
      args.push_back(lost_per_thousand);
    }
    pid_ = ::fork();
    if (pid_ == 0) {
      std::vector<char*> argv;
      for (auto& arg : args)
        argv.push_back(arg.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~FakeGvCamera() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds{2};
      while (::waitpid(pid_, nullptr, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > deadline) {
          ::kill(pid_, SIGKILL);
          ::waitpid(pid_, nullptr, 0);
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{10});
      }
    }
    if (lock_ >= 0)
      ::close(lock_);
  }
  FakeGvCamera(const FakeGvCamera&) = delete;
  FakeGvCamera& operator=(const FakeGvCamera&) = delete;

  static constexpr const char* address() { return "127.0.0.1"; }
  bool running() {
    if (pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) != 0)
      pid_ = -1;  // exited (and reaped): nothing to kill in teardown
    return pid_ > 0;
  }

 private:
  static constexpr auto kLockWait = std::chrono::seconds{60};
  int lock_ = -1;  // closing it releases the lock
  pid_t pid_ = -1;
};

// Configures `camera` for the fake, retrying while it starts up (bounded); configure()'s result.
inline auto configureWhenUp(drivers::Camera& camera, const drivers::CameraConfig& config,
                            FakeGvCamera& fake) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds{10};
  while (true) {
    auto configured = camera.configure(config);
    if (configured.ok() || std::chrono::steady_clock::now() > deadline || !fake.running())
      return configured;
    std::this_thread::sleep_for(std::chrono::milliseconds{100});
  }
}

struct SteppedTriggers {
  std::chrono::nanoseconds slowest{0};  // the longest one trigger() call took
  int refused = 0;                      // trigger() calls that returned false
};

// Triggers ids 1 … `count` on a started camera one after another, each once the previous frame
// reached `collector` or `timeout` passed, whichever is first: the fakes poll their trigger
// register once per 40 ms frame period, so triggers closer than that would merge into one frame.
// After a wait that timed out, a late frame (a damaged one is held until Aravis gives up on its
// packets) gets another `timeout` to land: counted as the next trigger's frame, it would send
// every later trigger one frame early, and a loaded host then merges them.
template <typename T>
SteppedTriggers triggerInStep(drivers::Camera& camera, Collector<T>& collector, int count,
                              std::chrono::milliseconds timeout) {
  SteppedTriggers run;
  for (int i = 1; i <= count; ++i) {
    const std::size_t frames = collector.size();
    const auto before = std::chrono::steady_clock::now();
    if (!camera.trigger(static_cast<std::uint64_t>(i)))
      ++run.refused;
    run.slowest = std::max(run.slowest, std::chrono::steady_clock::now() - before);
    if (!collector.waitFor(frames + 1, timeout))
      collector.waitFor(frames + 1, timeout);
  }
  return run;
}

}  // namespace fieldrig::testing_support
