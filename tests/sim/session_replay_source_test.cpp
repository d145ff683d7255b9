// The session replay source on a session written here by hand (two cameras, 4×2 Mono8, three
// sets: ok frames, a corrupt one, a missing one, a dropped one): set by set, wrapping around,
// the recorded pixels, format, statuses and timestamp offsets come out again, from memory and
// read per trigger; a damaged file and bad sessions are named.
#include "fieldrig/sim/session_replay_source.h"

#include <gtest/gtest.h>

#include <fstream>
#include <numeric>

#include "fieldrig/recording/session_writer.h"
#include "support/temp_dir.h"

namespace fieldrig::sim {
namespace {

using namespace std::chrono_literals;
using recording::FrameStatus;
using testing_support::ScopedTempDir;

constexpr int kReplayWidth = 4;
constexpr int kReplayHeight = 2;
constexpr std::int64_t kIssuedNs = 1'000'000'000;  // every trigger here is issued at 1 s

std::vector<std::uint8_t> pixelsFrom(std::uint8_t first) {
  std::vector<std::uint8_t> pixels(kReplayWidth * kReplayHeight);
  std::iota(pixels.begin(), pixels.end(), first);
  return pixels;
}

recording::FrameView view(int camera, FrameStatus status, std::int64_t device_timestamp_ns,
                          const std::vector<std::uint8_t>& pixels) {
  recording::FrameView frame;
  frame.camera_index = camera;
  frame.camera_name = camera == 0 ? "bottom_left" : "bottom_right";
  frame.width = kReplayWidth;
  frame.height = kReplayHeight;
  frame.pixel_format = core::PixelFormat::kMono8;
  frame.pixels = pixels;
  frame.device_timestamp_ns = device_timestamp_ns;
  frame.status = status;
  return frame;
}

// set 0 (trigger 10): camera 0 ok from 0 at 5000 ns, camera 1 ok from 100 at 5250 ns;
// set 1 (trigger 11): camera 0 corrupt from 20 at 6000 ns, camera 1 missing;
// set 2 (trigger 12): camera 0 dropped, camera 1 ok from 40 at 7040 ns.
std::filesystem::path writeSession(const std::filesystem::path& dir) {
  const std::filesystem::path session = dir / "session";
  recording::SessionWriter writer;
  const auto opened = writer.open(session, {}, {recording::FsyncPolicy::kNone});
  EXPECT_TRUE(opened.ok()) << opened.error().message;
  const auto a = pixelsFrom(0), b = pixelsFrom(100), c = pixelsFrom(20), d = pixelsFrom(40);
  const std::vector<std::uint8_t> none;
  recording::FrameSetRecord set;
  set.trigger_id = 10;
  set.frames = {view(0, FrameStatus::kOk, 5000, a), view(1, FrameStatus::kOk, 5250, b)};
  EXPECT_TRUE(writer.write(set).ok());
  set.trigger_id = 11;
  set.frames = {view(0, FrameStatus::kCorrupt, 6000, c), view(1, FrameStatus::kMissing, 0, none)};
  EXPECT_TRUE(writer.write(set).ok());
  set.trigger_id = 12;
  set.frames = {view(0, FrameStatus::kDropped, 0, none), view(1, FrameStatus::kOk, 7040, d)};
  EXPECT_TRUE(writer.write(set).ok());
  writer.close();
  return session;
}

drivers::CameraConfig cameraConfig(const std::string& id, int width = kReplayWidth) {
  drivers::CameraConfig config;
  config.id = id;
  config.width = static_cast<std::uint32_t>(width);
  config.height = kReplayHeight;
  config.format = core::PixelFormat::kBayerRG8;  // the recorded Mono8 must win
  return config;
}

// The frame `source` serves for the trigger `since_first` ids after the first.
struct Served {
  bool delivered = false;
  core::Frame frame;
  std::vector<std::uint8_t> pixels;  // empty without a buffer
};

Served serve(SessionReplaySource& source, core::FramePool& pool, std::uint32_t camera,
             std::uint64_t since_first) {
  const SimTrigger trigger{500 + since_first, since_first, core::SteadyTime{1s}};
  Served served;
  served.frame =
      stampedFrame(trigger, camera, kReplayWidth, kReplayHeight, core::PixelFormat::kBayerRG8);
  served.delivered = source.fill(trigger, pool, served.frame);
  if (served.frame.buffer) {
    const auto bytes = served.frame.buffer.bytes().first(std::size_t{kReplayWidth} * kReplayHeight);
    served.pixels.assign(bytes.begin(), bytes.end());
  }
  return served;
}

class SessionReplaySourceTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(SessionReplaySourceTest, ServesTheRecordedSetsInOrderAndWrapsAround) {
  const ScopedTempDir dir("replay_source_sets_" + std::to_string(GetParam()));
  const auto session = writeSession(dir.path());
  auto camera0 = SessionReplaySource::open(cameraConfig("0"), 0, session, GetParam());
  auto camera1 = SessionReplaySource::open(cameraConfig("1"), 1, session, GetParam());
  ASSERT_TRUE(camera0.ok()) << camera0.error().message;
  ASSERT_TRUE(camera1.ok()) << camera1.error().message;
  EXPECT_EQ((*camera0)->preloaded(), GetParam() > 0);
  EXPECT_EQ((*camera1)->preloaded(), GetParam() > 0);
  const auto pool = core::FramePool::create(16, std::size_t{kReplayWidth} * kReplayHeight).value();

  for (std::uint64_t lap = 0; lap < 2; ++lap) {
    SCOPED_TRACE("lap " + std::to_string(lap));
    const std::uint64_t k = 3 * lap;
    // Set 0: both ok; camera 1 recorded 250 ns after camera 0.
    Served s = serve(**camera0, *pool, 0, k);
    ASSERT_TRUE(s.delivered);
    EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kOk);
    EXPECT_EQ(s.frame.metadata.format, core::PixelFormat::kMono8);
    EXPECT_EQ(s.frame.metadata.device_timestamp_ns, kIssuedNs);
    EXPECT_EQ(s.pixels, pixelsFrom(0));
    s = serve(**camera1, *pool, 1, k);
    ASSERT_TRUE(s.delivered);
    EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kOk);
    EXPECT_EQ(s.frame.metadata.device_timestamp_ns, kIssuedNs + 250);
    EXPECT_EQ(s.pixels, pixelsFrom(100));
    // Set 1: camera 0 corrupt with its pixels, camera 1 missing: nothing delivered.
    s = serve(**camera0, *pool, 0, k + 1);
    ASSERT_TRUE(s.delivered);
    EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kCorrupt);
    EXPECT_EQ(s.pixels, pixelsFrom(20));
    EXPECT_FALSE(serve(**camera1, *pool, 1, k + 1).delivered);
    // Set 2: camera 0 dropped (no pixels), camera 1 the only frame with pixels: offset 0.
    s = serve(**camera0, *pool, 0, k + 2);
    ASSERT_TRUE(s.delivered);
    EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kDropped);
    EXPECT_FALSE(s.frame.buffer);
    EXPECT_EQ(s.frame.metadata.format, core::PixelFormat::kMono8);
    s = serve(**camera1, *pool, 1, k + 2);
    ASSERT_TRUE(s.delivered);
    EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kOk);
    EXPECT_EQ(s.frame.metadata.device_timestamp_ns, kIssuedNs);
    EXPECT_EQ(s.pixels, pixelsFrom(40));
  }
}

// 64 MiB: the frames are read at open(); 0: per trigger.
INSTANTIATE_TEST_SUITE_P(Preload, SessionReplaySourceTest, ::testing::Values(64u, 0u));

TEST(SessionReplaySourceErrorsTest, ADryPoolGivesADroppedFrame) {
  const ScopedTempDir dir("replay_source_dry");
  auto source = SessionReplaySource::open(cameraConfig("0"), 0, writeSession(dir.path()), 64);
  ASSERT_TRUE(source.ok()) << source.error().message;
  const auto pool = core::FramePool::create(1, std::size_t{kReplayWidth} * kReplayHeight).value();
  const core::FrameBuffer held = pool->acquire();
  const Served s = serve(**source, *pool, 0, 0);
  ASSERT_TRUE(s.delivered);
  EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kDropped);
  EXPECT_FALSE(s.frame.buffer);
}

TEST(SessionReplaySourceErrorsTest, ADamagedFileIsAnErrorAtOpenOrACorruptFrameWhenStreamed) {
  const ScopedTempDir dir("replay_source_damaged");
  const auto session = writeSession(dir.path());
  auto streamed = SessionReplaySource::open(cameraConfig("1"), 1, session, 0);
  ASSERT_TRUE(streamed.ok()) << streamed.error().message;
  const auto file = session / recording::frameFileName(0, 1, "bottom_right");
  ASSERT_TRUE(std::filesystem::remove(file));

  const auto pool = core::FramePool::create(2, std::size_t{kReplayWidth} * kReplayHeight).value();
  const Served s = serve(**streamed, *pool, 1, 0);
  ASSERT_TRUE(s.delivered);
  EXPECT_EQ(s.frame.metadata.status, core::FrameStatus::kCorrupt);
  EXPECT_EQ(s.pixels, std::vector<std::uint8_t>(kReplayWidth * kReplayHeight, 0));

  const auto preloaded = SessionReplaySource::open(cameraConfig("1"), 1, session, 64);
  ASSERT_FALSE(preloaded.ok());
  EXPECT_NE(preloaded.error().message.find("000000_1_bottom_right"), std::string::npos)
      << preloaded.error().message;
}

// A frame damaged inside (whole file, pixels that no longer match the index's CRC-32) was
// replayed as ok, and the new session stored a fresh checksum: the damage was laundered.
TEST(SessionReplaySourceErrorsTest, PixelsThatDoNotMatchTheIndexAreReplayedAsCorrupt) {
  const ScopedTempDir dir("replay_source_crc");
  const auto session = writeSession(dir.path());
  const auto file = session / recording::frameFileName(0, 1, "bottom_right");
  {
    std::fstream pgm(file, std::ios::in | std::ios::out | std::ios::binary);
    pgm.seekp(-1, std::ios::end);
    pgm.put('\x7f');
    ASSERT_TRUE(pgm.good());
  }
  const auto pool = core::FramePool::create(2, std::size_t{kReplayWidth} * kReplayHeight).value();
  for (const std::uint64_t preload_mb : {std::uint64_t{0}, std::uint64_t{64}}) {
    auto source = SessionReplaySource::open(cameraConfig("1"), 1, session, preload_mb);
    ASSERT_TRUE(source.ok()) << source.error().message;
    const Served damaged = serve(**source, *pool, 1, 0);
    ASSERT_TRUE(damaged.delivered);
    EXPECT_EQ(damaged.frame.metadata.status, core::FrameStatus::kCorrupt) << preload_mb;
    std::vector<std::uint8_t> expected = pixelsFrom(100);
    expected.back() = 0x7f;
    EXPECT_EQ(damaged.pixels, expected) << "the pixels as they are";
    const Served whole = serve(**source, *pool, 1, 2);
    ASSERT_TRUE(whole.delivered);
    EXPECT_EQ(whole.frame.metadata.status, core::FrameStatus::kOk) << preload_mb;
  }
}

TEST(SessionReplaySourceErrorsTest, BadSessionsAreErrorsNamingTheFolderAndWhatIsWrong) {
  const ScopedTempDir dir("replay_source_errors");
  const auto session = writeSession(dir.path());
  const auto expectError = [](const core::Result<std::unique_ptr<SessionReplaySource>>& opened,
                              const std::string& folder, const std::string& what) {
    ASSERT_FALSE(opened.ok());
    EXPECT_NE(opened.error().message.find("sim camera "), std::string::npos)
        << opened.error().message;
    EXPECT_NE(opened.error().message.find(folder), std::string::npos) << opened.error().message;
    EXPECT_NE(opened.error().message.find(what), std::string::npos) << opened.error().message;
  };
  expectError(SessionReplaySource::open(cameraConfig("7"), 7, session, 64), session.string(),
              "no frame of camera 7 in its 3 sets");
  expectError(SessionReplaySource::open(cameraConfig("0", 8), 0, session, 64), session.string(),
              "is 4x2, the camera is configured 8x2");
  const auto missing = dir.path() / "no_such_session";
  expectError(SessionReplaySource::open(cameraConfig("0"), 0, missing, 64), missing.string(), "");

  const auto empty = dir.path() / "empty";
  recording::SessionWriter writer;
  ASSERT_TRUE(writer.open(empty, {}, {recording::FsyncPolicy::kNone}).ok());
  writer.close();
  expectError(SessionReplaySource::open(cameraConfig("0"), 0, empty, 64), empty.string(),
              "no sets recorded");
}

}  // namespace
}  // namespace fieldrig::sim
