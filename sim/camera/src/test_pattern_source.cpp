#include "fieldrig/sim/test_pattern_source.h"

namespace fieldrig::sim {

TestPatternSource::TestPatternSource(std::uint32_t width) : row_template_(width) {
  for (std::uint32_t x = 0; x < width; ++x)
    row_template_[x] = patternAt(0, 0, x, 0);
}

std::uint8_t TestPatternSource::patternAt(std::uint32_t camera_index, std::uint64_t trigger_id,
                                          std::uint32_t x, std::uint32_t y) {
  // Cheap to generate and to check, different for every camera, trigger and position.
  return static_cast<std::uint8_t>(x * 3 + y * 7 + camera_index * 31 + trigger_id * 13);
}

bool TestPatternSource::fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) {
  core::FrameMetadata& m = frame.metadata;
  frame.buffer = pool.acquire();
  if (!frame.buffer) {
    m.status = core::FrameStatus::kDropped;
    return true;
  }
  // Row y is the row template (x * 3) plus a per-row constant, in 8-bit wrap-around: the same
  // values patternAt() gives, at memory speed (the sim must keep up with six 2 MP cameras).
  std::uint8_t* pixels = frame.buffer.bytes().data();
  for (std::uint32_t y = 0; y < m.height; ++y) {
    const std::uint8_t base = patternAt(m.camera, trigger.id, 0, y);
    std::uint8_t* row = pixels + std::size_t{y} * m.stride;
    for (std::uint32_t x = 0; x < m.width; ++x)
      row[x] = static_cast<std::uint8_t>(row_template_[x] + base);
  }
  return true;
}

}  // namespace fieldrig::sim
