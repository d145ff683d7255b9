// loadCloud never trusts a header: huge, truncated, garbage, empty and folder inputs are errors
// naming the file (before: std::bad_alloc for a huge PLY or PCD count, a segfault inside PCL for
// an empty or garbage .pcd). PCL's own test clouds, ASCII, binary and LZF-compressed, read
// exactly as PCL reads them.
#include <fcntl.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "fieldrig/traits/cloud_io.h"
#include "support/temp_dir.h"

namespace fieldrig::traits {
namespace {

using testing_support::ScopedTempDir;

const std::string kPclData = std::string(FIELDRIG_SHARED_DATA_DIR) + "/pointclouds/pcl/";

std::string writeFile(const ScopedTempDir& dir, const std::string& name, const std::string& bytes) {
  const std::string path = (dir / name).string();
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// The load fails, its message starts with the file and contains `what`.
void expectRefused(const std::string& path, const std::string& what) {
  const auto loaded = loadCloud(path);
  ASSERT_FALSE(loaded) << path << " loaded " << loaded->size() << " points";
  EXPECT_EQ(loaded.error().message.rfind(path + ":", 0), 0u) << loaded.error().message;
  EXPECT_NE(loaded.error().message.find(what), std::string::npos) << loaded.error().message;
}

std::string binary(std::initializer_list<float> values) {
  std::string bytes(values.size() * sizeof(float), '\0');
  std::memcpy(bytes.data(), values.begin(), bytes.size());
  return bytes;
}

const std::string kPlyBinaryHead =
    "ply\nformat binary_little_endian 1.0\nelement vertex COUNT\nproperty float x\n"
    "property float y\nproperty float z\nend_header\n";
const std::string kPlyAsciiHead =
    "ply\nformat ascii 1.0\nelement vertex COUNT\nproperty float x\nproperty float y\n"
    "property float z\nend_header\n";

std::string withCount(std::string head, const std::string& count) {
  return head.replace(head.find("COUNT"), 5, count);
}

TEST(CloudIo, PlyHugeVertexCountsAreRefusedBeforeReserving) {
  ScopedTempDir dir("cloud_io_ply_huge");
  const std::string points = binary({1, 2, 3, 4, 5, 6});
  for (const char* count : {"2147483647", "4294967295", "3"}) {
    expectRefused(writeFile(dir, "huge.ply", withCount(kPlyBinaryHead, count) + points),
                  "the header declares " + std::string(count) +
                      " 'vertex' elements, but the file's 24 bytes after the header hold at most "
                      "2 (12 bytes each)");
  }
  expectRefused(
      writeFile(dir, "huge_ascii.ply", withCount(kPlyAsciiHead, "4294967295") + "1 2 3\n4 5 6\n"),
      "hold at most 2 (6 bytes each at the least in ASCII)");
  std::string with_faces = withCount(kPlyBinaryHead, "2");
  with_faces.insert(with_faces.find("end_header"),
                    "element face 1000000000\nproperty list uchar int vertex_indices\n");
  expectRefused(writeFile(dir, "huge_face.ply", with_faces + points),
                "declares 1000000000 'face' elements");
  // A count beyond 64 bits is no count at all.
  expectRefused(
      writeFile(dir, "overflow.ply", withCount(kPlyBinaryHead, "99999999999999999999999") + points),
      "expected 'element NAME COUNT' with a whole COUNT");
}

TEST(CloudIo, PlyTruncatedGarbageEmptyAndFolder) {
  ScopedTempDir dir("cloud_io_ply_bad");
  // Fewer bytes than the declared vertices need, but within the bound.
  expectRefused(
      writeFile(dir, "cut.ply", withCount(kPlyAsciiHead, "3") + "1 2 3\n4 5 6\n7.5 8.25\n"),
      ":10: 2 values do not make one 'vertex' element (3 properties)");
  expectRefused(writeFile(dir, "cut_lines.ply",
                          withCount(kPlyAsciiHead, "3") + "1 2 3\n4 5 6\n\n\n\n\n\n\n\n\n"),
                "cut off: 2 of the 3 'vertex' elements");
  expectRefused(writeFile(dir, "no_end.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"),
                "no 'end_header' line");
  expectRefused(writeFile(dir, "garbage.ply", std::string("\x7f\x00\x13garbage\n\xff", 12)),
                "not a PLY file");
  expectRefused(writeFile(dir, "empty.ply", ""), "empty file");
  std::filesystem::create_directory(dir / "folder.ply");
  expectRefused((dir / "folder.ply").string(), "is a folder, not a cloud file");
  expectRefused((dir / "absent.ply").string(), "no such file");
}

TEST(CloudIo, PlyWithinTheFileLoads) {
  ScopedTempDir dir("cloud_io_ply_good");
  auto loaded = loadCloud(
      writeFile(dir, "two.ply", withCount(kPlyBinaryHead, "2") + binary({1, 2, 3, 4, 5, 6})));
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->size(), 2u);
  EXPECT_EQ((*loaded)[1], Eigen::Vector3f(4, 5, 6));
  // The last ASCII line may end without a line break.
  auto ascii =
      loadCloud(writeFile(dir, "two_ascii.ply", withCount(kPlyAsciiHead, "2") + "1 2 3\n4 5 6"));
  ASSERT_TRUE(ascii) << ascii.error().message;
  EXPECT_EQ(ascii->size(), 2u);
}

// A header that declares fewer points than the file holds read the first ones only, and
// `fieldrig traits` gave the traits of part of the plot with exit 0.
TEST(CloudIo, PlyWithMoreDataThanItsHeaderDeclaresIsRefused) {
  ScopedTempDir dir("cloud_io_ply_more");
  expectRefused(
      writeFile(dir, "more.ply", withCount(kPlyBinaryHead, "1") + binary({1, 2, 3, 4, 5, 6})),
      "12 bytes after the 1 'vertex' elements the header declares");
  expectRefused(
      writeFile(dir, "more_ascii.ply", withCount(kPlyAsciiHead, "1") + "1 2 3\n\n4 5 6\n"),
      "more_ascii.ply:10: a value after the 1 'vertex' elements the header declares");
  auto spaces =
      loadCloud(writeFile(dir, "spaces.ply", withCount(kPlyAsciiHead, "1") + "1 2 3\n \n\t\n"));
  ASSERT_TRUE(spaces) << spaces.error().message;
  EXPECT_EQ(spaces->size(), 1u);
}

// PCL's reader read a word as NaN and `fieldrig traits` went on with exit 0.
TEST(CloudIo, PlyAsciiWordsAreRefusedNamingTheLine) {
  ScopedTempDir dir("cloud_io_ply_word");
  expectRefused(writeFile(dir, "word.ply", withCount(kPlyAsciiHead, "2") + "1 2 3\n4 five 6\n"),
                "word.ply:9: 'five' is not a number");
  expectRefused(writeFile(dir, "long.ply", withCount(kPlyAsciiHead, "1") + "1 2 3 4\n"),
                ":8: 4 values do not make one 'vertex' element");
}

// These aborted (assert) or were undefined behaviour inside PCL 1.13's reader: colours out of
// order, damaged list properties, a vertex element of zero points.
TEST(CloudIo, PlyThatPclAbortedOnIsReadOrRefused) {
  ScopedTempDir dir("cloud_io_ply_pcl_crashes");
  std::string colour = withCount(kPlyBinaryHead, "1");
  colour.insert(colour.find("end_header"), "property uchar blue\nproperty uchar alpha\n");
  auto loaded = loadCloud(writeFile(dir, "blue.ply", colour + binary({1, 2, 3}) + "\x10\x20"));
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->size(), 1u);
  EXPECT_EQ((*loaded)[0], Eigen::Vector3f(1, 2, 3));

  const std::string faces_first =
      "ply\nformat ascii 1.0\nelement face 2\nproperty list uchar int vertex_indices\n"
      "element vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  loaded = loadCloud(writeFile(dir, "faces_first.ply", faces_first + "3 0 1 2\n0\n1 2 3\n4 5 6\n"));
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->size(), 2u);
  EXPECT_EQ((*loaded)[1], Eigen::Vector3f(4, 5, 6));
  expectRefused(writeFile(dir, "list_long.ply", faces_first + "9 0 1 2\n0\n1 2 3\n4 5 6\n"),
                ":10: 4 values do not make one 'face' element");
  expectRefused(writeFile(dir, "list_negative.ply", faces_first + "-1 0\n0\n1 2 3\n4 5 6\n"),
                ":10: list 'vertex_indices' has no whole, non-negative count");

  std::string binary_faces = withCount(kPlyBinaryHead, "1");
  binary_faces.insert(binary_faces.find("element vertex"),
                      "element face 1\nproperty list char int vertex_indices\n");
  expectRefused(
      writeFile(dir, "list_binary.ply", binary_faces + std::string("\xff", 1) + binary({1, 2, 3})),
      "list 'vertex_indices' has a negative count");
  expectRefused(writeFile(dir, "list_past_end.ply",
                          binary_faces + std::string("\x7f", 1) + binary({1, 2, 3})),
                "cut off in 'face' element 0 of 1");

  loaded = loadCloud(writeFile(dir, "none.ply", withCount(kPlyBinaryHead, "0")));
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(loaded->empty());
}

TEST(CloudIo, PlyBigEndianAndMixedTypes) {
  ScopedTempDir dir("cloud_io_ply_types");
  const std::string head =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\n"
      "property short y\nproperty uint z\nproperty uchar red\nend_header\n";
  // x = 1.5 (double), y = -2 (short), z = 70000 (uint), red = 7; all big-endian.
  const std::string body(
      "\x3f\xf8\0\0\0\0\0\0"
      "\xff\xfe"
      "\0\x01\x11\x70"
      "\x07",
      15);
  const auto loaded = loadCloud(writeFile(dir, "be.ply", head + body));
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->size(), 1u);
  EXPECT_EQ((*loaded)[0], Eigen::Vector3f(1.5f, -2.0f, 70000.0f));
}

// PCL's test clouds written as PLY by PCL's writer (ASCII and binary, with colour), read point
// for point as PCL's own PLY reader reads them.
TEST(CloudIo, PlyWrittenByPclReadsAsPclReadsIt) {
  ScopedTempDir dir("cloud_io_ply_pcl");
  // PCL's reader lists the properties of its own "camera" element that it does not handle.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  for (const char* name : {"bun0.pcd", "table_scene_mug_stereo_textured.pcd"}) {
    pcl::PointCloud<pcl::PointXYZRGB> source;
    ASSERT_EQ(pcl::io::loadPCDFile(kPclData + name, source), 0) << name;
    for (const bool binary_mode : {false, true}) {
      const std::string path =
          (dir / (std::string(name) + (binary_mode ? ".bin.ply" : ".ascii.ply"))).string();
      ASSERT_EQ(pcl::io::savePLYFile(path, source, binary_mode), 0) << path;
      pcl::PointCloud<pcl::PointXYZ> reference;
      ASSERT_EQ(pcl::io::loadPLYFile(path, reference), 0) << path;
      const auto loaded = loadCloud(path);
      ASSERT_TRUE(loaded) << loaded.error().message;
      ASSERT_EQ(loaded->size(), reference.size()) << path;
      std::size_t differing = 0;
      for (std::size_t i = 0; i < reference.size(); ++i) {
        const Eigen::Vector3f expected = reference[i].getVector3fMap();
        for (int k = 0; k < 3; ++k) {
          const float a = (*loaded)[i][k];
          const float b = expected[k];
          if (!(a == b || (std::isnan(a) && std::isnan(b))))
            ++differing;
        }
      }
      EXPECT_EQ(differing, 0u) << path;
    }
  }
}

// What fd 2 receives while `run` runs: PCL prints with fprintf(stderr, …), below std::cerr.
template <typename Run>
std::string stderrOf(const ScopedTempDir& dir, Run run) {
  std::fflush(stderr);
  const int saved = ::dup(2);
  const std::string path = (dir / "stderr.txt").string();
  const int file = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::dup2(file, 2);
  run();
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  ::close(file);
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A vertex element without x, y or z: PCL's reader printed "Failed to find match for field 'x'"
// and gave every point as (0, 0, 0), which `fieldrig traits` took for a plot without plants
// (exit 0). Now refused, naming the line; and nothing PCL says reaches stderr.
TEST(CloudIo, PlyWithoutXyzIsRefusedAndPclPrintsNothing) {
  ScopedTempDir dir("cloud_io_ply_no_xyz");
  std::string no_z = withCount(kPlyAsciiHead, "2") + "1 2 3\n4 5 6\n";
  no_z.replace(no_z.find("property float z"), 16, "property float w");
  expectRefused(writeFile(dir, "no_z.ply", no_z), ":3: the 'vertex' element has no property 'z'");
  expectRefused(writeFile(dir, "faces.ply",
                          "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int "
                          "vertex_indices\nend_header\n3 0 1 2\n"),
                "no 'vertex' element");
  const std::string err = stderrOf(dir, [&] {
    EXPECT_FALSE(loadCloud(
        writeFile(dir, "cut.ply", withCount(kPlyAsciiHead, "3") + "1 2 3\n4 5 6\n7.5 8\n")));
  });
  EXPECT_EQ(err, "");
}

// PCL's test clouds: ASCII (bun0, sac_plane_test) and LZF-compressed binary (the others), read
// point for point as PCL reads them.
TEST(CloudIo, PclTestCloudsReadAsPclReadsThem) {
  for (const char* name : {"bun0.pcd", "sac_plane_test.pcd", "noisy_slice_displaced.pcd",
                           "table_scene_mug_stereo_textured.pcd"}) {
    const std::string path = kPclData + name;
    pcl::PointCloud<pcl::PointXYZ> reference;
    ASSERT_EQ(pcl::io::loadPCDFile(path, reference), 0) << path;
    const auto loaded = loadCloud(path);
    ASSERT_TRUE(loaded) << loaded.error().message;
    ASSERT_EQ(loaded->size(), reference.size()) << name;
    std::size_t differing = 0;
    for (std::size_t i = 0; i < reference.size(); ++i) {
      const pcl::PointXYZ& r = reference[i];
      const Eigen::Vector3f& p = (*loaded)[i];
      for (int k = 0; k < 3; ++k) {
        const float a = p[k];
        const float b = k == 0 ? r.x : k == 1 ? r.y : r.z;
        if (!(a == b || (std::isnan(a) && std::isnan(b))))
          ++differing;
      }
    }
    EXPECT_EQ(differing, 0u) << name;
  }
}

const std::string kPcdHead =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH W\n"
    "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS W\nDATA KIND\n";

std::string pcdHead(const std::string& points, const std::string& kind) {
  std::string head = kPcdHead;
  for (std::size_t at; (at = head.find(" W\n")) != std::string::npos;)
    head.replace(at, 3, " " + points + "\n");
  return head.replace(head.find("KIND"), 4, kind);
}

TEST(CloudIo, PcdBinaryAndAsciiLoad) {
  ScopedTempDir dir("cloud_io_pcd_good");
  auto bin =
      loadCloud(writeFile(dir, "b.pcd", pcdHead("2", "binary") + binary({1, 2, 3, 4, 5, 6})));
  ASSERT_TRUE(bin) << bin.error().message;
  ASSERT_EQ(bin->size(), 2u);
  EXPECT_EQ((*bin)[1], Eigen::Vector3f(4, 5, 6));
  auto ascii = loadCloud(writeFile(dir, "a.pcd", pcdHead("2", "ascii") + "1 2 3\nnan 5 6\n"));
  ASSERT_TRUE(ascii) << ascii.error().message;
  ASSERT_EQ(ascii->size(), 2u);
  EXPECT_TRUE(std::isnan((*ascii)[1].x()));
}

TEST(CloudIo, PcdHugeCountsAreRefusedBeforeReserving) {
  ScopedTempDir dir("cloud_io_pcd_huge");
  const std::string points = binary({1, 2, 3, 4, 5, 6});
  expectRefused(writeFile(dir, "huge.pcd", pcdHead("2147483647", "binary") + points),
                "the header declares 2147483647 points, but the file's 24 bytes after the header "
                "hold at most 2 (12 bytes each)");
  expectRefused(writeFile(dir, "huge_ascii.pcd", pcdHead("4294967295", "ascii") + "1 2 3\n"),
                "hold at most 1 (6 bytes each at the least in ASCII)");
  // binary_compressed: the block's own sizes against the header and the file.
  const auto block = [](std::uint32_t compressed, std::uint32_t uncompressed) {
    std::string bytes(8, '\0');
    std::memcpy(bytes.data(), &compressed, 4);
    std::memcpy(bytes.data() + 4, &uncompressed, 4);
    return bytes;
  };
  expectRefused(writeFile(dir, "huge_lzf.pcd",
                          pcdHead("2147483647", "binary_compressed") + block(4, 4) + "abcd"),
                "more than a compressed block (at most 4 GiB) holds");
  expectRefused(writeFile(dir, "lzf_ratio.pcd",
                          pcdHead("100000", "binary_compressed") + block(4, 1200000) + "abcd"),
                "more than the 4 compressed bytes can hold");
  expectRefused(writeFile(dir, "lzf_claims.pcd",
                          pcdHead("2", "binary_compressed") + block(4000, 24) + "abcd"),
                "the compressed block claims 4000 bytes, but the file has 4");
  expectRefused(
      writeFile(dir, "lzf_size.pcd", pcdHead("2", "binary_compressed") + block(4, 8) + "abcd"),
      "the compressed block holds 8 bytes, but the header's 2 points of 12 bytes need 24");
  // A back reference before the start of the output: damaged, not read out of bounds.
  expectRefused(writeFile(dir, "lzf_damaged.pcd",
                          pcdHead("2", "binary_compressed") + block(4, 24) + "\xe0\xff\xff\xff"),
                "LZF data does not decode");
}

TEST(CloudIo, PcdTruncatedGarbageEmptyAndFolder) {
  ScopedTempDir dir("cloud_io_pcd_bad");
  expectRefused(writeFile(dir, "cut.pcd", pcdHead("3", "ascii") + "1.5 2.5 3.5\n4.5 5.5 6.5\n"),
                "cut off: 2 of the 3 points");
  expectRefused(writeFile(dir, "cut_bin.pcd", pcdHead("100", "binary") + "abc"),
                "hold at most 0 (12 bytes each)");
  expectRefused(writeFile(dir, "short_line.pcd", pcdHead("2", "ascii") + "1.5 2.5 3.5\n4.5 5.5\n"),
                "data line 2: 2 values, expected 3");
  expectRefused(writeFile(dir, "word.pcd", pcdHead("1", "ascii") + "1 two 3\n"),
                "'two' is not a number");
  // These segfaulted inside PCL's reader.
  expectRefused(writeFile(dir, "empty.pcd", ""), "empty file");
  expectRefused(writeFile(dir, "text.pcd", "hello world\n"), "no 'DATA' line");
  expectRefused(
      writeFile(dir, "garbage.pcd", std::string("\x01\x02\x03\n\xff\xfe DATA binary\n", 19)),
      "no 'DATA' line");
  expectRefused(writeFile(dir, "no_fields.pcd", "VERSION 0.7\nPOINTS 1\nDATA ascii\n1 2 3\n"),
                "no FIELDS line");
  expectRefused(
      writeFile(dir, "mismatch.pcd",
                "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n"),
      "FIELDS names 3 fields but SIZE, TYPE or COUNT gives another number");
  expectRefused(
      writeFile(dir, "no_z.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n"),
      "no field 'z'");
  expectRefused(writeFile(dir, "wh.pcd",
                          "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4\n"
                          "HEIGHT 2\nPOINTS 2\nDATA ascii\n1 2 3\n1 2 3\n"),
                "WIDTH x HEIGHT = 4 x 2 but POINTS = 2");
  std::filesystem::create_directory(dir / "folder.pcd");
  expectRefused((dir / "folder.pcd").string(), "is a folder, not a cloud file");
}

}  // namespace
}  // namespace fieldrig::traits
