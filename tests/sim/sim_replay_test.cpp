// The sim camera replaying a recorded session (option session=DIR): a session recorded with the
// generated sim rig, with a camera that drops frames, one that corrupts some and one whose clock
// is off, comes out of a replaying rig set by set as it was recorded: the same pixels, missing
// frames missing again, corrupt ones corrupt, the same skew; both when the frames are read at
// configure() and when they are read per trigger. Bad sessions are refused naming the folder;
// `fieldrig acquire --camera-option session=DIR` replays end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "fieldrig/daemon/acquisition.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/sim/sim_camera.h"
#include "support/cli_run.h"
#include "support/collector.h"
#include "support/sim_cameras.h"
#include "support/temp_dir.h"

namespace fieldrig::sim {
namespace {

using namespace std::chrono_literals;
using drivers::CameraConfig;
using drivers::Rig;
using drivers::RigOptions;
using drivers::RigStats;
using testing_support::ScopedTempDir;

constexpr std::uint32_t kWidth = 64;
constexpr std::uint32_t kHeight = 48;
constexpr int kRecordedSets = 12;

// Records kRecordedSets sets with the generated sim rig into dir/"recorded": camera 2 drops every
// 4th trigger, camera 1 corrupts every 5th, camera 5's clock is 250 µs ahead; Mono8, so that the
// replay (configured with the default Bayer format) has to take the format from the recording.
std::filesystem::path recordSession(const std::filesystem::path& dir) {
  daemon::AcquisitionOptions options;
  options.rig = testing_support::sixSimCameras(kWidth, kHeight);
  for (CameraConfig& camera : options.rig.cameras)
    camera.format = core::PixelFormat::kMono8;
  options.rig.cameras[2].options["drop_every"] = "4";
  options.rig.cameras[1].options["corrupt_every"] = "5";
  options.rig.cameras[5].options["clock_offset_us"] = "250";
  options.session_dir = dir / "recorded";
  options.writer.fsync = recording::FsyncPolicy::kNone;
  auto acquisition = daemon::Acquisition::create(options, testing_support::camerasWithSim());
  EXPECT_TRUE(acquisition.ok()) << acquisition.error().message;
  if (!acquisition)
    return options.session_dir;
  EXPECT_TRUE((*acquisition)->start().ok());
  for (int i = 0; i < kRecordedSets; ++i) {
    (*acquisition)->trigger();
    std::this_thread::sleep_for(2ms);
  }
  (*acquisition)->finish(10s);
  EXPECT_EQ((*acquisition)->stats().sets_recorded, std::uint64_t{kRecordedSets});
  return options.session_dir;
}

RigOptions replayingRig(const std::filesystem::path& session,
                        const std::map<std::string, std::string>& extra = {}) {
  RigOptions options = testing_support::sixSimCameras(kWidth, kHeight);
  for (CameraConfig& camera : options.cameras) {
    camera.options = extra;
    camera.options["session"] = session.string();
  }
  options.max_skew = 1000us;  // the recorded 250 µs is replayed, not flagged
  options.pool_sets = 64;     // the collector keeps every set (and its buffers) to the end
  return options;
}

using Collector = testing_support::Collector<core::FrameSet>;

// Replays the session twice over (the replay wraps around) with trigger ids unlike the
// recording's, so that a generated pattern could not pass for the recorded pixels, and compares
// every replayed frame with the recorded one.
void replayAndCompare(const std::filesystem::path& session,
                      const std::map<std::string, std::string>& extra) {
  const auto reader = recording::SessionReader::open(session);
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  const auto& recorded_sets = reader->sets();
  ASSERT_EQ(recorded_sets.size(), std::size_t{kRecordedSets});
  // The recording has what the replay must reproduce: missing, corrupt and incomplete sets.
  std::size_t missing = 0, corrupt = 0;
  for (const auto& set : recorded_sets) {
    for (const auto& frame : set.frames) {
      missing += frame.status == recording::FrameStatus::kMissing;
      corrupt += frame.status == recording::FrameStatus::kCorrupt;
    }
  }
  ASSERT_EQ(missing, 3u);  // camera 2, triggers 4, 8, 12
  ASSERT_EQ(corrupt, 2u);  // camera 1, triggers 5, 10

  auto rig = Rig::create(replayingRig(session, extra), testing_support::camerasWithSim());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  Collector collector;
  ASSERT_TRUE((*rig)->start(collector.sink()).ok());
  constexpr std::uint64_t kFirstId = 101;
  constexpr std::size_t kReplayed = 2 * kRecordedSets;
  for (std::uint64_t i = 0; i < kReplayed; ++i) {
    ASSERT_TRUE((*rig)->trigger(kFirstId + i));
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(collector.waitFor(kReplayed));
  (*rig)->stop();
  const auto sets = collector.take();
  ASSERT_EQ(sets.size(), kReplayed);

  for (std::size_t i = 0; i < kReplayed; ++i) {
    const core::FrameSet& replayed = sets[i];
    const recording::IndexedSet& recorded = recorded_sets[i % kRecordedSets];
    SCOPED_TRACE("replayed set " + std::to_string(i) + " (recorded trigger " +
                 std::to_string(recorded.trigger_id) + ")");
    EXPECT_EQ(replayed.trigger_id, kFirstId + i);
    EXPECT_EQ(replayed.complete(), recorded.complete);
    EXPECT_EQ(replayed.skew_ns, std::llround(recorded.skew_us * 1000.0));
    ASSERT_EQ(replayed.camera_count, recorded.frames.size());
    for (std::uint32_t c = 0; c < replayed.camera_count; ++c) {
      SCOPED_TRACE("camera " + std::to_string(c));
      const core::Frame& frame = replayed.frames[c];
      const recording::IndexedFrame& want = recorded.frames[c];
      ASSERT_EQ(want.camera_index, static_cast<int>(c));
      EXPECT_EQ(frame.metadata.status, want.status);  // one status type end to end
      if (want.file.empty()) {
        EXPECT_FALSE(frame.buffer);  // recorded missing: no pixels, timed out by the rig
        continue;
      }
      ASSERT_TRUE(frame.buffer);
      EXPECT_EQ(frame.metadata.format, want.pixel_format);
      EXPECT_EQ(frame.metadata.format, core::PixelFormat::kMono8);
      ASSERT_EQ(frame.metadata.width, kWidth);
      ASSERT_EQ(frame.metadata.height, kHeight);
      const auto image = reader->loadFrame(want);
      ASSERT_TRUE(image.ok()) << image.error().message;
      const std::vector<std::uint8_t> pixels(
          frame.buffer.bytes().begin(),
          frame.buffer.bytes().begin() + static_cast<std::ptrdiff_t>(kWidth * kHeight));
      EXPECT_EQ(pixels, image->pixels);
    }
  }
  const RigStats stats = (*rig)->stats();
  EXPECT_EQ(stats.frames_missing, 2 * missing);
  EXPECT_EQ(stats.frames_corrupt, 2 * corrupt);
  EXPECT_EQ(stats.skew_flagged, 0u);
}

TEST(SimReplayTest, ReplaysTheRecordingSetBySetFromMemory) {
  const ScopedTempDir dir("sim_replay_memory");
  const auto session = recordSession(dir.path());
  replayAndCompare(session, {});
}

TEST(SimReplayTest, ReplaysTheRecordingSetBySetReadingFramesPerTrigger) {
  const ScopedTempDir dir("sim_replay_stream");
  const auto session = recordSession(dir.path());
  replayAndCompare(session, {{"session_preload_mb", "0"}});  // nothing fits: read per trigger
}

TEST(SimReplayTest, ABadSessionPathIsAnErrorNamingIt) {
  const ScopedTempDir dir("sim_replay_bad_path");
  const auto missing = dir.path() / "no_such_session";
  const auto rig = Rig::create(replayingRig(missing), testing_support::camerasWithSim());
  ASSERT_FALSE(rig.ok());
  EXPECT_NE(rig.error().message.find(missing.string()), std::string::npos) << rig.error().message;
}

TEST(SimReplayTest, ACameraNotInTheSessionOrOfAnotherSizeIsAnErrorNamingTheSession) {
  const ScopedTempDir dir("sim_replay_mismatch");
  const auto session = recordSession(dir.path());
  {
    SimCamera camera;
    CameraConfig config = replayingRig(session).cameras[0];
    config.id = "7";  // the session has cameras 0-5
    const auto configured = camera.configure(config);
    ASSERT_FALSE(configured.ok());
    EXPECT_NE(configured.error().message.find(session.string()), std::string::npos)
        << configured.error().message;
    EXPECT_NE(configured.error().message.find("camera 7"), std::string::npos)
        << configured.error().message;
  }
  {
    SimCamera camera;
    CameraConfig config = replayingRig(session).cameras[0];
    config.width = kWidth * 2;
    const auto configured = camera.configure(config);
    ASSERT_FALSE(configured.ok());
    EXPECT_NE(configured.error().message.find(session.string()), std::string::npos)
        << configured.error().message;
    EXPECT_NE(configured.error().message.find("64x48"), std::string::npos)
        << configured.error().message;
  }
}

TEST(SimReplayCliTest, AcquireReplaysARecordedSessionIntoAnIdenticalOne) {
  const ScopedTempDir dir("sim_replay_cli");
  const auto first = dir.path() / "first";
  const auto second = dir.path() / "second";
  const std::vector<std::string> common = {"acquire", "--driver", "sim", "--count",
                                           "9",       "--rate",   "50",  "--width",
                                           "64",      "--height", "48",  "--frame-timeout-ms",
                                           "100"};
  auto record = common;
  record.insert(record.end(), {"--out", first.string(), "--camera-option", "drop_every=3"});
  const auto recorded_run = testing_support::runFieldrig(record, dir.path());
  ASSERT_EQ(recorded_run.exit_code, 0) << recorded_run.err;
  // Replayed twice into one session: the second run continues its numbering (trigger ids 10-18),
  // so pixels generated from the trigger id could not pass for the recorded ones.
  auto replay = common;
  replay.insert(replay.end(),
                {"--out", second.string(), "--camera-option", "session=" + first.string()});
  for (int run = 0; run < 2; ++run) {
    const auto replayed_run = testing_support::runFieldrig(replay, dir.path());
    ASSERT_EQ(replayed_run.exit_code, 0) << replayed_run.err;
    ASSERT_EQ(replayed_run.out_lines.size(), 1u);
    const auto summary = nlohmann::json::parse(replayed_run.out_lines[0]);
    EXPECT_EQ(summary["sets"], 9);
    EXPECT_EQ(summary["incomplete"], 3);  // the recording's triggers 3, 6, 9, all six missing
  }

  const auto a = recording::SessionReader::open(first);
  const auto b = recording::SessionReader::open(second);
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_TRUE(b.ok()) << b.error().message;
  ASSERT_EQ(a->sets().size(), 9u);
  ASSERT_EQ(b->sets().size(), 18u);
  for (std::size_t s = 0; s < b->sets().size(); ++s) {
    const auto& want = a->sets()[s % 9];
    const auto& got = b->sets()[s];
    EXPECT_EQ(got.trigger_id, s + 1);
    EXPECT_EQ(got.complete, want.complete) << "set " << s;
    ASSERT_EQ(got.frames.size(), want.frames.size()) << "set " << s;
    for (std::size_t c = 0; c < want.frames.size(); ++c) {
      EXPECT_EQ(got.frames[c].status, want.frames[c].status) << "set " << s << " camera " << c;
      EXPECT_EQ(got.frames[c].file.empty(), want.frames[c].file.empty())
          << "set " << s << " camera " << c;
      EXPECT_EQ(got.frames[c].crc32, want.frames[c].crc32) << "set " << s << " camera " << c;
    }
  }
  EXPECT_TRUE(b->verify().ok());
}

}  // namespace
}  // namespace fieldrig::sim
