#include "fieldrig/daemon/head_frames.h"

#include <algorithm>
#include <span>

#include "fieldrig/core/rig_layout.h"
#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/preprocess.h"

#include <opencv2/imgcodecs.hpp>

namespace fieldrig::daemon {
namespace {

// The head images in the order of rig.heads: `fill(camera name, image, pixel format)` loads one
// camera's image, or leaves it empty and says why in the caller's problems.
template <typename Fill>
std::vector<cloud::HeadFrames> perHead(const cloud::RigCalibration& rig, Fill fill) {
  std::vector<cloud::HeadFrames> frames;
  for (const cloud::HeadCalibration& head : rig.heads) {
    cloud::HeadFrames head_frames;
    for (const auto& [side, image] : {std::pair{core::CameraSide::kLeft, &head_frames.left},
                                      std::pair{core::CameraSide::kRight, &head_frames.right}}) {
      fill(core::RigLayout::cameraName(head.name, side), *image, head_frames.pixel_format);
    }
    frames.push_back(std::move(head_frames));
  }
  return frames;
}

// The set's recorded left frame of each head (null where not recorded), in the order of rig.heads.
std::vector<const recording::IndexedFrame*> leftFrames(const recording::IndexedSet& set,
                                                       const cloud::RigCalibration& rig) {
  std::vector<const recording::IndexedFrame*> frames;
  for (const cloud::HeadCalibration& head : rig.heads) {
    const std::string camera = core::RigLayout::cameraName(head.name, core::CameraSide::kLeft);
    const auto it = std::find_if(set.frames.begin(), set.frames.end(),
                                 [&](const auto& f) { return f.camera_name == camera; });
    const bool recorded = it != set.frames.end() && it->status == recording::FrameStatus::kOk &&
                          !it->file.empty() && it->file.ends_with(".pgm");
    frames.push_back(recorded ? &*it : nullptr);
  }
  return frames;
}

std::vector<std::string> truthSuffixes(TruthMaps maps) {
  switch (maps) {
    case TruthMaps::kNone:
      return {};
    case TruthMaps::kDepth:
      return {".depth.pfm"};
    case TruthMaps::kDepthAndVegetation:
      return {".depth.pfm", ".veg.png"};
  }
  return {};
}

}  // namespace

std::filesystem::path truthMapPath(const recording::SessionReader& reader,
                                   const recording::IndexedFrame& frame,
                                   const std::string& suffix) {
  std::string file = frame.file;
  if (file.ends_with(".pgm"))
    file.resize(file.size() - 4);
  return reader.dir() / (file + suffix);
}

core::Result<void> addTruthMaps(const recording::SessionReader& reader, std::uint64_t set_index,
                                const cloud::RigCalibration& rig, TruthMaps maps,
                                std::vector<cloud::HeadFrames>& frames,
                                std::vector<std::string>& problems) {
  const recording::IndexedSet* set = reader.bySetIndex(set_index);
  if (!set)
    return core::Error{reader.dir().string() + ": no set with index " + std::to_string(set_index)};
  const std::vector<const recording::IndexedFrame*> lefts = leftFrames(*set, rig);
  for (std::size_t i = 0; i < lefts.size() && i < frames.size(); ++i) {
    if (!lefts[i])
      continue;
    // A map of another size than the camera's is of another rig or damaged: it would score, or
    // stand in for, pixels it does not describe.
    const cv::Size camera_size = rig.heads[i].stereo.image_size;
    auto sizeMatches = [&](const cv::Mat& map, const std::filesystem::path& path) {
      if (camera_size.empty() || map.size() == camera_size)
        return true;
      problems.push_back(path.string() + ": truth map is " + std::to_string(map.cols) + "x" +
                         std::to_string(map.rows) + " but the " + rig.heads[i].name +
                         " head's calibration is for " + std::to_string(camera_size.width) + "x" +
                         std::to_string(camera_size.height) + ": left out");
      return false;
    };
    for (const std::string& suffix : truthSuffixes(maps)) {
      const std::filesystem::path path = truthMapPath(reader, *lefts[i], suffix);
      if (suffix == ".depth.pfm") {
        core::Result<cv::Mat> depth = stereo::readPfm(path);
        if (!depth)
          problems.push_back("truth depth map " + depth.error().message);
        else if (sizeMatches(*depth, path))
          frames[i].left_truth_depth = std::move(*depth);
        continue;
      }
      cv::Mat mask;
      try {
        mask = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
      } catch (const cv::Exception&) {
        mask.release();
      }
      if (mask.empty())
        problems.push_back(path.string() + ": truth vegetation mask missing or unreadable");
      else if (sizeMatches(mask, path))
        frames[i].left_truth_vegetation = std::move(mask);
    }
  }
  return {};
}

core::Result<void> checkTruthMaps(const recording::SessionReader& reader,
                                  const cloud::RigCalibration& rig, TruthMaps maps) {
  for (const recording::IndexedSet& set : reader.sets()) {
    for (const recording::IndexedFrame* left : leftFrames(set, rig)) {
      if (!left)
        continue;
      for (const std::string& suffix : truthSuffixes(maps)) {
        const std::filesystem::path path = truthMapPath(reader, *left, suffix);
        std::error_code error;
        if (!std::filesystem::is_regular_file(path, error)) {
          return core::Error{path.string() +
                             ": no truth map (only sessions rendered by `fieldrig simulate` with "
                             "the mesh renderer have them)"};
        }
      }
    }
  }
  return {};
}

core::Result<std::vector<cloud::HeadFrames>> headFramesFromRecording(
    const recording::SessionReader& reader, std::uint64_t set_index,
    const cloud::RigCalibration& rig, std::vector<std::string>& problems) {
  const recording::IndexedSet* set = reader.bySetIndex(set_index);
  if (!set) {
    return core::Error{reader.dir().string() + ": no set with index " + std::to_string(set_index) +
                       " (" + std::to_string(reader.sets().size()) + " sets)"};
  }
  return perHead(rig, [&](const std::string& camera, cv::Mat& image, core::PixelFormat& format) {
    const auto it = std::find_if(set->frames.begin(), set->frames.end(),
                                 [&](const auto& f) { return f.camera_name == camera; });
    if (it == set->frames.end()) {
      problems.push_back(camera + ": not in set " + std::to_string(set_index));
      return;
    }
    if (it->status != recording::FrameStatus::kOk || it->file.empty()) {
      problems.push_back(camera + ": recorded as " + std::string(recording::toString(it->status)) +
                         (it->reason.empty() ? "" : " (" + it->reason + ")"));
      return;
    }
    auto loaded = reader.loadFrame(*it);
    if (!loaded) {
      problems.push_back(loaded.error().message);
      return;
    }
    image = cv::Mat(loaded->height, loaded->width, CV_8UC1, loaded->pixels.data()).clone();
    format = it->pixel_format;
  });
}

core::Result<std::vector<cloud::HeadFrames>> headFramesFromImageFiles(
    const std::vector<std::string>& files, const cloud::RigCalibration& rig) {
  if (files.size() != 2 * rig.heads.size()) {
    return core::Error{std::to_string(files.size()) + " image files for a rig of " +
                       std::to_string(rig.heads.size()) + " heads, which needs " +
                       std::to_string(2 * rig.heads.size())};
  }
  std::vector<cloud::HeadFrames> frames;
  for (std::size_t i = 0; i < rig.heads.size(); ++i) {
    cloud::HeadFrames head;
    head.pixel_format = rig.pixel_format;
    for (const auto& [file, image] :
         {std::pair{&files[2 * i], &head.left}, std::pair{&files[2 * i + 1], &head.right}}) {
      core::Result<cv::Mat> read = stereo::readFrameImage(*file);
      if (!read)
        return read.error();
      *image = std::move(*read);
    }
    frames.push_back(std::move(head));
  }
  return frames;
}

core::Result<void> checkCalibratedHeadsHaveCameras(const cloud::RigCalibration& rig,
                                                   const core::RigLayout& layout) {
  const auto listed = [](const auto& names) {
    std::string out;
    for (const std::string& name : names)
      out += (out.empty() ? "" : ", ") + name;
    return out;
  };
  std::vector<std::string> calibrated;
  for (const cloud::HeadCalibration& head : rig.heads)
    calibrated.push_back(head.name);
  for (const std::string& head : calibrated) {
    if (std::find(layout.heads.begin(), layout.heads.end(), head) == layout.heads.end()) {
      return core::Error{"cameras.heads (" + listed(layout.heads) + ") has no head '" + head +
                         "', which the calibration has (" + listed(calibrated) +
                         "): every plot would go without it"};
    }
  }
  return {};
}

std::vector<cloud::HeadFrames> headFramesFromFrameSet(const core::FrameSet& set,
                                                      const std::vector<std::string>& camera_names,
                                                      const cloud::RigCalibration& rig,
                                                      std::vector<std::string>& problems) {
  return perHead(rig, [&](const std::string& camera, cv::Mat& image, core::PixelFormat& format) {
    const auto it = std::find(camera_names.begin(), camera_names.end(), camera);
    const auto index = static_cast<std::size_t>(it - camera_names.begin());
    if (it == camera_names.end() || index >= set.camera_count) {
      problems.push_back(camera + ": not in the rig");
      return;
    }
    const core::Frame& frame = set.frames[index];
    if (frame.metadata.status != core::FrameStatus::kOk || !frame.buffer) {
      problems.push_back(camera + ": " + std::string(recording::toString(frame.metadata.status)));
      return;
    }
    const std::span<std::uint8_t> bytes = frame.buffer.bytes();
    const std::size_t stride = frame.metadata.stride ? frame.metadata.stride : frame.metadata.width;
    if (bytes.size() < stride * frame.metadata.height) {
      problems.push_back(camera + ": frame shorter than its size says");
      return;
    }
    // A header over the pool's buffer: the matcher only reads it (it debayers into images of its
    // own), and the set holds the buffer until processing is done.
    image = cv::Mat(static_cast<int>(frame.metadata.height), static_cast<int>(frame.metadata.width),
                    CV_8UC1, bytes.data(), stride);
    format = frame.metadata.format;
  });
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

core::Result<cloud::RigCalibration> loadRigFor(const std::string& explicit_dir,
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
  return cloud::loadRigCalibration(*dir);
}

}  // namespace fieldrig::daemon
