// Reading plot clouds (PLY or PCD, by extension) as plain points. Clouds are written by
// cloud::writePly.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::traits {

// Loads x, y, z of every point (NaNs kept: the pipeline counts them). Errors name the file.
core::Result<std::vector<Eigen::Vector3f>> loadCloud(const std::string& path);

}  // namespace fieldrig::traits
