// Truth of a mesh plot by the trait definitions: the imaged plot's plant surfaces sampled densely
// (area-weighted, ~3 mm apart), each sample kept when some camera of the rig sees it (inside its
// distorted image, nothing of the scene in between: Embree occlusion rays), and sim/plots'
// plotTruth run on those samples with the soil level under the stems as the ground. This is
// what the existing synthetic truth means (the definitions on the noise-free visible geometry),
// now computed from the meshes the cameras were rendered from.
//
// Plants taller than the field of view: the heads see up to about `view_top_m` at the row
// (~2.9 m for the default rig), so `height_m` and the other traits are those of the geometry the
// cameras can see: what a perfect stereo pipeline would report. The same definitions on every
// sample of the plot in the same stretch of row, seen or not (`full`), and each plant's
// agronomic height say how much lies beyond the view.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fieldrig/sim/mesh_camera.h"
#include "fieldrig/sim/mesh_renderer.h"
#include "fieldrig/sim/plot_truth.h"

namespace fieldrig::sim {

struct MeshTruthOptions {
  double sample_spacing_m = 0.003;
  std::uint32_t seed = 1;
  traits::TraitsOptions traits;
};

struct MeshPlotTruth {
  PlotCloud visible;       // truth part only: visible plant samples, ground, plants
  PlotTruthTraits traits;  // the definitions on the visible samples
  PlotTruthTraits full;    // on all samples within the visible samples' stretch of row
  // On the samples both cameras of some head see: what a perfect stereo matcher can place. The
  // difference to `traits` is plant that only one camera of a pair sees (the ends of the row
  // within one camera's view, the sides of leaves the other camera sees edge-on).
  PlotTruthTraits stereo_view;
  double stereo_view_plant_area_m2 = 0.0;  // of those samples (visible.truth's counterpart)
  std::size_t samples = 0;                 // of the imaged plot's plants, before visibility
  double view_top_m = 0.0;    // above the ground: the top camera's top-centre ray at the row
  bool exceeds_view = false;  // some plant of the imaged plot reaches above view_top_m
};

MeshPlotTruth meshPlotTruth(const MeshRenderScene& scene, const std::vector<MeshCamera>& cameras,
                            const MeshTruthOptions& options);

// The truth line's mesh fields (added to the fields every synthetic truth line has): traits,
// areas, the full-geometry and stereo-view traits, the view limit and every plant of the imaged
// plot with its stem sections.
nlohmann::ordered_json meshTruthJson(const MeshPlotTruth& truth, const MeshScene& scene);

}  // namespace fieldrig::sim
