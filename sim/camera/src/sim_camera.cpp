#include "fieldrig/sim/sim_camera.h"

#include <charconv>
#include <filesystem>
#include <string>

#include "fieldrig/sim/fault_injector.h"
#include "fieldrig/sim/session_replay_source.h"
#include "fieldrig/sim/test_pattern_source.h"

namespace fieldrig::sim {
namespace {

// An option that is absent takes `absent`; a present one must be a non-negative integer.
core::Result<std::int64_t> integerOption(const drivers::CameraConfig& config,
                                         const std::string& key, std::int64_t absent = 0) {
  const auto it = config.options.find(key);
  if (it == config.options.end())
    return absent;
  std::int64_t value = 0;
  const std::string& text = it->second;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size() || value < 0) {
    return core::Error{"sim camera " + config.id + ": option '" + key + "': '" + text +
                       "' is not a non-negative integer"};
  }
  return value;
}

// The frame source configured by `config`'s options, with its faults around it.
core::Result<std::unique_ptr<FrameSource>> makeSource(const drivers::CameraConfig& config,
                                                      std::uint32_t camera_index) {
  const auto drop = integerOption(config, "drop_every");
  const auto corrupt = integerOption(config, "corrupt_every");
  const auto delay = integerOption(config, "delay_ms");
  const auto offset = integerOption(config, "clock_offset_us");
  const auto preload_mb = integerOption(config, "session_preload_mb", 64);
  for (const auto* option : {&drop, &corrupt, &delay, &offset, &preload_mb}) {
    if (!option->ok())
      return option->error();
  }
  std::unique_ptr<FrameSource> source;
  if (const auto session = config.options.find("session"); session != config.options.end()) {
    auto replay = SessionReplaySource::open(config, camera_index, session->second,
                                            static_cast<std::uint64_t>(*preload_mb));
    if (!replay)
      return replay.error();
    source = std::move(replay).value();
  } else {
    source = std::make_unique<TestPatternSource>(config.width);
  }
  FaultOptions faults;
  faults.drop_every = static_cast<std::uint64_t>(*drop);
  faults.corrupt_every = static_cast<std::uint64_t>(*corrupt);
  faults.delay = std::chrono::milliseconds{*delay};
  faults.clock_offset = std::chrono::microseconds{*offset};
  return std::unique_ptr<FrameSource>(std::make_unique<FaultInjector>(std::move(source), faults));
}

}  // namespace

SimCamera::SimCamera() = default;

SimCamera::~SimCamera() {
  stop();
}

core::Result<void> SimCamera::configure(const drivers::CameraConfig& config) {
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
  auto source = makeSource(config, index);
  if (!source)
    return source.error();
  config_ = config;
  camera_index_ = index;
  source_ = std::move(source).value();
  return {};
}

core::Result<void> SimCamera::start(core::FramePool& pool, FrameSink sink) {
  if (running_)
    return core::Error{"sim camera " + config_.id + ": already started"};
  if (!source_)
    return core::Error{"sim camera " + config_.id + ": start before configure"};
  if (pool.bufferBytes() < std::size_t{config_.width} * config_.height) {
    return core::Error{"sim camera " + config_.id + ": pool buffers are smaller than a frame"};
  }
  pool_ = &pool;
  sink_ = std::move(sink);
  first_trigger_id_.reset();  // every start replays from the first set
  running_ = true;
  worker_ = std::thread([this] { run(); });
  return {};
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
  // Every trigger counts, dropped ones too: the first one fixes where a replay starts.
  if (!first_trigger_id_)
    first_trigger_id_ = pending.id;
  // Trigger ids increase (the rig's contract), so the difference is the trigger's position.
  const SimTrigger trigger{pending.id, pending.id - *first_trigger_id_, pending.at};
  core::Frame frame =
      stampedFrame(trigger, camera_index_, config_.width, config_.height, config_.format);
  if (!source_->fill(trigger, *pool_, frame))
    return;
  frame.metadata.sequence = sequence_++;
  frame.metadata.received = core::ReceptionStamp::now();
  sink_(std::move(frame));
}

void addSimCamera(drivers::CameraRegistry& registry) {
  registry.add("sim", [] { return std::make_unique<SimCamera>(); });
}

}  // namespace fieldrig::sim
