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

core::Result<bool> saveCloudPly(const std::string& path, const std::vector<Eigen::Vector3f>& points,
                                const std::vector<std::array<std::uint8_t, 3>>& colors) {
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  cloud.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pcl::PointXYZRGB p;
    p.x = points[i].x();
    p.y = points[i].y();
    p.z = points[i].z();
    if (i < colors.size()) {
      p.r = colors[i][0];
      p.g = colors[i][1];
      p.b = colors[i][2];
    }
    cloud.push_back(p);
  }
  if (cloud.empty()) {
    // PCL refuses to write an empty cloud; an empty plot is still a valid (if useless) file.
    cloud.width = 0;
    cloud.height = 1;
  }
  // Without PCL's "camera" element, whose properties PCL's own reader then warns about.
  pcl::PLYWriter writer;
  if (writer.write(path, cloud, /*binary=*/true, /*use_camera=*/false) < 0)
    return core::Error{path + ": cannot write the PLY file"};
  return true;
}

}  // namespace fieldrig::traits
