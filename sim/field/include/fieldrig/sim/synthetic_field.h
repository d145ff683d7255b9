// Synthetic fields for hardware-free runs of the whole system.
//
// The ideal rig: three Grasshopper-like heads (1624×1224, f 1350 px, 0.12 m baseline) stacked at
// 0.55, 1.45 and 2.35 m above the soil, looking level at the row 1.2 m away, named by the rig
// layout (bottom, middle, top). Synthetic row plots (sim/plots) are rendered into its six raw
// Bayer frames per plot and recorded as the daemon records a set, with their truth: the trait
// definitions applied to the noise-free visible plant geometry.
//
// A synthetic field adds the drive: a serpentine RTK drive over a field plan (DriveSimulator),
// its imaging-location map, and a session with one rendered plot per location in the order the
// drive reaches them, so that `fieldrigd replay` with the sim cameras replaying that session
// records plot k at the k-th triggered location. The truth is keyed by location id.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/gps/trigger_planner.h"
#include "fieldrig/sim/plot_generator.h"

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

// The plots' heights run linearly from height_min_m to height_max_m over the plots; every third
// plot misses a plant, every third (offset by one) has an abnormally tall one.
struct PlotSeries {
  int count = 3;
  std::uint32_t seed = 1;
  double height_min_m = 1.4;
  double height_max_m = 2.4;
};
PlotSpec plotSpec(const PlotSeries& series, int index);

struct RecordedPlot {
  std::string location_id;  // the map's id (or plot-N without a map)
  std::uint64_t set_index = 0;
  PlotSpec spec;
};

// Records `locations.size()` rendered plots (plot i at locations[i]) into a new session folder,
// with the ideal rig's calibration in `calib_dir` (referenced from the session as calib_dir) and
// one truth line per plot in SESSION/truth.jsonl. `progress` is told of each plot written.
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
};

struct FieldFiles {
  std::filesystem::path nmea, map, session, calibration, truth;
  std::size_t locations = 0;
  std::size_t plots = 0;  // rendered: one per location the drive triggers
};

// DIR/drive.nmea, DIR/map.csv, DIR/source-session (with calib/ and truth.jsonl), DIR/truth.jsonl.
core::Result<FieldFiles> writeSyntheticField(
    const std::filesystem::path& dir, const FieldSpec& spec,
    const std::function<void(const RecordedPlot&)>& progress = {});

}  // namespace fieldrig::sim
