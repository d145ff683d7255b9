#include "fieldrig/drivers/rig.h"

#include <unistd.h>

#include <algorithm>

namespace fieldrig::drivers {
namespace {
// Sets waiting for their frames at once: 256 triggers span 25 s at 10 Hz, far beyond any timeout.
constexpr std::size_t kMaxWaitingSets = 256;
// Per camera: frames the rig thread may lag behind before a frame is dropped (counted).
constexpr std::size_t kFrameQueueCapacity = 64;

FrameGrouperOptions grouperOptions(const RigOptions& options) {
  FrameGrouperOptions grouping;
  grouping.camera_count = static_cast<std::uint32_t>(options.cameras.size());
  grouping.timeout = options.frame_timeout;
  grouping.max_skew = options.max_skew;
  grouping.max_waiting_sets = kMaxWaitingSets;
  return grouping;
}
std::size_t largestFrame(const RigOptions& options) {
  std::size_t largest = 0;
  for (const CameraConfig& c : options.cameras)
    largest = std::max(largest, std::size_t{c.width} * c.height);
  return largest;
}
}  // namespace

core::Result<void> Rig::checkOptions(const RigOptions& options, const CameraRegistry& registry) {
  if (options.cameras.empty() || options.cameras.size() > core::FrameSet::kMaxCameras) {
    return core::Error{"rig: between 1 and " + std::to_string(core::FrameSet::kMaxCameras) +
                       " cameras are needed, " + std::to_string(options.cameras.size()) +
                       " configured"};
  }
  const std::vector<std::string> drivers = registry.names();
  if (std::find(drivers.begin(), drivers.end(), options.driver) == drivers.end()) {
    // The registry's own words, which list the drivers this build has.
    if (auto unknown = registry.create(options.driver); !unknown)
      return unknown.error();
  }
  // pool_sets is unbounded in the configuration: refused before the product can wrap.
  if (options.pool_sets > core::FramePool::kMaxBuffers / options.cameras.size()) {
    return core::Error{"rig: " + std::to_string(options.pool_sets) + " pool sets of " +
                       std::to_string(options.cameras.size()) + " cameras exceed the " +
                       std::to_string(core::FramePool::kMaxBuffers) + " buffers a pool can hold"};
  }
  // A pool larger than the machine can never be allocated (or only by swapping the frames out).
  const std::size_t buffers = options.pool_sets * options.cameras.size();
  const std::size_t largest = largestFrame(options);
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page_bytes = ::sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page_bytes > 0 && largest > 0) {
    const std::size_t memory =
        static_cast<std::size_t>(pages) * static_cast<std::size_t>(page_bytes);
    if (buffers > memory / largest) {
      return core::Error{"rig: " + std::to_string(options.pool_sets) + " pool sets of " +
                         std::to_string(options.cameras.size()) + " frames of " +
                         std::to_string(largest) + " bytes need more than this machine's " +
                         std::to_string(memory >> 20) + " MiB of memory"};
    }
  }
  return {};
}

core::Result<std::unique_ptr<Rig>> Rig::create(const RigOptions& options,
                                               const CameraRegistry& registry) {
  if (auto checked = checkOptions(options, registry); !checked)
    return checked.error();
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
  // The pool comes after the cameras, whose own errors explain a bad frame size better.
  auto pool =
      core::FramePool::create(options.pool_sets * options.cameras.size(), largestFrame(options));
  if (!pool)
    return core::Error{"rig: " + pool.error().message};
  return std::unique_ptr<Rig>(new Rig(options, std::move(cameras), std::move(*pool)));
}

Rig::Rig(RigOptions options, std::vector<std::unique_ptr<Camera>> cameras,
         std::unique_ptr<core::FramePool> pool)
    : options_(std::move(options)),
      cameras_(std::move(cameras)),
      pool_(std::move(pool)),
      grouper_(grouperOptions(options_), [this](core::FrameSet&& set) {
        if (sink_)
          sink_(std::move(set));
      }) {
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    frame_queues_.push_back(std::make_unique<core::SpscQueue<core::Frame>>(kFrameQueueCapacity));
  }
}

Rig::~Rig() {
  stop();
}

core::Result<void> Rig::start(SetSink sink) {
  if (running_)
    return core::Error{"rig: already started"};
  sink_ = std::move(sink);
  running_ = true;
  thread_ = std::thread([this] { run(); });
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    core::SpscQueue<core::Frame>* queue = frame_queues_[i].get();
    auto started = cameras_[i]->start(*pool_, [this, queue](core::Frame&& frame) {
      if (queue->tryPush(frame))
        wake_.ring();
      else
        frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    });
    if (!started) {
      stop();
      return core::Error{"rig camera " + std::to_string(i) + ": " + started.error().message};
    }
  }
  return {};
}

void Rig::stop() {
  for (auto& camera : cameras_)
    camera->stop();  // no more frames after this
  if (!running_.exchange(false))
    return;
  wake_.ring();
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
  const bool in_order = !last_trigger_id_ || trigger_id > *last_trigger_id_;
  if (!running_ || !in_order || !trigger_queue_.tryPush(issued_trigger)) {
    triggers_refused_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  last_trigger_id_ = trigger_id;
  wake_.ring();
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
    const core::Doorbell::Ticket ticket = wake_.ticket();
    drainTriggers();
    drainFrames();
    grouper_.advance(std::chrono::steady_clock::now());
    publishStats();
    wake_.waitUntil(ticket, grouper_.nextDeadline());
  }
  drainTriggers();
  drainFrames();
  grouper_.flush();
  publishStats();
}

void Rig::drainTriggers() {
  IssuedTrigger trigger;
  while (trigger_queue_.tryPop(trigger))
    grouper_.addTrigger(std::move(trigger.event), trigger.issued);
}

void Rig::drainFrames() {
  core::Frame frame;
  for (auto& queue : frame_queues_) {
    while (queue->tryPop(frame)) {
      // A camera may answer before this thread saw the trigger it answers.
      if (!grouper_.announced(frame.metadata.trigger_id))
        drainTriggers();
      grouper_.addFrame(std::move(frame));
    }
  }
}

void Rig::publishStats() {
  std::lock_guard lock(stats_mutex_);
  grouping_stats_ = grouper_.stats();
}

RigStats Rig::stats() const {
  FrameGrouperStats grouping;
  {
    std::lock_guard lock(stats_mutex_);
    grouping = grouping_stats_;
  }
  RigStats s;
  s.triggers = triggers_.load();
  s.triggers_refused = triggers_refused_.load();
  s.camera_triggers_refused = camera_refusals_.load();
  s.sets = grouping.sets;
  s.incomplete_sets = grouping.incomplete_sets;
  s.frames_missing = grouping.frames_missing;
  s.frames_corrupt = grouping.frames_corrupt;
  s.frames_dropped = grouping.frames_dropped + frames_dropped_.load();
  s.frames_unexpected = grouping.framesRejected();
  s.skew_flagged = grouping.skew_flagged;
  s.sets_forced_out = grouping.sets_forced_out;
  s.max_skew_ns = grouping.max_skew_ns;
  return s;
}

std::vector<CameraLinkStats> Rig::cameraLinkStats() const {
  std::vector<CameraLinkStats> links;
  links.reserve(cameras_.size());
  for (const auto& camera : cameras_)
    links.push_back(camera->linkStats());
  return links;
}

}  // namespace fieldrig::drivers
