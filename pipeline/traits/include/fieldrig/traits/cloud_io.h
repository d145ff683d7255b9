// Reading and writing plot clouds (PLY or PCD, by extension) as plain points.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::traits {

// Loads x, y, z of every point (NaNs kept: the pipeline counts them). Errors name the file.
core::Result<std::vector<Eigen::Vector3f>> loadCloud(const std::string& path);

// Writes a binary PLY with x y z (float) and red green blue (uchar); colours may be empty.
core::Result<bool> saveCloudPly(const std::string& path, const std::vector<Eigen::Vector3f>& points,
                                const std::vector<std::array<std::uint8_t, 3>>& colors);

}  // namespace fieldrig::traits
