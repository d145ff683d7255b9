// The camera registry as the programs fill it: the hardware drivers this build has, and the sim
// driver, which drivers/ knows nothing of and its users add (sim::addSimCamera). Each call adds
// it again (idempotent): every test, run alone in its own process, gets it.
#pragma once

#include "fieldrig/drivers/camera.h"
#include "fieldrig/sim/sim_camera.h"

namespace fieldrig::testing_support {

inline drivers::CameraRegistry& camerasWithSim() {
  drivers::CameraRegistry& registry = drivers::CameraRegistry::instance();
  sim::addSimCamera(registry);
  return registry;
}

}  // namespace fieldrig::testing_support
