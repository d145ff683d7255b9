// Generated frames: each frame is a deterministic pattern of (camera, trigger id), so that readers
// can check that the pixels they got belong to the frame the metadata names.
#pragma once

#include <cstdint>
#include <vector>

#include "fieldrig/sim/frame_source.h"

namespace fieldrig::sim {

// Thread contract: see FrameSource.
class TestPatternSource final : public FrameSource {
 public:
  // For frames `width` pixels wide (the row template is built here, not per frame).
  explicit TestPatternSource(std::uint32_t width);

  bool fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) override;

  // The pixel value the pattern puts at (x, y) of camera `camera_index`'s frame for a trigger.
  static std::uint8_t patternAt(std::uint32_t camera_index, std::uint64_t trigger_id,
                                std::uint32_t x, std::uint32_t y);

 private:
  std::vector<std::uint8_t> row_template_;  // patternAt(0, 0, x, 0) for one row
};

}  // namespace fieldrig::sim
