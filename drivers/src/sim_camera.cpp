#include "fieldrig/drivers/sim_camera.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <optional>

#include "fieldrig/recording/session_reader.h"

namespace fieldrig::drivers {

struct SimCamera::Replay {
  // One recorded set, as this camera replays it.
  struct Entry {
    const recording::IndexedFrame* frame = nullptr;  // into reader.sets(); null: not in the set
    std::int64_t offset_ns = 0;        // device timestamp after the set's earliest one
    std::vector<std::uint8_t> pixels;  // preloaded; empty when read per trigger
  };

  explicit Replay(recording::SessionReader opened) : reader(std::move(opened)) {}

  recording::SessionReader reader;
  std::vector<Entry> entries;  // one per recorded set, in index order
  bool preloaded = false;
  // Worker thread only: the first trigger id since start() is set 0.
  std::optional<std::uint64_t> first_trigger_id;
};

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

std::string sizeText(std::uint64_t width, std::uint64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
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
  const auto preload_mb = config.options.contains("session_preload_mb")
                              ? integerOption(config, "session_preload_mb")
                              : core::Result<std::int64_t>{64};
  for (const auto* option : {&drop, &corrupt, &delay, &offset, &preload_mb}) {
    if (!option->ok())
      return option->error();
  }
  std::unique_ptr<Replay> replay;
  if (config.options.contains("session")) {
    auto opened = openReplay(config, index, *preload_mb);
    if (!opened)
      return opened.error();
    replay = std::move(opened).value();
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
  replay_ = std::move(replay);
  return true;
}

core::Result<std::unique_ptr<SimCamera::Replay>> SimCamera::openReplay(const CameraConfig& config,
                                                                       std::uint32_t index,
                                                                       std::int64_t preload_mb) {
  const std::filesystem::path dir = config.options.at("session");
  const std::string where = "sim camera " + config.id + ": session '" + dir.string() + "': ";
  auto opened = recording::SessionReader::open(dir);
  if (!opened)
    return core::Error{where + opened.error().message};
  auto replay = std::make_unique<Replay>(std::move(opened).value());
  const std::vector<recording::IndexedSet>& sets = replay->reader.sets();
  if (sets.empty())
    return core::Error{where + "no sets recorded"};
  replay->entries.resize(sets.size());
  std::uint64_t listed = 0;       // sets that name this camera, with or without pixels
  std::uint64_t pixel_bytes = 0;  // of this camera's frames with pixels
  for (std::size_t s = 0; s < sets.size(); ++s) {
    Replay::Entry& entry = replay->entries[s];
    // Offsets from the earliest frame with pixels: frames without have no meaningful timestamp.
    std::optional<std::int64_t> earliest;
    for (const recording::IndexedFrame& frame : sets[s].frames) {
      if (!frame.file.empty())
        earliest =
            std::min(earliest.value_or(frame.device_timestamp_ns), frame.device_timestamp_ns);
      if (frame.camera_index == static_cast<int>(index))
        entry.frame = &frame;
    }
    if (entry.frame == nullptr)
      continue;
    ++listed;
    if (entry.frame->file.empty())
      continue;
    entry.offset_ns = entry.frame->device_timestamp_ns - *earliest;
    if (static_cast<std::uint64_t>(entry.frame->width) != config.width ||
        static_cast<std::uint64_t>(entry.frame->height) != config.height) {
      return core::Error{where + entry.frame->file + " is " +
                         sizeText(static_cast<std::uint64_t>(entry.frame->width),
                                  static_cast<std::uint64_t>(entry.frame->height)) +
                         ", the camera is configured " + sizeText(config.width, config.height) +
                         ": configure the recorded size"};
    }
    pixel_bytes += std::uint64_t{config.width} * config.height;
  }
  if (listed == 0) {
    return core::Error{where + "no frame of camera " + std::to_string(index) + " in its " +
                       std::to_string(sets.size()) + " sets"};
  }
  constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
  replay->preloaded = (pixel_bytes + kMiB - 1) / kMiB <= static_cast<std::uint64_t>(preload_mb);
  if (replay->preloaded) {
    for (Replay::Entry& entry : replay->entries) {
      if (entry.frame == nullptr || entry.frame->file.empty())
        continue;
      auto image = replay->reader.loadFrame(*entry.frame);
      if (!image)
        return core::Error{where + image.error().message};
      entry.pixels = std::move(image->pixels);
    }
  }
  return replay;
}

core::Result<bool> SimCamera::start(core::FramePool& pool, FrameSink sink) {
  if (running_)
    return core::Error{"sim camera " + config_.id + ": already started"};
  if (pool.bufferBytes() < std::size_t{config_.width} * config_.height) {
    return core::Error{"sim camera " + config_.id + ": pool buffers are smaller than a frame"};
  }
  pool_ = &pool;
  sink_ = std::move(sink);
  if (replay_)
    replay_->first_trigger_id.reset();  // every start replays from the first set
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
  // Before any fault: a dropped first trigger still fixes where the replay starts.
  if (replay_ && !replay_->first_trigger_id)
    replay_->first_trigger_id = pending.id;
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
  if (replay_) {
    if (!replayInto(pending, frame))
      return;
  } else if (frame.buffer = pool_->acquire(); !frame.buffer) {
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
  }
  // Only a frame with pixels can be corrupt; a dropped one stays dropped.
  if (frame.buffer && corrupt_every_ != 0 && pending.id % corrupt_every_ == 0)
    m.status = core::FrameStatus::kCorrupt;
  m.received = core::ReceptionStamp::now();
  sink_(std::move(frame));
}

bool SimCamera::replayInto(const PendingTrigger& pending, core::Frame& frame) {
  core::FrameMetadata& m = frame.metadata;
  // Trigger ids increase (the rig's contract), so the difference is the trigger's position.
  const std::uint64_t position =
      (pending.id - *replay_->first_trigger_id) % replay_->entries.size();
  const Replay::Entry& entry = replay_->entries[position];
  const recording::IndexedFrame* recorded = entry.frame;
  if (recorded == nullptr)
    return false;  // the camera was not in this set: it is missing again
  if (recorded->file.empty() && recorded->status != recording::FrameStatus::kDropped)
    return false;  // recorded missing: deliver nothing, the rig's timeout marks it again
  m.format = recorded->pixel_format;
  m.device_timestamp_ns += entry.offset_ns;
  if (recorded->file.empty()) {
    m.status = core::FrameStatus::kDropped;
    return true;
  }
  frame.buffer = pool_->acquire();
  if (!frame.buffer) {
    m.status = core::FrameStatus::kDropped;
    return true;
  }
  // The width × height was checked at configure(): the recorded rows are packed like the buffer.
  std::uint8_t* out = frame.buffer.bytes().data();
  const std::size_t bytes = std::size_t{m.width} * m.height;
  m.status = recorded->status == recording::FrameStatus::kCorrupt ? core::FrameStatus::kCorrupt
                                                                  : core::FrameStatus::kOk;
  if (replay_->preloaded) {
    std::memcpy(out, entry.pixels.data(), bytes);
    return true;
  }
  // Read here, on the worker thread: a large session never has to fit in memory. loadFrame()
  // allocates the image it returns: the price of streaming (the preloaded path only copies).
  const auto image = replay_->reader.loadFrame(*recorded);
  if (!image || image->pixels.size() != bytes) {
    std::memset(out, 0, bytes);
    m.status = core::FrameStatus::kCorrupt;
    return true;
  }
  std::memcpy(out, image->pixels.data(), bytes);
  return true;
}

}  // namespace fieldrig::drivers
