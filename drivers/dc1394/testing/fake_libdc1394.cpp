// The fake bus behind fake_dc1394_bus.h: C definitions of the libdc1394 functions the driver
// calls. Linked into a test executable, they take precedence over the shared library's. One camera
// at a time captures (the tests open one); its frames are filled with the frame counter's low byte.
#include <dc1394/dc1394.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <memory>

#include "fake_dc1394_bus.h"

// libdc1394 leaves its context opaque; the fake completes it.
struct __dc1394_t {
  int unused = 0;
};

namespace fieldrig::drivers::testing {
namespace {

struct Capture {
  std::vector<dc1394video_frame_t> ring;
  std::vector<std::vector<unsigned char>> images;
  std::deque<std::uint32_t> ready;  // ring slots holding a frame not yet dequeued
  std::deque<std::uint32_t> free_slots;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::uint64_t frames = 0;
  int fd = -1;
  bool broadcast = false;
};

Capture& capture() {
  static Capture c;
  return c;
}

std::uint64_t nowUs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

// Exposes and "transmits" one frame into a free ring slot; a full ring drops it, as the kernel
// does. Caller holds the bus mutex.
void exposeLocked(FakeDc1394Bus& bus) {
  Capture& c = capture();
  if (!bus.capturing || !bus.transmitting)
    return;
  if (c.free_slots.empty())
    return;
  const std::uint32_t slot = c.free_slots.front();
  c.free_slots.pop_front();
  dc1394video_frame_t& f = c.ring[slot];
  std::memset(c.images[slot].data(), static_cast<int>(c.frames & 0xff), c.images[slot].size());
  ++c.frames;
  f.image = c.images[slot].data();
  f.size[0] = c.width;
  f.size[1] = c.height;
  f.image_bytes = c.width * c.height;
  f.total_bytes = f.image_bytes;
  f.packet_size = bus.packet_bytes;
  f.timestamp = nowUs() + 1000;  // transfer finishes a little after the exposure
  f.id = slot;
  f.data_in_padding = bus.corrupt_next ? DC1394_TRUE : DC1394_FALSE;  // marks corruption here
  bus.corrupt_next = false;
  c.ready.push_back(slot);
  const std::uint64_t one = 1;
  [[maybe_unused]] const auto written = ::write(c.fd, &one, sizeof one);
}

}  // namespace

FakeDc1394Bus& fakeDc1394Bus() {
  static FakeDc1394Bus bus;
  return bus;
}

void resetFakeDc1394Bus() {
  FakeDc1394Bus& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.guids.clear();
  bus.max_width = 1624;
  bus.max_height = 1224;
  bus.unit_bytes = 4;
  bus.max_bytes = 8192;
  bus.color_filter = 0;
  bus.fail_capture_setup = bus.fail_transmission = false;
  bus.broadcast_supported = true;
  bus.triggers_to_ignore = 0;
  bus.corrupt_next = false;
  bus.contexts_open = bus.cameras_open = bus.capture_setups = bus.capture_stops = 0;
  bus.iso_release_alls = 0;
  bus.capturing = bus.transmitting = bus.operation_mode_1394b = false;
  bus.iso_speed_mbps = 0;
  bus.packet_bytes = 0;
  bus.trigger_on = bus.software_source = false;
  bus.trigger_mode = -1;
  bus.dma_buffers = 0;
  bus.software_triggers = bus.broadcast_triggers = 0;
  bus.broadcast_left_on = false;
  bus.shutter_s = bus.gain_db = 0;
}

void fakeDc1394Pulse() {
  FakeDc1394Bus& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (bus.trigger_on && !bus.software_source)
    exposeLocked(bus);
}

void fakeDc1394SpuriousFrame() {
  FakeDc1394Bus& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  exposeLocked(bus);
}

}  // namespace fieldrig::drivers::testing

using fieldrig::drivers::testing::capture;
using fieldrig::drivers::testing::fakeDc1394Bus;

extern "C" {

dc1394_t* dc1394_new() {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  ++bus.contexts_open;
  return new __dc1394_t;
}

void dc1394_free(dc1394_t* context) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  --bus.contexts_open;
  delete context;
}

dc1394error_t dc1394_camera_enumerate(dc1394_t*, dc1394camera_list_t** list) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  auto* l = static_cast<dc1394camera_list_t*>(std::calloc(1, sizeof(dc1394camera_list_t)));
  l->num = static_cast<std::uint32_t>(bus.guids.size());
  l->ids = static_cast<dc1394camera_id_t*>(std::calloc(l->num + 1, sizeof(dc1394camera_id_t)));
  for (std::uint32_t i = 0; i < l->num; ++i)
    l->ids[i].guid = bus.guids[i];
  *list = l;
  return DC1394_SUCCESS;
}

void dc1394_camera_free_list(dc1394camera_list_t* list) {
  if (list)
    std::free(list->ids);
  std::free(list);
}

dc1394camera_t* dc1394_camera_new(dc1394_t*, uint64_t guid) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  for (const std::uint64_t g : bus.guids) {
    if (g == guid) {
      auto* camera = static_cast<dc1394camera_t*>(std::calloc(1, sizeof(dc1394camera_t)));
      camera->guid = guid;
      ++bus.cameras_open;
      return camera;
    }
  }
  return nullptr;
}

void dc1394_camera_free(dc1394camera_t* camera) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  --bus.cameras_open;
  std::free(camera);
}

const char* dc1394_error_get_string(dc1394error_t error) {
  return error == DC1394_SUCCESS ? "Success" : "fake bus refused";
}

dc1394error_t dc1394_log_register_handler(dc1394log_t, void (*)(dc1394log_t, const char*, void*),
                                          void*) {
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_video_set_operation_mode(dc1394camera_t*, dc1394operation_mode_t mode) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.operation_mode_1394b = mode == DC1394_OPERATION_MODE_1394B;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_video_set_iso_speed(dc1394camera_t*, dc1394speed_t speed) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.iso_speed_mbps = speed == DC1394_ISO_SPEED_800   ? 800
                       : speed == DC1394_ISO_SPEED_400 ? 400
                                                       : 0;
  // As on a real camera, S800 without 1394b mode is refused.
  return speed == DC1394_ISO_SPEED_800 && !bus.operation_mode_1394b ? DC1394_FAILURE
                                                                    : DC1394_SUCCESS;
}

dc1394error_t dc1394_video_set_mode(dc1394camera_t*, dc1394video_mode_t mode) {
  return mode >= DC1394_VIDEO_MODE_FORMAT7_0 && mode <= DC1394_VIDEO_MODE_FORMAT7_7
             ? DC1394_SUCCESS
             : DC1394_FAILURE;
}

dc1394error_t dc1394_format7_get_max_image_size(dc1394camera_t*, dc1394video_mode_t,
                                                uint32_t* width, uint32_t* height) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  *width = bus.max_width;
  *height = bus.max_height;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_format7_set_roi(dc1394camera_t*, dc1394video_mode_t,
                                     dc1394color_coding_t coding, int32_t, int32_t, int32_t,
                                     int32_t width, int32_t height) {
  if (coding != DC1394_COLOR_CODING_RAW8)
    return DC1394_FAILURE;
  capture().width = static_cast<std::uint32_t>(width);
  capture().height = static_cast<std::uint32_t>(height);
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_format7_get_color_filter(dc1394camera_t*, dc1394video_mode_t,
                                              dc1394color_filter_t* filter) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  *filter = static_cast<dc1394color_filter_t>(DC1394_COLOR_FILTER_RGGB + bus.color_filter);
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_format7_get_packet_parameters(dc1394camera_t*, dc1394video_mode_t,
                                                   uint32_t* unit_bytes, uint32_t* max_bytes) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  *unit_bytes = bus.unit_bytes;
  *max_bytes = bus.max_bytes;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_format7_set_packet_size(dc1394camera_t*, dc1394video_mode_t,
                                             uint32_t packet_size) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (packet_size == 0 || packet_size % bus.unit_bytes != 0 || packet_size > bus.max_bytes)
    return DC1394_FAILURE;
  bus.packet_bytes = packet_size;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_external_trigger_set_mode(dc1394camera_t*, dc1394trigger_mode_t mode) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.trigger_mode = mode - DC1394_TRIGGER_MODE_0;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_external_trigger_set_source(dc1394camera_t*, dc1394trigger_source_t source) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.software_source = source == DC1394_TRIGGER_SOURCE_SOFTWARE;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_external_trigger_set_power(dc1394camera_t*, dc1394switch_t power) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  bus.trigger_on = power == DC1394_ON;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_camera_set_broadcast(dc1394camera_t*, dc1394bool_t on) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (!bus.broadcast_supported)
    return DC1394_FUNCTION_NOT_SUPPORTED;
  capture().broadcast = on == DC1394_TRUE;
  bus.broadcast_left_on = capture().broadcast;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_feature_set_mode(dc1394camera_t*, dc1394feature_t, dc1394feature_mode_t) {
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_feature_set_absolute_control(dc1394camera_t*, dc1394feature_t,
                                                  dc1394switch_t) {
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_feature_set_absolute_value(dc1394camera_t*, dc1394feature_t feature,
                                                float value) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (feature == DC1394_FEATURE_SHUTTER)
    bus.shutter_s = value;
  if (feature == DC1394_FEATURE_GAIN)
    bus.gain_db = value;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_feature_whitebalance_set_value(dc1394camera_t*, uint32_t, uint32_t) {
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_capture_setup(dc1394camera_t*, uint32_t buffers, uint32_t) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  ++bus.capture_setups;
  if (bus.fail_capture_setup)
    return DC1394_NO_BANDWIDTH;
  auto& c = capture();
  c.ring.assign(buffers, dc1394video_frame_t{});
  c.images.assign(buffers, std::vector<unsigned char>(std::size_t{c.width} * c.height));
  c.ready.clear();
  c.free_slots.clear();
  for (std::uint32_t i = 0; i < buffers; ++i)
    c.free_slots.push_back(i);
  c.frames = 0;
  c.fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  bus.dma_buffers = buffers;
  bus.capturing = true;
  return DC1394_SUCCESS;
}

int dc1394_capture_get_fileno(dc1394camera_t*) {
  return capture().fd;
}

dc1394error_t dc1394_capture_stop(dc1394camera_t*) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  ++bus.capture_stops;
  if (!bus.capturing)
    return DC1394_CAPTURE_IS_NOT_SET;
  bus.capturing = false;
  auto& c = capture();
  ::close(c.fd);
  c.fd = -1;
  c.ring.clear();
  c.images.clear();
  c.ready.clear();
  c.free_slots.clear();
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_video_set_transmission(dc1394camera_t*, dc1394switch_t power) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (power == DC1394_ON && bus.fail_transmission)
    return DC1394_FAILURE;
  bus.transmitting = power == DC1394_ON;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_iso_release_all(dc1394camera_t*) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  ++bus.iso_release_alls;
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_software_trigger_set_power(dc1394camera_t*, dc1394switch_t power) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (power != DC1394_ON)
    return DC1394_SUCCESS;
  ++bus.software_triggers;
  if (capture().broadcast)
    ++bus.broadcast_triggers;
  if (!bus.trigger_on || !bus.software_source)
    return DC1394_SUCCESS;
  if (bus.triggers_to_ignore > 0) {
    --bus.triggers_to_ignore;
    return DC1394_SUCCESS;
  }
  fieldrig::drivers::testing::exposeLocked(bus);
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_capture_dequeue(dc1394camera_t*, dc1394capture_policy_t,
                                     dc1394video_frame_t** frame) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  auto& c = capture();
  *frame = nullptr;
  if (!bus.capturing)
    return DC1394_CAPTURE_IS_NOT_SET;
  if (c.ready.empty()) {
    std::uint64_t count = 0;
    [[maybe_unused]] const auto got = ::read(c.fd, &count, sizeof count);
    return DC1394_SUCCESS;
  }
  const std::uint32_t slot = c.ready.front();
  c.ready.pop_front();
  c.ring[slot].frames_behind = static_cast<std::uint32_t>(c.ready.size());
  *frame = &c.ring[slot];
  return DC1394_SUCCESS;
}

dc1394error_t dc1394_capture_enqueue(dc1394camera_t*, dc1394video_frame_t* frame) {
  auto& bus = fakeDc1394Bus();
  std::lock_guard lock(bus.mutex);
  if (bus.capturing)
    capture().free_slots.push_back(frame->id);
  return DC1394_SUCCESS;
}

dc1394bool_t dc1394_capture_is_frame_corrupt(dc1394camera_t*, dc1394video_frame_t* frame) {
  return frame->data_in_padding;
}

}  // extern "C"
