#include "commands/session_frames.h"

#include <algorithm>

namespace fieldrig::tools {

core::Result<std::vector<cloud::HeadFrames>> framesFromSession(
    const recording::SessionReader& reader, std::uint64_t set_index, const cloud::RigConfig& rig,
    std::vector<std::string>& problems) {
  const recording::IndexedSet* set = reader.bySetIndex(set_index);
  if (!set) {
    return core::Error{reader.dir().string() + ": no set with index " + std::to_string(set_index) +
                       " (" + std::to_string(reader.sets().size()) + " sets)"};
  }
  std::vector<cloud::HeadFrames> frames;
  for (const cloud::HeadConfig& head : rig.heads) {
    cloud::HeadFrames head_frames;
    for (const auto& [camera, image] : {std::pair{head.leftCamera(), &head_frames.left},
                                        std::pair{head.rightCamera(), &head_frames.right}}) {
      const auto it = std::find_if(set->frames.begin(), set->frames.end(),
                                   [&](const auto& f) { return f.camera_name == camera; });
      if (it == set->frames.end()) {
        problems.push_back(camera + ": not in set " + std::to_string(set_index));
        continue;
      }
      if (it->status != recording::FrameStatus::kOk || it->file.empty()) {
        problems.push_back(camera + ": recorded as " +
                           std::string(recording::toString(it->status)) +
                           (it->reason.empty() ? "" : " (" + it->reason + ")"));
        continue;
      }
      auto loaded = reader.loadFrame(*it);
      if (!loaded) {
        problems.push_back(loaded.error().message);
        continue;
      }
      *image = cv::Mat(loaded->height, loaded->width, CV_8UC1, loaded->pixels.data()).clone();
      head_frames.pixel_format = it->pixel_format;
    }
    frames.push_back(std::move(head_frames));
  }
  return frames;
}

std::optional<std::filesystem::path> sessionCalibrationDir(const std::string& explicit_dir,
                                                           const recording::SessionReader& reader) {
  if (!explicit_dir.empty())
    return std::filesystem::path(explicit_dir);
  for (const recording::CalibrationReference& reference : reader.metadata().calibration) {
    if (reference.name == "calib_dir") {
      const std::filesystem::path path(reference.path);
      return path.is_absolute() ? path : reader.dir() / path;
    }
  }
  return std::nullopt;
}

core::Result<cloud::RigConfig> loadRigFor(const std::string& explicit_dir,
                                          const recording::SessionReader* reader) {
  std::optional<std::filesystem::path> dir;
  if (reader) {
    dir = sessionCalibrationDir(explicit_dir, *reader);
  } else if (!explicit_dir.empty()) {
    dir = std::filesystem::path(explicit_dir);
  }
  if (!dir) {
    return core::Error{
        "no calibration: give --calib DIR (or record the session with a "
        "calibration reference named calib_dir)"};
  }
  return cloud::loadRig(*dir);
}

}  // namespace fieldrig::tools
