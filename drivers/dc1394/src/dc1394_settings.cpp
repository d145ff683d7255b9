#include "fieldrig/drivers/dc1394/dc1394_settings.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>

namespace fieldrig::drivers {
namespace {

const std::set<std::string, std::less<>> kKnownOptions = {
    "video_mode",          "iso_speed",   "camera_index", "bus_cameras", "rate_hz",
    "bus_bytes_per_cycle", "dma_buffers", "left",         "top",         "trigger_broadcast"};

template <typename T>
core::Result<T> parseNumber(const CameraConfig& config, std::string_view key, T fallback) {
  const auto it = config.options.find(std::string(key));
  if (it == config.options.end())
    return fallback;
  const std::string& text = it->second;
  T value{};
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size()) {
    return core::Error{"dc1394 camera " + config.id + ": option '" + std::string(key) + "': '" +
                       text + "' is not a number"};
  }
  return value;
}

}  // namespace

std::optional<core::PixelFormat> pixelFormatFromBayerPattern(std::string_view pattern) {
  if (pattern == "rggb")
    return core::PixelFormat::kBayerRG8;
  if (pattern == "grbg")
    return core::PixelFormat::kBayerGR8;
  if (pattern == "gbrg")
    return core::PixelFormat::kBayerGB8;
  if (pattern == "bggr")
    return core::PixelFormat::kBayerBG8;
  return std::nullopt;
}

std::string formatGuid(std::uint64_t guid) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(guid));
  return text;
}

std::optional<std::uint64_t> parseGuid(std::string_view text) {
  if (text.starts_with("0x") || text.starts_with("0X"))
    text.remove_prefix(2);
  if (text.empty() || text.size() > 16)
    return std::nullopt;
  std::uint64_t guid = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), guid, 16);
  if (ec != std::errc() || ptr != text.data() + text.size())
    return std::nullopt;
  return guid;
}

core::Result<Dc1394Settings> dc1394SettingsFromConfig(const CameraConfig& config) {
  const std::string who = "dc1394 camera " + (config.id.empty() ? "(no id)" : config.id);
  for (const auto& [key, _] : config.options) {
    if (!kKnownOptions.contains(key)) {
      return core::Error{who + ": unknown option '" + key + "'"};
    }
  }

  Dc1394Settings s;
  if (config.id != "first") {
    s.guid = parseGuid(config.id);
    if (!s.guid) {
      return core::Error{who +
                         ": id must be the camera's GUID in hex (e.g. 0800461000821fa2) "
                         "or 'first'"};
    }
  }

  if (const auto it = config.options.find("video_mode"); it != config.options.end()) {
    // Only Format7 gives the full 1624×1224 RAW8 frame and a settable packet size.
    const std::string& mode = it->second;
    constexpr std::string_view kPrefix = "format7_mode";
    if (!mode.starts_with(kPrefix) || mode.size() != kPrefix.size() + 1 || mode.back() < '0' ||
        mode.back() > '7') {
      return core::Error{who + ": video_mode '" + mode +
                         "' is not a Format7 mode (format7_mode0 … format7_mode7); the driver "
                         "only drives Format7"};
    }
    s.format7_mode = static_cast<std::uint32_t>(mode.back() - '0');
  }

  const auto speed = parseNumber<std::uint32_t>(config, "iso_speed", 800);
  if (!speed.ok())
    return speed.error();
  if (*speed == 800) {
    s.bus = IsoBus::s800();
    s.operation_mode_1394b = true;
  } else if (*speed == 400) {
    s.bus = IsoBus::s400();
    s.operation_mode_1394b = false;
  } else {
    return core::Error{who + ": iso_speed " + std::to_string(*speed) +
                       " is not supported (400 or 800)"};
  }
  s.iso_speed_mbps = *speed;

  if (config.format == core::PixelFormat::kMono8) {
    return core::Error{who +
                       ": the Grasshoppers deliver Bayer RAW8; pixel format Mono8 is not "
                       "supported by this driver"};
  }
  s.format = config.format;
  if (config.width == 0 || config.height == 0)
    return core::Error{who + ": width and height must be positive"};
  s.width = config.width;
  s.height = config.height;
  if (!(config.exposure_us > 0))
    return core::Error{who + ": exposure must be positive"};
  s.exposure_us = config.exposure_us;
  s.gain_db = config.gain_db;
  s.white_balance = config.white_balance;
  s.trigger = config.trigger;

  const auto index = parseNumber<std::uint32_t>(config, "camera_index", 0);
  const auto cameras = parseNumber<std::uint32_t>(config, "bus_cameras", 6);
  const auto rate = parseNumber<double>(config, "rate_hz", 5);
  const auto budget = parseNumber<std::uint32_t>(config, "bus_bytes_per_cycle", 0);
  const auto buffers = parseNumber<std::uint32_t>(config, "dma_buffers", 8);
  const auto left = parseNumber<std::uint32_t>(config, "left", 0);
  const auto top = parseNumber<std::uint32_t>(config, "top", 0);
  for (const auto* number : {&index, &cameras, &budget, &buffers, &left, &top}) {
    if (!number->ok())
      return number->error();
  }
  if (!rate.ok())
    return rate.error();
  if (*cameras == 0)
    return core::Error{who + ": bus_cameras must be at least 1"};
  if (!(*rate > 0) || !std::isfinite(*rate))
    return core::Error{who + ": rate_hz must be positive"};
  // The DMA ring must hold a frame being filled and one being copied out, at the least.
  if (*buffers < 2)
    return core::Error{who + ": dma_buffers must be at least 2"};
  s.camera_index = *index;
  s.bus_cameras = *cameras;
  s.rate_hz = *rate;
  if (*budget != 0)
    s.bus.bytes_per_cycle = *budget;
  s.dma_buffers = *buffers;
  s.left = *left;
  s.top = *top;

  if (const auto it = config.options.find("trigger_broadcast"); it != config.options.end()) {
    if (it->second == "off") {
      s.broadcast = Dc1394Broadcast::kOff;
    } else if (it->second == "send") {
      s.broadcast = Dc1394Broadcast::kSend;
    } else if (it->second == "receive") {
      s.broadcast = Dc1394Broadcast::kReceive;
    } else {
      return core::Error{who + ": trigger_broadcast '" + it->second +
                         "' is not one of off, send, receive"};
    }
    if (s.broadcast != Dc1394Broadcast::kOff && s.trigger != TriggerSource::kSoftware) {
      return core::Error{who + ": trigger_broadcast needs the software trigger source"};
    }
  }
  return s;
}

IsoRequest dc1394IsoRequest(const Dc1394Settings& settings, std::uint32_t unit_bytes,
                            std::uint32_t max_packet_bytes) {
  IsoRequest r;
  r.cameras = settings.bus_cameras;
  r.width = settings.width;
  r.height = settings.height;
  r.bytes_per_pixel = 1;
  r.rate_hz = settings.rate_hz;
  r.bus = settings.bus;
  r.unit_bytes = unit_bytes;
  r.max_packet_bytes = max_packet_bytes;
  return r;
}

}  // namespace fieldrig::drivers
