// A recorded FrameSet's frames as the cloud pipeline takes them, per head of the rig, and where a
// session's calibration is. Shared by `fieldrig cloud`, `fieldrig process` and the stem tool.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/result.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {

// The frames of set `set_index`, in the order of rig.heads. A camera that is absent, not ok or
// unreadable leaves its image empty and says why in `problems` (the cloud then flags the head);
// only a set that does not exist is an error.
core::Result<std::vector<cloud::HeadFrames>> framesFromSession(
    const recording::SessionReader& reader, std::uint64_t set_index, const cloud::RigConfig& rig,
    std::vector<std::string>& problems);

// `explicit_dir` when given, else the session's calibration reference named "calib_dir"
// (relative to the session folder unless absolute); nullopt when neither exists.
std::optional<std::filesystem::path> sessionCalibrationDir(const std::string& explicit_dir,
                                                           const recording::SessionReader& reader);

// The rig of `explicit_dir`, else of the session's calib_dir reference (`reader` may be null when
// the frames come from image files). The error says what to give, or names the file and field.
core::Result<cloud::RigConfig> loadRigFor(const std::string& explicit_dir,
                                          const recording::SessionReader* reader);

}  // namespace fieldrig::tools
