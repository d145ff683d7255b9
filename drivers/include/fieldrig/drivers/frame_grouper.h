// The rig's ordered merge (STYLE.md item 7): frames of N cameras, arriving in any order across
// cameras and triggers, grouped into one FrameSet per trigger. Every trigger waits for one frame
// of each camera; sets leave in trigger order, each as soon as it is whole and every older set
// has left, or when its deadline passes: then incomplete, the cameras that did not deliver
// marked kMissing. The spread of the frames' device timestamps is measured and flagged above a
// tolerance. Frames that fit no waiting set (late, duplicate, unknown camera or trigger) are
// released at once and counted; they never disturb a set.
//
// Pure: no clock (the caller passes the time), no thread, no I/O; the waiting sets live in a
// ring allocated at construction, so grouping allocates nothing per set.
//
// Thread contract: thread-compatible; the Rig calls it from its own thread only.
#pragma once

#include <boost/circular_buffer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>

#include "fieldrig/core/frame.h"

namespace fieldrig::drivers {

struct FrameGrouperOptions {
  std::uint32_t camera_count = 0;  // the inputs: every trigger waits for a frame of cameras 0..N-1
  std::chrono::nanoseconds timeout{std::chrono::milliseconds{500}};  // after the trigger
  std::chrono::nanoseconds max_skew{std::chrono::microseconds{125}};
  // Sets waiting at once; when a trigger finds them all waiting, the oldest leaves early.
  std::size_t max_waiting_sets = 256;
};

enum class FrameOutcome {
  kGrouped,         // in its set
  kLate,            // its trigger's set already left
  kDuplicate,       // its set already holds this camera's frame
  kUnknownCamera,   // camera index beyond camera_count
  kUnknownTrigger,  // for a trigger never announced (or refused)
};

struct FrameGrouperStats {
  std::uint64_t triggers_refused = 0;  // id not above the newest: ids are the merge's order
  std::uint64_t sets = 0;
  std::uint64_t incomplete_sets = 0;
  std::uint64_t sets_forced_out = 0;  // left incomplete early: too many sets were waiting
  std::uint64_t frames_missing = 0;   // none before the deadline
  std::uint64_t frames_corrupt = 0;
  std::uint64_t frames_dropped = 0;  // delivered marked dropped: the driver's pool ran dry
  std::uint64_t frames_late = 0;
  std::uint64_t frames_duplicate = 0;
  std::uint64_t frames_unknown_camera = 0;
  std::uint64_t frames_unknown_trigger = 0;
  std::uint64_t skew_flagged = 0;
  std::int64_t max_skew_ns = 0;

  // Every frame that fit no waiting set.
  std::uint64_t framesRejected() const {
    return frames_late + frames_duplicate + frames_unknown_camera + frames_unknown_trigger;
  }
};

class FrameGrouper {
 public:
  // Receives each set as it leaves, in trigger order; it may move or copy it.
  using SetSink = std::function<void(core::FrameSet&& set)>;

  FrameGrouper(const FrameGrouperOptions& options, SetSink sink);

  // Opens the set of `event.trigger_id`, to leave by `issued + timeout` at the latest. Ids must
  // increase; an id not above the newest one is refused (false, counted).
  bool addTrigger(core::TriggerEvent event, core::SteadyTime issued);
  // Puts the frame into its trigger's set (by metadata.camera and trigger_id); whole sets at the
  // front leave at once. Any other frame is released (its buffer back to the pool) and counted.
  FrameOutcome addFrame(core::Frame&& frame);
  // Lets go, in trigger order, the sets at the front that are whole or due at `now`.
  void advance(core::SteadyTime now);
  // Lets every waiting set go, incomplete ones marked (the rig stops).
  void flush();

  // True once a trigger with this id or a newer one was added: a frame for a trigger not yet
  // announced may only have overtaken its trigger on the way to the caller.
  bool announced(std::uint64_t trigger_id) const {
    return newest_trigger_ && trigger_id <= *newest_trigger_;
  }
  // When the oldest waiting set is due; none when no set waits.
  std::optional<core::SteadyTime> nextDeadline() const;
  std::size_t waitingSets() const { return waiting_.size(); }
  const FrameGrouperStats& stats() const { return stats_; }

 private:
  struct Waiting {
    core::FrameSet set;
    core::SteadyTime deadline{};
    std::uint32_t awaited = 0;  // bit c: camera c has not delivered yet
  };

  Waiting* find(std::uint64_t trigger_id);
  void emitFront();
  void measure(core::FrameSet& set);

  FrameGrouperOptions options_;
  SetSink sink_;
  boost::circular_buffer<Waiting> waiting_;  // oldest first; trigger ids increase along it
  std::optional<std::uint64_t> newest_trigger_;
  std::optional<std::uint64_t> last_emitted_;
  FrameGrouperStats stats_;
};

}  // namespace fieldrig::drivers
