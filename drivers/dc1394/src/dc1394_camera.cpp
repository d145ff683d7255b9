#include "fieldrig/drivers/dc1394/dc1394_camera.h"

#include <dc1394/dc1394.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>

#include "fieldrig/drivers/dc1394/trigger_matcher.h"

namespace fieldrig::drivers {
namespace {

// The driver thread wakes at least this often to notice stop() and to expire missed triggers.
constexpr int kPollTimeoutMs = 50;
// Triggers sent but not yet answered by a frame; far more than a camera can have in flight.
constexpr std::size_t kPendingTriggers = 64;

struct BusDeleter {
  void operator()(dc1394_t* bus) const { dc1394_free(bus); }
};
struct CameraDeleter {
  void operator()(dc1394camera_t* camera) const { dc1394_camera_free(camera); }
};
struct ListDeleter {
  void operator()(dc1394camera_list_t* list) const { dc1394_camera_free_list(list); }
};
using BusPtr = std::unique_ptr<dc1394_t, BusDeleter>;
using CameraHandle = std::unique_ptr<dc1394camera_t, CameraDeleter>;
using ListPtr = std::unique_ptr<dc1394camera_list_t, ListDeleter>;

// libdc1394 frame timestamps are microseconds of the host's system clock.
std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::optional<core::Error> failed(dc1394error_t err, const std::string& who,
                                  const std::string& what) {
  if (err == DC1394_SUCCESS)
    return std::nullopt;
  return core::Error{who + ": " + what + ": " + dc1394_error_get_string(err)};
}

// libdc1394 prints to stderr by default; route it through the process's logger instead.
void routeLibraryLog() {
  static std::once_flag once;
  std::call_once(once, [] {
    auto handler = [](dc1394log_t type, const char* message, void*) {
      if (type == DC1394_LOG_ERROR)
        spdlog::error("libdc1394: {}", message);
      else
        spdlog::warn("libdc1394: {}", message);
    };
    dc1394_log_register_handler(DC1394_LOG_ERROR, handler, nullptr);
    dc1394_log_register_handler(DC1394_LOG_WARNING, handler, nullptr);
  });
}

// Why the bus looks absent, for the operator: no /dev/fw* means no controller or no driver.
std::string busNodesDetail() {
  std::error_code ec;
  std::size_t nodes = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    if (entry.path().filename().string().starts_with("fw"))
      ++nodes;
  }
  if (nodes == 0) {
    return "no /dev/fw* device (no FireWire controller, or the firewire-ohci module is not "
           "loaded, or no permission)";
  }
  return std::to_string(nodes) + " /dev/fw* node(s) present but no IIDC camera answered";
}

core::Error noBus(const std::string& who, const std::string& why) {
  return core::Error{who + ": no IEEE-1394 bus/camera found: " + why + "; " + busNodesDetail()};
}

std::optional<core::PixelFormat> formatOfFilter(dc1394color_filter_t filter) {
  switch (filter) {
    case DC1394_COLOR_FILTER_RGGB:
      return core::PixelFormat::kBayerRG8;
    case DC1394_COLOR_FILTER_GBRG:
      return core::PixelFormat::kBayerGB8;
    case DC1394_COLOR_FILTER_GRBG:
      return core::PixelFormat::kBayerGR8;
    case DC1394_COLOR_FILTER_BGGR:
      return core::PixelFormat::kBayerBG8;
  }
  return std::nullopt;
}

// Owns the camera's isochronous state from capture setup on: whatever path leaves start(), the
// driver thread or the driver (error, stop, destructor), transmission is turned off, the DMA
// ring is torn down and the ISO channel and bandwidth go back to the bus. A leaked allocation
// would shrink the bus budget for every later run until the next bus reset.
class IsoSession {
 public:
  explicit IsoSession(dc1394camera_t* camera) : camera_(camera) {}
  ~IsoSession() {
    if (transmitting_)
      dc1394_video_set_transmission(camera_, DC1394_OFF);
    if (capturing_)
      dc1394_capture_stop(camera_);
    dc1394_iso_release_all(camera_);
  }
  IsoSession(const IsoSession&) = delete;
  IsoSession& operator=(const IsoSession&) = delete;

  void capturing() { capturing_ = true; }
  void transmitting() { transmitting_ = true; }

 private:
  dc1394camera_t* camera_;
  bool capturing_ = false;
  bool transmitting_ = false;
};

// Gives a dequeued DMA buffer back to the ring on every path out of the frame handler.
class Requeue {
 public:
  Requeue(dc1394camera_t* camera, dc1394video_frame_t* frame) : camera_(camera), frame_(frame) {}
  ~Requeue() { dc1394_capture_enqueue(camera_, frame_); }
  Requeue(const Requeue&) = delete;
  Requeue& operator=(const Requeue&) = delete;

 private:
  dc1394camera_t* camera_;
  dc1394video_frame_t* frame_;
};

void raiseMax(std::atomic<std::uint64_t>& max, std::uint64_t value) {
  std::uint64_t seen = max.load(std::memory_order_relaxed);
  while (value > seen && !max.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
  }
}

}  // namespace

// Declared in this order so that the session goes before the camera, and the camera before the
// bus context.
struct Dc1394Camera::Device {
  BusPtr bus;
  CameraHandle camera;
  std::uint64_t guid = 0;
  dc1394video_mode_t mode = DC1394_VIDEO_MODE_FORMAT7_0;
  std::unique_ptr<IsoSession> session;
  int capture_fd = -1;
  std::optional<TriggerMatcher> matcher;  // driver thread only while running
};

std::unique_ptr<Camera> makeDc1394Camera() {
  return std::make_unique<Dc1394Camera>();
}

Dc1394Camera::Dc1394Camera() : wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

Dc1394Camera::~Dc1394Camera() {
  stop();
  device_.reset();
  if (wake_fd_ >= 0)
    ::close(wake_fd_);
}

core::Result<void> Dc1394Camera::configure(const CameraConfig& config) {
  const std::string who = "dc1394 camera " + config.id;
  if (running_)
    return core::Error{who + ": configure while running"};
  auto settings = dc1394SettingsFromConfig(config);
  if (!settings.ok())
    return settings.error();
  routeLibraryLog();

  // A failed configure leaves the camera unconfigured, and the old handle is closed before the
  // camera is opened again.
  device_.reset();
  auto device = std::make_unique<Device>();
  device->bus.reset(dc1394_new());
  if (!device->bus)
    return noBus(who, "libdc1394 could not start (dc1394_new failed)");
  dc1394camera_list_t* raw_list = nullptr;
  const dc1394error_t listed = dc1394_camera_enumerate(device->bus.get(), &raw_list);
  const ListPtr list(raw_list);
  if (listed != DC1394_SUCCESS) {
    return noBus(
        who, std::string("camera enumeration failed (") + dc1394_error_get_string(listed) + ")");
  }
  if (!list || list->num == 0)
    return noBus(who, "libdc1394 enumerated 0 cameras");

  if (settings->guid) {
    std::string found;
    for (std::uint32_t i = 0; i < list->num; ++i) {
      if (list->ids[i].guid == *settings->guid)
        device->guid = *settings->guid;
      found += (found.empty() ? "" : ", ") + formatGuid(list->ids[i].guid);
    }
    if (device->guid != *settings->guid || device->guid == 0) {
      return core::Error{who + ": camera GUID " + formatGuid(*settings->guid) +
                         " is not on the bus (found: " + found + ")"};
    }
  } else {
    device->guid = list->ids[0].guid;
  }
  device->camera.reset(dc1394_camera_new(device->bus.get(), device->guid));
  if (!device->camera)
    return core::Error{who + ": cannot open camera " + formatGuid(device->guid)};
  dc1394camera_t* camera = device->camera.get();
  const Dc1394Settings& s = *settings;

  // Bus mode and speed: S800 exists only in 1394b operation mode.
  if (auto e = failed(dc1394_video_set_operation_mode(camera, s.operation_mode_1394b
                                                                  ? DC1394_OPERATION_MODE_1394B
                                                                  : DC1394_OPERATION_MODE_LEGACY),
                      who, s.operation_mode_1394b ? "set 1394b mode" : "set legacy mode"))
    return *e;
  if (auto e =
          failed(dc1394_video_set_iso_speed(
                     camera, s.iso_speed_mbps == 800 ? DC1394_ISO_SPEED_800 : DC1394_ISO_SPEED_400),
                 who, "set ISO speed " + std::to_string(s.iso_speed_mbps)))
    return *e;

  // Format7: mode, RAW8, ROI checked against the sensor, then the planned packet size.
  device->mode = static_cast<dc1394video_mode_t>(DC1394_VIDEO_MODE_FORMAT7_0 + s.format7_mode);
  const std::string mode_name = "Format7 mode " + std::to_string(s.format7_mode);
  if (auto e = failed(dc1394_video_set_mode(camera, device->mode), who, "set " + mode_name))
    return *e;
  std::uint32_t max_width = 0;
  std::uint32_t max_height = 0;
  if (auto e =
          failed(dc1394_format7_get_max_image_size(camera, device->mode, &max_width, &max_height),
                 who, mode_name + " max image size"))
    return *e;
  if (s.left + s.width > max_width || s.top + s.height > max_height) {
    return core::Error{who + ": ROI " + std::to_string(s.width) + "×" + std::to_string(s.height) +
                       "+" + std::to_string(s.left) + "+" + std::to_string(s.top) +
                       " exceeds the sensor's " + std::to_string(max_width) + "×" +
                       std::to_string(max_height)};
  }
  if (auto e = failed(dc1394_format7_set_roi(camera, device->mode, DC1394_COLOR_CODING_RAW8,
                                             DC1394_USE_MAX_AVAIL, static_cast<int>(s.left),
                                             static_cast<int>(s.top), static_cast<int>(s.width),
                                             static_cast<int>(s.height)),
                      who, mode_name + " RAW8 ROI"))
    return *e;
  dc1394color_filter_t filter{};
  if (dc1394_format7_get_color_filter(camera, device->mode, &filter) == DC1394_SUCCESS) {
    const auto reported = formatOfFilter(filter);
    if (reported && *reported != s.format) {
      return core::Error{who + ": the camera's colour filter is " +
                         std::string(core::toString(*reported)) + " but the configuration says " +
                         std::string(core::toString(s.format))};
    }
  }
  std::uint32_t unit_bytes = 0;
  std::uint32_t max_bytes = 0;
  if (auto e = failed(
          dc1394_format7_get_packet_parameters(camera, device->mode, &unit_bytes, &max_bytes), who,
          mode_name + " packet parameters"))
    return *e;
  auto plan = requireIsoPlan(dc1394IsoRequest(s, unit_bytes, max_bytes));
  if (!plan.ok())
    return core::Error{who + ": " + plan.error().message};
  if (auto e = failed(dc1394_format7_set_packet_size(camera, device->mode, plan->packet_bytes), who,
                      mode_name + " packet size " + std::to_string(plan->packet_bytes)))
    return *e;

  // Trigger mode 0: one exposure of the programmed length per trigger.
  if (auto e = failed(dc1394_external_trigger_set_mode(camera, DC1394_TRIGGER_MODE_0), who,
                      "set trigger mode 0"))
    return *e;
  const bool software = s.trigger == TriggerSource::kSoftware;
  if (auto e =
          failed(dc1394_external_trigger_set_source(
                     camera, software ? DC1394_TRIGGER_SOURCE_SOFTWARE : DC1394_TRIGGER_SOURCE_0),
                 who, software ? "set software trigger source" : "set trigger source 0"))
    return *e;
  if (auto e =
          failed(dc1394_external_trigger_set_power(camera, DC1394_ON), who, "turn the trigger on"))
    return *e;
  if (s.broadcast == Dc1394Broadcast::kSend) {
    // Not every libdc1394 platform can address the broadcast node: find out now, not by six
    // cameras that never expose.
    const dc1394error_t on = dc1394_camera_set_broadcast(camera, DC1394_TRUE);
    dc1394_camera_set_broadcast(camera, DC1394_FALSE);
    if (auto e = failed(on, who, "broadcast trigger (use trigger_broadcast=off)"))
      return *e;
  }

  // Exposure and gain in absolute units (seconds, dB), as CameraConfig states them.
  struct Absolute {
    dc1394feature_t feature;
    float value;
    const char* name;
  };
  for (const Absolute& a :
       {Absolute{DC1394_FEATURE_SHUTTER, static_cast<float>(s.exposure_us * 1e-6), "shutter"},
        Absolute{DC1394_FEATURE_GAIN, static_cast<float>(s.gain_db), "gain"}}) {
    if (auto e = failed(dc1394_feature_set_mode(camera, a.feature, DC1394_FEATURE_MODE_MANUAL), who,
                        std::string(a.name) + " manual mode"))
      return *e;
    if (auto e = failed(dc1394_feature_set_absolute_control(camera, a.feature, DC1394_ON), who,
                        std::string(a.name) + " absolute control"))
      return *e;
    if (auto e = failed(dc1394_feature_set_absolute_value(camera, a.feature, a.value), who,
                        std::string(a.name) + " value"))
      return *e;
  }
  if (s.white_balance) {
    // IIDC white balance has no absolute unit: the pair is the camera's register values.
    const auto blue = static_cast<std::uint32_t>(std::lround(s.white_balance->first));
    const auto red = static_cast<std::uint32_t>(std::lround(s.white_balance->second));
    if (auto e = failed(dc1394_feature_set_mode(camera, DC1394_FEATURE_WHITE_BALANCE,
                                                DC1394_FEATURE_MODE_MANUAL),
                        who, "white balance manual mode"))
      return *e;
    if (auto e = failed(dc1394_feature_whitebalance_set_value(camera, blue, red), who,
                        "white balance value"))
      return *e;
  }

  settings_ = s;
  plan_ = *plan;
  device_ = std::move(device);
  spdlog::info(
      "{}: GUID {}, {} at S{}, {}×{} RAW8, {}-byte packets, {} packets a frame, "
      "{:.2f} Hz at most",
      who, formatGuid(device_->guid), mode_name, s.iso_speed_mbps, s.width, s.height,
      plan_.packet_bytes, plan_.packets_per_frame, plan_.max_rate_hz);
  return {};
}

core::Result<void> Dc1394Camera::start(core::FramePool& pool, FrameSink sink) {
  const std::string who = "dc1394 camera " + formatGuid(device_ ? device_->guid : 0);
  if (running_)
    return core::Error{who + ": already started"};
  if (!device_ || !device_->camera)
    return core::Error{"dc1394 camera: start before a successful configure"};
  if (pool.bufferBytes() < std::size_t{settings_.width} * settings_.height)
    return core::Error{who + ": pool buffers are smaller than a frame"};
  if (wake_fd_ < 0)
    return core::Error{who + ": eventfd failed: " + std::strerror(errno)};
  dc1394camera_t* camera = device_->camera.get();

  auto session = std::make_unique<IsoSession>(camera);
  if (auto e =
          failed(dc1394_capture_setup(camera, settings_.dma_buffers, DC1394_CAPTURE_FLAGS_DEFAULT),
                 who, "capture setup (DMA ring, ISO channel and bandwidth)"))
    return *e;  // the session releases whatever the setup allocated
  session->capturing();
  device_->capture_fd = dc1394_capture_get_fileno(camera);
  if (auto e =
          failed(dc1394_video_set_transmission(camera, DC1394_ON), who, "turn transmission on"))
    return *e;
  session->transmitting();

  // Frames finish exposure + transfer after their trigger; half a trigger period of slack tells
  // a late frame from a missed trigger.
  const auto transfer_us = static_cast<std::int64_t>(plan_.packets_per_frame) * 125;
  const auto slack_us = static_cast<std::int64_t>(0.5e6 / settings_.rate_hz);
  device_->matcher.emplace(
      kPendingTriggers, static_cast<std::int64_t>(settings_.exposure_us) + transfer_us + slack_us);
  device_->session = std::move(session);
  pool_ = &pool;
  sink_ = std::move(sink);
  sequence_ = 0;
  PendingTrigger stale;
  while (triggers_.tryPop(stale)) {
  }
  running_ = true;
  worker_ = std::thread([this] { run(); });
  return {};
}

void Dc1394Camera::stop() {
  if (running_.exchange(false)) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const auto written = ::write(wake_fd_, &one, sizeof one);
    if (worker_.joinable())
      worker_.join();
  }
  if (device_)
    device_->session.reset();  // transmission off, capture stopped, ISO released
}

bool Dc1394Camera::trigger(std::uint64_t trigger_id) {
  if (!running_ || !triggers_.tryPush({trigger_id, nowUs()})) {
    triggers_refused_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // eventfd writes never block (EFD_NONBLOCK); the counter cannot realistically overflow.
  const std::uint64_t one = 1;
  [[maybe_unused]] const auto written = ::write(wake_fd_, &one, sizeof one);
  return true;
}

Dc1394Stats Dc1394Camera::stats() const {
  Dc1394Stats s;
  s.frames = frames_.load();
  s.corrupt = corrupt_.load();
  s.pool_exhausted = pool_exhausted_.load();
  s.triggers_fired = triggers_fired_.load();
  s.trigger_errors = trigger_errors_.load();
  s.triggers_refused = triggers_refused_.load();
  s.triggers_missed = triggers_missed_.load();
  s.unexpected = unexpected_.load();
  s.behind = behind_.load();
  s.max_frames_behind = max_frames_behind_.load();
  s.ring_full = ring_full_.load();
  return s;
}

void Dc1394Camera::run() {
  pollfd fds[2] = {{device_->capture_fd, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  bool reported_bus_error = false;
  while (running_.load(std::memory_order_acquire)) {
    const int ready = ::poll(fds, 2, kPollTimeoutMs);
    if (ready < 0 && errno != EINTR) {
      spdlog::error("dc1394 camera {}: poll failed: {}", formatGuid(device_->guid),
                    std::strerror(errno));
      std::this_thread::sleep_for(std::chrono::milliseconds{kPollTimeoutMs});
    }
    if (fds[1].revents & POLLIN) {
      std::uint64_t count = 0;
      [[maybe_unused]] const auto read = ::read(wake_fd_, &count, sizeof count);
    }
    fireTriggers();
    drainFrames();
    if ((fds[0].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
      // A bus reset or an unplugged camera: keep the thread alive (stop() cleans up) without
      // spinning, and say it once.
      if (!reported_bus_error) {
        spdlog::error("dc1394 camera {}: capture device error (bus reset or camera gone)",
                      formatGuid(device_->guid));
        reported_bus_error = true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds{kPollTimeoutMs});
    }
    if (const std::uint32_t missed = device_->matcher->expire(nowUs()); missed > 0)
      triggers_missed_.fetch_add(missed, std::memory_order_relaxed);
  }
}

void Dc1394Camera::fireTriggers() {
  dc1394camera_t* camera = device_->camera.get();
  const bool fires = settings_.trigger == TriggerSource::kSoftware &&
                     settings_.broadcast != Dc1394Broadcast::kReceive;
  const bool broadcast = settings_.broadcast == Dc1394Broadcast::kSend;
  PendingTrigger pending;
  while (triggers_.tryPop(pending)) {
    std::int64_t fired_us = pending.announced_us;
    if (fires) {
      // Taken before the write: the exposure cannot start earlier.
      fired_us = nowUs();
      // Broadcast makes this one register write reach every camera on the bus in the same bus
      // cycle; it is turned off again at once so that no other write goes to all cameras.
      if (broadcast)
        dc1394_camera_set_broadcast(camera, DC1394_TRUE);
      const dc1394error_t err = dc1394_software_trigger_set_power(camera, DC1394_ON);
      if (broadcast)
        dc1394_camera_set_broadcast(camera, DC1394_FALSE);
      if (err != DC1394_SUCCESS) {
        trigger_errors_.fetch_add(1, std::memory_order_relaxed);
        continue;  // no frame will come: the rig's timeout marks it missing
      }
    }
    if (!device_->matcher->addTrigger(pending.id, fired_us)) {
      triggers_missed_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    triggers_fired_.fetch_add(1, std::memory_order_relaxed);
  }
}

void Dc1394Camera::drainFrames() {
  dc1394camera_t* camera = device_->camera.get();
  const std::size_t frame_bytes = std::size_t{settings_.width} * settings_.height;
  while (running_.load(std::memory_order_relaxed)) {
    dc1394video_frame_t* dma = nullptr;
    if (dc1394_capture_dequeue(camera, DC1394_CAPTURE_POLICY_POLL, &dma) != DC1394_SUCCESS ||
        dma == nullptr) {
      return;
    }
    const Requeue requeue(camera, dma);

    if (dma->frames_behind > 0) {
      behind_.fetch_add(1, std::memory_order_relaxed);
      raiseMax(max_frames_behind_, dma->frames_behind);
      // Every other buffer is waiting to be read: the next frames off the bus have nowhere to
      // go and are dropped by the kernel (they show up as missed triggers).
      if (dma->frames_behind + 1 >= settings_.dma_buffers)
        ring_full_.fetch_add(1, std::memory_order_relaxed);
    }
    const auto frame_us = static_cast<std::int64_t>(dma->timestamp);
    const TriggerMatcher::Match match = device_->matcher->matchFrame(frame_us);
    if (match.missed > 0)
      triggers_missed_.fetch_add(match.missed, std::memory_order_relaxed);
    if (!match.trigger_id) {
      unexpected_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }

    core::Frame frame;
    core::FrameMetadata& m = frame.metadata;
    m.camera = settings_.camera_index;
    m.trigger_id = *match.trigger_id;
    m.sequence = sequence_++;
    m.width = settings_.width;
    m.height = settings_.height;
    m.stride = settings_.width;
    m.format = settings_.format;
    m.device_timestamp_ns = frame_us * 1000;
    const bool whole = dc1394_capture_is_frame_corrupt(camera, dma) == DC1394_FALSE &&
                       dma->size[0] == settings_.width && dma->size[1] == settings_.height &&
                       dma->image_bytes >= frame_bytes;
    frame.buffer = pool_->acquire();
    if (!frame.buffer) {
      m.status = core::FrameStatus::kDropped;
      pool_exhausted_.fetch_add(1, std::memory_order_relaxed);
    } else {
      std::memcpy(frame.buffer.bytes().data(), dma->image,
                  std::min<std::size_t>(frame_bytes, dma->image_bytes));
      m.status = whole ? core::FrameStatus::kOk : core::FrameStatus::kCorrupt;
      if (!whole)
        corrupt_.fetch_add(1, std::memory_order_relaxed);
    }
    m.received = core::ReceptionStamp::now();
    frames_.fetch_add(1, std::memory_order_relaxed);
    sink_(std::move(frame));
  }
}

}  // namespace fieldrig::drivers
