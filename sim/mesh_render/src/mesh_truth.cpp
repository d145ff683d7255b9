#include "fieldrig/sim/mesh_truth.h"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace fieldrig::sim {
namespace {

SurfaceLabel labelOf(PartKind kind) {
  switch (kind) {
    case PartKind::kStem:
      return SurfaceLabel::kStem;
    case PartKind::kLeaf:
      return SurfaceLabel::kLeaf;
    case PartKind::kWhorl:
    case PartKind::kPanicle:
      return SurfaceLabel::kWhorl;
    default:
      return SurfaceLabel::kBackground;
  }
}

// Area-weighted samples of the imaged plot's plants: each triangle gets samples in proportion to
// its area (the fraction decided at random), each sample weighing its share of the area.
std::vector<PlotSample> samplePlants(const MeshScene& scene, double spacing, std::uint32_t seed,
                                     double& total_area) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0F, 1.0F);
  const double per_m2 = 1.0 / (spacing * spacing);
  std::vector<PlotSample> samples;
  total_area = 0.0;
  for (const MeshPart& part : scene.parts) {
    if (part.plot != PlotCode::kThis || !isPlantPart(part.kind))
      continue;
    const SurfaceLabel label = labelOf(part.kind);
    for (const auto& t : part.triangles) {
      const Eigen::Vector3f& a = part.vertices[t[0]];
      const Eigen::Vector3f& b = part.vertices[t[1]];
      const Eigen::Vector3f& c = part.vertices[t[2]];
      const double area = 0.5 * static_cast<double>((b - a).cross(c - a).norm());
      total_area += area;
      const double expected = area * per_m2;
      int count = static_cast<int>(expected);
      if (uni(rng) < expected - count)
        ++count;
      if (count == 0)
        continue;
      const auto weight = static_cast<float>(area / count);
      for (int k = 0; k < count; ++k) {
        float u = uni(rng);
        float v = uni(rng);
        if (u + v > 1.0F) {
          u = 1.0F - u;
          v = 1.0F - v;
        }
        samples.push_back({a + u * (b - a) + v * (c - a), weight, label});
      }
    }
  }
  return samples;
}

// Where the top-centre pixel's ray of `camera` crosses the plane z = depth (x, plot frame).
double viewTopAt(const MeshCamera& camera, double depth) {
  std::vector<cv::Point2d> pixel{{(camera.size.width - 1) / 2.0, 0.0}};
  std::vector<cv::Point2d> normalised;
  cv::undistortPoints(pixel, normalised, camera.camera_matrix, camera.distortion, cv::noArray(),
                      cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-9));
  const Eigen::Vector3d d =
      camera.plot_from_camera * Eigen::Vector3d(normalised[0].x, normalised[0].y, 1.0);
  if (std::abs(d.z()) < 1e-9)
    return std::numeric_limits<double>::infinity();
  const double t = (depth - camera.position.z()) / d.z();
  return camera.position.x() + t * d.x();
}

}  // namespace

MeshPlotTruth meshPlotTruth(const MeshRenderScene& render_scene,
                            const std::vector<MeshCamera>& cameras,
                            const MeshTruthOptions& options) {
  const MeshScene& scene = render_scene.scene();
  MeshPlotTruth truth;
  PlotTruth& plot = truth.visible.truth;
  plot.ground_x_m = scene.ground_x_m;
  plot.base_depth_m = scene.row_depth_m;
  for (const MeshPlant& plant : scene.plants) {
    if (plant.plot != PlotCode::kThis)
      continue;
    plot.plant_y_m.push_back(plant.base.y());
    plot.plant_height_m.push_back(plant.height_m);
  }
  double total_area = 0.0;
  const std::vector<PlotSample> samples =
      samplePlants(scene, std::max(options.sample_spacing_m, 5e-4), options.seed, total_area);
  truth.samples = samples.size();
  plot.total_plant_area_m2 = total_area;
  std::vector<Eigen::Vector3f> positions;
  positions.reserve(samples.size());
  for (const PlotSample& s : samples)
    positions.push_back(s.position);
  const std::vector<std::uint8_t> seen_by = camerasSeeing(render_scene, cameras, positions);
  float y_lo = std::numeric_limits<float>::infinity();
  float y_hi = -std::numeric_limits<float>::infinity();
  // Stereo can only place a point both cameras of one head see; the cameras come in heads'
  // (left, right) pairs.
  std::uint8_t head_pairs_mask = 0;
  for (std::size_t c = 0; c + 1 < cameras.size(); c += 2)
    head_pairs_mask = static_cast<std::uint8_t>(head_pairs_mask | (1U << c));
  PlotCloud stereo_view;
  stereo_view.truth = plot;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (seen_by[i] == 0)
      continue;
    plot.visible_plant_samples.push_back(samples[i]);
    plot.visible_plant_area_m2 += samples[i].area_m2;
    y_lo = std::min(y_lo, samples[i].position.y());
    y_hi = std::max(y_hi, samples[i].position.y());
    const auto both = static_cast<std::uint8_t>(seen_by[i] & (seen_by[i] >> 1) & head_pairs_mask);
    if (both != 0) {
      stereo_view.truth.visible_plant_samples.push_back(samples[i]);
      stereo_view.truth.visible_plant_area_m2 += samples[i].area_m2;
    }
  }
  truth.traits = plotTruth(truth.visible, options.traits);
  truth.stereo_view = plotTruth(stereo_view, options.traits);
  truth.stereo_view_plant_area_m2 = stereo_view.truth.visible_plant_area_m2;

  PlotCloud full;
  full.truth = plot;
  full.truth.visible_plant_samples.clear();
  for (const PlotSample& s : samples) {
    if (s.position.y() >= y_lo && s.position.y() <= y_hi)
      full.truth.visible_plant_samples.push_back(s);
  }
  truth.full = plotTruth(full, options.traits);

  // The top head's left camera (the last head's first camera) bounds what the rig sees.
  double top = std::numeric_limits<double>::infinity();
  if (cameras.size() >= 2)
    top = viewTopAt(cameras[cameras.size() - 2], scene.row_depth_m);
  truth.view_top_m = top - scene.ground_x_m;
  for (const MeshPlant& plant : scene.plants) {
    if (plant.plot == PlotCode::kThis && plant.base.x() + plant.top_m > top)
      truth.exceeds_view = true;
  }
  return truth;
}

nlohmann::ordered_json meshTruthJson(const MeshPlotTruth& truth, const MeshScene& scene) {
  using Json = nlohmann::ordered_json;
  const traits::TraitsResult& d = truth.traits.definitions;
  Json j;
  j["status"] = traits::statusName(d.status);
  j["vai"] = truth.traits.vai;
  j["ega_m2"] = d.ega_m2;
  j["total_volume_m3"] = d.total_volume_m3;
  j["visible_area_in_box_m2"] = truth.traits.visible_area_m2;
  j["total_plant_area_m2"] = truth.visible.truth.total_plant_area_m2;
  j["ground_x_m"] = truth.visible.truth.ground_x_m;
  j["row_depth_m"] = scene.row_depth_m;
  j["x_max_m"] = d.x_max;
  j["y_min_m"] = d.y_min;
  j["y_max_m"] = d.y_max;
  j["view_top_m"] = truth.view_top_m;
  j["exceeds_view"] = truth.exceeds_view;
  const traits::TraitsResult& f = truth.full.definitions;
  j["full"] = {{"status", traits::statusName(f.status)},
               {"height_m", f.height_m},
               {"width_m", f.width_m},
               {"vvi", f.vvi},
               {"vai", truth.full.vai},
               {"z_min_m", f.z_min},
               {"z_max_m", f.z_max}};
  const traits::TraitsResult& stereo = truth.stereo_view.definitions;
  j["stereo_view"] = {{"status", traits::statusName(stereo.status)},
                      {"height_m", stereo.height_m},
                      {"width_m", stereo.width_m},
                      {"vvi", stereo.vvi},
                      {"vai", truth.stereo_view.vai},
                      {"z_min_m", stereo.z_min},
                      {"z_max_m", stereo.z_max},
                      {"visible_plant_area_m2", truth.stereo_view_plant_area_m2}};
  j["samples"] = truth.samples;
  j["visible_samples"] = truth.visible.truth.visible_plant_samples.size();
  Json plants = Json::array();
  for (const MeshPlant& plant : scene.plants) {
    if (plant.plot != PlotCode::kThis)
      continue;
    Json stem = Json::array();
    for (const StemSection& s : plant.stem) {
      stem.push_back({{"height_m", s.height_m},
                      {"diameter_m", s.diameter_m},
                      {"axis_m", {s.axis_point.x(), s.axis_point.y(), s.axis_point.z()}}});
    }
    plants.push_back({{"id", plant.id},
                      {"index", plant.index},
                      {"base_m", {plant.base.x(), plant.base.y(), plant.base.z()}},
                      {"height_m", plant.height_m},
                      {"top_m", plant.top_m},
                      {"leaves", plant.leaves},
                      {"panicle", plant.panicle},
                      {"abnormal", plant.abnormal},
                      {"stem", stem}});
  }
  j["plants"] = plants;
  return j;
}

}  // namespace fieldrig::sim
