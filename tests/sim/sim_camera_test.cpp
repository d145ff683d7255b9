// The sim camera as a driver: added to a registry from above (drivers/ does not know it), its
// options checked and named, and the example configuration of sim/camera/README.md loaded by the
// configuration loader and run on a rig with exactly the faults the README describes.
#include "fieldrig/sim/sim_camera.h"

#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "fieldrig/config/config.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/sim/test_pattern_source.h"
#include "support/sim_cameras.h"

namespace fieldrig::sim {
namespace {

using namespace std::chrono_literals;

drivers::CameraConfig smallCamera(const std::string& id = "2") {
  drivers::CameraConfig config;
  config.id = id;
  config.width = 16;
  config.height = 8;
  return config;
}

TEST(SimCameraTest, ARegistryHasTheSimDriverOnceItIsAdded) {
  drivers::CameraRegistry registry;
  EXPECT_FALSE(registry.create("sim").ok());
  addSimCamera(registry);
  const auto camera = registry.create("sim");
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  EXPECT_EQ((*camera)->driverName(), "sim");
  const auto unknown = registry.create("gige");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("unknown camera driver 'gige' (this build has: sim)"),
            std::string::npos)
      << unknown.error().message;
}

TEST(SimCameraTest, ABadOptionValueIsAnErrorNamingTheCameraAndTheOption) {
  for (const std::string option :
       {"drop_every", "corrupt_every", "delay_ms", "clock_offset_us", "session_preload_mb"}) {
    for (const std::string value : {"-1", "x", "3ms", ""}) {
      SimCamera camera;
      drivers::CameraConfig config = smallCamera();
      config.options[option] = value;
      const auto configured = camera.configure(config);
      ASSERT_FALSE(configured.ok()) << option << "=" << value;
      EXPECT_EQ(configured.error().message, "sim camera 2: option '" + option + "': '" + value +
                                                "' is not a non-negative integer");
    }
  }
}

TEST(SimCameraTest, OptionsOfOtherDriversAreLeftAloneAndIdsMustBeCameraIndices) {
  SimCamera camera;
  drivers::CameraConfig config = smallCamera();
  config.options = {{"video_mode", "format7_mode0"}, {"iso_speed", "800"}, {"drop_every", "0"}};
  EXPECT_TRUE(camera.configure(config).ok());
  const auto named = camera.configure(smallCamera("left"));
  ASSERT_FALSE(named.ok());
  EXPECT_EQ(named.error().message, "sim camera: id 'left' is not a camera index");
  drivers::CameraConfig empty = smallCamera();
  empty.height = 0;
  EXPECT_FALSE(camera.configure(empty).ok());
}

TEST(SimCameraTest, StartingWithoutAConfigurationOrWithSmallBuffersIsAnError) {
  const auto pool = core::FramePool::create(2, 16 * 8).value();
  SimCamera unconfigured;
  EXPECT_FALSE(unconfigured.start(*pool, [](core::Frame&&) {}).ok());
  SimCamera camera;
  drivers::CameraConfig config = smallCamera();
  config.width = 32;
  ASSERT_TRUE(camera.configure(config).ok());
  const auto started = camera.start(*pool, [](core::Frame&&) {});
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.error().message.find("smaller than a frame"), std::string::npos);
}

// The first ```yaml block of sim/camera/README.md.
std::string readmeExample() {
  std::ifstream in(std::string(FIELDRIG_SOURCE_DIR) + "/sim/camera/README.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string readme = text.str();
  const std::string open = "```yaml\n";
  const auto begin = readme.find(open);
  if (begin == std::string::npos)
    return "";
  const auto end = readme.find("```", begin + open.size());
  return readme.substr(begin + open.size(), end - begin - open.size());
}

struct SeenSet {
  std::uint64_t trigger_id = 0;
  std::array<core::FrameStatus, 6> status{};
  bool pattern = true;  // every frame with pixels shows its camera's and trigger's pattern
  std::int64_t skew_ns = 0;
  std::int64_t least_delay_ns = std::numeric_limits<std::int64_t>::max();
};

TEST(SimCameraTest, TheReadmeExampleLoadsAndGivesTheFaultsItDescribes) {
  const std::string example = readmeExample();
  ASSERT_FALSE(example.empty()) << "no yaml block in sim/camera/README.md";
  auto loaded = config::parseConfig(example, "sim/camera/README.md", FIELDRIG_SOURCE_DIR);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  drivers::RigOptions rig = loaded->cameras.rig;
  ASSERT_EQ(rig.driver, "sim");
  ASSERT_EQ(rig.cameras.size(), 6u);
  const std::map<std::string, std::string> faults = {
      {"drop_every", "5"}, {"corrupt_every", "7"}, {"delay_ms", "3"}, {"clock_offset_us", "40"}};
  for (const auto& camera : rig.cameras)
    EXPECT_EQ(camera.options, faults);
  // A loaded test machine may starve a camera's worker for longer than the example's 200 ms, and
  // the sets behind a dropped one wait for its timeout: more time and buffers than the example.
  rig.frame_timeout = 2s;
  rig.pool_sets = 64;

  auto created = drivers::Rig::create(rig, testing_support::camerasWithSim());
  ASSERT_TRUE(created.ok()) << created.error().message;
  drivers::Rig& running = **created;
  std::mutex mutex;
  std::vector<SeenSet> seen;
  ASSERT_TRUE(running
                  .start([&](core::FrameSet&& set) {
                    SeenSet s;
                    s.trigger_id = set.trigger_id;
                    s.skew_ns = set.skew_ns;
                    for (std::uint32_t c = 0; c < 6; ++c) {
                      const core::Frame& frame = set.frames[c];
                      s.status[c] = frame.metadata.status;
                      if (!frame.buffer)
                        continue;
                      const std::uint8_t* pixels = frame.buffer.bytes().data();
                      const std::uint8_t at_1_1 = pixels[frame.metadata.stride + 1];
                      s.pattern = s.pattern &&
                                  at_1_1 == TestPatternSource::patternAt(c, set.trigger_id, 1, 1);
                      const auto received = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          frame.metadata.received.steady.time_since_epoch());
                      s.least_delay_ns = std::min(
                          s.least_delay_ns, received.count() - frame.metadata.device_timestamp_ns);
                    }
                    std::lock_guard lock(mutex);
                    seen.push_back(s);
                  })
                  .ok());
  constexpr std::uint64_t kTriggers = 35;
  for (std::uint64_t id = 1; id <= kTriggers; ++id) {
    ASSERT_TRUE(running.trigger(id));
    std::this_thread::sleep_for(10ms);
  }
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < deadline && running.stats().sets < kTriggers)
    std::this_thread::sleep_for(5ms);
  running.stop();

  std::lock_guard lock(mutex);
  ASSERT_EQ(seen.size(), kTriggers);
  for (const SeenSet& s : seen) {
    SCOPED_TRACE("trigger " + std::to_string(s.trigger_id));
    const core::FrameStatus want = s.trigger_id % 5 == 0   ? core::FrameStatus::kMissing
                                   : s.trigger_id % 7 == 0 ? core::FrameStatus::kCorrupt
                                                           : core::FrameStatus::kOk;
    for (const core::FrameStatus status : s.status)
      EXPECT_EQ(status, want);
    EXPECT_TRUE(s.pattern);   // corrupt frames keep their pixels
    EXPECT_EQ(s.skew_ns, 0);  // the same 40 µs on every clock
    if (want != core::FrameStatus::kMissing) {
      // Delivered at least 3 ms after the trigger, whose instant is 40 µs before the stamp.
      EXPECT_GE(s.least_delay_ns, std::chrono::nanoseconds{3ms - 40us}.count());
    }
  }
  const drivers::RigStats stats = running.stats();
  EXPECT_EQ(stats.frames_missing, 7u * 6u);  // triggers 5, 10 … 35
  EXPECT_EQ(stats.frames_corrupt, 4u * 6u);  // triggers 7, 14, 21, 28 (35 was dropped)
  EXPECT_EQ(stats.incomplete_sets, 11u);
  EXPECT_EQ(stats.frames_dropped, 0u);
  EXPECT_EQ(stats.skew_flagged, 0u);
}

}  // namespace
}  // namespace fieldrig::sim
