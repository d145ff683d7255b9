#include "fieldrig/cloud/cloud_options.h"

#include <cmath>

namespace fieldrig::cloud {

const char* toString(DepthSource source) {
  switch (source) {
    case DepthSource::kTruth:
      return "truth";
    case DepthSource::kTruthWhereMatched:
      return "truth-where-matched";
    case DepthSource::kStereo:
      break;
  }
  return "stereo";
}

core::Result<void> validate(const CloudOptions& options) {
  using core::Error;
  // Written as negations so that NaN fails every check.
  if (!(options.scale > 0 && options.scale <= 1))
    return Error{"scale " + std::to_string(options.scale) + " is not in (0, 1]"};
  if (auto matcher = stereo::validate(options.matcher); !matcher)
    return Error{"matcher." + matcher.error().message};
  if (!(options.min_depth_m >= 0 && options.max_depth_m > options.min_depth_m &&
        std::isfinite(options.max_depth_m))) {
    return Error{"the depth crop must satisfy 0 <= min_depth_m (" +
                 std::to_string(options.min_depth_m) + ") < max_depth_m (" +
                 std::to_string(options.max_depth_m) + ")"};
  }
  if (!(options.edge_max_jump_px >= 0 && std::isfinite(options.edge_max_jump_px))) {
    return Error{"edge_max_jump_px " + std::to_string(options.edge_max_jump_px) +
                 " is not a finite number >= 0 (0 keeps depth edges)"};
  }
  return {};
}

}  // namespace fieldrig::cloud
