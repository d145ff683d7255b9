// The camera registry as the programs fill it: the hardware drivers this build has, and the sim
// driver, which drivers/ knows nothing of and its users add (sim::addSimCamera). Each call adds
// it again (idempotent): every test, run alone in its own process, gets it.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "fieldrig/drivers/camera.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/sim/sim_camera.h"

namespace fieldrig::testing_support {

inline drivers::CameraRegistry& camerasWithSim() {
  drivers::CameraRegistry& registry = drivers::CameraRegistry::instance();
  sim::addSimCamera(registry);
  return registry;
}

// The six cameras of the rig as sim cameras (ids "0" … "5", in the rig layout's order) of
// width × height, a set given up on after 100 ms.
inline drivers::RigOptions sixSimCameras(std::uint32_t width, std::uint32_t height) {
  drivers::RigOptions options;
  options.driver = "sim";
  for (int i = 0; i < 6; ++i) {
    drivers::CameraConfig camera;
    camera.id = std::to_string(i);
    camera.width = width;
    camera.height = height;
    options.cameras.push_back(camera);
  }
  options.frame_timeout = std::chrono::milliseconds{100};
  return options;
}

}  // namespace fieldrig::testing_support
