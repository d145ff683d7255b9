// libFuzzer target for the calibration loaders: stereo::loadStereoCalibration (a head's
// intrinsics.yml and extrinsics.yml, OpenCV's stereo_calib layout) and cloud::loadRigCalibration
// (rig.yml, whose heads are read from their folders). An input is three files cut at "=====" lines:
// intrinsics.yml, extrinsics.yml, rig.yml; the head's two files are written for the heads bottom,
// middle and top.
//
// Besides crashes and sanitizer reports: an error names the file it comes from; a calibration
// that loads passes its own plausibility checks and reads back unchanged from what
// saveStereoCalibration / saveRigCalibration write of it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/stereo/calibration.h"
#include "fuzz_support.h"

namespace {

namespace fs = std::filesystem;
using fieldrig::fuzz::check;
using fieldrig::fuzz::startsWith;
using fieldrig::stereo::StereoCalibration;

constexpr const char* kHeads[] = {"bottom", "middle", "top"};

bool same(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || b.empty())
    return a.empty() && b.empty();
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// The first field in which two calibrations differ, or nothing.
std::string difference(const StereoCalibration& a, const StereoCalibration& b) {
  const std::pair<const char*, const cv::Mat StereoCalibration::*> fields[] = {
      {"M1", &StereoCalibration::M1}, {"D1", &StereoCalibration::D1},
      {"M2", &StereoCalibration::M2}, {"D2", &StereoCalibration::D2},
      {"R", &StereoCalibration::R},   {"T", &StereoCalibration::T},
      {"R1", &StereoCalibration::R1}, {"R2", &StereoCalibration::R2},
      {"P1", &StereoCalibration::P1}, {"P2", &StereoCalibration::P2},
      {"Q", &StereoCalibration::Q}};
  for (const auto& [name, field] : fields) {
    if (!same(a.*field, b.*field))
      return name;
  }
  return a.image_size == b.image_size ? "" : "image_size";
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void checkStereo(const StereoCalibration& c, const fs::path& scratch) {
  check(static_cast<bool>(fieldrig::stereo::checkIntrinsics(c)) &&
            static_cast<bool>(fieldrig::stereo::checkExtrinsics(c)),
        "a calibration that loads fails its own checks");
  check(std::isfinite(c.baseline()) && c.baseline() >= fieldrig::stereo::kMinBaselineM &&
            c.baseline() <= fieldrig::stereo::kMaxBaselineM,
        "a baseline out of range was accepted");
  check(std::isfinite(c.rectifiedFocalPx()) && c.rectifiedFocalPx() > 0,
        "a rectified focal length that is not positive was accepted");
  const auto saved = fieldrig::stereo::saveStereoCalibration(c, scratch);
  check(static_cast<bool>(saved), "a loaded calibration cannot be saved");
  const auto again = fieldrig::stereo::loadStereoCalibration(scratch);
  check(static_cast<bool>(again), "a saved calibration does not load again");
  const std::string differs = difference(c, *again);
  check(differs.empty(), "a saved calibration reads back otherwise: " + differs);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (fieldrig::fuzz::seedFolder() == nullptr)
    return 0;
  const fieldrig::fuzz::FuzzFolder folder("calibration_yaml_seeds");
  fieldrig::cloud::RigCalibration rig;
  for (int i = 0; i < 2; ++i) {
    fieldrig::cloud::HeadCalibration head;
    head.name = kHeads[i];
    head.stereo = fieldrig::stereo::idealStereoCalibration(1400, cv::Size(1624, 1224), 0.12);
    head.to_bottom(1, 3) = 0.3 * i;
    rig.heads.push_back(head);
  }
  check(static_cast<bool>(fieldrig::cloud::saveRigCalibration(rig, folder.path())),
        "the seed calibration cannot be saved");
  const std::string sep(fieldrig::fuzz::kFileSeparator);
  const std::string intrinsics = readText(folder.path() / "bottom" / "intrinsics.yml");
  const std::string extrinsics = readText(folder.path() / "bottom" / "extrinsics.yml");
  fieldrig::fuzz::writeSeed(
      "rig", intrinsics + sep + extrinsics + sep + readText(folder.path() / "rig.yml"));
  // OpenCV's own sample (no image size: the rig refuses it, the head loader takes it).
  if (const char* data = std::getenv("FIELDRIG_SHARED_DATA_DIR")) {
    const fs::path sample = fs::path(data) / "stereo" / "opencv_calib" / "intrinsics.yml";
    if (fs::is_regular_file(sample))
      fieldrig::fuzz::writeSeed("opencv_sample", readText(sample) + sep + extrinsics + sep);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  static const fieldrig::fuzz::FuzzFolder folder("calibration_yaml");
  const std::string_view data(reinterpret_cast<const char*>(bytes), size);
  const fs::path& dir = folder.path();
  for (const char* head : kHeads) {
    folder.write(std::string(head) + "/intrinsics.yml", fieldrig::fuzz::part(data, 0));
    folder.write(std::string(head) + "/extrinsics.yml", fieldrig::fuzz::part(data, 1));
  }
  folder.write("rig.yml", fieldrig::fuzz::part(data, 2));

  const auto stereo = fieldrig::stereo::loadStereoCalibration(dir / "bottom");
  if (!stereo) {
    check(startsWith(stereo.error().message, (dir / "bottom").string()),
          "a head calibration error that does not name the file: " + stereo.error().message);
  } else {
    checkStereo(*stereo, dir / "saved_head");
  }

  const auto rig = fieldrig::cloud::loadRigCalibration(dir);
  if (!rig) {
    const std::string& message = rig.error().message;
    // "FILE: …" or "FILE:LINE: …".
    const bool names_a_file = message.find("rig.yml:") != std::string::npos ||
                              message.find("intrinsics.yml:") != std::string::npos ||
                              message.find("extrinsics.yml:") != std::string::npos;
    check(names_a_file, "a rig calibration error that does not name the file: " + message);
    return 0;
  }
  check(!rig->heads.empty(), "a rig without heads was accepted");
  for (const fieldrig::cloud::HeadCalibration& head : rig->heads)
    check(!head.stereo.image_size.empty(), "a rig head without the cameras' size was accepted");
  check(static_cast<bool>(fieldrig::stereo::checkRotation(rig->plot_rotation)),
        "a plot rotation that is not a rotation was accepted");
  for (const fieldrig::cloud::HeadCalibration& head : rig->heads) {
    check(!head.name.empty() && head.name != "." && head.name != ".." &&
              head.name.find_first_of(std::string("/\\\0", 3)) == std::string::npos,
          "a head name that is a path was accepted: " + head.name);
  }
  const fs::path saved = dir / "saved_rig";
  fs::remove_all(saved);
  check(static_cast<bool>(fieldrig::cloud::saveRigCalibration(*rig, saved)),
        "a loaded rig calibration cannot be saved");
  const auto again = fieldrig::cloud::loadRigCalibration(saved);
  check(again && again->heads.size() == rig->heads.size() &&
            again->pixel_format == rig->pixel_format &&
            cv::norm(cv::Mat(again->plot_rotation), cv::Mat(rig->plot_rotation), cv::NORM_INF) == 0,
        "a saved rig calibration reads back otherwise");
  for (std::size_t i = 0; i < rig->heads.size(); ++i) {
    check(again->heads[i].name == rig->heads[i].name &&
              difference(again->heads[i].stereo, rig->heads[i].stereo).empty(),
          "a saved rig head reads back otherwise");
  }
  return 0;
}
