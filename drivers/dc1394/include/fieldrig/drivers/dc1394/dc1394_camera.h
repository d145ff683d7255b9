// The dc1394 driver: one IIDC camera on an IEEE-1394 bus through libdc1394-2, for the rig's six
// Point Grey Grasshopper GRAS-20S4C (Format7 mode 0, RAW8 Bayer, 1394b at S800, trigger mode 0).
//
// configure() opens the camera by GUID (see dc1394_settings.h for the options), sets 1394b and the
// ISO speed, the Format7 mode, RAW8, the ROI and the packet size from the bandwidth planner (an
// impossible plan is refused with its numbers), trigger mode 0 with the external line
// (TRIGGER_SOURCE_0) or the software trigger, and exposure, gain and white balance. Without a bus
// or camera it returns "no IEEE-1394 bus/camera found: …".
//
// start() sets up the DMA ring and turns transmission on; one driver thread fires software
// triggers (optionally as a bus broadcast so every camera exposes in the same cycle), dequeues
// frames, copies each into a pool buffer, pairs it with its trigger (TriggerMatcher), stamps the
// metadata and hands it to the sink. stop() and the destructor turn transmission off, stop capture
// and release the ISO channel and bandwidth whatever happened before.
//
// With the external source, trigger(id) announces the id of the pulse the trigger hardware fires
// now (nothing goes on the bus) so that the frame can be paired with it.
//
// Thread contract: see Camera. configure/start/stop on the owner's thread; trigger() on one other
// thread (never blocks: it posts to the driver thread); stats() from any thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "fieldrig/core/spsc_queue.h"
#include "fieldrig/drivers/camera.h"
#include "fieldrig/drivers/dc1394/dc1394_settings.h"
#include "fieldrig/drivers/dc1394/iso_bandwidth.h"

namespace fieldrig::drivers {

struct Dc1394Stats {
  std::uint64_t frames = 0;            // delivered to the sink
  std::uint64_t corrupt = 0;           // delivered marked kCorrupt (libdc1394 or size check)
  std::uint64_t pool_exhausted = 0;    // delivered marked kDropped: no free pool buffer
  std::uint64_t triggers_fired = 0;    // software triggers written (or external ids announced)
  std::uint64_t trigger_errors = 0;    // software trigger writes the bus refused
  std::uint64_t triggers_refused = 0;  // trigger() calls refused (not started, queue full)
  std::uint64_t triggers_missed = 0;   // triggers no frame answered (dropped frames)
  std::uint64_t unexpected = 0;        // frames for no trigger (not delivered)
  std::uint64_t behind = 0;            // frames dequeued with others waiting behind them
  std::uint64_t max_frames_behind = 0;
  std::uint64_t ring_full = 0;  // frames dequeued from a full DMA ring: the kernel may drop
};

class Dc1394Camera final : public Camera {
 public:
  Dc1394Camera();
  ~Dc1394Camera() override;
  Dc1394Camera(const Dc1394Camera&) = delete;
  Dc1394Camera& operator=(const Dc1394Camera&) = delete;

  std::string driverName() const override { return "dc1394"; }
  core::Result<void> configure(const CameraConfig& config) override;
  core::Result<void> start(core::FramePool& pool, FrameSink sink) override;
  void stop() override;
  bool trigger(std::uint64_t trigger_id) override;

  Dc1394Stats stats() const;
  // The bandwidth plan applied by the last successful configure().
  const IsoPlan& plan() const { return plan_; }

 private:
  struct Device;  // the libdc1394 handles; vendor types stay in the .cpp
  struct PendingTrigger {
    std::uint64_t id = 0;
    std::int64_t announced_us = 0;  // system clock, the clock of libdc1394's frame timestamps
  };

  void run();
  void fireTriggers();
  void drainFrames();

  Dc1394Settings settings_;
  IsoPlan plan_;
  std::unique_ptr<Device> device_;
  // eventfd through which trigger() and stop() wake the driver thread; open for the object's
  // whole life so that a late trigger() never writes to a closed descriptor.
  int wake_fd_ = -1;
  core::FramePool* pool_ = nullptr;
  FrameSink sink_;
  core::SpscQueue<PendingTrigger> triggers_{256};
  std::atomic<bool> running_{false};
  std::uint64_t sequence_ = 0;  // driver thread only
  std::thread worker_;

  // Written by the driver thread (trigger() for triggers_refused_), read by stats().
  std::atomic<std::uint64_t> frames_{0}, corrupt_{0}, pool_exhausted_{0}, triggers_fired_{0},
      trigger_errors_{0}, triggers_refused_{0}, triggers_missed_{0}, unexpected_{0}, behind_{0},
      max_frames_behind_{0}, ring_full_{0};
};

std::unique_ptr<Camera> makeDc1394Camera();

}  // namespace fieldrig::drivers
