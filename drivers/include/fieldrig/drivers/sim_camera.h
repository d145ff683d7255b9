// The simulator camera: a real driver (same interface as the hardware ones) that serves a
// generated frame per trigger, so that rig, recording and pipeline run without hardware.
//
// Each frame is a deterministic pattern of (camera, trigger id): readers can check that the
// pixels they got belong to the frame the metadata names. Faults are injected on request through
// CameraConfig::options:
//   drop_every=N     no frame for trigger ids divisible by N
//   corrupt_every=N  frames of trigger ids divisible by N are delivered marked kCorrupt
//   delay_ms=D       each frame is delivered D ms after its trigger
//   clock_offset_us=U  added to the device timestamp (a camera out of sync by U µs)
//
// Thread contract: see Camera. Frames are produced on one worker thread per camera.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/drivers/camera.h"

namespace fieldrig::drivers {

class SimCamera final : public Camera {
 public:
  SimCamera();
  ~SimCamera() override;

  std::string driverName() const override { return "sim"; }
  core::Result<bool> configure(const CameraConfig& config) override;
  core::Result<bool> start(core::FramePool& pool, FrameSink sink) override;
  void stop() override;
  bool trigger(std::uint64_t trigger_id) override;
  // The sim's "exposure" happens at `issued` for every camera, as with a broadcast on the bus:
  // the rig's skew then measures the sim's injected clock offsets, not thread scheduling.
  bool triggerAt(std::uint64_t trigger_id, core::SteadyTime issued) override;

  // The pixel value the pattern puts at (x, y) of camera `camera_index`'s frame for a trigger.
  static std::uint8_t patternAt(std::uint32_t camera_index, std::uint64_t trigger_id,
                                std::uint32_t x, std::uint32_t y);

 private:
  struct PendingTrigger {
    std::uint64_t id = 0;
    core::SteadyTime at{};
  };

  void run();
  void produce(const PendingTrigger& pending);

  CameraConfig config_;
  std::uint32_t camera_index_ = 0;
  std::uint64_t drop_every_ = 0;
  std::uint64_t corrupt_every_ = 0;
  std::chrono::milliseconds delay_{0};
  std::int64_t clock_offset_ns_ = 0;
  core::FramePool* pool_ = nullptr;
  FrameSink sink_;
  core::SpscQueue<PendingTrigger> triggers_{256};
  std::atomic<std::uint32_t> wakeups_{0};  // bumped per trigger; the worker waits on it
  std::atomic<bool> running_{false};
  std::uint64_t sequence_ = 0;              // worker thread only
  std::vector<std::uint8_t> row_template_;  // x * 3 for one row, built by configure()
  std::thread worker_;
};

}  // namespace fieldrig::drivers
