// The dc1394 driver. Without an IEEE-1394 bus (this is the common case: CI, laptops) the no-bus
// error path runs for real; the hardware tests skip, saying why. With the rig's six Grasshoppers
// on the bus, set FIELDRIG_DC1394_GUIDS to their six GUIDs (comma-separated, rig order) to run
// them.
#include "fieldrig/drivers/dc1394/dc1394_camera.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <sstream>
#include <thread>

#include "fieldrig/drivers/rig.h"

namespace fieldrig::drivers {
namespace {

using namespace std::chrono_literals;

constexpr std::string_view kNoBus = "no IEEE-1394 bus/camera found: ";

CameraConfig firstCamera() {
  CameraConfig config;
  config.id = "first";
  // emplace, not operator[] then = "1": GCC 12 -O3 gives a false-positive -Wrestrict on that.
  config.options.emplace("bus_cameras", "1");
  return config;
}

// Empty when a camera answers; otherwise the driver's own explanation of why none does.
std::string whyNoCamera() {
  Dc1394Camera probe;
  const auto configured = probe.configure(firstCamera());
  if (configured.ok())
    return {};
  return configured.error().message;
}

bool isNoBus(const std::string& message) {
  return message.find(kNoBus) != std::string::npos;
}

TEST(Dc1394Camera, IsRegistered) {
  const auto camera = CameraRegistry::instance().create("dc1394");
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  EXPECT_EQ((*camera)->driverName(), "dc1394");
}

TEST(Dc1394Camera, WithoutABusConfigureSaysSoClearly) {
  const std::string why = whyNoCamera();
  if (why.empty() || !isNoBus(why))
    GTEST_SKIP() << "an IIDC camera is on the bus here; the no-bus path cannot be exercised";
  // e.g. "dc1394 camera first: no IEEE-1394 bus/camera found: libdc1394 enumerated 0 cameras;
  // no /dev/fw* device (...)"
  EXPECT_NE(why.find("dc1394 camera first: "), std::string::npos) << why;
  EXPECT_NE(why.find("/dev/fw"), std::string::npos) << why;

  Dc1394Camera camera;
  CameraConfig by_guid = firstCamera();
  by_guid.id = "0800461000821fa2";
  const auto configured = camera.configure(by_guid);
  ASSERT_FALSE(configured.ok());
  EXPECT_TRUE(isNoBus(configured.error().message)) << configured.error().message;

  // The camera stays unusable, and says so, without crashing.
  const auto pool = core::FramePool::create(2, 1624 * 1224).value();
  const auto started = camera.start(*pool, [](core::Frame&&) {});
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.error().message.find("start before a successful configure"), std::string::npos);
  EXPECT_FALSE(camera.trigger(1));
  EXPECT_EQ(camera.stats().triggers_refused, 1u);
  camera.stop();
  camera.stop();
}

TEST(Dc1394Camera, BadConfigurationIsRefusedBeforeTheBusIsTouched) {
  Dc1394Camera camera;
  CameraConfig config = firstCamera();
  config.options["video_mode"] = "640x480_yuv411";
  const auto configured = camera.configure(config);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("not a Format7 mode"), std::string::npos);
}

TEST(Dc1394Camera, RepeatedFailedConfigurationsReleaseEverything) {
  // Each attempt opens and frees a libdc1394 context; run under valgrind by the
  // dc1394_no_bus_memcheck test, this shows that nothing leaks on the error path.
  for (int i = 0; i < 20; ++i) {
    Dc1394Camera camera;
    const auto configured = camera.configure(firstCamera());
    if (configured.ok())
      GTEST_SKIP() << "an IIDC camera is on the bus here";
  }
}

TEST(Dc1394Camera, RigRefusesToStartWithoutABus) {
  RigOptions options;
  options.driver = "dc1394";
  options.cameras.push_back(firstCamera());
  const auto rig = Rig::create(options, CameraRegistry::instance());
  if (rig.ok())
    GTEST_SKIP() << "an IIDC camera is on the bus here";
  EXPECT_NE(rig.error().message.find("rig camera 0: dc1394 camera first: no IEEE-1394"),
            std::string::npos)
      << rig.error().message;
}

// --- Hardware: the six Grasshoppers on one 1394b bus. ---

std::vector<std::string> rigGuids() {
  std::vector<std::string> guids;
  if (const char* env = std::getenv("FIELDRIG_DC1394_GUIDS")) {
    std::stringstream list(env);
    for (std::string guid; std::getline(list, guid, ',');)
      guids.push_back(guid);
  }
  return guids;
}

// Skips the calling test, with the reason, unless six cameras are present and named.
#define FIELDRIG_REQUIRE_SIX_CAMERAS(guids)                                                   \
  do {                                                                                        \
    const std::string why = whyNoCamera();                                                    \
    if (!why.empty() && isNoBus(why))                                                         \
      GTEST_SKIP() << "no FireWire camera on this machine (" << why << ")";                   \
    if ((guids).size() != 6)                                                                  \
      GTEST_SKIP() << "set FIELDRIG_DC1394_GUIDS to the six Grasshoppers' GUIDs to run this"; \
  } while (false)

RigOptions grasshopperRig(const std::vector<std::string>& guids, double rate_hz) {
  RigOptions options;
  options.driver = "dc1394";
  options.frame_timeout = 1s;
  for (std::size_t i = 0; i < guids.size(); ++i) {
    CameraConfig camera;
    camera.id = guids[i];
    camera.trigger = TriggerSource::kSoftware;
    camera.options["camera_index"] = std::to_string(i);
    camera.options["rate_hz"] = std::to_string(rate_hz);
    // One software trigger, broadcast by the first camera, exposes all six in the same cycle.
    camera.options["trigger_broadcast"] = i == 0 ? "send" : "receive";
    options.cameras.push_back(camera);
  }
  return options;
}

TEST(Dc1394Hardware, SixCamerasPlanS800) {
  const auto guids = rigGuids();
  FIELDRIG_REQUIRE_SIX_CAMERAS(guids);
  for (const std::string& guid : guids) {
    Dc1394Camera camera;
    CameraConfig config;
    config.id = guid;
    const auto configured = camera.configure(config);
    ASSERT_TRUE(configured.ok()) << configured.error().message;
    EXPECT_LE(camera.plan().bytes_per_cycle, 8000u);
    EXPECT_GE(camera.plan().max_rate_hz, 5.0);
  }
}

TEST(Dc1394Hardware, SixCamerasAtTenHertzAreRefused) {
  const auto guids = rigGuids();
  FIELDRIG_REQUIRE_SIX_CAMERAS(guids);
  Dc1394Camera camera;
  CameraConfig config;
  config.id = guids[0];
  config.options["rate_hz"] = "10";
  const auto configured = camera.configure(config);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("S800 allows 8,000"), std::string::npos);
}

TEST(Dc1394Hardware, TriggersYieldWholeSets) {
  const auto guids = rigGuids();
  FIELDRIG_REQUIRE_SIX_CAMERAS(guids);
  auto rig = Rig::create(grasshopperRig(guids, 4), CameraRegistry::instance());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  std::mutex mutex;
  std::vector<core::FrameSet> sets;  // guarded by mutex
  ASSERT_TRUE((*rig)->start([&](core::FrameSet&& set) {
    std::lock_guard lock(mutex);
    sets.push_back(std::move(set));
  }));
  for (std::uint64_t id = 1; id <= 20; ++id) {
    EXPECT_TRUE((*rig)->trigger(id));
    std::this_thread::sleep_for(250ms);  // 4 Hz, under the 5.36 Hz the bus allows
  }
  std::this_thread::sleep_for(1500ms);
  (*rig)->stop();
  std::lock_guard lock(mutex);
  ASSERT_EQ(sets.size(), 20u);
  for (const core::FrameSet& set : sets)
    EXPECT_TRUE(set.complete()) << "trigger " << set.trigger_id;
  EXPECT_EQ((*rig)->stats().skew_flagged, 0u);
}

}  // namespace
}  // namespace fieldrig::drivers
