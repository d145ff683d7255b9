#include "fieldrig/daemon/acquisition.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace fieldrig::daemon {
namespace {

// Sets whose frames went missing hold no buffers, so the pool alone does not bound the queue:
// room for this many sets (about 1 KB each, allocated at start) before one could be lost.
constexpr std::size_t kRecorderQueueSets = 4096;

std::string_view statusReason(core::FrameStatus status) {
  switch (status) {
    case core::FrameStatus::kOk:
      return "";
    case core::FrameStatus::kMissing:
      return "no frame before the rig's timeout";
    case core::FrameStatus::kCorrupt:
      return "the driver marked the frame damaged";
    case core::FrameStatus::kDropped:
      return "no free buffer: the frame pool was exhausted";
  }
  return "";
}

}  // namespace

core::Result<std::unique_ptr<Acquisition>> Acquisition::create(
    AcquisitionOptions options, const drivers::CameraRegistry& registry) {
  auto rig = drivers::Rig::create(options.rig, registry);
  if (!rig)
    return rig.error();
  std::unique_ptr<Acquisition> acquisition(new Acquisition(std::move(options)));
  acquisition->rig_ = std::move(*rig);
  const core::RigLayout& layout = acquisition->options_.layout;
  for (std::size_t i = 0; i < acquisition->options_.rig.cameras.size(); ++i) {
    acquisition->camera_names_.push_back(i < layout.cameraCount() ? layout.cameraName(i)
                                                                  : "camera" + std::to_string(i));
  }
  auto opened =
      acquisition->writer_.open(acquisition->options_.session_dir, acquisition->options_.session,
                                acquisition->options_.writer);
  if (!opened)
    return opened.error();
  if (opened->map_changed)
    spdlog::warn("session reopened with another map: {}", *opened->map_changed);
  acquisition->next_trigger_id_ = opened->next_set_index + 1;
  return acquisition;
}

Acquisition::Acquisition(AcquisitionOptions options)
    : options_(std::move(options)),
      to_recorder_(std::make_unique<core::SpscQueue<core::FrameSet>>(
          std::max(options_.rig.pool_sets + 1, kRecorderQueueSets))),
      to_processing_(
          std::make_unique<core::SpscQueue<core::FrameSet>>(options_.processing_queue_sets)) {}

Acquisition::~Acquisition() {
  if (running_)
    finish(std::chrono::milliseconds{0});
}

core::Result<void> Acquisition::start(ProcessSet process) {
  process_ = std::move(process);
  running_ = true;
  recorder_ = std::thread([this] { recordLoop(); });
  if (process_)
    processor_ = std::thread([this] { processLoop(); });
  auto started = rig_->start([this](core::FrameSet&& set) {
    if (process_) {
      if (to_processing_->tryPush(set)) {
        processing_bell_.ring();
      } else {
        skipped_.fetch_add(1, std::memory_order_relaxed);  // live processing only: it is recorded
        progress_.ring();
      }
    }
    if (to_recorder_->tryPush(set)) {
      recorder_bell_.ring();
    } else {
      // Only when the recorder is thousands of sets behind: counted, and said loudly.
      lost_.fetch_add(1, std::memory_order_relaxed);
      progress_.ring();
      spdlog::error("acquisition: recording queue full, set {} lost", set.trigger_id);
    }
  });
  if (!started) {
    finish(std::chrono::milliseconds{0});
    return started.error();
  }
  return {};
}

bool Acquisition::trigger(core::TriggerEvent event) {
  event.trigger_id = next_trigger_id_++;
  const bool accepted = rig_->trigger(event);
  triggered_.fetch_add(1);
  return accepted;
}

bool Acquisition::trigger() {
  return trigger(core::TriggerEvent{});
}

std::uint64_t Acquisition::inFlight() const {
  const std::uint64_t triggered = triggered_.load();
  const std::uint64_t refused = rig_->stats().triggers_refused;
  const std::uint64_t left_recording = recorded_.load() + lost_.load() + refused;
  std::uint64_t in_flight = triggered > left_recording ? triggered - left_recording : 0;
  if (process_) {
    const std::uint64_t left_processing = processed_.load() + skipped_.load() + refused;
    in_flight = std::max(in_flight, triggered > left_processing ? triggered - left_processing : 0);
  }
  return in_flight;
}

template <typename Done>
void Acquisition::waitForProgress(Done done, std::optional<core::SteadyTime> deadline) {
  while (true) {
    const core::Doorbell::Ticket ticket = progress_.ticket();
    if (done() || (deadline && std::chrono::steady_clock::now() >= *deadline))
      return;
    progress_.waitUntil(ticket, deadline);
  }
}

void Acquisition::waitForRoom(std::uint64_t room) {
  waitForProgress([&] { return waits_interrupted_ || recording_stopped_ || inFlight() < room; },
                  std::nullopt);
}

void Acquisition::interruptWaits() {
  waits_interrupted_ = true;
  progress_.ring();
}

void Acquisition::finish(std::chrono::milliseconds timeout) {
  waitForProgress(
      [&] {
        return recording_stopped_ ||
               recorded_.load() + lost_.load() + rig_->stats().triggers_refused >= triggered_;
      },
      std::chrono::steady_clock::now() + timeout);
  rig_->stop();  // emits what is still pending, incomplete
  running_ = false;
  recorder_bell_.ring();
  processing_bell_.ring();
  if (recorder_.joinable())
    recorder_.join();
  if (processor_.joinable())
    processor_.join();
  writer_.close();
}

void Acquisition::recordLoop() {
  recording::FrameSetRecord record;  // reused: its vectors and strings keep their capacity
  core::FrameSet set;
  while (true) {
    const core::Doorbell::Ticket ticket = recorder_bell_.ticket();
    if (!to_recorder_->tryPop(set)) {
      if (!running_)
        return;
      recorder_bell_.waitUntil(ticket, std::nullopt);
      continue;
    }
    if (writer_.stopped())
      continue;  // drained, not written: the alarm has been raised
    record.trigger_id = set.trigger_id;
    record.complete = set.complete();
    record.skew_us = static_cast<double>(set.skew_ns) / 1000.0;
    const core::TriggerEvent& event = set.trigger;
    if (event.location_id.empty()) {  // a manual trigger: when the rig sent it, host clock
      record.location_id.reset();
      record.fix.reset();
      record.trigger_time = event.sent_time != core::UtcTime{}
                                ? event.sent_time
                                : core::UtcTime{std::chrono::duration_cast<core::Nanoseconds>(
                                      std::chrono::system_clock::now().time_since_epoch())};
      record.planned_time.reset();
      record.trigger_status.reset();
    } else {
      record.location_id = event.location_id;
      record.fix = event.fix;
      record.trigger_time = event.time;
      record.planned_time = event.planned_time;
      record.trigger_status = std::string(core::toString(event.status));
    }
    if (event.sent_time != core::UtcTime{})
      record.sent_time = event.sent_time;
    else
      record.sent_time.reset();
    record.frames.resize(set.camera_count);
    for (std::uint32_t c = 0; c < set.camera_count; ++c) {
      const core::Frame& frame = set.frames[c];
      recording::FrameView& view = record.frames[c];
      view.camera_index = static_cast<int>(c);
      view.camera_name = camera_names_[c];
      view.width = static_cast<int>(frame.metadata.width);
      view.height = static_cast<int>(frame.metadata.height);
      view.stride = static_cast<int>(frame.metadata.stride);
      view.pixel_format = frame.metadata.format;
      view.pixels = frame.buffer ? std::span<const std::uint8_t>(frame.buffer.bytes())
                                 : std::span<const std::uint8_t>();
      view.device_timestamp_ns = frame.metadata.device_timestamp_ns;
      view.received = frame.metadata.received;
      view.sequence = frame.metadata.sequence;
      view.status = frame.metadata.status;
      if (!frame.buffer && view.status != core::FrameStatus::kDropped) {
        view.status = core::FrameStatus::kMissing;  // no pixels, whatever the driver said
      }
      view.reason = statusReason(frame.metadata.status);
    }
    const recording::WriteOutcome outcome = writer_.write(record);
    set = core::FrameSet{};  // buffers back to the pool now, not at the next pop
    if (!outcome.ok()) {
      alarm_ = outcome.message;
      recording_stopped_ = true;
      progress_.ring();
      spdlog::error("acquisition: recording stopped: {}", outcome.message);
      continue;
    }
    if (options_.on_recorded)
      options_.on_recorded(record.location_id.value_or(std::string()), record.complete);
    recorded_.fetch_add(1, std::memory_order_relaxed);
    bytes_.store(writer_.bytesWritten(), std::memory_order_relaxed);
    progress_.ring();
  }
}

void Acquisition::processLoop() {
  core::FrameSet set;
  while (true) {
    const core::Doorbell::Ticket ticket = processing_bell_.ticket();
    if (!to_processing_->tryPop(set)) {
      if (!running_)
        return;
      processing_bell_.waitUntil(ticket, std::nullopt);
      continue;
    }
    process_(set);
    set = core::FrameSet{};
    processed_.fetch_add(1, std::memory_order_relaxed);
    progress_.ring();
  }
}

std::size_t Acquisition::poolBytes() const {
  return rig_->pool().capacity() * rig_->pool().bufferBytes();
}

AcquisitionStats Acquisition::stats() const {
  AcquisitionStats s;
  s.rig = rig_->stats();
  s.sets_recorded = recorded_.load();
  s.sets_lost = lost_.load();
  s.sets_skipped_for_processing = skipped_.load();
  s.sets_processed = processed_.load();
  s.bytes_written = bytes_.load();
  s.recording_stopped = recording_stopped_.load();
  if (s.recording_stopped)
    s.alarm = alarm_;
  return s;
}

LinkSummary Acquisition::linkSummary() const {
  LinkSummary summary;
  const std::vector<drivers::CameraLinkStats> links = rig_->cameraLinkStats();
  for (std::size_t i = 0; i < links.size(); ++i) {
    const drivers::CameraLinkStats& link = links[i];
    if (link.has_packets) {
      summary.has_packets = true;
      summary.packets_resent += link.packets_resent;
      summary.packets_missing += link.packets_missing;
      summary.frames_missing_packets += link.frames_missing_packets;
    }
    if (link.counts_merged_triggers) {
      summary.counts_merged_triggers = true;
      summary.triggers_merged += link.triggers_merged;
    }
    summary.cameras.push_back(
        {i < camera_names_.size() ? camera_names_[i] : "camera" + std::to_string(i), link});
  }
  return summary;
}

}  // namespace fieldrig::daemon
