// The camera driver interface and its registry: one abstract Camera, drivers created by name
// (the configuration names "sim", "aravis" or "dc1394"); a driver whose library is absent is not
// built and so not registered (STYLE.md items 1 and 2).
//
// Thread contract: configure/start/stop/trigger are called by the camera's owner (the Rig).
// trigger() never blocks: the GPS/trigger thread calls it. Frames are delivered on the driver's
// own thread through the FrameSink, which must not block either (it only posts the frame).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/result.h"

namespace fieldrig::drivers {

enum class TriggerSource { kSoftware, kExternal };

struct CameraConfig {
  std::string id;  // driver-specific: GUID for dc1394, device id for aravis, index for sim
  core::PixelFormat format = core::PixelFormat::kBayerRG8;
  std::uint32_t width = 1624;
  std::uint32_t height = 1224;
  double exposure_us = 2000;
  double gain_db = 0;
  std::optional<std::pair<double, double>> white_balance;  // (blue/U, red/V) gains
  TriggerSource trigger = TriggerSource::kSoftware;
  std::map<std::string, std::string> options;  // driver-specific extras
};

// The link between one camera and the host as its driver counts it, for run summaries and the
// daemon's status: generic, so that neither knows a driver. A snapshot.
struct CameraLinkStats {
  // The transport carries a frame in packets that the host can ask to have resent (GigE Vision).
  // False for the others (1394 isochronous DMA, sim): the packet counts are then not known, and
  // are reported as absent rather than as a clean link.
  bool has_packets = false;
  std::uint64_t packets_resent = 0;   // came back after a resend request
  std::uint64_t packets_missing = 0;  // never came, resends included: their frames are damaged
  std::uint64_t frames_missing_packets = 0;  // delivered marked corrupt for missing packets
  // Triggers the camera folded into the exposure of an earlier one, so that their frames were
  // never taken (the camera, not the link, was late). Known only where the driver can tell from
  // the camera's own timestamps (Aravis, once a frame was matched by them); false elsewhere, and
  // the count is then not known.
  bool counts_merged_triggers = false;
  std::uint64_t triggers_merged = 0;
};

class Camera {
 public:
  using FrameSink = std::function<void(core::Frame&& frame)>;

  virtual ~Camera() = default;
  virtual std::string driverName() const = 0;
  virtual core::Result<void> configure(const CameraConfig& config) = 0;
  // Frames are written into buffers from `pool` and handed to `sink` on the driver's thread.
  virtual core::Result<void> start(core::FramePool& pool, FrameSink sink) = 0;
  virtual void stop() = 0;
  // Software trigger for `trigger_id`; false if the camera cannot take it now (not started,
  // external trigger, queue full). Never blocks.
  virtual bool trigger(std::uint64_t trigger_id) = 0;
  // The same, for a trigger the rig issued to all cameras at `issued` (one broadcast on a real
  // bus). Drivers whose device stamps exposures themselves ignore the time.
  virtual bool triggerAt(std::uint64_t trigger_id, core::SteadyTime issued) {
    (void)issued;
    return trigger(trigger_id);
  }
  // The link's counters so far (after stop(): of the whole run). Any thread, at any time, also
  // during start() and stop(); never blocks the frame path. Drivers without packets keep this.
  virtual CameraLinkStats linkStats() const { return {}; }
};

class CameraRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Camera>()>;

  // The registry with every hardware driver this build has. Other drivers are added by their
  // users, before they create cameras: the sim driver by sim::addSimCamera.
  static CameraRegistry& instance();

  void add(const std::string& name, Factory factory);
  core::Result<std::unique_ptr<Camera>> create(const std::string& name) const;
  std::vector<std::string> names() const;

 private:
  std::map<std::string, Factory> factories_;
};

}  // namespace fieldrig::drivers
