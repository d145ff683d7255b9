#include "fieldrig/drivers/frame_grouper.h"

#include <algorithm>

namespace fieldrig::drivers {

FrameGrouper::FrameGrouper(const FrameGrouperOptions& options, SetSink sink)
    : options_(options),
      sink_(std::move(sink)),
      waiting_(std::max<std::size_t>(1, options.max_waiting_sets)) {
  // A FrameSet holds at most kMaxCameras frames; Rig::create refuses more cameras than that.
  options_.camera_count =
      std::min<std::uint32_t>(options_.camera_count, core::FrameSet::kMaxCameras);
}

bool FrameGrouper::addTrigger(core::TriggerEvent event, core::SteadyTime issued) {
  if (newest_trigger_ && event.trigger_id <= *newest_trigger_) {
    ++stats_.triggers_refused;
    return false;
  }
  newest_trigger_ = event.trigger_id;
  if (waiting_.full()) {
    // Every slot waits on a camera: the oldest leaves now, incomplete, to make room.
    ++stats_.sets_forced_out;
    emitFront();
  }
  waiting_.push_back();  // constructed in the ring's storage, allocated at construction
  Waiting& waiting = waiting_.back();
  waiting.deadline = issued + options_.timeout;
  waiting.awaited = (1u << options_.camera_count) - 1;
  core::FrameSet& set = waiting.set;
  set.trigger_id = event.trigger_id;
  set.trigger = std::move(event);
  set.camera_count = options_.camera_count;
  for (std::uint32_t c = 0; c < options_.camera_count; ++c) {
    core::FrameMetadata& metadata = set.frames[c].metadata;
    metadata.camera = c;
    metadata.trigger_id = set.trigger_id;
    metadata.status = core::FrameStatus::kMissing;
  }
  return true;
}

FrameOutcome FrameGrouper::addFrame(core::Frame&& frame) {
  const std::uint32_t camera = frame.metadata.camera;
  const std::uint64_t trigger_id = frame.metadata.trigger_id;
  Waiting* waiting = camera < options_.camera_count ? find(trigger_id) : nullptr;
  FrameOutcome outcome = FrameOutcome::kGrouped;
  if (camera >= options_.camera_count) {
    outcome = FrameOutcome::kUnknownCamera;
    ++stats_.frames_unknown_camera;
  } else if (waiting == nullptr && last_emitted_ && trigger_id <= *last_emitted_) {
    outcome = FrameOutcome::kLate;
    ++stats_.frames_late;
  } else if (waiting == nullptr) {
    outcome = FrameOutcome::kUnknownTrigger;
    ++stats_.frames_unknown_trigger;
  } else if ((waiting->awaited & (1u << camera)) == 0) {
    outcome = FrameOutcome::kDuplicate;
    ++stats_.frames_duplicate;
  }
  if (outcome != FrameOutcome::kGrouped) {
    frame = core::Frame{};  // its buffer back to the pool at once
    return outcome;
  }
  waiting->set.frames[camera] = std::move(frame);
  waiting->awaited &= ~(1u << camera);
  while (!waiting_.empty() && waiting_.front().awaited == 0)
    emitFront();
  return outcome;
}

void FrameGrouper::advance(core::SteadyTime now) {
  while (!waiting_.empty() && (waiting_.front().awaited == 0 || waiting_.front().deadline <= now)) {
    emitFront();
  }
}

void FrameGrouper::flush() {
  while (!waiting_.empty())
    emitFront();
}

std::optional<core::SteadyTime> FrameGrouper::nextDeadline() const {
  if (waiting_.empty())
    return std::nullopt;
  return waiting_.front().deadline;
}

FrameGrouper::Waiting* FrameGrouper::find(std::uint64_t trigger_id) {
  const auto it = std::lower_bound(
      waiting_.begin(), waiting_.end(), trigger_id,
      [](const Waiting& waiting, std::uint64_t id) { return waiting.set.trigger_id < id; });
  return it != waiting_.end() && it->set.trigger_id == trigger_id ? &*it : nullptr;
}

void FrameGrouper::emitFront() {
  core::FrameSet& set = waiting_.front().set;
  measure(set);
  last_emitted_ = set.trigger_id;
  if (sink_)
    sink_(std::move(set));
  // A sink may copy instead of moving (the acquisition pushes copies to two queues): the slot
  // lets go of its buffers now.
  waiting_.pop_front();
}

void FrameGrouper::measure(core::FrameSet& set) {
  std::int64_t earliest = 0, latest = 0;
  bool first = true;
  for (std::uint32_t c = 0; c < set.camera_count; ++c) {
    const core::FrameMetadata& m = set.frames[c].metadata;
    if (m.status == core::FrameStatus::kMissing)
      ++stats_.frames_missing;
    if (m.status == core::FrameStatus::kCorrupt)
      ++stats_.frames_corrupt;
    if (m.status == core::FrameStatus::kDropped)
      ++stats_.frames_dropped;
    if (m.status != core::FrameStatus::kOk && m.status != core::FrameStatus::kCorrupt)
      continue;
    earliest = first ? m.device_timestamp_ns : std::min(earliest, m.device_timestamp_ns);
    latest = first ? m.device_timestamp_ns : std::max(latest, m.device_timestamp_ns);
    first = false;
  }
  set.skew_ns = latest - earliest;
  if (set.skew_ns > options_.max_skew.count())
    ++stats_.skew_flagged;
  stats_.max_skew_ns = std::max(stats_.max_skew_ns, set.skew_ns);
  ++stats_.sets;
  if (!set.complete())
    ++stats_.incomplete_sets;
}

}  // namespace fieldrig::drivers
