// The camera rig: owns the cameras (six Grasshoppers as three stereo heads in the field),
// triggers them together and groups their frames into one FrameSet per trigger.
//
// Grouping is the FrameGrouper's ordered merge, run on the rig's own thread. Frames reach that
// thread through one lock-free SPSC queue per camera, triggers through another, and each push
// rings the thread's doorbell: trigger() and the camera callbacks never wait, and the rig thread
// sleeps until a frame or trigger arrives or the oldest waiting set is due.
//
// Thread contract: create/start/stop on the owner thread; trigger() on one thread (the
// trigger thread); the SetSink runs on the rig's own thread and must not block.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/core/doorbell.h"
#include "fieldrig/core/frame.h"
#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/drivers/camera.h"
#include "fieldrig/drivers/frame_grouper.h"

namespace fieldrig::drivers {

struct RigOptions {
  std::string driver = "sim";
  std::vector<CameraConfig> cameras;             // in rig order: bottom L/R, middle L/R, top L/R
  std::chrono::milliseconds frame_timeout{500};  // after the trigger, a set leaves incomplete
  std::chrono::microseconds max_skew{125};       // the 1394b bus syncs to ~125 µs
  std::size_t pool_sets = 16;                    // buffers for this many sets are allocated
};

struct RigStats {
  std::uint64_t triggers = 0;
  std::uint64_t triggers_refused = 0;  // not taken at all (not running, id not increasing): no set
  std::uint64_t camera_triggers_refused = 0;  // a camera could not take it: its frame will miss
  std::uint64_t sets = 0;
  std::uint64_t incomplete_sets = 0;
  std::uint64_t frames_missing = 0;  // no frame before the timeout
  std::uint64_t frames_corrupt = 0;
  std::uint64_t frames_dropped = 0;  // pool exhausted or rig queue full
  std::uint64_t frames_unexpected =
      0;  // fit no waiting set: late, duplicate, unknown camera or trigger
  std::uint64_t skew_flagged = 0;
  std::uint64_t sets_forced_out = 0;  // left incomplete early: too many sets were waiting
  std::int64_t max_skew_ns = 0;
};

class Rig {
 public:
  using SetSink = std::function<void(core::FrameSet&& set)>;

  // What can be refused in the options without creating anything: the camera count, a driver
  // the registry does not have, a pool beyond what a pool can hold or larger than this machine's
  // memory. create() runs it first; fieldrigd --check-config runs it alone.
  static core::Result<void> checkOptions(const RigOptions& options, const CameraRegistry& registry);
  // Allocates the frame pool, creates and configures the cameras; errors name the camera (or the
  // pool) and the problem.
  static core::Result<std::unique_ptr<Rig>> create(const RigOptions& options,
                                                   const CameraRegistry& registry);
  ~Rig();
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  core::Result<void> start(SetSink sink);
  // Stops the cameras, emits what is pending (incomplete), joins the rig thread.
  void stop();
  // Triggers every camera for `event.trigger_id`; the event travels with the set (its sent_time
  // is stamped here). Never blocks; false if refused: not running, or the id is not above the
  // previous trigger's (ids order the merge).
  bool trigger(const core::TriggerEvent& event);
  // A trigger that no location asked for (manual, tests, `fieldrig acquire`).
  bool trigger(std::uint64_t trigger_id);

  RigStats stats() const;  // a snapshot; thread-safe
  // Each camera's link counters, in rig order (Camera::linkStats); thread-safe. Allocates: for
  // summaries and the status, never the trigger path.
  std::vector<CameraLinkStats> cameraLinkStats() const;
  std::size_t cameraCount() const { return cameras_.size(); }
  core::FramePool& pool() { return *pool_; }
  const core::FramePool& pool() const { return *pool_; }

 private:
  struct IssuedTrigger {
    core::TriggerEvent event;
    core::SteadyTime issued{};
  };

  Rig(RigOptions options, std::vector<std::unique_ptr<Camera>> cameras,
      std::unique_ptr<core::FramePool> pool);
  void run();
  void drainTriggers();
  void drainFrames();
  void publishStats();

  RigOptions options_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  std::unique_ptr<core::FramePool> pool_;
  std::vector<std::unique_ptr<core::SpscQueue<core::Frame>>> frame_queues_;  // one per camera
  core::SpscQueue<IssuedTrigger> trigger_queue_{1024};
  core::Doorbell wake_;  // rung by trigger() and the camera callbacks, and by stop()
  SetSink sink_;
  FrameGrouper grouper_;                          // rig thread only
  std::optional<std::uint64_t> last_trigger_id_;  // trigger thread only
  std::atomic<bool> running_{false};
  std::thread thread_;

  // Counters of the trigger thread and the camera callbacks.
  std::atomic<std::uint64_t> triggers_{0}, triggers_refused_{0}, camera_refusals_{0},
      frames_dropped_{0};
  mutable std::mutex stats_mutex_;
  FrameGrouperStats grouping_stats_;  // guarded by stats_mutex_: the rig thread's copy for stats()
};

}  // namespace fieldrig::drivers
