// Synthetic fields for hardware-free runs of the whole system.
//
// The ideal rig: three Grasshopper-like heads (1624×1224, f 1350 px, 0.12 m baseline) stacked at
// 0.55, 1.45 and 2.35 m above the soil, looking level at the row 1.2 m away, named by the rig
// layout (bottom, middle, top). Synthetic row plots (sim/plots) are rendered into its six raw
// Bayer frames per plot and recorded as the daemon records a set, with their truth: the trait
// definitions applied to the noise-free visible plant geometry.
//
// Two renderers make the frames: `kSplat` (sim/rig_render: the generator's surface samples
// splatted through distortion-free pinhole cameras, the ideal rig) and `kMesh` (sim/mesh_render:
// triangle-mesh plants at a growth stage, ray-cast with Embree through the calibrated rig's
// distorted cameras, with sun, shadows, sky, sensor noise and per-pixel truth beside each frame).
//
// A synthetic field adds the drive: a serpentine RTK drive over a field plan (DriveSimulator),
// its imaging-location map, and a session with one rendered plot per location in the order the
// drive reaches them, so that `fieldrigd replay` with the sim cameras replaying that session
// records plot k at the k-th triggered location. The truth is keyed by location id.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/gps/trigger_planner.h"
#include "fieldrig/sim/mesh_scene.h"
#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::sim {

// The ideal heads' optics: Grasshopper-like cameras, distortion-free.
inline constexpr double kIdealFocalPx = 1350.0;
inline constexpr double kIdealBaselineM = 0.12;
inline constexpr int kIdealImageWidth = 1624;
inline constexpr int kIdealImageHeight = 1224;

// Where the ideal rig's heads sit (bottom, middle, top): height above the soil, and the tilt of
// each head down towards the soil about its camera x axis. The default is the tractor's rig.
struct IdealRigGeometry {
  std::vector<double> head_heights_m{0.55, 1.45, 2.35};
  std::vector<double> head_tilts_down_deg{0, 0, 0};
};

// The ideal rig's calibration (rig.yml and the heads' files, as `fieldrig calibrate` writes them).
cloud::RigCalibration idealRig(const IdealRigGeometry& geometry = {});

// The same rig as a calibration of real cameras finds it: each camera with its own focal length,
// principal point and 6 mm lens distortion (k1 about -0.12, k2 about 0.09, small tangential
// terms), the right camera slightly turned and off the baseline, rectified with stereoRectify.
// The mesh renderer images through exactly these files. Deterministic (no seed: one rig).
cloud::RigCalibration calibratedRig(const IdealRigGeometry& geometry = {});

enum class SceneRenderer { kSplat, kMesh };
std::string_view rendererName(SceneRenderer renderer);
std::optional<SceneRenderer> parseRenderer(std::string_view name);

// The plots' heights run linearly from height_min_m to height_max_m over the plots; every third
// plot misses a plant, every third (offset by one) has an abnormally tall one.
//
// With the mesh renderer the plots are split into consecutive blocks, one per entry of `stages`
// (in order), and within a block the heights run over the stage's range (stageHeights) unless
// `stage_heights` is false, when height_min_m…height_max_m is used for every block.
struct PlotSeries {
  int count = 3;
  std::uint32_t seed = 1;
  double height_min_m = 1.4;
  double height_max_m = 2.4;
  SceneRenderer renderer = SceneRenderer::kSplat;
  std::vector<GrowthStage> stages{GrowthStage::kMid};
  bool stage_heights = true;
  bool truth_maps = true;  // mesh: depth, plot, plant and vegetation maps beside each frame
  // The trait definitions the truth lines are computed with: those the session will be processed
  // with (`--traits-config`), so that truth and measurement define height and width alike.
  traits::TraitsOptions truth_traits;
};
PlotSpec plotSpec(const PlotSeries& series, int index);
// The mesh scene of plot `index`: stage and height as above, 3 m plots of 20 plants at 0.15 m
// with 1 m alleys (a plant missing or abnormally tall as in plotSpec, near the plot centre),
// neighbouring plots of other genotypes, two rows behind, soil sloped up to 2° either way, the row
// 1.15–1.25 m from the cameras (the tractor's distance to the row varies).
MeshPlotSpec meshPlotSpec(const PlotSeries& series, int index);
// The range error of a series, naming the field; nullopt when usable.
std::optional<std::string> validatePlotSeries(const PlotSeries& series);

struct RecordedPlot {
  std::string location_id;  // the map's id (or plot-N without a map)
  std::uint64_t set_index = 0;
  PlotSpec spec;                     // splat renderer (plant_height_m and seed for both)
  std::optional<MeshPlotSpec> mesh;  // mesh renderer
  double render_seconds = 0.0;       // the six frames (mesh: scene build, frames, truth maps)
  double truth_seconds = 0.0;        // the truth by the definitions
};

// Records `locations.size()` rendered plots (plot i at locations[i]) into a new session folder,
// with the rig's calibration in `calib_dir` (referenced from the session as calib_dir; the ideal
// rig for the splat renderer, calibratedRig for the mesh renderer) and one truth line per plot in
// SESSION/truth.jsonl. `progress` is told of each plot written.
//
// The mesh renderer also writes, beside each frame frames/SSSSSS_C_NAME.pgm:
//   SSSSSS_C_NAME.depth.pfm   float, metres: z of the surface in that camera's own (unrectified)
//                             frame through the pixel's centre; 0 where the ray meets only sky
//   SSSSSS_C_NAME.plot.png    8-bit plot code (0 soil or sky, 1 this plot, 2 the plot before it
//                             along the row, 3 the plot after it, 4 rows behind); the truth line's
//                             plot_codes names them
//   SSSSSS_C_NAME.plant.png   16-bit plant id (0 none); the truth line's plants list the imaged
//                             plot's by id
//   SSSSSS_C_NAME.veg.png     8-bit vegetation mask: 255 where the centre ray meets a plant
//                             (of any plot, or the distant canopy band), else 0
// and adds the mesh truth to each truth line (mesh_truth.h).
core::Result<std::vector<RecordedPlot>> recordSyntheticPlots(
    const std::filesystem::path& session_dir, const std::filesystem::path& calib_dir,
    const PlotSeries& series, const std::vector<std::string>& locations,
    const std::function<void(const RecordedPlot&)>& progress = {});

struct FieldSpec {
  int plots = 12;
  int rows = 2;
  std::uint32_t seed = 1;
  double height_min_m = 1.0;
  double height_max_m = 2.6;
  double speed_mps = 2.0;
  double position_noise_m = 0.01;
  gps::TriggerChainOptions triggers;  // what the replay will use, to order the plots
  SceneRenderer renderer = SceneRenderer::kSplat;
  std::vector<GrowthStage> stages{GrowthStage::kMid};  // mesh: as PlotSeries
  bool stage_heights = true;
  bool truth_maps = true;
  traits::TraitsOptions truth_traits;  // as PlotSeries
};

struct FieldFiles {
  std::filesystem::path nmea, map, session, calibration, truth;
  std::size_t locations = 0;
  std::size_t plots = 0;  // rendered: one per location the drive triggers
};

// The plot series of a field whose drive triggers `plots` locations.
PlotSeries fieldPlotSeries(const FieldSpec& spec, int plots);

// Why `dir` cannot take a new field (an empty path, something that is not a folder, a folder
// that already holds files), or nullopt: a field is written whole into a new or empty folder,
// never mixed into an earlier one.
std::optional<std::string> checkFieldFolder(const std::filesystem::path& dir);

// DIR/drive.nmea, DIR/map.csv, DIR/source-session (with calib/ and truth.jsonl), DIR/truth.jsonl.
// The spec and the folder (checkFieldFolder) are checked before anything is written. The field is
// written into a hidden folder beside DIR and renamed to DIR when it is whole; on an error that
// folder is removed, so nothing half-written is left.
core::Result<FieldFiles> writeSyntheticField(
    const std::filesystem::path& dir, const FieldSpec& spec,
    const std::function<void(const RecordedPlot&)>& progress = {});

}  // namespace fieldrig::sim
