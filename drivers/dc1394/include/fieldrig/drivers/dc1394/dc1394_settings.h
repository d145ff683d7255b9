// What the dc1394 driver will ask of an IIDC camera, derived from a CameraConfig without touching
// the bus, so that configuration files are checked (and tested) on machines without FireWire.
//
// CameraConfig::id is the camera's 64-bit GUID in hex ("0800461000821fa2", an optional "0x"),
// or "first" for the first camera found. CameraConfig::options, all optional:
//   video_mode=format7_mode0   Format7 mode 0-7 (ROS camera1394's name); other modes are refused
//   iso_speed=800              400 (1394a, legacy operation mode) or 800 (1394b operation mode)
//   camera_index=0             the camera's index in the rig (stamped on its frames)
//   bus_cameras=6              cameras sharing the bus, for the bandwidth plan
//   rate_hz=5                  the wanted trigger rate, for the bandwidth plan
//   bus_bytes_per_cycle=N      overrides the bus budget (S800: 8000, S400: 4096)
//   dma_buffers=8              frames in the DMA ring
//   left=0, top=0              ROI offset (width/height come from CameraConfig)
//   trigger_broadcast=off      software trigger: "off" (this camera triggers itself), "send"
//                              (this camera's trigger is broadcast to every camera on the bus),
//                              "receive" (another camera's broadcast exposes this one)
// An unknown key is an error that names it.
//
// Thread-compatible (plain functions on values).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"
#include "fieldrig/drivers/camera.h"
#include "fieldrig/drivers/dc1394/iso_bandwidth.h"

namespace fieldrig::drivers {

enum class Dc1394Broadcast { kOff, kSend, kReceive };

struct Dc1394Settings {
  std::optional<std::uint64_t> guid;  // nullopt: the first camera enumerated
  std::uint32_t format7_mode = 0;
  std::uint32_t iso_speed_mbps = 800;
  bool operation_mode_1394b = true;                         // needed for speeds above S400
  core::PixelFormat format = core::PixelFormat::kBayerRG8;  // RAW8 with this colour filter
  std::uint32_t left = 0;
  std::uint32_t top = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  TriggerSource trigger = TriggerSource::kSoftware;
  Dc1394Broadcast broadcast = Dc1394Broadcast::kOff;
  double exposure_us = 0;
  double gain_db = 0;
  std::optional<std::pair<double, double>> white_balance;
  std::uint32_t camera_index = 0;
  std::uint32_t bus_cameras = 6;
  double rate_hz = 5;
  IsoBus bus = IsoBus::s800();
  std::uint32_t dma_buffers = 8;
};

core::Result<Dc1394Settings> dc1394SettingsFromConfig(const CameraConfig& config);

// The planner's request for these settings and the camera's Format7 packet limits.
IsoRequest dc1394IsoRequest(const Dc1394Settings& settings, std::uint32_t unit_bytes,
                            std::uint32_t max_packet_bytes);

// ROS camera1394's bayer_pattern names ("rggb", "gbrg", "grbg", "bggr") as fieldrig formats.
std::optional<core::PixelFormat> pixelFormatFromBayerPattern(std::string_view pattern);

// A GUID as the 16 lowercase hex digits configuration files use.
std::string formatGuid(std::uint64_t guid);
std::optional<std::uint64_t> parseGuid(std::string_view text);

}  // namespace fieldrig::drivers
