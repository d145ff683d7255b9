// One index line, parsed alone: numbers that do not fit their field are refused naming the key
// (the session index fuzzer found a float such as 1e300 cast to an int, undefined behaviour, and
// out-of-range integers wrapped silently).
#include <gtest/gtest.h>

#include <string>

#include "fieldrig/recording/session_format.h"

namespace fieldrig::recording {
namespace {

IndexedSet oneFrameSet() {
  IndexedSet set;
  set.set_index = 3;
  set.trigger_id = 5;
  IndexedFrame frame;
  frame.camera_index = 1;
  frame.camera_name = "bottom_right";
  frame.file = frameFileName(3, 1, "bottom_right");
  frame.width = 16;
  frame.height = 8;
  frame.crc32 = 0xffffffffU;
  frame.host_system_ns = -5;
  set.frames.push_back(frame);
  return set;
}

// The set's line with the first `"key":VALUE` replaced by `"key":replacement`.
std::string withValue(const std::string& key, const std::string& replacement) {
  std::string line = toIndexLine(oneFrameSet());
  const std::size_t at = line.find("\"" + key + "\":");
  EXPECT_NE(at, std::string::npos) << key;
  const std::size_t begin = at + key.size() + 3;
  const std::size_t end = line.find_first_of(",}", begin);
  return line.replace(begin, end - begin, replacement);
}

TEST(IndexLine, ReadsBackWhatItWrites) {
  std::string error;
  const auto set = fromIndexLine(toIndexLine(oneFrameSet()), error);
  ASSERT_TRUE(set) << error;
  EXPECT_EQ(set->set_index, 3U);
  ASSERT_EQ(set->frames.size(), 1U);
  EXPECT_EQ(set->frames[0].crc32, 0xffffffffU);
  EXPECT_EQ(set->frames[0].host_system_ns, -5);
}

TEST(IndexLine, NumbersThatDoNotFitTheirFieldAreRefusedNamingTheKey) {
  const struct {
    const char* key;
    const char* value;
  } cases[] = {
      {"camera", "1e300"},
      {"width", "2.5"},
      {"height", "-1e19"},
      {"crc32", "4294967296"},
      {"set", "-1"},
      {"trigger_id", "18446744073709551616"},
      {"sequence", "-3"},
      {"camera", "2147483648"},
      {"host_steady_ns", "9.3e18"},
  };
  for (const auto& c : cases) {
    std::string error;
    const auto set = fromIndexLine(withValue(c.key, c.value), error);
    EXPECT_FALSE(set) << c.key << " = " << c.value;
    EXPECT_NE(error.find(std::string("'") + c.key + "' is not a whole number"), std::string::npos)
        << c.key << " = " << c.value << ": " << error;
  }
}

// `session info --verify` passed a fix at latitude 500: no place on Earth, and the map placement
// and geodesic distances after it took it as given.
TEST(IndexLine, AFixOutsideTheEarthsAnglesIsRefusedNamingTheKey) {
  IndexedSet set = oneFrameSet();
  core::GpsFix fix;
  fix.latitude_deg = 42.01;
  fix.longitude_deg = -93.74;
  fix.valid = true;
  set.fix = fix;
  const std::string line = toIndexLine(set);
  std::string error;
  ASSERT_TRUE(fromIndexLine(line, error)) << error;
  const struct {
    const char* from;
    const char* to;
    const char* key;
  } cases[] = {
      {"\"lat\":42.01", "\"lat\":500", "'gps.lat' is 500"},
      {"\"lat\":42.01", "\"lat\":-90.5", "'gps.lat' is -90.5"},
      {"\"lon\":-93.74", "\"lon\":180.25", "'gps.lon' is 180.25"},
  };
  for (const auto& c : cases) {
    std::string damaged = line;
    const std::size_t at = damaged.find(c.from);
    ASSERT_NE(at, std::string::npos) << line;
    damaged.replace(at, std::string(c.from).size(), c.to);
    error.clear();
    EXPECT_FALSE(fromIndexLine(damaged, error)) << damaged;
    EXPECT_NE(error.find(c.key), std::string::npos) << error;
    EXPECT_NE(error.find("degrees"), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace fieldrig::recording
