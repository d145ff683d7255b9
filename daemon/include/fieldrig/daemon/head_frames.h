// The adapters in front of the plot processor: a recorded set, a live FrameSet, or image files, as
// the per-head images it takes (in the order of the calibration's heads), and where a session's
// calibration is. Cameras are found by the rig layout's names ("bottom_left"); one that is
// absent, not ok or unreadable leaves its image empty and says why in `problems` (the cloud then
// leaves the head out and names it).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/frame.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::daemon {

// The frames of recorded set `set_index`; only a set that does not exist is an error.
core::Result<std::vector<cloud::HeadFrames>> headFramesFromRecording(
    const recording::SessionReader& reader, std::uint64_t set_index,
    const cloud::RigCalibration& rig, std::vector<std::string>& problems);

// What of the simulator's truth maps the left cameras' frames take along (sim/field writes them
// beside each frame of a rendered session: frames/SSSSSS_C_NAME.depth.pfm and .veg.png for .pgm).
enum class TruthMaps { kNone, kDepth, kDepthAndVegetation };

// Where the truth map with `suffix` (".depth.pfm", ".veg.png") of a recorded frame is.
std::filesystem::path truthMapPath(const recording::SessionReader& reader,
                                   const recording::IndexedFrame& frame, const std::string& suffix);

// Adds the truth maps of each head's left camera in set `set_index` to `frames` (in the order of
// rig.heads). A head whose left frame was not recorded is skipped (it has no image either). A map
// that is missing or unreadable is left out and named in `problems` (the head then goes without
// it: in a truth depth mode it gives no points, and it is not scored); only a set that does not
// exist is an error.
core::Result<void> addTruthMaps(const recording::SessionReader& reader, std::uint64_t set_index,
                                const cloud::RigCalibration& rig, TruthMaps maps,
                                std::vector<cloud::HeadFrames>& frames,
                                std::vector<std::string>& problems);

// Whether every recorded left frame of the session has its truth maps on disk, checked before
// processing starts; the error names the first missing file and says where they come from.
core::Result<void> checkTruthMaps(const recording::SessionReader& reader,
                                  const cloud::RigCalibration& rig, TruthMaps maps);

// The live path's cameras against the calibration: a calibrated head that `layout` (the
// configuration's cameras.heads) has no cameras for would be left out of every plot. The error
// names the head and both lists.
core::Result<void> checkCalibratedHeadsHaveCameras(const cloud::RigCalibration& rig,
                                                   const core::RigLayout& layout);

// The frames of a live set whose camera c is named camera_names[c]. The images point into the
// set's pool buffers (no copy): keep the set alive while they are used.
std::vector<cloud::HeadFrames> headFramesFromFrameSet(const core::FrameSet& set,
                                                      const std::vector<std::string>& camera_names,
                                                      const cloud::RigCalibration& rig,
                                                      std::vector<std::string>& problems);

// The frames of image files (8-bit raw in the rig's pixel format, or BGR), two per head: L1, R1,
// L2, R2, … in the order of the rig's heads. Unlike a recorded set, every file must be there: the
// error names the one that cannot be read, or says how many files the rig needs.
core::Result<std::vector<cloud::HeadFrames>> headFramesFromImageFiles(
    const std::vector<std::string>& files, const cloud::RigCalibration& rig);

// `explicit_dir` when given, else the session's calibration reference named "calib_dir"
// (relative to the session folder unless absolute); nullopt when neither exists.
std::optional<std::filesystem::path> sessionCalibrationDir(const std::string& explicit_dir,
                                                           const recording::SessionReader& reader);

// The rig of `explicit_dir`, else of the session's calib_dir reference (`reader` may be null when
// the frames come from image files). The error says what to give, or names the file and field.
core::Result<cloud::RigCalibration> loadRigFor(const std::string& explicit_dir,
                                               const recording::SessionReader* reader);

}  // namespace fieldrig::daemon
