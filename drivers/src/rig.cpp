#include "fieldrig/drivers/rig.h"

#include <algorithm>

namespace fieldrig::drivers {
namespace {
// The rig thread sleeps this long when nothing arrived: sets leave at most this late.
constexpr auto kIdlePoll = std::chrono::microseconds{200};
// Sets waiting for their frames at once: 256 triggers span 25 s at 10 Hz, far beyond any timeout.
constexpr std::size_t kMaxPendingSets = 256;
// Per camera: frames the rig thread may lag behind before a frame is dropped (counted).
constexpr std::size_t kFrameQueueCapacity = 64;
}  // namespace

core::Result<std::unique_ptr<Rig>> Rig::create(const RigOptions& options,
                                               const CameraRegistry& registry) {
  if (options.cameras.empty() || options.cameras.size() > core::FrameSet::kMaxCameras) {
    return core::Error{"rig: between 1 and " + std::to_string(core::FrameSet::kMaxCameras) +
                       " cameras are needed, " + std::to_string(options.cameras.size()) +
                       " configured"};
  }
  std::vector<std::unique_ptr<Camera>> cameras;
  for (std::size_t i = 0; i < options.cameras.size(); ++i) {
    auto camera = registry.create(options.driver);
    if (!camera)
      return camera.error();
    if (auto configured = (*camera)->configure(options.cameras[i]); !configured) {
      return core::Error{"rig camera " + std::to_string(i) + ": " + configured.error().message};
    }
    cameras.push_back(std::move(*camera));
  }
  return std::unique_ptr<Rig>(new Rig(options, std::move(cameras)));
}

Rig::Rig(RigOptions options, std::vector<std::unique_ptr<Camera>> cameras)
    : options_(std::move(options)), cameras_(std::move(cameras)) {
  std::size_t largest = 0;
  for (const CameraConfig& c : options_.cameras) {
    largest = std::max(largest, std::size_t{c.width} * c.height);
  }
  pool_ = std::make_unique<core::FramePool>(options_.pool_sets * cameras_.size(), largest);
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    frame_queues_.push_back(std::make_unique<core::SpscQueue<core::Frame>>(kFrameQueueCapacity));
  }
  pending_.resize(kMaxPendingSets);
}

Rig::~Rig() {
  stop();
}

core::Result<bool> Rig::start(SetSink sink) {
  if (running_)
    return core::Error{"rig: already started"};
  sink_ = std::move(sink);
  running_ = true;
  thread_ = std::thread([this] { run(); });
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    core::SpscQueue<core::Frame>* queue = frame_queues_[i].get();
    auto started = cameras_[i]->start(*pool_, [this, queue](core::Frame&& frame) {
      if (!queue->tryPush(frame))
        frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    });
    if (!started) {
      stop();
      return core::Error{"rig camera " + std::to_string(i) + ": " + started.error().message};
    }
  }
  return true;
}

void Rig::stop() {
  for (auto& camera : cameras_)
    camera->stop();  // no more frames after this
  if (!running_.exchange(false))
    return;
  if (thread_.joinable())
    thread_.join();
}

bool Rig::trigger(std::uint64_t trigger_id) {
  core::TriggerEvent event;
  event.trigger_id = trigger_id;
  return trigger(event);
}

bool Rig::trigger(const core::TriggerEvent& trigger_event) {
  const std::uint64_t trigger_id = trigger_event.trigger_id;
  const core::SteadyTime issued = std::chrono::steady_clock::now();
  IssuedTrigger issued_trigger{trigger_event, issued};
  issued_trigger.event.sent_time = core::UtcTime{std::chrono::duration_cast<core::Nanoseconds>(
      std::chrono::system_clock::now().time_since_epoch())};
  if (!running_ || !trigger_queue_.tryPush(issued_trigger)) {
    triggers_refused_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  triggers_.fetch_add(1, std::memory_order_relaxed);
  bool all = true;
  for (auto& camera : cameras_)
    all = camera->triggerAt(trigger_id, issued) && all;
  if (!all)  // the set still comes, its frames from the refusing cameras marked missing
    camera_refusals_.fetch_add(1, std::memory_order_relaxed);
  return all;
}

void Rig::run() {
  while (running_) {
    const bool busy = drain();
    emitReady(false);
    if (!busy)
      std::this_thread::sleep_for(kIdlePoll);
  }
  drain();
  emitReady(true);
}

bool Rig::drain() {
  bool any = false;
  IssuedTrigger trigger;
  while (trigger_queue_.tryPop(trigger)) {
    any = true;
    if (pending_count_ == pending_.size()) {
      // Every slot waits on a camera: the oldest leaves now, incomplete, to make room.
      forced_out_.fetch_add(1, std::memory_order_relaxed);
      emit(pending_[pending_head_]);
      popFront();
    }
    Pending& pending = pending_[(pending_head_ + pending_count_) % pending_.size()];
    ++pending_count_;
    pending.set = core::FrameSet{};  // releases nothing: emitted slots are already empty
    pending.arrived = 0;
    pending.set.trigger_id = trigger.event.trigger_id;
    pending.set.trigger = std::move(trigger.event);
    pending.set.camera_count = static_cast<std::uint32_t>(cameras_.size());
    for (std::uint32_t c = 0; c < cameras_.size(); ++c) {
      pending.set.frames[c].metadata.camera = c;
      pending.set.frames[c].metadata.trigger_id = pending.set.trigger_id;
      pending.set.frames[c].metadata.status = core::FrameStatus::kMissing;
    }
    pending.deadline = trigger.issued + options_.frame_timeout;
  }
  core::Frame frame;
  for (auto& queue : frame_queues_) {
    while (queue->tryPop(frame)) {
      any = true;
      Pending* pending = findPending(frame.metadata.trigger_id);
      const std::uint32_t camera = frame.metadata.camera;
      if (pending == nullptr || camera >= cameras_.size() ||
          pending->set.frames[camera].metadata.status != core::FrameStatus::kMissing) {
        unexpected_.fetch_add(1, std::memory_order_relaxed);
        frame = core::Frame{};  // its buffer back to the pool at once
        continue;
      }
      pending->set.frames[camera] = std::move(frame);
      ++pending->arrived;
    }
  }
  return any;
}

Rig::Pending* Rig::findPending(std::uint64_t trigger_id) {
  // Newest first: frames mostly belong to the latest triggers. At most kMaxPendingSets steps.
  for (std::size_t i = pending_count_; i-- > 0;) {
    Pending& pending = pending_[(pending_head_ + i) % pending_.size()];
    if (pending.set.trigger_id == trigger_id)
      return &pending;
  }
  return nullptr;
}

void Rig::popFront() {
  pending_head_ = (pending_head_ + 1) % pending_.size();
  --pending_count_;
}

void Rig::emitReady(bool flush_all) {
  const core::SteadyTime now = std::chrono::steady_clock::now();
  // In trigger order: a set leaves when whole or timed out, and never before an older one.
  while (pending_count_ > 0) {
    Pending& pending = pending_[pending_head_];
    if (!flush_all && pending.arrived < cameras_.size() && now < pending.deadline)
      break;
    emit(pending);
    popFront();
  }
}

void Rig::emit(Pending& pending) {
  core::FrameSet& set = pending.set;
  std::int64_t earliest = 0, latest = 0;
  bool first = true;
  for (std::uint32_t c = 0; c < set.camera_count; ++c) {
    const core::FrameMetadata& m = set.frames[c].metadata;
    if (m.status == core::FrameStatus::kMissing)
      missing_.fetch_add(1, std::memory_order_relaxed);
    if (m.status == core::FrameStatus::kCorrupt)
      corrupt_.fetch_add(1, std::memory_order_relaxed);
    if (m.status == core::FrameStatus::kDropped)  // the driver found the pool exhausted
      frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    if (m.status != core::FrameStatus::kOk && m.status != core::FrameStatus::kCorrupt)
      continue;
    earliest = first ? m.device_timestamp_ns : std::min(earliest, m.device_timestamp_ns);
    latest = first ? m.device_timestamp_ns : std::max(latest, m.device_timestamp_ns);
    first = false;
  }
  set.skew_ns = latest - earliest;
  if (set.skew_ns > std::chrono::nanoseconds(options_.max_skew).count()) {
    skew_flagged_.fetch_add(1, std::memory_order_relaxed);
  }
  std::int64_t seen = max_skew_ns_.load(std::memory_order_relaxed);
  while (set.skew_ns > seen && !max_skew_ns_.compare_exchange_weak(seen, set.skew_ns)) {
  }
  sets_.fetch_add(1, std::memory_order_relaxed);
  if (!set.complete())
    incomplete_.fetch_add(1, std::memory_order_relaxed);
  if (sink_)
    sink_(std::move(set));
  // A sink may copy instead of moving (the acquisition pushes copies to two queues): the slot
  // lets go of its buffers now, not when it is reused 256 triggers later.
  set = core::FrameSet{};
}

RigStats Rig::stats() const {
  RigStats s;
  s.triggers = triggers_.load();
  s.triggers_refused = triggers_refused_.load();
  s.camera_triggers_refused = camera_refusals_.load();
  s.sets = sets_.load();
  s.incomplete_sets = incomplete_.load();
  s.frames_missing = missing_.load();
  s.frames_corrupt = corrupt_.load();
  s.frames_dropped = frames_dropped_.load();
  s.frames_unexpected = unexpected_.load();
  s.skew_flagged = skew_flagged_.load();
  s.sets_forced_out = forced_out_.load();
  s.max_skew_ns = max_skew_ns_.load();
  return s;
}

}  // namespace fieldrig::drivers
