// libFuzzer target for config::parseConfig, fieldrig's YAML configuration (yaml-cpp).
//
// Besides crashes and sanitizer reports (yaml-cpp throws on malformed text; nothing may escape the
// loader): an error names the origin; a configuration that loads passes the option structs' own
// checks (cloud, matcher, traits), has one camera per side of every head, and parsing the same
// text again gives the same outcome.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fieldrig/config/config.h"
#include "fuzz_support.h"

namespace {

using fieldrig::fuzz::check;
using fieldrig::fuzz::startsWith;

const std::string kOrigin = "fuzz.yaml";

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fieldrig::fuzz::writeSeed(
      "sections",
      "gps:\n  serial: {device: /dev/ttyUSB0, baud: 115200}\n  latency_s: 0.1\n"
      "map: map.csv\ncameras:\n  driver: sim\n  heads: [bottom, top]\n"
      "  white_balance: [1.2, 1.5]\n  options: {pattern: bars}\n"
      "pipeline:\n  matcher: {mode: sgbm, num_disparities: 128}\n"
      "  traits:\n    camera_to_plot: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n"
      "    slices: 12\n  cloud: {scale: 0.5}\n"
      "outputs: {csv: false}\nstatus: {port: 0}\nlog: {level: debug}\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(bytes), size);
  const auto config = fieldrig::config::parseConfig(text, kOrigin, "/fuzz/base");
  const auto again = fieldrig::config::parseConfig(text, kOrigin, "/fuzz/base");
  check(static_cast<bool>(config) == static_cast<bool>(again),
        "the same text loads once and fails once");
  if (!config) {
    check(startsWith(config.error().message, kOrigin), "an error that does not name the file");
    check(config.error().message == again.error().message, "the same text fails otherwise");
    return 0;
  }
  check(!config->pipeline.traits.validate().has_value(),
        "traits options out of range were accepted");
  check(static_cast<bool>(fieldrig::cloud::validate(config->pipeline.cloud)),
        "cloud options out of range were accepted");
  check(static_cast<bool>(fieldrig::stereo::validate(config->pipeline.cloud.matcher)),
        "matcher options out of range were accepted");
  check(config->cameras.rig.cameras.size() == config->cameras.layout.cameraCount(),
        "not one camera per side of every head");
  check(!config->cameras.layout.heads.empty(), "a rig without heads was accepted");
  return 0;
}
