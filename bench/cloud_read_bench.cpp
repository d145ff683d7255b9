// cloud_read_bench: reading plot clouds and the whole `fieldrig traits --cloud` run, against stock
// PCL in the same run (issue 11's targets: a whole run on a 300k-point ASCII plot >= 8x faster than
// the paper's pipeline on stock PCL, reading included).
//
// One synthetic plot of exactly 300,000 points is written by PCL's own writers as ASCII and binary
// PLY and PCD. Printed: read MB/s of fieldrig's readers (traits::loadCloud) and of PCL's
// (pcl::io::loadPLYFile / loadPCDFile) per format; the start-up of `fieldrig traits`, of the full
// tool and of a program on stock PCL (processes that only print their help, or exit); and the whole
// run, ours (`fieldrig traits` start-up + loadCloud + computeTraits with the shipped options)
// against the paper's (stock PCL start-up + PCL's PLY reader + computeTraits with the paper's SOR,
// plate ICP and MLS + greedy projection triangulation).
// Times are CPU seconds (user + system; of the child process for the start-up), which barely move
// when other work loads this 2-core machine, as wall time does; medians of alternating repeats.
#include <fcntl.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "bench_stats.h"
#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/traits/cloud_io.h"
#include "fieldrig/traits/plot_traits.h"
#include "paper_pipeline.h"
#include "process_cpu.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
namespace traits = fieldrig::traits;
using fieldrig::bench::processCpuSeconds;

constexpr std::size_t kPoints = 300000;

double secondsSince(double cpu_start) {
  return processCpuSeconds() - cpu_start;
}

using fieldrig::bench::loadAverage;
using fieldrig::bench::median;

// CPU seconds of one process `program args…` with stdout to /dev/null: dynamic loading and static
// start-up when the arguments make it exit at once.
double startupSeconds(const char* program, std::vector<std::string> args) {
  std::vector<char*> argv;
  std::string arg0 = program;
  argv.push_back(arg0.data());
  for (std::string& arg : args)
    argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  if (posix_spawn(&pid, program, &actions, nullptr, argv.data(), environ) != 0) {
    std::fprintf(stderr, "cannot start %s\n", program);
    std::exit(1);
  }
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "%s did not exit cleanly\n", program);
    std::exit(1);
  }
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double medianStartup(int repeats, const char* program, const std::vector<std::string>& args) {
  std::vector<double> seconds;
  for (int r = 0; r < repeats; ++r)
    seconds.push_back(startupSeconds(program, args));
  return median(seconds);
}

// PCL's reader for the file's format, as points.
std::vector<Eigen::Vector3f> pclRead(const std::string& path) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  const bool ply = path.ends_with(".ply");
  if ((ply ? pcl::io::loadPLYFile(path, cloud) : pcl::io::loadPCDFile(path, cloud)) < 0) {
    std::fprintf(stderr, "PCL cannot read %s\n", path.c_str());
    std::exit(1);
  }
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.size());
  for (const auto& p : cloud)
    points.emplace_back(p.x, p.y, p.z);
  return points;
}

std::vector<Eigen::Vector3f> ours(const std::string& path) {
  auto loaded = traits::loadCloud(path);
  if (!loaded) {
    std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
    std::exit(1);
  }
  return std::move(*loaded);
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 && std::string(argv[1]) == "--quick" ? 3 : 7;
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  std::printf("# cloud_read_bench: load average before: %s\n", loadAverage().c_str());

  // A 2.5 m plot sampled densely, cut to exactly 300,000 points at random.
  fieldrig::sim::PlotSpec spec;
  spec.plant_height_m = 2.5;
  spec.depth_noise_m = 0.003;
  spec.seed = 5;
  spec.sample_spacing_m = 0.002;
  const fieldrig::sim::PlotCloud plot = fieldrig::sim::generatePlot(spec);
  std::vector<Eigen::Vector3f> points = plot.points;
  std::shuffle(points.begin(), points.end(), std::mt19937(7));
  if (points.size() < kPoints) {
    std::fprintf(stderr, "the plot has %zu points, fewer than %zu\n", points.size(), kPoints);
    return 1;
  }
  points.resize(kPoints);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const Eigen::Vector3f& p : points)
    cloud.push_back({p.x(), p.y(), p.z()});

  const fs::path dir = fs::temp_directory_path() / "fieldrig_cloud_read_bench";
  fs::create_directories(dir);
  struct Format {
    const char* name;
    std::string path;
  };
  const std::vector<Format> formats = {{"PLY ascii", (dir / "plot_ascii.ply").string()},
                                       {"PLY binary", (dir / "plot_binary.ply").string()},
                                       {"PCD ascii", (dir / "plot_ascii.pcd").string()},
                                       {"PCD binary", (dir / "plot_binary.pcd").string()}};
  pcl::io::savePLYFile(formats[0].path, cloud, false);
  pcl::io::savePLYFile(formats[1].path, cloud, true);
  pcl::io::savePCDFile(formats[2].path, cloud, false);
  pcl::io::savePCDFile(formats[3].path, cloud, true);

  std::printf(
      "\n| format (300,000 points) | MB | fieldrig CPU s | fieldrig MB/s | PCL CPU s | PCL MB/s | "
      "ratio |\n|---|---|---|---|---|---|---|\n");
  for (const Format& format : formats) {
    const double mb = static_cast<double>(fs::file_size(format.path)) / 1e6;
    std::vector<double> ours_s, pcl_s;
    for (int r = 0; r < repeats; ++r) {
      double start = processCpuSeconds();
      const std::size_t n_ours = ours(format.path).size();
      ours_s.push_back(secondsSince(start));
      start = processCpuSeconds();
      const std::size_t n_pcl = pclRead(format.path).size();
      pcl_s.push_back(secondsSince(start));
      if (n_ours != kPoints || n_pcl != kPoints) {
        std::fprintf(stderr, "%s: read %zu (fieldrig) and %zu (PCL) points\n", format.name, n_ours,
                     n_pcl);
        return 1;
      }
    }
    const double a = median(ours_s), b = median(pcl_s);
    std::printf("| %s | %.1f | %.3f | %.0f | %.3f | %.0f | %.1fx |\n", format.name, mb, a, mb / a,
                b, mb / b, b / a);
  }

  // `fieldrig traits` runs the launcher and the light fieldrig-traits; the other subcommands the
  // full fieldrig-commands; the paper's pipeline is a program on stock PCL (paper_startup).
  const double startup = medianStartup(repeats, FIELDRIG_BINARY, {"traits", "--help"});
  const double startup_full = medianStartup(repeats, FIELDRIG_BINARY, {"--help"});
  const double startup_paper = medianStartup(repeats, PAPER_STARTUP, {});
  std::printf("\n| start-up (median of %d) | CPU s |\n|---|---|\n", repeats);
  std::printf("| `fieldrig traits --help` (launcher + fieldrig-traits) | %.3f |\n", startup);
  std::printf("| `fieldrig --help` (launcher + fieldrig-commands) | %.3f |\n", startup_full);
  std::printf("| paper_startup (a program on stock PCL: reader, VTK) | %.3f |\n", startup_paper);

  // The whole run on the ASCII PLY.
  traits::TraitsOptions shipped;
  const traits::TraitsOptions paper = fieldrig::bench::paperPipelineOptions(shipped);
  std::vector<double> ours_read, ours_traits, paper_read, paper_traits;
  const int whole_repeats = std::max(3, repeats / 2);
  for (int r = 0; r < whole_repeats; ++r) {
    double start = processCpuSeconds();
    const std::vector<Eigen::Vector3f> a = ours(formats[0].path);
    ours_read.push_back(secondsSince(start));
    start = processCpuSeconds();
    traits::computeTraits(a, traits::InputFrame::kPlot, shipped);
    ours_traits.push_back(secondsSince(start));
    start = processCpuSeconds();
    const std::vector<Eigen::Vector3f> b = pclRead(formats[0].path);
    paper_read.push_back(secondsSince(start));
    start = processCpuSeconds();
    traits::computeTraits(b, traits::InputFrame::kPlot, paper);
    paper_traits.push_back(secondsSince(start));
  }
  const double ours_total = startup + median(ours_read) + median(ours_traits);
  const double paper_total = startup_paper + median(paper_read) + median(paper_traits);
  std::printf(
      "\n| whole run, 300,000-point ASCII PLY | start-up CPU s | read CPU s | traits CPU s | total "
      "CPU s |\n"
      "|---|---|---|---|---|\n");
  std::printf("| fieldrig (own reader, shipped traits) | %.3f | %.3f | %.3f | %.3f |\n", startup,
              median(ours_read), median(ours_traits), ours_total);
  std::printf(
      "| paper on stock PCL (PCL reader, SOR k50, plate ICP, MLS + GPT) | %.3f | %.3f | "
      "%.3f | %.3f |\n",
      startup_paper, median(paper_read), median(paper_traits), paper_total);
  std::printf("\nwhole run: fieldrig %.2fx faster than the paper's pipeline (target >= 8x)\n",
              paper_total / ours_total);
  // The comparison of earlier versions, which gave both runs the full tool's start-up.
  const double rest_ours = median(ours_read) + median(ours_traits);
  const double rest_paper = median(paper_read) + median(paper_traits);
  std::printf("with the full fieldrig's start-up on both sides: %.2fx\n",
              (startup_full + rest_paper) / (startup_full + rest_ours));
  std::printf("# load average after: %s\n", loadAverage().c_str());
  fs::remove_all(dir);
  return 0;
}
