// Whole-run benchmark of recording::SessionWriter at the rig's frame size: sets of six
// 1624×1224 RAW8 frames (~2 MB each, ~12 MB a set) written for a few seconds per fsync policy,
// as fast as the writer goes (the target is ≥ 30 sets/s sustained; the real bus gives ~7).
//
//   recording_bench [DIR] [SECONDS_PER_POLICY]
//
// DIR defaults to the system temporary folder; the session folders are removed afterwards. Each
// policy stops after SECONDS (default 4) or 150 sets (~1.8 GB), whichever comes first, so the
// run stays under ~2 GB of disk (each policy's folder is removed, and the disk synced, before
// the next). CPU time is the process's user + system time (CLOCK_PROCESS_CPUTIME_ID); the kernel's
// own writeback threads are not in it.
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fieldrig/recording/session_writer.h"
#include "recording/synthetic_sets.h"

#include "process_cpu.h"

namespace {

namespace fs = std::filesystem;
using namespace fieldrig;
using Clock = std::chrono::steady_clock;

constexpr int kWidth = 1624;
constexpr int kHeight = 1224;
constexpr std::uint64_t kMaxSets = 150;

// Writes sets until `seconds` pass or kMaxSets are written; prints one table row.
bool runPolicy(const fs::path& root, recording::FsyncPolicy policy, double seconds,
               const testing_support::SyntheticRig& rig, std::uint64_t max_sets = kMaxSets,
               const char* label = nullptr) {
  const fs::path session = root / ("session_" + std::string(recording::toString(policy)));
  recording::SessionWriter writer;
  core::Result<recording::OpenReport> opened =
      writer.open(session, recording::SessionInfo{}, recording::WriterOptions{policy});
  if (!opened) {
    std::fprintf(stderr, "%s\n", opened.error().message.c_str());
    return false;
  }
  const double cpu_start = fieldrig::bench::processCpuSeconds();
  const Clock::time_point start = Clock::now();
  const Clock::time_point end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t sets = 0;
  while (sets < max_sets && Clock::now() < end) {
    // The same buffers every time (the pool's frames would be); metadata differs per trigger.
    const recording::WriteOutcome outcome = writer.write(rig.record(sets, "plot"));
    if (!outcome.ok()) {
      std::fprintf(stderr, "write failed: %s\n", outcome.message.c_str());
      return false;
    }
    ++sets;
  }
  writer.close();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = fieldrig::bench::processCpuSeconds() - cpu_start;
  const double megabytes = static_cast<double>(writer.bytesWritten()) / 1e6;
  std::printf("| %-9s | %5llu | %6.1f | %7.1f | %8.0f | %11.2f | %9.2f |\n",
              label != nullptr ? label : std::string(recording::toString(policy)).c_str(),
              static_cast<unsigned long long>(sets), wall, static_cast<double>(sets) / wall,
              megabytes / wall, 1e3 * cpu / static_cast<double>(sets),
              1e3 * wall / static_cast<double>(sets));
  std::fflush(stdout);
  std::error_code ec;
  fs::remove_all(session, ec);
  // Let the disk drain (outside the timed part), so that the next policy does not pay for the
  // writeback of this one.
  ::sync();
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path base = argc > 1 ? fs::path(argv[1]) : fs::temp_directory_path();
  const double seconds = argc > 2 ? std::atof(argv[2]) : 4.0;
  const fs::path root = base / ("fieldrig_recording_bench_" + std::to_string(::getpid()));
  fs::create_directories(root);

  testing_support::SyntheticRig rig(kWidth, kHeight);
  rig.fill(1);

  std::printf(
      "recording_bench: 6 × %d×%d RAW8 per set (%.1f MB), into %s, ≤ %.1f s or %llu sets "
      "per policy\n\n",
      kWidth, kHeight, 6.0 * kWidth * kHeight / 1e6, root.c_str(), seconds,
      static_cast<unsigned long long>(kMaxSets));
  // The writer checksums every frame (CRC-32, zlib); its share of the CPU time per set:
  {
    const double cpu_start = fieldrig::bench::processCpuSeconds();
    constexpr int kRounds = 20;
    uLong crc = 0;
    for (int round = 0; round < kRounds; ++round) {
      for (const recording::FrameView& frame : rig.record(1, std::nullopt).frames)
        crc = ::crc32(crc, frame.pixels.data(), static_cast<uInt>(frame.pixels.size()));
    }
    const double ms = 1e3 * (fieldrig::bench::processCpuSeconds() - cpu_start) / kRounds;
    std::printf("CRC-32 of one set (zlib %s): %.2f ms CPU (%.0f MB/s) [%lx]\n\n", zlibVersion(), ms,
                6.0 * kWidth * kHeight / 1e3 / ms, crc);
  }
  std::printf("| fsync     | sets  | wall s | sets/s  | MB/s     | CPU ms/set  | wall ms/set |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- |\n");
  // The first gigabytes a process writes cost more (page cache growth, first block allocations);
  // a short unreported-as-policy round takes that cost out of the first row.
  bool ok = runPolicy(root, recording::FsyncPolicy::kNone, seconds, rig, 40, "(warm-up)");
  for (recording::FsyncPolicy policy :
       {recording::FsyncPolicy::kNone, recording::FsyncPolicy::kPerSet,
        recording::FsyncPolicy::kPerFrame}) {
    ok = runPolicy(root, policy, seconds, rig) && ok;
  }
  std::error_code ec;
  fs::remove_all(root, ec);
  return ok ? 0 : 1;
}
