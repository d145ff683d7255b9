#include "fieldrig/traits/plot_traits.h"
#include "fieldrig/core/time.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "pcl_steps.h"

namespace fieldrig::traits {
namespace {

using Points = std::vector<Eigen::Vector3f>;
using Clock = std::chrono::steady_clock;

TraitsResult failed(TraitsResult result, TraitsStatus status, std::string message) {
  result.status = status;
  result.message = std::move(message);
  result.height_m = result.width_m = result.vvi = result.vai = 0.0;
  result.total_volume_m3 = result.total_area_m2 = result.ega_m2 = 0.0;
  return result;
}

// The value at quantile q of one coordinate (0..1), by partial sort of a copy.
float quantile(const Points& points, int axis, double q) {
  std::vector<float> values;
  values.reserve(points.size());
  for (const Eigen::Vector3f& p : points)
    values.push_back(p[axis]);
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

// The data-driven plate pose: the soil is the densest horizontal layer at the bottom of the
// cloud (mode of a 1 cm histogram of x over the lowest metre), and the row plane is the median
// depth of what stands just above it (the stem bases).
struct PlatePose {
  double ground_x = 0.0;
  double base_z = 0.0;
  bool found = false;
};

PlatePose initialPlatePose(const Points& points, double strip) {
  PlatePose pose;
  const double bottom = quantile(points, 0, 0.005);
  const double bin = 0.01;
  const int bins = 100;
  std::vector<int> histogram(bins, 0);
  for (const Eigen::Vector3f& p : points) {
    const int b = static_cast<int>(std::floor((p.x() - bottom) / bin));
    if (b >= 0 && b < bins)
      ++histogram[static_cast<std::size_t>(b)];
  }
  const auto peak = std::max_element(histogram.begin(), histogram.end()) - histogram.begin();
  pose.ground_x = bottom + (static_cast<double>(peak) + 0.5) * bin;
  std::vector<float> base_depths;
  for (const Eigen::Vector3f& p : points) {
    if (p.x() > pose.ground_x + 0.05 && p.x() < pose.ground_x + 0.05 + strip)
      base_depths.push_back(p.z());
  }
  if (base_depths.size() < 10)
    return pose;
  const auto mid = base_depths.begin() + static_cast<std::ptrdiff_t>(base_depths.size() / 2);
  std::nth_element(base_depths.begin(), mid, base_depths.end());
  pose.base_z = *mid;
  pose.found = true;
  return pose;
}

// How far along `normal` the soil where the stems stand lies from the ground through
// `edge_centre`: the densest 1.5 cm layer of the points within `band` across the row of the base
// edge and within `max_shift` of the ground. Soil seen between the stems fills one layer; stems
// and leaves spread over all of them, so a layer holding less than twice the average is no soil
// (the row base hidden by leaves): 0 then.
double rowBaseGroundShift(const Points& points, const Eigen::Vector3d& edge_centre,
                          const Eigen::Vector3d& normal, const Eigen::Vector3d& across, double band,
                          double max_shift) {
  constexpr double kBin = 0.005;
  constexpr int kWindow = 3;  // bins in a layer
  constexpr std::size_t kMinLayerPoints = 20;
  const int bins = static_cast<int>(std::ceil(2.0 * max_shift / kBin));
  if (bins < kWindow)
    return 0.0;
  std::vector<std::size_t> histogram(static_cast<std::size_t>(bins), 0);
  std::size_t counted = 0;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d d = p.cast<double>() - edge_centre;
    if (std::abs(across.dot(d)) > band)
      continue;
    const int b = static_cast<int>(std::floor((normal.dot(d) + max_shift) / kBin));
    if (b >= 0 && b < bins) {
      ++histogram[static_cast<std::size_t>(b)];
      ++counted;
    }
  }
  std::size_t best = 0;
  int best_first = 0;
  for (int first = 0; first + kWindow <= bins; ++first) {
    std::size_t layer = 0;
    for (int b = first; b < first + kWindow; ++b)
      layer += histogram[static_cast<std::size_t>(b)];
    if (layer > best) {
      best = layer;
      best_first = first;
    }
  }
  const double average_layer = static_cast<double>(counted) * kWindow / static_cast<double>(bins);
  if (best < kMinLayerPoints || static_cast<double>(best) < 2.0 * average_layer)
    return 0.0;
  // The layer's mean height, so that the shift is not quantised to the bins.
  double sum = 0.0;
  std::size_t n = 0;
  const double lo = -max_shift + best_first * kBin;
  const double hi = lo + kWindow * kBin;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3d d = p.cast<double>() - edge_centre;
    const double h = normal.dot(d);
    if (std::abs(across.dot(d)) <= band && h >= lo && h < hi) {
      sum += h;
      ++n;
    }
  }
  return n > 0 ? sum / static_cast<double>(n) : 0.0;
}

}  // namespace

namespace {

// Counts print as written ("2000000000", not "2e+09"); lengths in their shortest exact form.
std::string optionNumber(double value) {
  if (std::isfinite(value) && value == std::trunc(value) && std::abs(value) < 1e15)
    return std::to_string(static_cast<long long>(value));
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

// `value` in [lo, hi] (or [lo, hi) when hi_open), else the problem naming `key`.
std::optional<OptionsProblem> outOfRange(const char* key, double value, double lo, double hi,
                                         bool hi_open = false) {
  if (std::isfinite(value) && value >= lo && value <= hi && !(hi_open && value == hi))
    return std::nullopt;
  return OptionsProblem{key, optionNumber(value) + " is out of range [" + optionNumber(lo) + ", " +
                                 optionNumber(hi) + (hi_open ? ")" : "]")};
}

}  // namespace

std::optional<OptionsProblem> TraitsOptions::validate() const {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (auto bad = outOfRange("camera_to_plot", camera_to_plot(r, c), -1e3, 1e3))
        return bad;
    }
  }
  // Lengths from a millimetre (below, voxels and cells outnumber any cloud's points) to what a
  // side-view camera a metre or two from the row can see.
  const std::optional<OptionsProblem> checks[] = {
      outOfRange("voxel_leaf_m", voxel_leaf_m, 0.001, 1),
      outOfRange("outlier_mean_k", outlier_mean_k, 1, 1000),
      outOfRange("outlier_stddev_mul", outlier_stddev_mul, 0, 100),
      outOfRange("outlier_min_neighbours", outlier_min_neighbours, 0, 26),
      outOfRange("min_piece_voxels", min_piece_voxels, 0, 1000000),
      outOfRange("crop_z_max_m", crop_z_max_m, 0.01, 100),
      outOfRange("crop_z_min_m", crop_z_min_m, 0, 100),
      outOfRange("max_abs_coordinate_m", max_abs_coordinate_m, 1, 1e6),
      outOfRange("template_strip_m", template_strip_m, 0.01, 10),
      outOfRange("template_step_m", template_step_m, 0.001, 1),
      outOfRange("icp_target_leaf_m", icp_target_leaf_m, 0.001, 1),
      outOfRange("icp_coarse_distance_m", icp_coarse_distance_m, 0.001, 10),
      outOfRange("icp_fine_distance_m", icp_fine_distance_m, 0, 10),
      outOfRange("icp_iterations", icp_iterations, 1, 1000),
      outOfRange("max_ground_tilt_deg", max_ground_tilt_deg, 0, 90),
      outOfRange("ground_tilt_limit_deg", ground_tilt_limit_deg, 0, 90),
      outOfRange("max_ground_shift_m", max_ground_shift_m, 0, 10),
      outOfRange("ground_margin_m", ground_margin_m, 0, 1),
      outOfRange("row_base_band_m", row_base_band_m, 0, 1),
      outOfRange("ground_tilt_deg", ground_tilt_deg, 0, 90, true),
      outOfRange("row_length_m", row_length_m, 0.01, 100),
      outOfRange("intra_row_spacing_m", intra_row_spacing_m, 0.001, 10),
      // sliceCount's own ceiling for a count derived from the row.
      outOfRange("slices", slices, 0, 1000),
      outOfRange("slice_width_quantile", slice_width_quantile, 0, 0.25),
      outOfRange("width_band_m", width_band_m, 0, 100),
      outOfRange("min_row_extent_m", min_row_extent_m, 0, 100),
      outOfRange("min_plant_points", static_cast<double>(min_plant_points), 0, 1e9),
      outOfRange("alpha", alpha, 0, 1, true),
      outOfRange("alpha_near_margin", alpha_near_margin, 0, 1),
      outOfRange("depth_map_cell_m", depth_map_cell_m, 0.001, 1),
      outOfRange("depth_map_max_step_m", depth_map_max_step_m, 0.001, 10),
      outOfRange("depth_map_min_fill", depth_map_min_fill, 0, 1),
      outOfRange("mls_radius_m", mls_radius_m, 0.001, 1),
      outOfRange("gpt_radius_m", gpt_radius_m, 0.001, 1),
      outOfRange("gpt_mu", gpt_mu, 0.1, 100),
      outOfRange("gpt_max_neighbors", gpt_max_neighbors, 1, 10000),
  };
  for (const std::optional<OptionsProblem>& problem : checks) {
    if (problem)
      return problem;
  }
  if (!(crop_z_min_m < crop_z_max_m)) {
    return OptionsProblem{"crop_z_min_m", "the depth crop must satisfy crop_z_min_m (" +
                                              optionNumber(crop_z_min_m) + ") < crop_z_max_m (" +
                                              optionNumber(crop_z_max_m) + ")"};
  }
  return std::nullopt;
}

int sliceCount(const TraitsOptions& options) {
  if (options.slices > 0)
    return options.slices;
  if (!(options.intra_row_spacing_m > 0.0) || !(options.row_length_m > 0.0))
    return 20;
  return std::clamp(
      static_cast<int>(std::ceil(2.0 * options.row_length_m / options.intra_row_spacing_m - 1e-9)),
      1, 1000);
}

const char* statusName(TraitsStatus status) {
  switch (status) {
    case TraitsStatus::kOk:
      return "ok";
    case TraitsStatus::kEmptyCloud:
      return "empty_cloud";
    case TraitsStatus::kNoFinitePoints:
      return "no_finite_points";
    case TraitsStatus::kHugeCoordinates:
      return "huge_coordinates";
    case TraitsStatus::kNoPlants:
      return "no_plants";
    case TraitsStatus::kGroundNotFound:
      return "ground_not_found";
    case TraitsStatus::kSingleSlice:
      return "single_slice";
    case TraitsStatus::kNoValidSlices:
      return "no_valid_slices";
  }
  return "unknown";
}

double weightedQuantile(std::vector<std::pair<double, double>> value_weight, double q) {
  std::erase_if(value_weight, [](const auto& vw) {
    return !(vw.second > 0.0) || !std::isfinite(vw.first) || !std::isfinite(vw.second);
  });
  if (value_weight.empty())
    return 0.0;
  std::sort(value_weight.begin(), value_weight.end());
  double total = 0.0;
  for (const auto& vw : value_weight)
    total += vw.second;
  double cumulative = 0.0;
  for (const auto& vw : value_weight) {
    cumulative += vw.second;
    if (cumulative >= q * total)
      return vw.first;
  }
  return value_weight.back().first;
}

double weightedMedian(std::vector<std::pair<double, double>> value_weight) {
  return weightedQuantile(std::move(value_weight), 0.5);
}

std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points,
                                             double leaf, const Eigen::Vector3f& grid_offset) {
  Points shifted;
  shifted.reserve(points.size());
  for (const Eigen::Vector3f& p : points)
    shifted.push_back(p + grid_offset);
  Points out = detail::voxelGrid(shifted, leaf);
  for (Eigen::Vector3f& p : out)
    p -= grid_offset;
  return out;
}

TraitsResult traitsFromPlantPoints(const std::vector<Eigen::Vector3f>& all_plant_points,
                                   double x_min, const TraitsOptions& options) {
  TraitsResult result;
  const auto slices_start = Clock::now();
  // The plot is row_length_m long, centred on its location (y = 0): what lies beyond is the
  // neighbouring plots' leaves and the ends of the cameras' view, where only the far side of the
  // row is seen by both cameras of a head.
  std::vector<Eigen::Vector3f> in_row;
  if (options.crop_to_row_length) {
    const double half = options.row_length_m / 2.0;
    in_row.reserve(all_plant_points.size());
    for (const Eigen::Vector3f& p : all_plant_points) {
      if (std::abs(p.y()) <= half)
        in_row.push_back(p);
    }
    result.quality.points_beyond_row = all_plant_points.size() - in_row.size();
  }
  const std::vector<Eigen::Vector3f>& plant_points =
      options.crop_to_row_length ? in_row : all_plant_points;
  result.quality.points_plants = plant_points.size();
  if (plant_points.size() < options.min_plant_points)
    return failed(std::move(result), TraitsStatus::kNoPlants,
                  std::to_string(plant_points.size()) + " points above the ground, need " +
                      std::to_string(options.min_plant_points));
  Eigen::Vector3f lo = plant_points.front();
  Eigen::Vector3f hi = plant_points.front();
  for (const Eigen::Vector3f& p : plant_points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  result.x_min = x_min;
  result.y_min = lo.y();
  result.y_max = hi.y();
  const double row_extent = result.y_max - result.y_min;
  result.quality.row_coverage = row_extent / options.row_length_m;
  if (row_extent < options.min_row_extent_m)
    return failed(std::move(result), TraitsStatus::kSingleSlice,
                  "plants span " + std::to_string(row_extent) + " m along the row, need " +
                      std::to_string(options.min_row_extent_m) + " m");

  // Slices along y (the paper's N_slice) and their extremes.
  const int n = sliceCount(options);
  result.quality.slices = n;
  const double slice_length = row_extent / n;
  result.slices.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    SliceStats& s = result.slices[static_cast<std::size_t>(i)];
    s.y_begin = result.y_min + i * slice_length;
    s.y_end = result.y_min + (i + 1) * slice_length;
    s.x_max = -std::numeric_limits<double>::infinity();
    s.z_min = std::numeric_limits<double>::infinity();
    s.z_max = -std::numeric_limits<double>::infinity();
  }
  auto sliceOf = [&](float y) {
    return static_cast<std::size_t>(
        std::clamp(static_cast<int>((y - result.y_min) / slice_length), 0, n - 1));
  };
  std::vector<std::vector<float>> slice_depths;  // for slice_width_quantile
  if (options.slice_width_quantile > 0.0)
    slice_depths.resize(static_cast<std::size_t>(n));
  for (const Eigen::Vector3f& p : plant_points) {
    const std::size_t index = sliceOf(p.y());
    SliceStats& s = result.slices[index];
    ++s.points;
    s.x_max = std::max(s.x_max, static_cast<double>(p.x()));
    s.z_min = std::min(s.z_min, static_cast<double>(p.z()));
    s.z_max = std::max(s.z_max, static_cast<double>(p.z()));
    if (!slice_depths.empty())
      slice_depths[index].push_back(p.z());
  }
  for (std::size_t i = 0; i < slice_depths.size(); ++i) {
    std::vector<float>& depths = slice_depths[i];
    if (depths.empty())
      continue;
    // The near edge the same number of voxels in from the nearest as the far edge from the
    // furthest.
    const auto k = static_cast<std::size_t>(options.slice_width_quantile *
                                            static_cast<double>(depths.size() - 1));
    const auto at = [&](std::size_t rank) {
      std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(rank),
                       depths.end());
      return static_cast<double>(depths[rank]);
    };
    result.slices[i].z_min = at(k);
    result.slices[i].z_max = at(depths.size() - 1 - k);
  }
  std::vector<std::pair<double, double>> x_max, z_min, z_max, band_z_min, band_z_max;
  for (SliceStats& s : result.slices) {
    if (s.points == 0) {
      s.x_max = s.z_min = s.z_max = 0.0;  // no NaN or infinity leaves this function
      continue;
    }
    ++result.quality.occupied_slices;
    const auto w = static_cast<double>(s.points);
    x_max.emplace_back(s.x_max, w);
    z_min.emplace_back(s.z_min, w);
    z_max.emplace_back(s.z_max, w);
    if (options.width_band_m > 0.0 &&
        std::abs(0.5 * (s.y_begin + s.y_end)) <= 0.5 * options.width_band_m) {
      band_z_min.emplace_back(s.z_min, w);
      band_z_max.emplace_back(s.z_max, w);
    }
  }
  // Without a slice in the band (plants beside the location only) every slice gives the width.
  if (!band_z_min.empty()) {
    z_min = std::move(band_z_min);
    z_max = std::move(band_z_max);
  }
  result.quality.width_slices = static_cast<int>(z_min.size());
  if (result.quality.occupied_slices < 2)
    return failed(std::move(result), TraitsStatus::kSingleSlice,
                  "points in " + std::to_string(result.quality.occupied_slices) +
                      " slice(s) only of " + std::to_string(n));
  result.x_max = weightedMedian(x_max);
  result.z_min = weightedMedian(z_min);
  result.z_max = weightedMedian(z_max);
  const auto spread = [](const std::vector<std::pair<double, double>>& value_weight) {
    return weightedQuantile(value_weight, 0.75) - weightedQuantile(value_weight, 0.25);
  };
  result.quality.slice_top_spread_m = spread(x_max);
  result.quality.slice_near_spread_m = spread(z_min);
  result.quality.slice_far_spread_m = spread(z_max);
  result.height_m = result.x_max - result.x_min;
  result.width_m = result.z_max - result.z_min;
  result.timings.slices_ms = core::millisecondsSince(slices_start);
  if (!(result.height_m > 0.0) || !(result.width_m > 0.0))
    return failed(std::move(result), TraitsStatus::kNoPlants,
                  "no plant above the ground: height " + std::to_string(result.height_m) +
                      " m, width " + std::to_string(result.width_m) + " m");

  // VVI: points in the refined box, one convex hull per slice (equations 3-6).
  const auto hulls_start = Clock::now();
  std::vector<Points> in_box(static_cast<std::size_t>(n));
  Points box_points;
  box_points.reserve(plant_points.size());
  for (const Eigen::Vector3f& p : plant_points) {
    if (p.x() < result.x_min || p.x() > result.x_max || p.z() < result.z_min ||
        p.z() > result.z_max) {
      ++result.quality.points_outside_box;
      continue;
    }
    in_box[sliceOf(p.y())].push_back(p);
    box_points.push_back(p);
  }
  const double slice_box = slice_length * result.width_m * result.height_m;
  result.quality.alpha_margin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < result.slices.size(); ++i) {
    SliceStats& s = result.slices[i];
    s.box_points = in_box[i].size();
    s.hull_volume_m3 = detail::convexHullVolume(in_box[i]);
    s.box_volume_m3 = slice_box;
    s.ratio = slice_box > 0.0 ? s.hull_volume_m3 / slice_box : 0.0;
    s.valid = s.ratio > options.alpha;
    const double margin = std::abs(s.ratio - options.alpha);
    result.quality.alpha_margin = std::min(result.quality.alpha_margin, margin);
    result.quality.slices_near_alpha += margin < options.alpha_near_margin ? 1 : 0;
    if (s.valid) {
      ++result.quality.valid_slices;
      result.total_volume_m3 += s.hull_volume_m3;
    }
  }
  result.timings.hulls_ms = core::millisecondsSince(hulls_start);
  const double beta = static_cast<double>(result.quality.valid_slices) / n;
  result.ega_m2 = beta * row_extent * result.width_m;

  // VAI: surface area / EGA (equation 9).
  const auto area_start = Clock::now();
  switch (options.area_method) {
    case AreaMethod::kDepthMap: {
      // A cloud too sparse for the cell leaves holes that read as rims (low fill): coarser cells
      // until the surface closes, up to 3 cells.
      SurfaceArea area;
      for (int factor = 1; factor <= 3; ++factor) {
        const double cell = factor * options.depth_map_cell_m;
        area = multiViewDepthMapArea(
            box_points, cell, options.depth_map_max_step_m * cell / options.depth_map_cell_m);
        if (area.fill >= options.depth_map_min_fill)
          break;
      }
      result.total_area_m2 = area.area_m2;
      result.quality.area_cell_m = area.cell_m;
      result.quality.area_fill = area.fill;
      result.quality.area_computed = true;
      break;
    }
    case AreaMethod::kPaperMlsGpt:
      result.total_area_m2 =
          detail::paperMlsGptArea(box_points, options.mls_radius_m, options.gpt_radius_m,
                                  options.gpt_mu, options.gpt_max_neighbors);
      result.quality.area_computed = true;
      break;
    case AreaMethod::kNone:
      break;
  }
  result.timings.area_ms = core::millisecondsSince(area_start);
  if (result.quality.valid_slices == 0) {
    // Height and width stand; without a valid slice there is no EGA, so no VVI and no VAI.
    result.status = TraitsStatus::kNoValidSlices;
    result.message = "no slice's hull exceeds alpha = " + std::to_string(options.alpha) +
                     " of its box; height and width are valid, VVI and VAI are not";
    result.vvi = result.vai = result.ega_m2 = result.total_volume_m3 = 0.0;
    return result;
  }
  const double ebbv = result.ega_m2 * result.height_m;
  result.vvi = result.total_volume_m3 / ebbv;
  result.vai = result.total_area_m2 / result.ega_m2;
  result.status = TraitsStatus::kOk;
  return result;
}

TraitsResult computeTraits(const std::vector<Eigen::Vector3f>& points, InputFrame frame,
                           const TraitsOptions& options) {
  const auto start = Clock::now();
  TraitsResult result;
  TraitsQuality& q = result.quality;
  q.points_in = points.size();
  if (points.empty())
    return failed(std::move(result), TraitsStatus::kEmptyCloud, "the cloud has no points");

  // Finite points, in the plot frame.
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  if (frame == InputFrame::kCamera)
    rotation = options.camera_to_plot.cast<float>();
  Points cloud;
  cloud.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) {
      ++q.points_non_finite;
      continue;
    }
    cloud.push_back(rotation * p);
  }
  if (cloud.empty())
    return failed(
        std::move(result), TraitsStatus::kNoFinitePoints,
        "all " + std::to_string(points.size()) + " points have NaN or infinite coordinates");
  // Coordinates far from the origin lose float precision (e.g. UTM eastings): refuse those; a
  // few absurd points far from the bulk are dropped and counted.
  Eigen::Vector3f median;
  for (int axis = 0; axis < 3; ++axis)
    median[axis] = quantile(cloud, axis, 0.5);
  if (median.cwiseAbs().maxCoeff() > options.max_abs_coordinate_m)
    return failed(std::move(result), TraitsStatus::kHugeCoordinates,
                  "the cloud's median lies " + std::to_string(median.cwiseAbs().maxCoeff()) +
                      " m from the origin (limit " + std::to_string(options.max_abs_coordinate_m) +
                      " m): shift it to a local frame before computing traits");
  std::erase_if(cloud, [&](const Eigen::Vector3f& p) {
    const bool far = (p - median).cwiseAbs().maxCoeff() > 100.0F;
    q.points_far += far ? 1 : 0;
    return far;
  });

  // Background rows by depth, then the paper's VoxelGrid and StatisticalOutlierRemoval.
  const auto filter_start = Clock::now();
  std::erase_if(cloud, [&](const Eigen::Vector3f& p) {
    const bool out = p.z() > options.crop_z_max_m || p.z() < options.crop_z_min_m;
    q.points_background += out ? 1 : 0;
    return out;
  });
  cloud = detail::voxelGrid(cloud, options.voxel_leaf_m);
  q.points_after_voxel = cloud.size();
  if (options.outlier_method == OutlierMethod::kStatistical) {
    cloud = detail::removeStatisticalOutliers(cloud, options.outlier_mean_k,
                                              options.outlier_stddev_mul, q.points_outliers);
  } else {
    cloud = removeSparseOutliers(cloud, options.voxel_leaf_m, options.outlier_min_neighbours,
                                 q.points_outliers);
  }
  cloud =
      removeSmallPieces(cloud, options.voxel_leaf_m,
                        static_cast<std::size_t>(options.min_piece_voxels), q.points_small_pieces);
  result.timings.filter_ms = core::millisecondsSince(filter_start);
  if (cloud.size() < options.min_plant_points)
    return failed(std::move(result), TraitsStatus::kNoPlants,
                  std::to_string(cloud.size()) + " points left after the depth crop and filters");

  // Ground: the plate template at the data-driven pose, registered by ICP (coarse + fine).
  const auto ground_start = Clock::now();
  const double strip = options.template_strip_m;
  const PlatePose pose = initialPlatePose(cloud, strip);
  if (!pose.found)
    return failed(std::move(result), TraitsStatus::kNoPlants,
                  "nothing stands above the ground layer at x = " + std::to_string(pose.ground_x) +
                      " m: ground only, no plants");
  const double y_lo = quantile(cloud, 1, 0.02);
  const double y_hi = quantile(cloud, 1, 0.98);
  const double step = std::max(options.template_step_m, 1e-3);
  Points plate;
  for (double y = y_lo; y <= y_hi; y += step) {
    for (double s = 0.0; s <= strip + 1e-9; s += step) {
      plate.emplace_back(pose.ground_x, y, pose.base_z - s);  // toward the camera
      if (s > 0.0)
        plate.emplace_back(pose.ground_x + s, y, pose.base_z);  // up the plant plane
    }
  }
  Points target;
  for (const Eigen::Vector3f& p : cloud) {
    if (p.x() < pose.ground_x + strip + 0.15 && p.x() > pose.ground_x - 0.3 &&
        p.z() > pose.base_z - strip - 0.15 && p.z() < pose.base_z + 0.15)
      target.push_back(p);
  }
  if (options.icp_target_leaf_m > 0.0)
    target = detail::voxelGrid(target, options.icp_target_leaf_m);
  const detail::PlateFit fit = detail::registerPlate(
      plate, target, options.icp_coarse_distance_m, options.icp_fine_distance_m,
      options.icp_iterations, options.max_ground_tilt_deg);
  q.icp_fitness_coarse = fit.fitness_coarse;
  q.icp_fitness_fine = fit.fitness_fine;
  q.icp_converged = fit.converged;
  q.icp_fell_back = fit.fell_back;
  q.ground_tilt_deg = fit.tilt_deg;
  if (!fit.converged || fit.tilt_deg > options.max_ground_tilt_deg)
    return failed(std::move(result), TraitsStatus::kGroundNotFound,
                  "plate registration " +
                      std::string(fit.converged ? "tilted the ground by " +
                                                      std::to_string(fit.tilt_deg) + " degrees"
                                                : "did not converge"));
  const Eigen::Vector3d data_edge_centre(pose.ground_x, 0.5 * (y_lo + y_hi), pose.base_z);
  Eigen::Matrix4d plate_transform = fit.transform;
  // Once the plate's soil strip has crept beyond the fine stage's reach, only its plant strip has
  // correspondences, and it slides up the stems (14 cm seen on a rendered plot). The data's
  // ground layer is then the better ground.
  const double ground_shift = (plate_transform.block<3, 3>(0, 0) * data_edge_centre +
                               plate_transform.block<3, 1>(0, 3) - data_edge_centre)
                                  .x();
  q.icp_ground_shift_m = ground_shift;
  q.ground_tilt_fitted_deg = fit.tilt_deg;
  if (std::abs(ground_shift) > options.max_ground_shift_m) {
    plate_transform.setIdentity();
    q.ground_from_data_pose = true;
    q.ground_tilt_deg = 0.0;
  } else if (options.ground_tilt_limit_deg > 0.0 && fit.tilt_deg > options.ground_tilt_limit_deg) {
    // Turn the plate's normal back toward the data's vertical until it leans by the limit, keeping
    // its turn about the normal and the place of its base-ground edge.
    plate_transform =
        detail::limitTilt(plate_transform, data_edge_centre, options.ground_tilt_limit_deg);
    q.ground_tilt_limited = true;
    q.ground_tilt_deg = options.ground_tilt_limit_deg;
  }
  const Eigen::Matrix3d r = plate_transform.block<3, 3>(0, 0);
  const Eigen::Vector3d t = plate_transform.block<3, 1>(0, 3);
  const Eigen::Vector3d normal = r * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d across = r * Eigen::Vector3d::UnitZ();
  Eigen::Vector3d edge_centre = r * data_edge_centre + t;
  if (options.row_base_band_m > 0.0) {
    const double shift = rowBaseGroundShift(cloud, edge_centre, normal, across,
                                            options.row_base_band_m, options.max_ground_shift_m);
    edge_centre += shift * normal;
    q.ground_row_base_shift_m = shift;
  }
  q.base_edge_centre = edge_centre;
  // Below the plate's ground (plus a noise margin) is soil; so is whatever lies below the planes
  // tilted by 10 degrees about the base-ground edge, on both sides: clods and weeds in front, and
  // the soil seen between the stems behind the row.
  const double tilt = std::tan(options.ground_tilt_deg * std::numbers::pi / 180.0);
  Points plants;
  plants.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud) {
    const Eigen::Vector3d d = p.cast<double>() - edge_centre;
    const double h = normal.dot(d);
    if (h <= options.ground_margin_m) {
      ++q.points_ground;
    } else if (h <= options.ground_margin_m + tilt * std::abs(across.dot(d))) {
      ++q.points_ground_tilted;
    } else {
      plants.push_back(p);
    }
  }
  result.timings.ground_ms = core::millisecondsSince(ground_start);

  TraitsResult traits = traitsFromPlantPoints(plants, edge_centre.x(), options);
  traits.quality.points_in = q.points_in;
  traits.quality.points_non_finite = q.points_non_finite;
  traits.quality.points_far = q.points_far;
  traits.quality.points_background = q.points_background;
  traits.quality.points_after_voxel = q.points_after_voxel;
  traits.quality.points_outliers = q.points_outliers;
  traits.quality.points_small_pieces = q.points_small_pieces;
  traits.quality.points_ground = q.points_ground;
  traits.quality.points_ground_tilted = q.points_ground_tilted;
  traits.quality.icp_fitness_coarse = q.icp_fitness_coarse;
  traits.quality.icp_fitness_fine = q.icp_fitness_fine;
  traits.quality.icp_converged = q.icp_converged;
  traits.quality.icp_fell_back = q.icp_fell_back;
  traits.quality.icp_ground_shift_m = q.icp_ground_shift_m;
  traits.quality.ground_from_data_pose = q.ground_from_data_pose;
  traits.quality.ground_row_base_shift_m = q.ground_row_base_shift_m;
  traits.quality.ground_tilt_deg = q.ground_tilt_deg;
  traits.quality.ground_tilt_fitted_deg = q.ground_tilt_fitted_deg;
  traits.quality.ground_tilt_limited = q.ground_tilt_limited;
  traits.quality.base_edge_centre = q.base_edge_centre;
  traits.timings.filter_ms = result.timings.filter_ms;
  traits.timings.ground_ms = result.timings.ground_ms;
  if (!std::isfinite(traits.quality.alpha_margin))
    traits.quality.alpha_margin = 0.0;
  traits.timings.total_ms = core::millisecondsSince(start);
  return traits;
}

}  // namespace fieldrig::traits
