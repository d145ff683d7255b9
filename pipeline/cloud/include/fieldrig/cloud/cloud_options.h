// How a set of head images becomes a cloud: the matching resolution, the matcher, the depth crop
// and the depth-edge filter. Processing choices, set in the configuration (pipeline.cloud and
// pipeline.matcher); the rig's geometry is cloud::RigCalibration.
#pragma once

#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/stereo/matcher.h"

namespace fieldrig::cloud {

// Where each head's depth comes from: its stereo pair (always, on the rig), or the simulator's
// rendered truth depth of its left camera (stereo/truth_depth.h), which runs the same chain after
// matching on perfect disparities: `fieldrig process --depth-source truth`, to tell what stereo
// costs from what fusion, crop and traits cost. kTruthWhereMatched runs stereo and then puts the
// truth's disparity on exactly the pixels stereo matched (none elsewhere): stereo's coverage with
// no depth error, which splits what stereo costs into the pixels it leaves out and the depth it
// gets wrong. Not a configuration key: no real camera has it.
enum class DepthSource { kStereo, kTruth, kTruthWhereMatched };

const char* toString(DepthSource source);

struct CloudOptions {
  double scale = 0.5;  // matching resolution / camera resolution, in (0, 1]
  // The disparity search range at matching resolution is matcher.[min_disparity, min + num).
  // With f ≈ 675 px and B = 0.12 m at 812×612, 0.8–1.7 m plants are 101–48 px.
  stereo::MatcherOptions matcher;
  double max_depth_m = 1.7;  // plot-frame z beyond this is a background row: cropped
  double min_depth_m = 0.2;  // closer than this is not a plant (mismatches near the lens)
  // Pixels on a depth edge — whose 3×3 neighbourhood spans more than this many pixels of
  // disparity — are not reprojected, meant for the blend of foreground and background that lands
  // as "flying" points between a leaf and what is behind it. 0 (the default) keeps them: on three
  // 24-plot rendered fields (bench/attribution_bench.py, seeds 11-13) 2 px dropped mostly real
  // leaf edges and tips. With rendered truth depth it cost 1.8 cm of width (mean abs 2.7 → 4.5
  // cm, seed 11). From stereo, turned off, the width's mean abs error on the plots inside the
  // view fell 0.7-1.3 cm on every field against both truths (what any camera sees, what both
  // cameras of a head see) and its worst nowhere rose; points > 3 cm off the surfaces went from
  // 7.8-10.1 % to 8.8-11.1 %.
  double edge_max_jump_px = 0.0;
  // With edge_max_jump_px > 0: drop only the far side of each such jump (a pixel with a
  // neighbour more than the jump nearer): the blend and the background beside a leaf go, the
  // leaf's own edge pixels stay. Off: both sides go, which also removes the edges of every leaf,
  // its tips included.
  bool edge_keep_near_side = false;
  DepthSource depth_source = DepthSource::kStereo;
};

// Why `options` cannot be used (naming the field), or nothing.
core::Result<void> validate(const CloudOptions& options);

}  // namespace fieldrig::cloud
