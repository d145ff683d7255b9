// libFuzzer target for traits::loadCloud, the plot-cloud reader (PLY and PCD, both our own
// readers). An input starting with "ply" is written as a .ply file, any other as a .pcd file.
//
// Besides crashes and sanitizer reports (a header count trusted before the file's size is the
// std::bad_alloc this reader was fixed for): an error starts with the file's path; a cloud that
// loads holds no more points than the file has bytes (every point takes at least one byte in
// every format), and reading the same file again gives the same points.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/traits/cloud_io.h"
#include "fuzz_support.h"

namespace {

using fieldrig::fuzz::check;
using fieldrig::fuzz::startsWith;

// The headers of tests/pipeline/traits/cloud_io_test.cpp, with their points.
std::string plyHead(const char* format, int count, const char* extra_properties = "") {
  return std::string("ply\nformat ") + format +
         " 1.0\ncomment written by fieldrig\nelement vertex " + std::to_string(count) +
         "\nproperty float x\nproperty float y\nproperty float z\n" + extra_properties +
         "end_header\n";
}

std::string floats(std::initializer_list<float> values) {
  std::string bytes(values.size() * sizeof(float), '\0');
  std::memcpy(bytes.data(), values.begin(), bytes.size());
  return bytes;
}

bool samePoints(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b) {
  if (a.size() != b.size())
    return false;
  // Bytes, not values: NaN coordinates are kept and must read back as NaN.
  return a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Eigen::Vector3f)) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  using fieldrig::fuzz::writeSeed;
  writeSeed("ascii.ply", plyHead("ascii", 3) + "1 2 3\n4 5 6\nnan 0.5 -1e3\n");
  writeSeed("binary.ply", plyHead("binary_little_endian", 2) + floats({1, 2, 3, 4, 5, 6}));
  writeSeed("big_endian.ply", plyHead("binary_big_endian", 1) +
                                  std::string("\x3f\x80\0\0\x40\0\0\0\x40\x40\0\0", 12));
  writeSeed("colour.ply",
            plyHead("binary_little_endian", 1,
                    "property uchar red\nproperty uchar green\nproperty uchar blue\n") +
                floats({0.25f, -0.5f, 1.5f}) + "\x10\x20\x30");
  std::string faces = plyHead("ascii", 3);
  faces.insert(faces.find("end_header"),
               "element face 1\nproperty list uchar int vertex_indices\n");
  writeSeed("faces.ply", faces + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  writeSeed("ascii.pcd",
            "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  static const fieldrig::fuzz::FuzzFolder folder("cloud_file");
  const std::string_view data(reinterpret_cast<const char*>(bytes), size);
  const std::string path =
      folder.write(startsWith(data, "ply") ? "cloud.ply" : "cloud.pcd", data).string();

  const auto loaded = fieldrig::traits::loadCloud(path);
  if (!loaded) {
    check(startsWith(loaded.error().message, path + ":"), "an error that does not name the file");
    return 0;
  }
  check(loaded->size() <= size, "more points than the file has bytes");
  const auto again = fieldrig::traits::loadCloud(path);
  check(again && samePoints(*loaded, *again), "the same file reads as other points");
  return 0;
}
