// The simulator camera: a real driver (the drivers' Camera interface, registered as "sim") that
// serves a frame per trigger from a frame source, so that rig, recording and pipeline run without
// hardware. Configured by CameraConfig (id: the camera index) and its options (README.md):
//   session=DIR           replay the recorded session DIR (SessionReplaySource); without it,
//                         generate a test pattern (TestPatternSource)
//   session_preload_mb=M  read the replayed frames into memory at configure() when this camera's
//                         total at most M MiB (default 64), else per trigger
//   drop_every=N, corrupt_every=N, delay_ms=D, clock_offset_us=U   faults (FaultInjector)
// Options it does not know are left to other drivers (a configuration gives every camera the same
// options). A bad value is an error at configure() naming the camera and the option.
//
// Thread contract: see Camera. Frames are produced on one worker thread per camera.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <thread>

#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/drivers/camera.h"
#include "fieldrig/sim/frame_source.h"

namespace fieldrig::sim {

class SimCamera final : public drivers::Camera {
 public:
  SimCamera();
  ~SimCamera() override;

  std::string driverName() const override { return "sim"; }
  core::Result<void> configure(const drivers::CameraConfig& config) override;
  core::Result<void> start(core::FramePool& pool, FrameSink sink) override;
  void stop() override;
  bool trigger(std::uint64_t trigger_id) override;
  // The sim's "exposure" happens at `issued` for every camera, as with a broadcast on the bus:
  // the rig's skew then measures the sim's injected clock offsets, not thread scheduling.
  bool triggerAt(std::uint64_t trigger_id, core::SteadyTime issued) override;

 private:
  struct PendingTrigger {
    std::uint64_t id = 0;
    core::SteadyTime at{};
  };

  void run();
  void produce(const PendingTrigger& pending);

  drivers::CameraConfig config_;
  std::uint32_t camera_index_ = 0;
  std::unique_ptr<FrameSource> source_;  // set by configure(); used by the worker thread
  core::FramePool* pool_ = nullptr;
  FrameSink sink_;
  core::SpscQueue<PendingTrigger> triggers_{256};
  std::atomic<std::uint32_t> wakeups_{0};  // bumped per trigger; the worker waits on it
  std::atomic<bool> running_{false};
  std::uint64_t sequence_ = 0;                     // frames delivered; worker thread only
  std::optional<std::uint64_t> first_trigger_id_;  // worker thread only; reset by start()
  std::thread worker_;
};

// Adds the "sim" driver to `registry`. drivers/ knows nothing of sim/: the programs, tests and
// benchmarks that want the sim driver call this once, before they create cameras.
void addSimCamera(drivers::CameraRegistry& registry);

}  // namespace fieldrig::sim
