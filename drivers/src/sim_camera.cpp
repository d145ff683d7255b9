#include "fieldrig/drivers/sim_camera.h"

#include <charconv>
#include <cstring>

namespace fieldrig::drivers {
namespace {

core::Result<std::int64_t> integerOption(const CameraConfig& config, const std::string& key) {
  const auto it = config.options.find(key);
  if (it == config.options.end())
    return std::int64_t{0};
  std::int64_t value = 0;
  const std::string& text = it->second;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || value < 0) {
    return core::Error{"sim camera " + config.id + ": option '" + key + "': '" + text +
                       "' is not a non-negative integer"};
  }
  return value;
}

}  // namespace

SimCamera::SimCamera() = default;

SimCamera::~SimCamera() {
  stop();
}

std::uint8_t SimCamera::patternAt(std::uint32_t camera_index, std::uint64_t trigger_id,
                                  std::uint32_t x, std::uint32_t y) {
  // Cheap to generate and to check, different for every camera, trigger and position.
  return static_cast<std::uint8_t>(x * 3 + y * 7 + camera_index * 31 + trigger_id * 13);
}

core::Result<bool> SimCamera::configure(const CameraConfig& config) {
  if (running_)
    return core::Error{"sim camera " + config.id + ": configure while running"};
  if (config.width == 0 || config.height == 0) {
    return core::Error{"sim camera " + config.id + ": width and height must be positive"};
  }
  std::uint32_t index = 0;
  const auto [ptr, ec] =
      std::from_chars(config.id.data(), config.id.data() + config.id.size(), index);
  if (ec != std::errc() || ptr != config.id.data() + config.id.size()) {
    return core::Error{"sim camera: id '" + config.id + "' is not a camera index"};
  }
  const auto drop = integerOption(config, "drop_every");
  const auto corrupt = integerOption(config, "corrupt_every");
  const auto delay = integerOption(config, "delay_ms");
  const auto offset = integerOption(config, "clock_offset_us");
  for (const auto* option : {&drop, &corrupt, &delay, &offset}) {
    if (!option->ok())
      return option->error();
  }
  config_ = config;
  camera_index_ = index;
  row_template_.resize(config.width);
  for (std::uint32_t x = 0; x < config.width; ++x) {
    row_template_[x] = static_cast<std::uint8_t>(patternAt(0, 0, x, 0));
  }
  drop_every_ = static_cast<std::uint64_t>(*drop);
  corrupt_every_ = static_cast<std::uint64_t>(*corrupt);
  delay_ = std::chrono::milliseconds{*delay};
  clock_offset_ns_ = *offset * 1000;
  return true;
}

core::Result<bool> SimCamera::start(core::FramePool& pool, FrameSink sink) {
  if (running_)
    return core::Error{"sim camera " + config_.id + ": already started"};
  if (pool.bufferBytes() < std::size_t{config_.width} * config_.height) {
    return core::Error{"sim camera " + config_.id + ": pool buffers are smaller than a frame"};
  }
  pool_ = &pool;
  sink_ = std::move(sink);
  running_ = true;
  worker_ = std::thread([this] { run(); });
  return true;
}

void SimCamera::stop() {
  if (!running_.exchange(false))
    return;
  wakeups_.fetch_add(1, std::memory_order_release);
  wakeups_.notify_one();
  if (worker_.joinable())
    worker_.join();
}

bool SimCamera::trigger(std::uint64_t trigger_id) {
  return triggerAt(trigger_id, std::chrono::steady_clock::now());
}

bool SimCamera::triggerAt(std::uint64_t trigger_id, core::SteadyTime issued) {
  if (!running_)
    return false;
  if (!triggers_.tryPush({trigger_id, issued}))
    return false;
  wakeups_.fetch_add(1, std::memory_order_release);
  wakeups_.notify_one();
  return true;
}

void SimCamera::run() {
  std::uint32_t seen = wakeups_.load(std::memory_order_acquire);
  while (true) {
    PendingTrigger pending;
    while (triggers_.tryPop(pending))
      produce(pending);
    if (!running_)
      return;
    wakeups_.wait(seen, std::memory_order_acquire);
    seen = wakeups_.load(std::memory_order_acquire);
  }
}

void SimCamera::produce(const PendingTrigger& pending) {
  if (drop_every_ != 0 && pending.id % drop_every_ == 0)
    return;
  if (delay_.count() > 0)
    std::this_thread::sleep_until(pending.at + delay_);
  core::Frame frame;
  core::FrameMetadata& m = frame.metadata;
  m.camera = camera_index_;
  m.trigger_id = pending.id;
  m.sequence = sequence_++;
  m.width = config_.width;
  m.height = config_.height;
  m.stride = config_.width;
  m.format = config_.format;
  // The "exposure" happened when triggered: the device clock is the host's steady clock here.
  m.device_timestamp_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(pending.at.time_since_epoch()).count() +
      clock_offset_ns_;
  frame.buffer = pool_->acquire();
  if (!frame.buffer) {
    m.status = core::FrameStatus::kDropped;
  } else {
    // Row y is the row template (x * 3) plus a per-row constant, in 8-bit wrap-around: the same
    // values patternAt() gives, at memory speed (the sim must keep up with six 2 MP cameras).
    std::uint8_t* pixels = frame.buffer.bytes().data();
    for (std::uint32_t y = 0; y < m.height; ++y) {
      const std::uint8_t base = patternAt(camera_index_, pending.id, 0, y);
      std::uint8_t* row = pixels + std::size_t{y} * m.stride;
      for (std::uint32_t x = 0; x < m.width; ++x) {
        row[x] = static_cast<std::uint8_t>(row_template_[x] + base);
      }
    }
    if (corrupt_every_ != 0 && pending.id % corrupt_every_ == 0) {
      m.status = core::FrameStatus::kCorrupt;
    }
  }
  m.received = core::ReceptionStamp::now();
  sink_(std::move(frame));
}

}  // namespace fieldrig::drivers
