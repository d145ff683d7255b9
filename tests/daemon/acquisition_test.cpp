// Acquisition end to end with the sim rig on a real filesystem: every triggered set recorded and
// readable, incomplete sets recorded as such, live processing skipped (counted) when slow but the
// recording whole; and the `fieldrig acquire` CLI contract.
#include "fieldrig/daemon/acquisition.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <thread>

#include "fieldrig/recording/session_reader.h"
#include "fieldrig/sim/test_pattern_source.h"
#if defined(FIELDRIG_HAVE_ARAVIS)
#include <cstring>

#include "support/aravis_fakes.h"
#endif
#include "support/cli_run.h"
#include "support/sim_cameras.h"
#include "support/temp_dir.h"

namespace fieldrig::daemon {
namespace {

using namespace std::chrono_literals;
using testing_support::ScopedTempDir;

AcquisitionOptions smallRig(const std::filesystem::path& dir) {
  AcquisitionOptions options;
  options.rig = testing_support::sixSimCameras(80, 60);
  options.session_dir = dir / "session";
  options.writer.fsync = recording::FsyncPolicy::kNone;
  return options;
}

void triggerAndFinish(Acquisition& acquisition, int count) {
  for (int i = 0; i < count; ++i) {
    // At most half the pool in flight: these tests are about what is recorded, and a recorder
    // starved by a loaded machine must not turn into an exhausted pool (dropped frames are
    // tested on their own).
    for (int wait = 0; acquisition.inFlight() >= 8 && wait < 5000; ++wait)
      std::this_thread::sleep_for(1ms);
    acquisition.trigger();
    std::this_thread::sleep_for(2ms);
  }
  acquisition.finish(10s);
}

TEST(AcquisitionTest, EveryTriggeredSetIsRecordedAndReadsBackIdentically) {
  const ScopedTempDir dir("acquisition_all");
  AcquisitionOptions options = smallRig(dir.path());
  // This test is about what is recorded, not about a late camera (tested on its own): under
  // AddressSanitizer on a loaded machine a sim camera's frame came after the 100 ms, and its set
  // was rightly recorded incomplete.
  options.rig.frame_timeout = 2s;
  auto acquisition = Acquisition::create(options, testing_support::camerasWithSim());
  ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
  ASSERT_TRUE((*acquisition)->start().ok());
  triggerAndFinish(**acquisition, 40);
  const AcquisitionStats stats = (*acquisition)->stats();
  EXPECT_EQ(stats.sets_recorded, 40u);
  EXPECT_FALSE(stats.recording_stopped);

  const auto reader = recording::SessionReader::open(dir.path() / "session");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 40u);
  for (const recording::IndexedSet& set : reader->sets()) {
    EXPECT_TRUE(set.complete);
    ASSERT_EQ(set.frames.size(), 6u);
    for (const recording::IndexedFrame& frame : set.frames) {
      const auto image = reader->loadFrame(frame);
      ASSERT_TRUE(image.ok()) << image.error().message;
      for (int y = 0; y < 60; y += 11) {
        for (int x = 0; x < 80; x += 13) {
          ASSERT_EQ(image->pixels[static_cast<std::size_t>(y * 80 + x)],
                    sim::TestPatternSource::patternAt(
                        static_cast<std::uint32_t>(frame.camera_index), set.trigger_id,
                        static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y)));
        }
      }
    }
  }
  EXPECT_TRUE(reader->verify().ok());
}

TEST(AcquisitionTest, ARecordedSetNamesItsTriggersLocationFixAndTimes) {
  const ScopedTempDir dir("acquisition_event");
  auto acquisition = Acquisition::create(smallRig(dir.path()), testing_support::camerasWithSim());
  ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
  ASSERT_TRUE((*acquisition)->start().ok());
  const core::UtcTime base = core::UtcTime{} + std::chrono::hours{24 * 20600};
  for (int i = 0; i < 3; ++i) {
    core::TriggerEvent event;
    event.trigger_id = 99;  // the planner's own numbering: replaced by the session's
    event.location_id = "R01P0" + std::to_string(i + 1);
    event.time = base + std::chrono::seconds{2 * i} + 5ms;
    event.planned_time = base + std::chrono::seconds{2 * i};
    event.status = i == 2 ? core::TriggerStatus::kLate : core::TriggerStatus::kOnTime;
    core::GpsFix fix;
    fix.time = base + std::chrono::seconds{2 * i} - 40ms;
    fix.valid = true;
    fix.has_date = true;
    fix.latitude_deg = 42.0 + 0.0001 * i;
    fix.longitude_deg = -93.6;
    fix.speed_mps = 2.0;
    event.fix = fix;
    (*acquisition)->trigger(event);
  }
  (*acquisition)->trigger();  // a manual trigger: no location, no fix
  (*acquisition)->finish(10s);
  const auto reader = recording::SessionReader::open(dir.path() / "session");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 4u);
  for (int i = 0; i < 3; ++i) {
    const recording::IndexedSet& set = reader->sets()[static_cast<std::size_t>(i)];
    SCOPED_TRACE(i);
    EXPECT_EQ(set.trigger_id, static_cast<std::uint64_t>(i + 1));
    ASSERT_TRUE(set.location_id.has_value());
    EXPECT_EQ(*set.location_id, "R01P0" + std::to_string(i + 1));
    EXPECT_EQ(set.trigger_time, base + std::chrono::seconds{2 * i} + 5ms);
    ASSERT_TRUE(set.planned_time.has_value());
    EXPECT_EQ(*set.planned_time, base + std::chrono::seconds{2 * i});
    ASSERT_TRUE(set.sent_time.has_value());
    EXPECT_GT(set.sent_time->time_since_epoch().count(), 0);
    EXPECT_EQ(set.trigger_status.value_or(""), i == 2 ? "late" : "on_time");
    ASSERT_TRUE(set.fix.has_value());
    EXPECT_EQ(set.fix->time, base + std::chrono::seconds{2 * i} - 40ms);
    EXPECT_DOUBLE_EQ(set.fix->latitude_deg, 42.0 + 0.0001 * i);
    ASSERT_TRUE(set.fix->speed_mps.has_value());
    EXPECT_DOUBLE_EQ(*set.fix->speed_mps, 2.0);
  }
  const recording::IndexedSet& manual = reader->sets()[3];
  EXPECT_FALSE(manual.location_id.has_value());
  EXPECT_FALSE(manual.fix.has_value());
  EXPECT_FALSE(manual.planned_time.has_value());
  EXPECT_TRUE(manual.sent_time.has_value());
}

TEST(AcquisitionTest, IncompleteSetsAreRecordedWithTheMissingCameraMarked) {
  const ScopedTempDir dir("acquisition_incomplete");
  AcquisitionOptions options = smallRig(dir.path());
  options.rig.cameras[2].options["drop_every"] = "4";
  auto acquisition = Acquisition::create(options, testing_support::camerasWithSim());
  ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
  ASSERT_TRUE((*acquisition)->start().ok());
  triggerAndFinish(**acquisition, 12);
  const auto reader = recording::SessionReader::open(dir.path() / "session");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 12u);
  for (const recording::IndexedSet& set : reader->sets()) {
    EXPECT_EQ(set.complete, set.trigger_id % 4 != 0) << set.trigger_id;
    if (set.trigger_id % 4 == 0) {
      EXPECT_EQ(set.frames[2].status, recording::FrameStatus::kMissing);
      EXPECT_TRUE(set.frames[2].file.empty());
    }
  }
}

TEST(AcquisitionTest, SlowProcessingSkipsSetsButTheRecordingKeepsThemAll) {
  const ScopedTempDir dir("acquisition_slow");
  auto acquisition = Acquisition::create(smallRig(dir.path()), testing_support::camerasWithSim());
  ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
  ASSERT_TRUE((*acquisition)
                  ->start([](const core::FrameSet&) {
                    std::this_thread::sleep_for(30ms);  // a pipeline slower than the triggers
                  })
                  .ok());
  triggerAndFinish(**acquisition, 30);
  const AcquisitionStats stats = (*acquisition)->stats();
  EXPECT_EQ(stats.sets_recorded, 30u);
  EXPECT_GT(stats.sets_skipped_for_processing, 0u);
  EXPECT_EQ(stats.sets_processed + stats.sets_skipped_for_processing, 30u);
}

TEST(AcquisitionTest, ReopeningASessionContinuesItsTriggerNumbering) {
  const ScopedTempDir dir("acquisition_reopen");
  for (int run = 0; run < 2; ++run) {
    auto acquisition = Acquisition::create(smallRig(dir.path()), testing_support::camerasWithSim());
    ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
    ASSERT_TRUE((*acquisition)->start().ok());
    triggerAndFinish(**acquisition, 5);
  }
  const auto reader = recording::SessionReader::open(dir.path() / "session");
  ASSERT_TRUE(reader.ok());
  ASSERT_EQ(reader->sets().size(), 10u);
  for (std::size_t i = 0; i < 10; ++i)
    EXPECT_EQ(reader->sets()[i].trigger_id, i + 1);
}

TEST(AcquireCliTest, PrintsTheSummaryContract) {
  const ScopedTempDir dir("acquire_cli");
  const auto run = testing_support::runFieldrig(
      {"acquire", "--driver", "sim", "--count", "12", "--rate", "40", "--width", "64", "--height",
       "48", "--out", (dir.path() / "s").string(), "--camera-option", "drop_every=6"},
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const auto summary = nlohmann::json::parse(run.out_lines[0]);
  EXPECT_EQ(summary["sets"], 12);
  EXPECT_EQ(summary["incomplete"], 2);    // triggers 6 and 12: every camera dropped them
  EXPECT_EQ(summary["frames_lost"], 12);  // 2 sets × 6 cameras
  EXPECT_TRUE(summary["max_skew_us"].is_number());
  EXPECT_GT(summary["mb_per_s"].get<double>(), 0.0);
  // The sim cameras have no packets: the counts are not known, not zero.
  EXPECT_TRUE(summary["packets_resent"].is_null()) << run.out_lines[0];
  EXPECT_TRUE(summary["packets_missing"].is_null()) << run.out_lines[0];
  EXPECT_TRUE(summary["triggers_merged"].is_null()) << run.out_lines[0];
}

TEST(AcquisitionTest, SimCamerasReportNoPacketLink) {
  const ScopedTempDir dir("acquisition_link");
  auto acquisition = Acquisition::create(smallRig(dir.path()), testing_support::camerasWithSim());
  ASSERT_TRUE(acquisition.ok()) << acquisition.error().message;
  ASSERT_TRUE((*acquisition)->start().ok());
  triggerAndFinish(**acquisition, 3);
  const LinkSummary link = (*acquisition)->linkSummary();
  EXPECT_FALSE(link.has_packets);
  ASSERT_EQ(link.cameras.size(), 6u);
  for (std::size_t i = 0; i < link.cameras.size(); ++i) {
    EXPECT_EQ(link.cameras[i].name, (*acquisition)->cameraNames()[i]);
    EXPECT_FALSE(link.cameras[i].link.has_packets);
  }
}

#if defined(FIELDRIG_HAVE_ARAVIS)
// `fieldrig acquire --driver aravis` against arv-fake-gv-camera-0.8 on the loopback losing 1 % of
// its stream packets (-r 10): the summary counts the packets the host asked to have resent and
// those that never came, and they agree with the frames it reports damaged. (arv-fake-gv-camera
// 0.8.26 does not answer resend requests, so nothing is recovered against it; a real camera
// resends. The test asserts the accounting, not a recovery the fake cannot give.)
TEST(AcquireCliTest, GigEPacketCountsAreInTheSummary) {
  if (std::strlen(FIELDRIG_ARV_FAKE_GV_CAMERA) == 0)
    GTEST_SKIP() << "arv-fake-gv-camera-0.8 not installed (package aravis-tools)";
  const ScopedTempDir dir("acquire_cli_gige");
  testing_support::FakeGvCamera fake("10");
  constexpr int kCount = 40;
  const std::vector<std::string> args = {"acquire",
                                         "--driver",
                                         "aravis",
                                         "--camera",
                                         fake.address(),
                                         "--count",
                                         std::to_string(kCount),
                                         "--rate",
                                         "10",
                                         "--width",
                                         "320",
                                         "--height",
                                         "240",
                                         "--pixel-format",
                                         "Mono8",
                                         "--fsync",
                                         "none",
                                         "--frame-timeout-ms",
                                         "2000",
                                         "--out",
                                         (dir.path() / "s").string()};
  // The fake takes a moment to listen: a run that cannot open the camera is retried (bounded).
  testing_support::CliRun run;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (true) {
    std::filesystem::remove_all(dir.path() / "s");
    run = testing_support::runFieldrig(args, dir.path());
    const bool not_up = run.exit_code != 0 && run.err.find("cannot open") != std::string::npos;
    if (!not_up || !fake.running() || std::chrono::steady_clock::now() > deadline)
      break;
    std::this_thread::sleep_for(200ms);
  }
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u);
  const auto summary = nlohmann::json::parse(run.out_lines[0]);
  std::printf("%s\n", run.out_lines[0].c_str());
  EXPECT_EQ(summary["sets"], kCount);
  ASSERT_TRUE(summary["packets_resent"].is_number_unsigned()) << run.out_lines[0];
  ASSERT_TRUE(summary["packets_missing"].is_number_unsigned()) << run.out_lines[0];
  // Frames lost beyond the damaged ones are the camera's merges, which Aravis counts.
  ASSERT_TRUE(summary["triggers_merged"].is_number_unsigned()) << run.out_lines[0];
  EXPECT_LE(summary["triggers_merged"].get<std::uint64_t>(),
            summary["frames_lost"].get<std::uint64_t>())
      << run.out_lines[0];
  // 40 frames of ~55 packets at 1 % loss: about 22 packets lost; none lost has odds of e^-22.
  EXPECT_GT(summary["packets_resent"].get<std::uint64_t>() +
                summary["packets_missing"].get<std::uint64_t>(),
            0u)
      << run.out_lines[0];
  // A packet that never came damages its frame: missing packets and damaged frames go together.
  EXPECT_EQ(
      summary["packets_missing"].get<std::uint64_t>() > 0,
      summary["frames_corrupt"].get<std::uint64_t>() + summary["frames_lost"].get<std::uint64_t>() >
          0)
      << run.out_lines[0];
}
#endif

TEST(AcquireCliTest, UnknownDriverIsAClearError) {
  const ScopedTempDir dir("acquire_cli_bad");
  const auto run =
      testing_support::runFieldrig({"acquire", "--driver", "gige", "--camera", "x", "--count", "1",
                                    "--rate", "1", "--out", (dir.path() / "s").string()},
                                   dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("unknown camera driver 'gige'"), std::string::npos) << run.err;
  // The program added the sim driver (drivers/ does not know it): the error lists it.
  const auto listed = run.err.find("this build has: ");
  ASSERT_NE(listed, std::string::npos) << run.err;
  EXPECT_NE(run.err.find("sim", listed), std::string::npos) << run.err;
}

}  // namespace
}  // namespace fieldrig::daemon
