// Acquisition: the rig's FrameSets go to the recorder first (never dropped) and to live
// processing when it keeps up (skipped and counted when it does not).
//
//   rig thread ──► SpscQueue (sized to the pool: cannot overflow) ──► recorder thread ──► disk
//             └──► SpscQueue (small) ──► processing thread (optional)
//
// Each consumer sleeps on its doorbell until the rig thread pushes a set (core::Doorbell: the
// rig thread never waits on it); the owner's waits (finish, waitForRoom) sleep until a set
// leaves the pipeline.
//
// The recording queue is sized far beyond the pool: when the disk falls behind, the pool runs
// dry first and the cameras' frames are counted as dropped, in the open, while every set (if
// only with missing frames) still reaches the recording.
//
// Thread contract: construct, start, trigger and stop from one owner thread (trigger() never
// blocks); stats() from any thread.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/core/doorbell.h"
#include "fieldrig/core/frame.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/core/trigger_event.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/recording/session_writer.h"

namespace fieldrig::daemon {

struct AcquisitionOptions {
  drivers::RigOptions rig;
  std::filesystem::path session_dir;
  recording::SessionInfo session;
  recording::WriterOptions writer;
  core::RigLayout layout;  // names the cameras (rig order); cameras beyond it are "cameraN"
  std::size_t processing_queue_sets = 2;
  // Called on the recorder thread after each set is written (the location's id, empty for a
  // manual trigger; whether every camera delivered). Must be quick: the recorder waits on it.
  std::function<void(const std::string& location_id, bool complete)> on_recorded;
};

struct AcquisitionStats {
  drivers::RigStats rig;
  std::uint64_t sets_recorded = 0;
  std::uint64_t sets_lost = 0;  // never recorded: the recording queue was full
  std::uint64_t sets_skipped_for_processing = 0;
  std::uint64_t sets_processed = 0;
  std::uint64_t bytes_written = 0;
  bool recording_stopped = false;  // disk full or I/O error: see alarm
  std::string alarm;
};

// The cameras' links (drivers::CameraLinkStats) summed over the rig and per camera, for
// `fieldrig acquire`'s summary and the daemon's status. The packet totals count only the cameras
// whose transport has packets; with none (sim, dc1394) they are not known: has_packets false.
struct LinkSummary {
  struct Camera {
    std::string name;  // the layout's camera name
    drivers::CameraLinkStats link;
  };
  bool has_packets = false;
  std::uint64_t packets_resent = 0;
  std::uint64_t packets_missing = 0;
  std::uint64_t frames_missing_packets = 0;
  bool counts_merged_triggers = false;  // some camera's driver counts them
  std::uint64_t triggers_merged = 0;
  std::vector<Camera> cameras;  // rig order
};

class Acquisition {
 public:
  using ProcessSet = std::function<void(const core::FrameSet& set)>;

  // Opens the session and creates the rig; errors name what failed.
  static core::Result<std::unique_ptr<Acquisition>> create(AcquisitionOptions options,
                                                           const drivers::CameraRegistry& registry);
  ~Acquisition();

  // Starts the recorder (and processing, when given) and the rig.
  core::Result<void> start(ProcessSet process = {});
  // Triggers the next set for a location the planner chose: the event (location, fix, times)
  // travels with the set into the recording and to processing. Its trigger id is replaced by the
  // session's own numbering, which continues across reopenings. Never blocks.
  bool trigger(core::TriggerEvent event);
  // A set no location asked for (manual, `fieldrig acquire`): stamped with the host clock.
  bool trigger();
  // Waits (bounded) until every triggered set has left the rig and been recorded, then stops.
  void finish(std::chrono::milliseconds timeout);
  // Sleeps until fewer than `room` sets are in flight (see inFlight()), the recording stopped,
  // or interruptWaits() was called. Virtual-time replay paces its triggers on this.
  void waitForRoom(std::uint64_t room);
  // Ends waitForRoom() now and for good: the run is stopping. Any thread.
  void interruptWaits();

  AcquisitionStats stats() const;
  // Any thread; allocates (for summaries and the status, not for the trigger path).
  LinkSummary linkSummary() const;
  std::uint64_t triggered() const { return triggered_.load(); }
  // Triggered sets that have not yet left the pipeline: not recorded (or lost) or, when live
  // processing runs, not processed or skipped. Virtual-time replay paces itself on this.
  std::uint64_t inFlight() const;
  const std::vector<std::string>& cameraNames() const { return camera_names_; }
  std::size_t poolBytes() const;

 private:
  explicit Acquisition(AcquisitionOptions options);
  void recordLoop();
  void processLoop();
  // Owner thread: sleeps until done() or the deadline, looking again whenever a set leaves.
  template <typename Done>
  void waitForProgress(Done done, std::optional<core::SteadyTime> deadline);

  AcquisitionOptions options_;
  std::unique_ptr<drivers::Rig> rig_;
  recording::SessionWriter writer_;  // recorder thread only, once started
  std::unique_ptr<core::SpscQueue<core::FrameSet>> to_recorder_;
  std::unique_ptr<core::SpscQueue<core::FrameSet>> to_processing_;
  ProcessSet process_;
  std::vector<std::string> camera_names_;
  std::uint64_t next_trigger_id_ = 1;
  std::atomic<std::uint64_t> triggered_{0};
  std::atomic<bool> running_{false};
  std::thread recorder_;
  std::thread processor_;
  core::Doorbell recorder_bell_;    // a set for the recorder, or the end of the run
  core::Doorbell processing_bell_;  // a set for processing, or the end of the run
  core::Doorbell progress_;         // a set left the pipeline (or the recording stopped)
  std::atomic<bool> waits_interrupted_{false};

  std::atomic<std::uint64_t> recorded_{0}, lost_{0}, skipped_{0}, processed_{0}, bytes_{0};
  std::atomic<bool> recording_stopped_{false};
  std::string alarm_;  // written by the recorder thread before recording_stopped_ is set
};

}  // namespace fieldrig::daemon
