#include "fieldrig/sim/fault_injector.h"

#include <thread>

namespace fieldrig::sim {

FaultInjector::FaultInjector(std::unique_ptr<FrameSource> source, const FaultOptions& faults)
    : source_(std::move(source)), faults_(faults) {}

bool FaultInjector::fill(const SimTrigger& trigger, core::FramePool& pool, core::Frame& frame) {
  if (faults_.drop_every != 0 && trigger.id % faults_.drop_every == 0)
    return false;
  if (faults_.delay.count() > 0)
    std::this_thread::sleep_until(trigger.issued + faults_.delay);
  if (!source_->fill(trigger, pool, frame))
    return false;
  frame.metadata.device_timestamp_ns += faults_.clock_offset.count();
  if (frame.buffer && faults_.corrupt_every != 0 && trigger.id % faults_.corrupt_every == 0)
    frame.metadata.status = core::FrameStatus::kCorrupt;
  return true;
}

}  // namespace fieldrig::sim
