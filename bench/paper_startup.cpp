// paper_startup: a program built as the paper's pipeline is, on stock PCL: PCL's PLY reader and
// its modules linked the way PCL's CMake config links them (every component, VTK through pcl_io
// and pcl_surface). cloud_read_bench runs it with no argument to measure that start-up, the
// paper's share of a whole `traits` run. Given a PLY it reads it and prints the point count, so
// the reader is really linked and used.
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc < 2)
    return 0;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  if (pcl::io::loadPLYFile(argv[1], cloud) < 0)
    return 1;
  std::printf("%zu\n", cloud.size());
  return 0;
}
