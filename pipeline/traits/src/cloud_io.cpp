#include "fieldrig/traits/cloud_io.h"

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace fieldrig::traits {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

core::Result<std::vector<Eigen::Vector3f>> loadCloud(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return core::Error{path + ": no such file"};
  const std::string ext = lowerExtension(path);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  int status = -1;
  if (ext == ".ply") {
    status = pcl::io::loadPLYFile(path, cloud);
  } else if (ext == ".pcd") {
    status = pcl::io::loadPCDFile(path, cloud);
  } else {
    return core::Error{path + ": unknown cloud format '" + ext + "' (expected .ply or .pcd)"};
  }
  if (status < 0)
    return core::Error{path + ": not a readable " + ext.substr(1) + " point cloud"};
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.size());
  for (const pcl::PointXYZ& p : cloud)
    points.emplace_back(p.x, p.y, p.z);
  return points;
}

}  // namespace fieldrig::traits
