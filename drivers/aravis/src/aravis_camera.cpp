#include "fieldrig/drivers/aravis/aravis_camera.h"

#include <arv.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <thread>

namespace fieldrig::drivers {
namespace {

// Aravis' GigE Vision block ids are 16 bits and skip 0 when they wrap (65535 → 1).
constexpr std::uint64_t kBlockIdWrap = 0xFFFF;

std::string takeMessage(GError* error) {
  std::string message = error != nullptr ? error->message : "unknown error";
  g_clear_error(&error);
  return message;
}

core::Error featureError(const CameraConfig& config, const std::string& feature, GError* error) {
  return core::Error{"aravis camera " + config.id + ": feature " + feature + ": " +
                     takeMessage(error)};
}

core::Result<std::uint32_t> unsignedOption(const CameraConfig& config, const std::string& key,
                                           std::uint32_t fallback) {
  const auto it = config.options.find(key);
  if (it == config.options.end())
    return fallback;
  std::uint32_t value = 0;
  const std::string& text = it->second;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size()) {
    return core::Error{"aravis camera " + config.id + ": option '" + key + "': '" + text +
                       "' is not a non-negative integer"};
  }
  return value;
}

std::string stringOption(const CameraConfig& config, const std::string& key,
                         const std::string& fallback) {
  const auto it = config.options.find(key);
  return it == config.options.end() ? fallback : it->second;
}

// How many frames the camera sent since `last` (1 when none was lost). Ids that go backwards
// other than by a 16-bit wrap (a camera reset) count as the next frame: nothing is known lost.
std::uint64_t frameIdGap(std::uint64_t last, std::uint64_t id) {
  if (id > last)
    return id - last;
  if (last > kBlockIdWrap - 0x1000 && last <= kBlockIdWrap && id > 0 && id < 0x1000)
    return kBlockIdWrap - last + id;
  return 1;
}

// The host's real-time clock, the clock of device timestamps that are synchronised with it.
std::int64_t realtimeNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A device timestamp is taken to be on the host's clock when it is at most this far after the
// frame's arrival (clock steps and sync error) and at most kStampAge before it (a frame's
// exposure, transfer and a stalled host).
constexpr std::int64_t kStampAheadNs = 20'000'000;
constexpr std::int64_t kStampAgeNs = 10'000'000'000;
// Added to the longest answer seen (plus a quarter) before an undecided trigger is taken to have
// been merged: scheduling jitter of the host that stamps the commands.
constexpr std::int64_t kLatencySlackNs = 5'000'000;

// Enables the in-process fake interface once: Aravis keeps it enabled for the process.
void enableFakeInterface() {
  static std::once_flag once;
  std::call_once(once, [] { arv_enable_interface("Fake"); });
}

}  // namespace

struct AravisCamera::Vendor {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong handler = 0;  // the "new-buffer" signal connection

  // Releases the stream: no callback runs after this returns (unref joins the stream thread,
  // which also frees the Aravis buffers the stream holds).
  void releaseStream() {
    if (stream == nullptr)
      return;
    arv_stream_set_emit_signals(stream, FALSE);
    if (handler != 0)
      g_signal_handler_disconnect(stream, handler);
    handler = 0;
    g_object_unref(stream);
    stream = nullptr;
  }
  void releaseCamera() {
    if (camera != nullptr)
      g_object_unref(camera);
    camera = nullptr;
  }
};

// The "new-buffer" signal handler, on Aravis' stream thread: copy out and give the buffer back.
struct AravisCallbacks {
  static void onNewBuffer(ArvStream* stream, void* user_data) {
    auto* self = static_cast<AravisCamera*>(user_data);
    ArvBuffer* buffer = arv_stream_try_pop_buffer(stream);
    if (buffer == nullptr)
      return;
    std::size_t size = 0;
    const void* data = arv_buffer_get_data(buffer, &size);
    self->deliver(data, size, static_cast<int>(arv_buffer_get_status(buffer)),
                  arv_buffer_get_frame_id(buffer), arv_buffer_get_timestamp(buffer));
    arv_stream_push_buffer(stream, buffer);
  }
};

AravisCamera::AravisCamera()
    : vendor_(std::make_unique<Vendor>()),
      issued_ids_(std::make_unique<std::atomic<std::uint64_t>[]>(kIssuedRing)),
      issued_sent_ns_(std::make_unique<std::atomic<std::int64_t>[]>(kIssuedRing)),
      issued_acked_ns_(std::make_unique<std::atomic<std::int64_t>[]>(kIssuedRing)) {}

AravisCamera::~AravisCamera() {
  stop();
  vendor_->releaseCamera();
}

core::Result<void> AravisCamera::configure(const CameraConfig& config) {
  if (running_)
    return core::Error{"aravis camera " + config.id + ": configure while running"};
  if (config.width == 0 || config.height == 0)
    return core::Error{"aravis camera " + config.id + ": width and height must be positive"};
  const auto index = unsignedOption(config, "camera_index", 0);
  const auto offset_x = unsignedOption(config, "offset_x", 0);
  const auto offset_y = unsignedOption(config, "offset_y", 0);
  const auto buffers = unsignedOption(config, "buffers", 8);
  const auto packet_size = unsignedOption(config, "packet_size", 0);
  // Read now for its error; the default needs the camera's frame rate (below).
  const auto min_interval = unsignedOption(config, "min_trigger_interval_us", 0);
  for (const auto* option : {&index, &offset_x, &offset_y, &buffers, &packet_size, &min_interval}) {
    if (!option->ok())
      return option->error();
  }
  if (*buffers < 2)
    return core::Error{"aravis camera " + config.id + ": option 'buffers': at least 2 needed"};
  const std::string resend = stringOption(config, "packet_resend", "");
  if (!resend.empty() && resend != "never" && resend != "always") {
    return core::Error{"aravis camera " + config.id + ": option 'packet_resend': '" + resend +
                       "' is neither 'never' nor 'always'"};
  }

  vendor_->releaseCamera();
  if (config.id.rfind("Fake_", 0) == 0)
    enableFakeInterface();
  GError* error = nullptr;
  vendor_->camera = arv_camera_new(config.id.c_str(), &error);
  if (vendor_->camera == nullptr) {
    return core::Error{"aravis camera '" + config.id + "': cannot open: " + takeMessage(error)};
  }
  ArvCamera* camera = vendor_->camera;
  // Any failure below leaves the camera closed, so that a half-configured one is never started.
  auto fail = [&](const std::string& feature) {
    core::Error e = featureError(config, feature, error);
    vendor_->releaseCamera();
    return e;
  };

  const std::string format =
      stringOption(config, "genicam_pixel_format", std::string(core::toString(config.format)));
  arv_camera_set_pixel_format_from_string(camera, format.c_str(), &error);
  if (error != nullptr)
    return fail("PixelFormat (" + format + ")");
  const char* format_now = arv_camera_get_pixel_format_as_string(camera, &error);
  if (error != nullptr)
    return fail("PixelFormat");
  if (format_now == nullptr || format != format_now) {
    const std::string got = format_now != nullptr ? format_now : "nothing";
    vendor_->releaseCamera();
    return core::Error{"aravis camera " + config.id + ": feature PixelFormat: asked for " + format +
                       ", the camera reports " + got};
  }

  arv_camera_set_region(camera, static_cast<gint>(*offset_x), static_cast<gint>(*offset_y),
                        static_cast<gint>(config.width), static_cast<gint>(config.height), &error);
  if (error != nullptr)
    return fail("OffsetX/OffsetY/Width/Height");
  gint x = 0, y = 0, width = 0, height = 0;
  arv_camera_get_region(camera, &x, &y, &width, &height, &error);
  if (error != nullptr)
    return fail("Width/Height");
  if (static_cast<std::uint32_t>(width) != config.width ||
      static_cast<std::uint32_t>(height) != config.height) {
    vendor_->releaseCamera();
    return core::Error{"aravis camera " + config.id + ": feature Width/Height: asked for " +
                       std::to_string(config.width) + "x" + std::to_string(config.height) +
                       ", the camera set " + std::to_string(width) + "x" + std::to_string(height)};
  }

  arv_camera_set_exposure_time(camera, config.exposure_us, &error);
  if (error != nullptr)
    return fail("ExposureTime");
  arv_camera_set_gain(camera, config.gain_db, &error);
  if (error != nullptr)
    return fail("Gain");
  if (config.white_balance) {
    for (const auto& [selector, ratio] : {std::pair{"Blue", config.white_balance->first},
                                          std::pair{"Red", config.white_balance->second}}) {
      arv_camera_set_string(camera, "BalanceRatioSelector", selector, &error);
      if (error != nullptr)
        return fail(std::string("BalanceRatioSelector (") + selector + ")");
      arv_camera_set_float(camera, "BalanceRatio", ratio, &error);
      if (error != nullptr)
        return fail(std::string("BalanceRatio (") + selector + ")");
    }
  }

  // Trigger mode on the FrameStart trigger: one frame per software command or line pulse.
  const std::string source = config.trigger == TriggerSource::kSoftware
                                 ? std::string("Software")
                                 : stringOption(config, "trigger_line", "Line0");
  arv_camera_set_string(camera, "TriggerSelector", "FrameStart", &error);
  if (error != nullptr)
    return fail("TriggerSelector (FrameStart)");
  arv_camera_set_string(camera, "TriggerMode", "On", &error);
  if (error != nullptr)
    return fail("TriggerMode (On)");
  arv_camera_set_string(camera, "TriggerSource", source.c_str(), &error);
  if (error != nullptr)
    return fail("TriggerSource (" + source + ")");
  arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
  if (error != nullptr)
    return fail("AcquisitionMode (Continuous)");

  if (arv_camera_is_gv_device(camera)) {
    if (*packet_size != 0) {
      arv_camera_gv_set_packet_size(camera, static_cast<gint>(*packet_size), &error);
      if (error != nullptr)
        return fail("GevSCPSPacketSize");
    }
  } else if (*packet_size != 0 || !resend.empty()) {
    vendor_->releaseCamera();
    return core::Error{"aravis camera " + config.id +
                       ": options 'packet_size' and 'packet_resend' need a GigE Vision camera"};
  }

  const guint payload = arv_camera_get_payload(camera, &error);
  if (error != nullptr)
    return fail("PayloadSize");
  if (payload < std::size_t{config.width} * config.height) {
    vendor_->releaseCamera();
    return core::Error{"aravis camera " + config.id + ": feature PayloadSize: " +
                       std::to_string(payload) + " bytes is less than one 8-bit frame"};
  }

  // Pacing: the period of the camera's own frame rate unless the option names one. A camera
  // without AcquisitionFrameRate is not paced.
  std::chrono::microseconds pacing{*min_interval};
  if (config.options.find("min_trigger_interval_us") == config.options.end()) {
    const double rate = arv_camera_get_frame_rate(camera, &error);
    g_clear_error(&error);
    pacing = rate > 0 && rate < 1e6
                 ? std::chrono::microseconds{static_cast<std::int64_t>(std::ceil(1e6 / rate))}
                 : std::chrono::microseconds{0};
  }

  config_ = config;
  gv_device_ = arv_camera_is_gv_device(camera) != FALSE;
  min_trigger_interval_ = pacing;
  camera_index_ = *index;
  offset_x_ = *offset_x;
  offset_y_ = *offset_y;
  buffer_count_ = *buffers;
  return {};
}

core::Result<void> AravisCamera::start(core::FramePool& pool, FrameSink sink) {
  if (running_)
    return core::Error{"aravis camera " + config_.id + ": already started"};
  if (vendor_->camera == nullptr)
    return core::Error{"aravis camera: start before a successful configure"};
  if (pool.bufferBytes() < std::size_t{config_.width} * config_.height)
    return core::Error{"aravis camera " + config_.id + ": pool buffers are smaller than a frame"};
  ArvCamera* camera = vendor_->camera;
  GError* error = nullptr;
  const guint payload = arv_camera_get_payload(camera, &error);
  if (error != nullptr)
    return featureError(config_, "PayloadSize", error);

  pool_ = &pool;
  sink_ = std::move(sink);
  issued_ = 0;
  consumed_ = 0;
  last_trigger_acked_ = {};
  shortest_gap_us_ = -1;
  have_frame_id_ = false;
  last_exposed_ns_.reset();
  answer_latency_ns_ = -1;
  external_count_ = 0;

  {
    std::lock_guard lock(stream_mutex_);
    vendor_->stream = arv_camera_create_stream(camera, nullptr, nullptr, &error);
  }
  if (vendor_->stream == nullptr) {
    return core::Error{"aravis camera " + config_.id +
                       ": cannot create the stream: " + takeMessage(error)};
  }
  const std::string resend = stringOption(config_, "packet_resend", "");
  if (!resend.empty()) {
    g_object_set(
        vendor_->stream, "packet-resend",
        resend == "never" ? ARV_GV_STREAM_PACKET_RESEND_NEVER : ARV_GV_STREAM_PACKET_RESEND_ALWAYS,
        nullptr);
  }
  // The only Aravis buffers of the run: the stream recycles them, nothing is allocated per frame.
  for (std::uint32_t i = 0; i < buffer_count_; ++i)
    arv_stream_push_buffer(vendor_->stream, arv_buffer_new_allocate(payload));
  // GCallback is GLib's generic function pointer; GLib calls it back with the handler's real
  // signature, as g_signal_connect's own cast does.
  vendor_->handler = g_signal_connect_data(
      vendor_->stream, "new-buffer", reinterpret_cast<GCallback>(&AravisCallbacks::onNewBuffer),
      this, nullptr, GConnectFlags{});
  arv_stream_set_emit_signals(vendor_->stream, TRUE);

  running_ = true;
  arv_camera_start_acquisition(camera, &error);
  if (error != nullptr) {
    running_ = false;
    std::lock_guard lock(stream_mutex_);
    vendor_->releaseStream();
    return featureError(config_, "AcquisitionStart", error);
  }
  trigger_worker_ = std::thread([this] { runTriggers(); });
  return {};
}

void AravisCamera::stop() {
  if (!running_.exchange(false))
    return;
  wakeups_.fetch_add(1, std::memory_order_release);
  wakeups_.notify_one();
  if (trigger_worker_.joinable())
    trigger_worker_.join();
  std::uint64_t ignored = 0;
  while (triggers_.tryPop(ignored))
    failed_.fetch_add(1, std::memory_order_relaxed);  // accepted but never sent

  GError* error = nullptr;
  arv_camera_stop_acquisition(vendor_->camera, &error);
  if (error != nullptr) {
    spdlog::warn("aravis camera {}: AcquisitionStop: {}", config_.id, takeMessage(error));
  }
  {
    // Readers on other threads wait out the release (it joins the stream thread) and then see
    // the totals instead of the stream.
    std::lock_guard lock(stream_mutex_);
    guint64 completed = 0, failures = 0, underruns = 0, resent = 0, missing = 0;
    arv_stream_get_statistics(vendor_->stream, &completed, &failures, &underruns);
    if (ARV_IS_GV_STREAM(vendor_->stream))
      arv_gv_stream_get_statistics(ARV_GV_STREAM(vendor_->stream), &resent, &missing);
    vendor_->releaseStream();
    stream_completed_ = completed;
    stream_failures_ = failures;
    stream_underruns_ = underruns;
    packets_resent_ = resent;
    packets_missing_ = missing;
  }
  // The stream thread has ended: what is still outstanding will never come.
  lost_.fetch_add(outstandingTriggers(), std::memory_order_relaxed);
  consumed_.store(issued_.load());
}

bool AravisCamera::trigger(std::uint64_t trigger_id) {
  if (!running_ || config_.trigger != TriggerSource::kSoftware || !triggers_.tryPush(trigger_id)) {
    refused_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  accepted_.fetch_add(1, std::memory_order_relaxed);
  wakeups_.fetch_add(1, std::memory_order_release);
  wakeups_.notify_one();
  return true;
}

void AravisCamera::runTriggers() {
  std::uint32_t seen = wakeups_.load(std::memory_order_acquire);
  while (running_) {
    std::uint64_t id = 0;
    while (running_ && triggers_.tryPop(id))
      issueTrigger(id);
    wakeups_.wait(seen, std::memory_order_acquire);
    seen = wakeups_.load(std::memory_order_acquire);
  }
}

void AravisCamera::issueTrigger(std::uint64_t trigger_id) {
  const std::uint64_t slot = issued_.load(std::memory_order_relaxed);
  if (slot - consumed_.load(std::memory_order_acquire) >= kIssuedRing) {
    // The camera answered none of the last kIssuedRing triggers: it is gone or far behind.
    failed_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  // Published before the command: a short exposure can bring the frame back before the
  // command's acknowledgement does.
  // Held back (on this worker, never in trigger()) until the camera can take another trigger.
  if (min_trigger_interval_.count() > 0 &&
      last_trigger_acked_ != std::chrono::steady_clock::time_point{}) {
    const auto earliest = last_trigger_acked_ + min_trigger_interval_;
    if (std::chrono::steady_clock::now() < earliest) {
      paced_.fetch_add(1, std::memory_order_relaxed);
      std::this_thread::sleep_until(earliest);
    }
  }
  if (last_trigger_acked_ != std::chrono::steady_clock::time_point{}) {
    const std::int64_t gap_us = std::chrono::duration_cast<std::chrono::microseconds>(
                                    std::chrono::steady_clock::now() - last_trigger_acked_)
                                    .count();
    const std::int64_t shortest = shortest_gap_us_.load(std::memory_order_relaxed);
    if (shortest < 0 || gap_us < shortest)
      shortest_gap_us_.store(gap_us, std::memory_order_relaxed);
  }
  issued_ids_[slot % kIssuedRing].store(trigger_id, std::memory_order_relaxed);
  issued_acked_ns_[slot % kIssuedRing].store(kNotAcked, std::memory_order_relaxed);
  issued_sent_ns_[slot % kIssuedRing].store(realtimeNs(), std::memory_order_relaxed);
  issued_.store(slot + 1, std::memory_order_release);
  GError* error = nullptr;
  arv_camera_software_trigger(vendor_->camera, &error);
  last_trigger_acked_ = std::chrono::steady_clock::now();
  issued_acked_ns_[slot % kIssuedRing].store(realtimeNs(), std::memory_order_release);
  if (error != nullptr) {
    // The slot stays, marked, so that the next frame is not matched to a trigger never sent.
    issued_ids_[slot % kIssuedRing].store(kFailedTrigger, std::memory_order_release);
    failed_.fetch_add(1, std::memory_order_relaxed);
    spdlog::warn("aravis camera {}: TriggerSoftware for trigger {}: {}", config_.id, trigger_id,
                 takeMessage(error));
  }
}

bool AravisCamera::matchTrigger(std::uint64_t gap, std::optional<std::int64_t> exposed_ns,
                                std::uint64_t& trigger_id) {
  const std::uint64_t issued = issued_.load(std::memory_order_acquire);
  std::uint64_t consumed = consumed_.load(std::memory_order_relaxed);
  auto skipFailed = [&] {
    while (consumed < issued &&
           issued_ids_[consumed % kIssuedRing].load(std::memory_order_acquire) == kFailedTrigger)
      ++consumed;
  };
  // The camera sent gap - 1 frames that never arrived: they answered the oldest triggers.
  for (std::uint64_t i = 1; i < gap; ++i) {
    skipFailed();
    if (consumed == issued)
      break;
    ++consumed;
    lost_.fetch_add(1, std::memory_order_relaxed);
  }
  skipFailed();
  bool matched = false;
  if (!exposed_ns) {
    if (consumed < issued) {
      trigger_id = issued_ids_[consumed % kIssuedRing].load(std::memory_order_relaxed);
      ++consumed;
      matched = true;
    }
    last_exposed_ns_.reset();  // an exposure of unknown time: nothing to settle against it
    consumed_.store(consumed, std::memory_order_release);
    return matched;
  }
  const std::int64_t exposed = *exposed_ns;
  auto sentAt = [&](std::uint64_t slot) {
    return issued_sent_ns_[slot % kIssuedRing].load(std::memory_order_relaxed);
  };
  auto countMerged = [&] {
    ++consumed;
    merged_.fetch_add(1, std::memory_order_relaxed);
    lost_.fetch_add(1, std::memory_order_relaxed);
    skipFailed();
  };
  // Triggers left undecided at the last exposure (sent before it, acknowledged after it): one
  // this frame could not answer, because it came later than any trigger's answer has taken, was
  // received before that exposure and merged into it.
  while (consumed < issued && last_exposed_ns_ && sentAt(consumed) <= *last_exposed_ns_ &&
         answer_latency_ns_ >= 0 &&
         exposed - sentAt(consumed) > answer_latency_ns_ + answer_latency_ns_ / 4 + kLatencySlackNs)
    countMerged();
  if (consumed < issued && sentAt(consumed) <= exposed) {
    const std::int64_t sent = sentAt(consumed);
    trigger_id = issued_ids_[consumed % kIssuedRing].load(std::memory_order_relaxed);
    ++consumed;
    matched = true;
    matched_by_time_.fetch_add(1, std::memory_order_relaxed);
    // Sent after the last exposure, this trigger can only be this frame's: how long the camera
    // took to answer it bounds the settling above.
    if (!last_exposed_ns_ || sent > *last_exposed_ns_)
      answer_latency_ns_ = std::max(answer_latency_ns_, exposed - sent);
    // The camera exposes once for all the triggers it holds: those it acknowledged before this
    // exposure get no frame of their own.
    skipFailed();
    while (consumed < issued &&
           issued_acked_ns_[consumed % kIssuedRing].load(std::memory_order_acquire) < exposed)
      countMerged();
    last_exposed_ns_ = exposed;
  }
  consumed_.store(consumed, std::memory_order_release);
  return matched;
}

std::uint64_t AravisCamera::outstandingTriggers() const {
  std::uint64_t outstanding = 0;
  for (std::uint64_t i = consumed_.load(); i < issued_.load(); ++i) {
    if (issued_ids_[i % kIssuedRing].load() != kFailedTrigger)
      ++outstanding;
  }
  return outstanding;
}

void AravisCamera::deliver(const void* data, std::size_t size, int arv_status,
                           std::uint64_t frame_id, std::uint64_t device_timestamp_ns) {
  const core::ReceptionStamp received = core::ReceptionStamp::now();
  // A damaged GigE Vision frame can carry a stale frame id (measured with arv-fake-gv-camera's
  // packet loss: the id of the frame the Aravis buffer held before). Only whole frames are
  // trusted; a damaged one is taken to be the next frame, and the next whole frame's id settles
  // any frames lost around it.
  const bool whole = arv_status == ARV_BUFFER_STATUS_SUCCESS;
  std::optional<std::int64_t> exposed_ns;
  const auto stamp = static_cast<std::int64_t>(device_timestamp_ns);
  const std::int64_t arrived_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(received.system.time_since_epoch())
          .count();
  if (whole && stamp > 0 && stamp <= arrived_ns + kStampAheadNs &&
      stamp >= arrived_ns - kStampAgeNs)
    exposed_ns = stamp;
  if (!whole)
    frame_id = have_frame_id_ ? last_frame_id_ % kBlockIdWrap + 1 : frame_id;
  const std::uint64_t gap = have_frame_id_ ? frameIdGap(last_frame_id_, frame_id) : 1;
  have_frame_id_ = true;
  last_frame_id_ = frame_id;

  core::Frame frame;
  core::FrameMetadata& m = frame.metadata;
  if (config_.trigger == TriggerSource::kSoftware) {
    if (!matchTrigger(gap, exposed_ns, m.trigger_id)) {
      unsolicited_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  } else {
    lost_.fetch_add(gap - 1, std::memory_order_relaxed);
    external_count_ += gap;
    m.trigger_id = external_count_;
  }
  m.camera = camera_index_;
  m.sequence = frame_id;
  m.device_timestamp_ns = static_cast<std::int64_t>(device_timestamp_ns);
  m.received = received;
  m.width = config_.width;
  m.height = config_.height;
  m.stride = config_.width;
  m.format = config_.format;

  const std::size_t frame_bytes = std::size_t{m.stride} * m.height;
  switch (static_cast<ArvBufferStatus>(arv_status)) {
    case ARV_BUFFER_STATUS_SUCCESS:
      if (size < frame_bytes) {
        m.status = core::FrameStatus::kCorrupt;
        size_mismatch_.fetch_add(1, std::memory_order_relaxed);
      }
      break;
    case ARV_BUFFER_STATUS_TIMEOUT:
      m.status = core::FrameStatus::kCorrupt;
      timeout_.fetch_add(1, std::memory_order_relaxed);
      break;
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      m.status = core::FrameStatus::kCorrupt;
      missing_packets_.fetch_add(1, std::memory_order_relaxed);
      break;
    case ARV_BUFFER_STATUS_SIZE_MISMATCH:
      m.status = core::FrameStatus::kCorrupt;
      size_mismatch_.fetch_add(1, std::memory_order_relaxed);
      break;
    default:
      m.status = core::FrameStatus::kCorrupt;
      other_status_.fetch_add(1, std::memory_order_relaxed);
      break;
  }

  frame.buffer = pool_->acquire();
  if (!frame.buffer) {
    m.status = core::FrameStatus::kDropped;
    dropped_.fetch_add(1, std::memory_order_relaxed);
  } else {
    std::uint8_t* pixels = frame.buffer.bytes().data();
    const std::size_t copied = data != nullptr ? std::min(size, frame_bytes) : 0;
    if (copied > 0)
      std::memcpy(pixels, data, copied);
    // A damaged frame keeps what arrived; the rest must not show a previous frame's pixels.
    if (copied < frame_bytes)
      std::memset(pixels + copied, 0, frame_bytes - copied);
  }
  if (m.status == core::FrameStatus::kCorrupt)
    corrupt_.fetch_add(1, std::memory_order_relaxed);
  delivered_.fetch_add(1, std::memory_order_relaxed);
  sink_(std::move(frame));
}

AravisStats AravisCamera::stats() const {
  AravisStats s;
  s.triggers_accepted = accepted_.load();
  s.triggers_refused = refused_.load();
  s.triggers_failed = failed_.load();
  s.frames_delivered = delivered_.load();
  s.frames_corrupt = corrupt_.load();
  s.frames_dropped = dropped_.load();
  s.frames_lost = lost_.load();
  s.frames_unsolicited = unsolicited_.load();
  s.status_timeout = timeout_.load();
  s.status_missing_packets = missing_packets_.load();
  s.status_size_mismatch = size_mismatch_.load();
  s.status_other = other_status_.load();
  s.triggers_paced = paced_.load();
  s.triggers_merged = merged_.load();
  s.frames_matched_by_time = matched_by_time_.load();
  s.min_trigger_interval_us = min_trigger_interval_.count();
  s.shortest_trigger_gap_us = shortest_gap_us_.load();
  std::lock_guard lock(stream_mutex_);
  s.stream_completed = stream_completed_;
  s.stream_failures = stream_failures_;
  s.stream_underruns = stream_underruns_;
  s.packets_resent = packets_resent_;
  s.packets_missing = packets_missing_;
  if (vendor_->stream != nullptr) {
    guint64 completed = 0, failures = 0, underruns = 0, resent = 0, missing = 0;
    arv_stream_get_statistics(vendor_->stream, &completed, &failures, &underruns);
    s.stream_completed = completed;
    s.stream_failures = failures;
    s.stream_underruns = underruns;
    if (ARV_IS_GV_STREAM(vendor_->stream)) {
      arv_gv_stream_get_statistics(ARV_GV_STREAM(vendor_->stream), &resent, &missing);
      s.packets_resent = resent;
      s.packets_missing = missing;
    }
  }
  return s;
}

CameraLinkStats AravisCamera::linkStats() const {
  const AravisStats s = stats();
  CameraLinkStats link;
  link.has_packets = gv_device_.load();
  link.packets_resent = s.packets_resent;
  link.packets_missing = s.packets_missing;
  link.frames_missing_packets = s.status_missing_packets;
  // Merges are seen only by matching frames by the camera's timestamps; a camera on another
  // clock is matched in order, and its count would read 0 without meaning it.
  link.counts_merged_triggers = s.frames_matched_by_time > 0;
  link.triggers_merged = s.triggers_merged;
  return link;
}

}  // namespace fieldrig::drivers
