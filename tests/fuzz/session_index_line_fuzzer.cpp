// libFuzzer target for recording::fromIndexLine, one line of a session's index.jsonl.
//
// Besides crashes and sanitizer reports: a line that is refused says why; a set that is read has
// every frame file inside the session folder (relative, no "..": readers join it to the folder),
// a fix on Earth (latitude within 90 degrees, longitude within 180), and what toIndexLine() writes
// of it reads back into a set that writes the same line again.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "fieldrig/recording/session_format.h"
#include "fuzz_support.h"

namespace {

using fieldrig::fuzz::check;
using fieldrig::recording::fromIndexLine;
using fieldrig::recording::IndexedFrame;
using fieldrig::recording::IndexedSet;
using fieldrig::recording::toIndexLine;

IndexedFrame frame(int camera, const char* name, bool missing) {
  IndexedFrame f;
  f.camera_index = camera;
  f.camera_name = name;
  f.width = 1624;
  f.height = 1224;
  f.pixel_format = fieldrig::core::PixelFormat::kBayerRG8;
  f.sequence = 41;
  f.device_timestamp_ns = 123456789012;
  f.host_steady_ns = 987654321;
  f.host_system_ns = 1717000000123456789;
  if (missing) {
    f.status = fieldrig::recording::FrameStatus::kMissing;
    f.reason = "no frame within 200 ms";
  } else {
    f.file = fieldrig::recording::frameFileName(7, camera, name);
    f.file_bytes = 1624 * 1224 + 17;
    f.crc32 = 0xdeadbeef;
  }
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  IndexedSet set;
  set.set_index = 7;
  set.trigger_id = 12;
  set.location_id = "R01P03";
  set.trigger_time = fieldrig::core::UtcTime{std::chrono::nanoseconds{1717000000123456789}};
  set.planned_time = set.trigger_time - std::chrono::milliseconds{3};
  set.sent_time = set.trigger_time - std::chrono::milliseconds{1};
  set.trigger_status = "on_time";
  set.skew_us = 12.5;
  fieldrig::core::GpsFix fix;
  fix.time = set.trigger_time;
  fix.has_date = true;
  fix.latitude_deg = 42.0106225;
  fix.longitude_deg = -93.7385;
  fix.valid = true;
  fix.speed_mps = 1.5;
  fix.course_deg = 359.9;
  fix.altitude_m = 300.25;
  fix.hdop = 0.8;
  fix.quality = fieldrig::core::FixQuality::kRtkFixed;
  fix.satellites = 14;
  fix.talker = "GN";
  set.fix = fix;
  set.frames = {frame(0, "bottom_left", false), frame(1, "bottom_right", true)};
  fieldrig::fuzz::writeSeed("located", toIndexLine(set));
  IndexedSet bare;
  bare.complete = false;
  bare.frames = {frame(0, "cam", false)};
  fieldrig::fuzz::writeSeed("bare", toIndexLine(bare));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(bytes), size);
  std::string error;
  const std::optional<IndexedSet> set = fromIndexLine(line, error);
  if (!set) {
    check(!error.empty(), "a line refused without a reason");
    return 0;
  }
  for (const IndexedFrame& f : set->frames) {
    const std::filesystem::path file(f.file);
    check(!file.is_absolute() && std::find(file.begin(), file.end(), "..") == file.end(),
          "a frame file outside the session folder was accepted");
  }
  check(std::isfinite(set->skew_us), "a skew that is not finite");
  if (set->fix) {
    check(std::isfinite(set->fix->latitude_deg) && std::fabs(set->fix->latitude_deg) <= 90,
          "a fix's latitude out of range");
    check(std::isfinite(set->fix->longitude_deg) && std::fabs(set->fix->longitude_deg) <= 180,
          "a fix's longitude out of range");
  }

  const std::string written = toIndexLine(*set);
  check(written.find('\n') == std::string::npos, "an index line with a line break in it");
  std::string again_error;
  const std::optional<IndexedSet> again = fromIndexLine(written, again_error);
  check(again.has_value(), "the set's own index line does not read back");
  check(again->set_index == set->set_index && again->trigger_id == set->trigger_id &&
            again->frames.size() == set->frames.size() && again->location_id == set->location_id,
        "the set changes when written and read again");
  check(toIndexLine(*again) == written, "writing the set again gives another line");
  return 0;
}
