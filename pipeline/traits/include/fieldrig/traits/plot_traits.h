// Plot traits from one fused side-view cloud: ground by template ICP, slices along the row,
// weighted-median height and width, VVI from per-slice convex hulls, VAI from a surface area.
// Section 2.3 of the paper (equations 1-9). All lengths in metres, plot frame x up, y along the
// row, z away from the camera. Pure computation: no I/O, thread-compatible.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace fieldrig::traits {

// How the surface area behind VAI is measured.
enum class AreaMethod {
  kDepthMap,     // 2.5D depth-map triangulation per camera-facing layer (fast; the default)
  kPaperMlsGpt,  // the paper: MovingLeastSquares + GreedyProjectionTriangulation (PCL)
  kNone,         // skip the area (VAI and total area are reported as 0 with area_computed false)
};

enum class OutlierMethod {
  kStatistical,      // PCL StatisticalOutlierRemoval (the paper)
  kVoxelNeighbours,  // removeSparseOutliers below
};

// An option of TraitsOptions outside its range: its key as the configuration names it, and what
// is wrong (the value and the allowed range), to be said after the key.
struct OptionsProblem {
  std::string key;      // "depth_map_cell_m"
  std::string message;  // "1e-09 is out of range [0.001, 1]"
};

struct TraitsOptions {
  // Camera frame (x right, y down, z forward) to plot frame: applied for camera-frame input.
  Eigen::Matrix3d camera_to_plot = (Eigen::Matrix3d() << 0, -1, 0, 1, 0, 0, 0, 0, 1).finished();
  double voxel_leaf_m = 0.01;
  // Outliers: the paper's PCL StatisticalOutlierRemoval, or (default, ~20x faster) a neighbour
  // count on the voxel grid: a voxel with fewer occupied cells among its 26 goes.
  OutlierMethod outlier_method = OutlierMethod::kVoxelNeighbours;
  int outlier_mean_k = 50;  // StatisticalOutlierRemoval neighbours
  double outlier_stddev_mul = 1.0;
  int outlier_min_neighbours = 2;
  // After the outlier filter: connected pieces (through the voxels' 26 neighbours) of fewer voxels
  // than this are dropped, whichever outlier method ran; 0 keeps them. Meant for mismatched depth
  // floating apart from the plants and soil. Off: on the 24-plot rendered field
  // (bench/mesh_field_bench.py, seed 11) most small pieces were real leaf; from 8 voxels on, the
  // far edge lost leaves and the width came out narrower than the truth (bias -6.1 to -7.3 cm).
  int min_piece_voxels = 0;
  double crop_z_max_m = 1.7;  // background rows beyond this depth are removed
  double crop_z_min_m = 0.0;
  double max_abs_coordinate_m = 1.0e4;  // beyond this float precision is worse than 1 mm
  // Ground: a right-angle plate (a strip toward the camera and one up the plant plane).
  double template_strip_m = 0.3;
  double template_step_m = 0.04;       // point spacing of the plate (the paper's: 0.01)
  double icp_target_leaf_m = 0.02;     // the registration target is voxelised to this
  double icp_coarse_distance_m = 0.3;  // the paper's correspondence distance
  double icp_fine_distance_m = 0.03;   // fine stage, so the plate cannot hang on leaves; 0: none
  int icp_iterations = 10;             // per stage
  double max_ground_tilt_deg = 15.0;   // a registration tilted further is rejected
  // The steepest ground the field and the rig's attitude allow (soil sloped up to 3 degrees, about
  // 1 of roll or pitch): a registration tilted further (furrows pull it) is turned back to this
  // tilt about its base-ground edge (quality.ground_tilt_limited); 0: no limit.
  double ground_tilt_limit_deg = 4.0;
  // A registration that moves the ground level further than this from the data's lowest dense
  // layer has slid up the plants: the data's layer is used instead (quality.ground_from_data_pose).
  double max_ground_shift_m = 0.05;
  double ground_margin_m = 0.01;  // points this close above the plate's ground go with it
  // The ground level is the soil where the stems stand, not the soil in front of the row: where a
  // planting ridge raises the row, the plate's soil strip settles between the ridge top and the
  // lower soil in front, up to its height below the stems. Points within this distance across the
  // row of the plate's base-ground edge and within max_ground_shift_m of its ground are
  // histogrammed by height; their densest layer (the soil seen between the stems) becomes the
  // ground (quality.ground_row_base_shift_m). 0: the plate's ground. On the 24-plot rendered field
  // (4 cm ridges) the plate's ground was up to 4.3 cm low on 1 plot of 24 from stereo and 6 from
  // rendered depth; with 0.05-0.12 every ground came within 0.7 cm.
  double row_base_band_m = 0.08;
  double ground_tilt_deg = 10.0;  // the paper's tilted plane about the base-ground edge
  // Slicing (equation 15): n = ceil(2 * row length / intra-row spacing) unless slices > 0.
  double row_length_m = 1.5;
  // Only plant points within ±row_length_m / 2 of the plot's location (y = 0) are the plot's.
  // Off: on the 24-plot rendered field (bench/mesh_field_bench.py, seed 11, the truth cropped
  // alike) width against what any camera sees stayed as it was (6.6 → 6.8 cm mean abs) and VVI got
  // worse (5.7 → 7.9 %); against what both cameras of a head see, width improved (5.7 → 4.8 cm on
  // the plots in view). An earlier "worse" (width 8.3 cm) was against an uncropped truth. On five
  // fields (75 in-view plots) it lines the slices up with the truth's: with the truth's own depth
  // the height came within 3 cm on 74 plots (off: 70; worst 7.7 to 3.2 cm) and the width on 45
  // (off: 40), but through stereo height and width stayed as they were (60 and 20 plots).
  bool crop_to_row_length = false;
  double intra_row_spacing_m = 0.15;
  int slices = 0;
  // Each slice's near and far edge (the width): its extreme point (0, the paper), or the quantile
  // this far in from it (0.02: the 2 % of the slice's points nearest and the 2 % furthest do not
  // count), so that a few mismatched voxels or one leaf tip cannot move the edge. It defines a
  // different, narrower width (0.02: 19 cm narrower on the rendered field's plants), so the truth
  // must take the same value (`fieldrig simulate --traits-config`); off, as the paper. Even so
  // compared, 0.02 comes out narrow on five rendered fields (bias -3.9 cm against the stereo-view
  // truth, 0: -0.9): stereo misses more of the far side than the truth, so the quantile cuts
  // deeper there. The top stays the slice's highest point: a quantile there made height worse
  // (2.2 to 4.0 cm).
  double slice_width_quantile = 0.0;
  // The width's near and far edges come from the slices whose middle lies within
  // ±width_band_m / 2 of the plot's location (y = 0); 0: every slice (the paper). Side-view
  // cameras see the near side of the canopy only where it is inside their view (the rig's: |y|
  // below 0.6 times the depth): toward the row's ends a slice's nearest point is where the view
  // ends, not where the leaves end, and the slices' near edges spread over up to 30 cm, so the
  // median moves with the slices' weights. Off: on five rendered fields (75 in-view plots, both
  // truth and processing with crop_to_row_length and the same band) 0.6 brought the width with
  // the truth's own depth within 3 cm on 60 plots against what any camera sees (0: 45) and made
  // it nearer the plants' whole canopy (mean error 9.7 to 3.9 cm), but through stereo it did not
  // help (7.0 to 7.7 cm mean, 20 plots within 3 cm either way; worst 18 to 21 cm): fewer slices
  // give less room for stereo's edge errors. 0.9 sat in between.
  double width_band_m = 0.0;
  double min_row_extent_m = 0.05;  // shorter plants-only extent along y is "one slice only"
  std::size_t min_plant_points = 50;
  double alpha = 0.3;               // slice validity: hull volume / slice box volume
  double alpha_near_margin = 0.05;  // slices whose ratio is this close to alpha are counted
  AreaMethod area_method = AreaMethod::kDepthMap;
  double depth_map_cell_m = 0.01;
  double depth_map_max_step_m = 0.025;  // neighbours further apart in depth are not joined
  double depth_map_min_fill = 0.6;      // below this mean cell weight the cell size grows
  double mls_radius_m = 0.03;
  double gpt_radius_m = 0.05;
  double gpt_mu = 2.5;
  int gpt_max_neighbors = 100;

  // Every number finite and inside the range the steps are meant for (a 1e-9 m depth-map cell or
  // two billion slices would run out of memory or time, a negative length mean nothing); the
  // first option that is not, or nothing. The configuration loader calls it, so that no program
  // takes such a value silently.
  std::optional<OptionsProblem> validate() const;
};

// Fills slices from row length and spacing when it is 0 (equation 15).
int sliceCount(const TraitsOptions& options);

enum class TraitsStatus {
  kOk,
  kEmptyCloud,       // no points at all
  kNoFinitePoints,   // every point has a NaN or infinite coordinate
  kHugeCoordinates,  // coordinates too far from the origin for float precision (e.g. UTM)
  kNoPlants,         // nothing left above the ground (ground only, or no plants)
  kGroundNotFound,   // the plate could not be registered to a plausible ground
  kSingleSlice,      // the plants span one slice only along the row
  kNoValidSlices,    // height and width are valid, but no slice passed alpha: no VVI/VAI
};

const char* statusName(TraitsStatus status);

struct SliceStats {
  double y_begin = 0.0;
  double y_end = 0.0;
  std::size_t points = 0;
  double x_max = 0.0;
  double z_min = 0.0;
  double z_max = 0.0;
  std::size_t box_points = 0;  // points inside the refined box (VVI stage)
  double hull_volume_m3 = 0.0;
  double box_volume_m3 = 0.0;
  double ratio = 0.0;  // hull / box
  bool valid = false;
};

struct TraitsQuality {
  std::size_t points_in = 0;
  std::size_t points_non_finite = 0;
  std::size_t points_far = 0;         // single points absurdly far from the rest
  std::size_t points_background = 0;  // cropped by depth
  std::size_t points_after_voxel = 0;
  std::size_t points_outliers = 0;       // StatisticalOutlierRemoval
  std::size_t points_small_pieces = 0;   // in pieces under min_piece_voxels
  std::size_t points_ground = 0;         // below the plate's ground plane (+ margin)
  std::size_t points_ground_tilted = 0;  // below the 10-degree tilted planes only
  std::size_t points_plants = 0;
  std::size_t points_beyond_row = 0;  // plant points beyond ±row_length_m / 2 (crop_to_row_length)
  // How much of the plot's row length the plant points span (y_max − y_min over row_length_m):
  // well under 1 when the cameras saw part of the plot; a little over 1 from leaves reaching
  // beyond its ends when crop_to_row_length is off.
  double row_coverage = 0.0;
  std::size_t points_outside_box = 0;
  double icp_fitness_coarse = -1.0;  // mean squared correspondence distance, m^2 (-1: not run)
  double icp_fitness_fine = -1.0;
  bool icp_converged = false;
  bool icp_fell_back = false;    // the coarse stage tilted too far; fine stage from the data pose
  double ground_tilt_deg = 0.0;  // angle between the ground normal used and x
  double ground_tilt_fitted_deg = 0.0;   // the registration's, before the limit or the data pose
  bool ground_tilt_limited = false;      // turned back to ground_tilt_limit_deg
  double icp_ground_shift_m = 0.0;       // ground level, registered − data's lowest dense layer
  bool ground_from_data_pose = false;    // the registration moved it too far (max_ground_shift_m)
  double ground_row_base_shift_m = 0.0;  // ground moved to the soil at the stems (row_base_band_m)
  Eigen::Vector3d base_edge_centre = Eigen::Vector3d::Zero();
  int slices = 0;
  int occupied_slices = 0;
  // Occupied slices that gave the width's edges (fewer with width_band_m; the near and far
  // spreads below are over these).
  int width_slices = 0;
  int valid_slices = 0;
  // How much the occupied slices disagree on their top, near edge and far edge: the weighted
  // interquartile range of each, m. Height and width are weighted medians over the slices, so a
  // plot whose slices split into two levels (a gap in the row, an off-type tall plant, a band of
  // stray points) can move by up to this much with a small change in which points were matched;
  // small spreads say the median stands on agreeing slices.
  double slice_top_spread_m = 0.0;
  double slice_near_spread_m = 0.0;
  double slice_far_spread_m = 0.0;
  double alpha_margin = 0.0;  // smallest |ratio - alpha| over slices: how close beta is to flipping
  int slices_near_alpha = 0;
  bool area_computed = false;
  double area_cell_m = 0.0;  // depth-map cell actually used
  double area_fill = 0.0;    // its mean cell weight (1 = closed surface)
};

struct TraitsTimings {
  double filter_ms = 0.0;
  double ground_ms = 0.0;
  double slices_ms = 0.0;
  double hulls_ms = 0.0;
  double area_ms = 0.0;
  double total_ms = 0.0;
};

struct TraitsResult {
  TraitsStatus status = TraitsStatus::kEmptyCloud;
  std::string message;  // why, when status is not kOk
  double height_m = 0.0;
  double width_m = 0.0;
  double vvi = 0.0;
  double vai = 0.0;
  double total_volume_m3 = 0.0;
  double total_area_m2 = 0.0;
  double ega_m2 = 0.0;
  double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0, z_min = 0.0, z_max = 0.0;
  std::vector<SliceStats> slices;
  TraitsQuality quality;
  TraitsTimings timings;

  bool heightWidthValid() const {
    return status == TraitsStatus::kOk || status == TraitsStatus::kNoValidSlices;
  }
  bool volumeValid() const { return status == TraitsStatus::kOk; }
};

enum class InputFrame { kPlot, kCamera };

// The whole pipeline on a raw fused cloud. Never throws for bad data: the status says why.
TraitsResult computeTraits(const std::vector<Eigen::Vector3f>& points, InputFrame frame,
                           const TraitsOptions& options);

// The trait definitions alone (slices, weighted medians, hulls, area), on points already known to
// be plants, with the ground level given: used for truth on noise-free synthetic geometry and by
// computeTraits after its ground stage.
TraitsResult traitsFromPlantPoints(const std::vector<Eigen::Vector3f>& plant_points, double x_min,
                                   const TraitsOptions& options);

// Weighted median as in the paper: sort the values, return the first whose cumulative weight
// reaches half the total. Pairs with non-positive weight are ignored; 0 when nothing is left.
double weightedMedian(std::vector<std::pair<double, double>> value_weight);

// The same at any quantile q in [0, 1]: the first sorted value whose cumulative weight reaches
// q times the total (q = 0.5 is weightedMedian).
double weightedQuantile(std::vector<std::pair<double, double>> value_weight, double q);

// Surface area by 2.5D depth-map triangulation (seen along +z): cells of `cell` metres in (x, y),
// each holding the depth layers found there; neighbouring cells are joined into triangles where
// their depths differ by less than `max_step`. Exposed for tests.
double depthMapArea(const std::vector<Eigen::Vector3f>& points, double cell, double max_step);

// The same over three viewing directions: each voxel cell goes to the axis its local surface
// normal (PCA of the 3x3x3 neighbourhood) faces most, and the three depth maps are summed, so that
// stems and steep leaves seen edge-on along z still count. The VAI estimator of the pipeline.
// `fill` is the mean triangulation weight of the cells (1 inside a surface, less at rims): a
// cloud too sparse for the cell size shows as a low fill.
struct SurfaceArea {
  double area_m2 = 0.0;
  double cell_m = 0.0;
  double fill = 0.0;
};
SurfaceArea multiViewDepthMapArea(const std::vector<Eigen::Vector3f>& points, double cell,
                                  double max_step);

// Drops points with fewer than `min_neighbours` occupied cells among the 26 around their own
// (cells of `cell` metres on the global grid); `removed` counts them.
std::vector<Eigen::Vector3f> removeSparseOutliers(const std::vector<Eigen::Vector3f>& points,
                                                  double cell, int min_neighbours,
                                                  std::size_t& removed);

// Drops the points of every connected piece (cells joined through their 26 neighbours) of fewer
// than `min_cells` occupied cells: blobs of mismatched depth floating beside the plants, in front
// of them or against the sky. `removed` counts the points.
std::vector<Eigen::Vector3f> removeSmallPieces(const std::vector<Eigen::Vector3f>& points,
                                               double cell, std::size_t min_cells,
                                               std::size_t& removed);

// Voxel-grid downsampling with an offset of the grid (PCL VoxelGrid on shifted points): used to
// measure how much the truth itself moves with the grid's phase.
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points,
                                             double leaf, const Eigen::Vector3f& grid_offset);

}  // namespace fieldrig::traits
