// The simulator camera: a real driver (same interface as the hardware ones) that serves a
// generated frame per trigger, or replays a recorded session, so that rig, recording and pipeline
// run without hardware.
//
// Generated: each frame is a deterministic pattern of (camera, trigger id): readers can check that
// the pixels they got belong to the frame the metadata names.
//
// Replay, with the option session=DIR: the camera's id is a camera index of the recorded session,
// and trigger k after start() (counted by trigger id: set (id - first id) mod N of the session's
// N sets) serves that set's recorded frame of this camera. Counting by id rather than by triggers
// taken keeps the six cameras on the same set even when one of them refused a trigger. After
// the last set the replay wraps around to the first: a long replay (a bench, a soak test) never
// runs dry. What was recorded comes out again:
//   - the pixels, byte for byte, and the recorded pixel format (the configured one is ignored);
//   - kOk and kCorrupt frames with their status; a recorded kMissing frame is not delivered at
//     all, so the rig times it out as missing again; a recorded kDropped one is delivered as
//     kDropped without pixels (what the sim does when its pool is dry);
//   - the device timestamps relative to the set's earliest one, added to the trigger instant:
//     the recorded skew between cameras is the replayed skew.
// configure() fails, naming the folder, when the session cannot be opened, has no sets, has no
// frame of this camera, or when a recorded frame is not the configured width × height (the rig
// sizes its pool from the configuration, so the configuration must say the recorded size).
// Frames are read into memory at configure() when this camera's frames total at most
// session_preload_mb=M MiB (default 64: every test session, a few dozen full frames): the worker
// then only copies, and a damaged file is an error at configure(). A larger session is read
// frame by frame on the worker thread, after each trigger (never on the trigger thread): memory
// stays bounded whatever the session's length; a frame that cannot be read then is delivered
// kCorrupt with zeroed pixels (the file is damaged; `fieldrig session info --verify` names it).
//
// Faults are injected on request through CameraConfig::options, on generated and replayed frames:
//   drop_every=N     no frame for trigger ids divisible by N
//   corrupt_every=N  frames of trigger ids divisible by N are delivered marked kCorrupt
//   delay_ms=D       each frame is delivered D ms after its trigger
//   clock_offset_us=U  added to the device timestamp (a camera out of sync by U µs)
//
// Thread contract: see Camera. Frames are produced on one worker thread per camera.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
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

  // The recorded session being replayed (session=DIR); defined in the .cpp so that this header
  // does not pull in the recording library's.
  struct Replay;

  // Opens the session of config.options["session"] for camera `index`, checked against the
  // configuration; errors name the folder.
  static core::Result<std::unique_ptr<Replay>> openReplay(const CameraConfig& config,
                                                          std::uint32_t index,
                                                          std::int64_t preload_mb);
  void run();
  void produce(const PendingTrigger& pending);
  // Fills `frame` from the recorded set of this trigger; false when nothing is to be delivered.
  bool replayInto(const PendingTrigger& pending, core::Frame& frame);

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
  std::unique_ptr<Replay> replay_;          // null when generating; set by configure()
  std::thread worker_;
};

}  // namespace fieldrig::drivers
