// What a sim camera serves for each trigger, as libcamera's virtual pipeline has frame
// generators: a source fills one frame per trigger (TestPatternSource, SessionReplaySource), and
// FaultInjector wraps a source to drop, delay, corrupt or mis-stamp its frames.
#pragma once

#include <cstdint>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/frame_pool.h"
#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/time.h"

namespace fieldrig::sim {

// One trigger, as a sim camera's worker thread serves it.
struct SimTrigger {
  std::uint64_t id = 0;           // the rig's trigger id; ids increase
  std::uint64_t since_first = 0;  // id minus the first id the camera took since start()
  core::SteadyTime issued{};      // the rig's trigger instant: when the sim "exposes"
};

// The frame a sim camera hands its source for `trigger`, pixels not yet filled: camera index,
// trigger id, width × height with packed rows, `format`, and the trigger instant as the device
// timestamp (the sim "exposes" when triggered; its device clock is the host's steady clock).
core::Frame stampedFrame(const SimTrigger& trigger, std::uint32_t camera_index, std::uint32_t width,
                         std::uint32_t height, core::PixelFormat format);

// Thread contract: owned by one camera; fill() is called on its worker thread only.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Completes `frame` for `trigger`; it arrives as stampedFrame() made it, with the configured
  // pixel format. Pixels go into a buffer of `pool`; a dry pool gives a kDropped frame without
  // pixels. False: nothing is delivered for this trigger (the rig times the frame out as
  // missing). Allocates nothing per frame.
  virtual bool fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) = 0;
};

}  // namespace fieldrig::sim
