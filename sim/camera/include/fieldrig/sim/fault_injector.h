// Faults injected around a frame source, on request (the sim camera's options): the rig, the
// recorder and the daemon are tested against missing, late, corrupt and out-of-sync frames, for
// generated and replayed frames alike.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "fieldrig/sim/frame_source.h"

namespace fieldrig::sim {

struct FaultOptions {
  std::uint64_t drop_every = 0;              // no frame for trigger ids divisible by N (0: none)
  std::uint64_t corrupt_every = 0;           // frames of ids divisible by N are marked kCorrupt
  std::chrono::milliseconds delay{0};        // each frame is delivered this long after its trigger
  std::chrono::nanoseconds clock_offset{0};  // added to the device timestamp (a camera out of sync)
};

// Thread contract: see FrameSource.
class FaultInjector final : public FrameSource {
 public:
  FaultInjector(std::unique_ptr<FrameSource> source, const FaultOptions& faults);

  // A dropped trigger never reaches the source; a delayed one sleeps on the worker thread (never
  // on the trigger thread). Only a frame with pixels is marked corrupt: a dropped one stays
  // dropped.
  bool fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) override;

 private:
  std::unique_ptr<FrameSource> source_;
  FaultOptions faults_;
};

}  // namespace fieldrig::sim
