// Whole-run benchmark of capture under load (issue 12): trigger → FrameSet latency on the sim
// driver path, idle and while a stereo+traits-like workload keeps both cores busy, measured in
// the same run so that the ratios against the idle baseline compare like with like.
//
//   capture_load_bench [TRIGGERS] [RATE_HZ] [WIDTH] [HEIGHT]
//
// Path: Acquisition::trigger() → six sim cameras (a worker thread each) → the rig thread groups
// the set → the recorder thread writes it (fsync none: the disk is not what is measured) and the
// processing thread receives it; the latency is taken when the processing thread holds the whole
// set, as in trigger_to_record_bench. Triggers are sent on a clock at RATE_HZ, as `fieldrig
// acquire` and the GPS chain send them (default 400 at 20 Hz, 640×480 RAW8 frames).
//
// Load: one thread per core, each looping over what the daemon's processing does per set, in
// miniature: OpenCV StereoSGBM (3WAY, 128 disparities) on an 812×612 textured pair (the
// pipeline's half-resolution head), then traits-like work on 200,000 points (median height by
// nth_element per slice, a convex hull per slice). OpenCV runs single-threaded in each thread, so
// the load is exactly the machine's two cores.
//
// dc1394: the Grasshoppers' path needs an IEEE-1394 bus; where none exists the bench says so
// (the driver's own error) instead of printing figures.
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench_stats.h"
#include "fieldrig/daemon/acquisition.h"
#include "fieldrig/drivers/rig.h"
#include "fieldrig/sim/sim_camera.h"
#include "support/sim_cameras.h"

namespace {

namespace fs = std::filesystem;
using namespace fieldrig;
using Clock = std::chrono::steady_clock;

struct Run {
  std::vector<double> us;  // one per whole set the processing thread received
  std::uint64_t triggers = 0;
  std::uint64_t incomplete = 0;
  std::uint64_t frames_missing = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t skipped = 0;  // sets processing never saw (its queue was full)
  std::uint64_t recorded = 0;
  std::uint64_t load_rounds = 0;  // stereo+traits rounds the load threads completed
  double seconds = 0;
};

double quantile(std::vector<double> v, double q) {
  if (v.empty())
    return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

// One core's worth of the processing: a stereo match, then slice statistics and hulls.
class StereoTraitsLoad {
 public:
  StereoTraitsLoad() {
    cv::RNG rng(7);
    left_.create(612, 812, CV_8UC1);
    rng.fill(left_, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(left_, left_, cv::Size(3, 3), 0);
    // The right view: the left shifted by 40 px, as a plant 1 m from the rig.
    right_ = cv::Mat::zeros(left_.size(), left_.type());
    left_.colRange(40, left_.cols).copyTo(right_.colRange(0, left_.cols - 40));
    matcher_ = cv::StereoSGBM::create(0, 128, 5, 8 * 25, 32 * 25, 1, 0, 10, 100, 2,
                                      cv::StereoSGBM::MODE_SGBM_3WAY);
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> coordinate(0.0f, 3.0f);
    points_.resize(200'000);
    for (cv::Point2f& p : points_)
      p = {coordinate(gen), coordinate(gen)};
  }

  void round() {
    matcher_->compute(left_, right_, disparity_);
    constexpr int kSlices = 20;
    const std::size_t per_slice = points_.size() / kSlices;
    for (int s = 0; s < kSlices; ++s) {
      slice_.assign(points_.begin() + static_cast<std::ptrdiff_t>(s * per_slice),
                    points_.begin() + static_cast<std::ptrdiff_t>((s + 1) * per_slice));
      heights_.resize(slice_.size());
      std::transform(slice_.begin(), slice_.end(), heights_.begin(),
                     [](const cv::Point2f& p) { return p.y; });
      std::nth_element(heights_.begin(),
                       heights_.begin() + static_cast<std::ptrdiff_t>(heights_.size() / 2),
                       heights_.end());
      cv::convexHull(slice_, hull_);
    }
  }

 private:
  cv::Mat left_, right_, disparity_;
  cv::Ptr<cv::StereoSGBM> matcher_;
  std::vector<cv::Point2f> points_, slice_, hull_;
  std::vector<float> heights_;
};

daemon::AcquisitionOptions sixSimCameras(const fs::path& dir, std::uint32_t width,
                                         std::uint32_t height) {
  daemon::AcquisitionOptions options;
  options.rig = testing_support::sixSimCameras(width, height);
  options.rig.frame_timeout = std::chrono::milliseconds{500};
  options.rig.pool_sets = 32;
  options.session_dir = dir;
  options.writer.fsync = recording::FsyncPolicy::kNone;
  options.processing_queue_sets = 4;
  return options;
}

Run measure(const fs::path& dir, int triggers, double rate_hz, std::uint32_t width,
            std::uint32_t height, int load_threads) {
  auto acquisition = daemon::Acquisition::create(sixSimCameras(dir, width, height),
                                                 drivers::CameraRegistry::instance());
  if (!acquisition) {
    std::fprintf(stderr, "%s\n", acquisition.error().message.c_str());
    std::exit(1);
  }
  Run run;
  run.triggers = static_cast<std::uint64_t>(triggers);
  run.us.reserve(run.triggers);
  std::vector<Clock::time_point> sent(run.triggers + 1);
  // A new session numbers its sets from 1: the i-th trigger is set i. `sent[i]` is written
  // before trigger i is pushed, which the rig's queues publish to the processing thread.
  if (!(*acquisition)->start([&](const core::FrameSet& set) {
        if (set.complete() && set.trigger_id < sent.size()) {
          run.us.push_back(
              std::chrono::duration<double, std::micro>(Clock::now() - sent[set.trigger_id])
                  .count());
        }
      })) {
    std::exit(1);
  }

  std::atomic<bool> loading{load_threads > 0};
  std::atomic<std::uint64_t> rounds{0};
  std::vector<std::thread> load;
  for (int i = 0; i < load_threads; ++i) {
    load.emplace_back([&] {
      StereoTraitsLoad work;
      while (loading) {
        work.round();
        rounds.fetch_add(1);
      }
    });
  }
  if (load_threads > 0)
    std::this_thread::sleep_for(std::chrono::seconds{1});  // the load is running before we trigger

  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
  const Clock::time_point begin = Clock::now();
  for (std::uint64_t i = 1; i <= run.triggers; ++i) {
    std::this_thread::sleep_until(begin + static_cast<long>(i - 1) * period);
    sent[i] = Clock::now();
    (*acquisition)->trigger();
  }
  (*acquisition)->finish(std::chrono::seconds{30});
  run.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
  loading = false;
  for (std::thread& t : load)
    t.join();
  run.load_rounds = rounds.load();
  const daemon::AcquisitionStats stats = (*acquisition)->stats();
  run.incomplete = stats.rig.incomplete_sets;
  run.frames_missing = stats.rig.frames_missing;
  run.frames_dropped = stats.rig.frames_dropped;
  run.skipped = stats.sets_skipped_for_processing;
  run.recorded = stats.sets_recorded;
  return run;
}

void printRow(const char* name, const Run& run, const Run& idle) {
  const double p50 = quantile(run.us, 0.5), p99 = quantile(run.us, 0.99);
  const double idle_p50 = quantile(idle.us, 0.5), idle_p99 = quantile(idle.us, 0.99);
  std::printf(
      "| %s | %zu/%llu | %llu | %.0f | %.0f | %.0f | %.2f | %.2f | %llu (%llu missing, "
      "%llu dropped) | %llu | %llu |\n",
      name, run.us.size(), static_cast<unsigned long long>(run.triggers),
      static_cast<unsigned long long>(run.recorded), p50, p99, quantile(run.us, 1.0),
      idle_p50 > 0 ? p50 / idle_p50 : 0.0, idle_p99 > 0 ? p99 / idle_p99 : 0.0,
      static_cast<unsigned long long>(run.incomplete),
      static_cast<unsigned long long>(run.frames_missing),
      static_cast<unsigned long long>(run.frames_dropped),
      static_cast<unsigned long long>(run.skipped),
      static_cast<unsigned long long>(run.load_rounds));
}

// The dc1394 path cannot run without an IEEE-1394 bus: the driver's own answer, or why it is
// not built.
std::string dc1394Availability() {
  auto camera = drivers::CameraRegistry::instance().create("dc1394");
  if (!camera)
    return "not built here (libdc1394-2 not found): " + camera.error().message;
  drivers::CameraConfig config;
  config.id = "0";
  const auto configured = (*camera)->configure(config);
  return configured ? "a camera answered: run this bench's dc1394 row on the tractor"
                    : configured.error().message;
}

}  // namespace

int main(int argc, char** argv) {
  const int triggers = argc > 1 ? std::atoi(argv[1]) : 400;
  const double rate_hz = argc > 2 ? std::atof(argv[2]) : 20.0;
  const int width = argc > 3 ? std::atoi(argv[3]) : 640;
  const int height = argc > 4 ? std::atoi(argv[4]) : 480;
  if (triggers <= 0 || !(rate_hz > 0 && rate_hz <= 1000) || width <= 0 || height <= 0) {
    std::fprintf(stderr, "usage: capture_load_bench [TRIGGERS] [RATE_HZ] [WIDTH] [HEIGHT]\n");
    return 2;
  }
  cv::setNumThreads(1);  // each load thread is one core's work, no pool of OpenCV's own
  sim::addSimCamera(drivers::CameraRegistry::instance());
  const fs::path root =
      fs::temp_directory_path() / ("capture_load_bench_" + std::to_string(::getpid()));
  fs::create_directories(root);
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());

  std::printf(
      "sim driver, six cameras %dx%d, %d triggers at %.1f Hz; load: %u threads of "
      "StereoSGBM 812x612 + slice medians and hulls on 200k points\n",
      width, height, triggers, rate_hz, cores);
  std::printf("load average before: %s\n\n", bench::loadAverage().c_str());
  const Run idle = measure(root / "idle", triggers, rate_hz, static_cast<std::uint32_t>(width),
                           static_cast<std::uint32_t>(height), 0);
  const Run loaded = measure(root / "loaded", triggers, rate_hz, static_cast<std::uint32_t>(width),
                             static_cast<std::uint32_t>(height), static_cast<int>(cores));
  std::printf(
      "| trigger → processing thread | whole sets | recorded | p50 µs | p99 µs | max µs | "
      "p50 / idle | p99 / idle | incomplete (frames) | skipped for processing | "
      "load rounds |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  printRow("sim, idle", idle, idle);
  printRow("sim, stereo+traits load on every core", loaded, idle);
  std::printf("\nload average after: %s\n", bench::loadAverage().c_str());
  std::printf("dc1394 (Grasshoppers over IEEE-1394): not measured: %s\n",
              dc1394Availability().c_str());
  std::error_code ignored;
  fs::remove_all(root, ignored);
  return 0;
}
