// The Embree mesh renderer against the geometry it renders: the depth truth of a pixel is where
// that pixel's ray meets the meshes; a flat soil plane shows the depth the calibration predicts;
// a straight 3D bar images as the curve the calibration's k1 makes of it (and not as a straight
// line); the same seed gives the same bytes; the Bayer filter puts each colour where the pattern
// says; and a recorded mesh session carries truth maps and a truth line whose traits fit the
// meshes. Cameras are rendered at a quarter of the Grasshoppers' size where the full size adds
// nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "fieldrig/recording/session_reader.h"
#include "fieldrig/sim/mesh_renderer.h"
#include "fieldrig/sim/mesh_truth.h"
#include "fieldrig/sim/synthetic_field.h"
#include "fieldrig/stereo/disparity_io.h"
#include "support/temp_dir.h"

namespace fieldrig::sim {
namespace {

namespace fs = std::filesystem;

std::shared_ptr<MeshRenderDevice> device() {
  static std::shared_ptr<MeshRenderDevice> shared = [] {
    auto created = MeshRenderDevice::create();
    EXPECT_TRUE(created.ok()) << created.error().message;
    return created.ok() ? *created : nullptr;
  }();
  return shared;
}

// The calibrated rig's cameras, bottom head's rectified left camera 0.55 m above the soil.
std::vector<MeshCamera> calibratedCameras() {
  return rigCameras(calibratedRig(), Eigen::Vector3d(0.55, 0.0, 0.0));
}

// The same camera imaging at `factor` of its size (same field of view, same distortion).
MeshCamera scaled(MeshCamera camera, double factor) {
  cv::Matx33d& k = camera.camera_matrix;
  k(0, 0) *= factor;
  k(1, 1) *= factor;
  k(0, 2) = (k(0, 2) + 0.5) * factor - 0.5;
  k(1, 2) = (k(1, 2) + 0.5) * factor - 0.5;
  camera.size = cv::Size(static_cast<int>(std::lround(camera.size.width * factor)),
                         static_cast<int>(std::lround(camera.size.height * factor)));
  return camera;
}

// Ray of a pixel in the plot frame, camera-z component 1 (so the ray parameter is the depth).
Eigen::Vector3d pixelRay(const MeshCamera& camera, double u, double v) {
  std::vector<cv::Point2d> pixel{{u, v}};
  std::vector<cv::Point2d> normalised;
  cv::undistortPoints(pixel, normalised, camera.camera_matrix, camera.distortion, cv::noArray(),
                      cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-9));
  return camera.plot_from_camera * Eigen::Vector3d(normalised[0].x, normalised[0].y, 1.0);
}

MeshPlotSpec earlySpec(std::uint32_t seed) {
  PlotSeries series;
  series.count = 3;
  series.seed = seed;
  series.renderer = SceneRenderer::kMesh;
  series.stages = {GrowthStage::kEarly};
  return meshPlotSpec(series, 1);
}

std::unique_ptr<MeshRenderScene> buildScene(MeshScene scene) {
  auto built = MeshRenderScene::build(device(), std::move(scene));
  EXPECT_TRUE(built.ok()) << built.error().message;
  return built.ok() ? std::move(*built) : nullptr;
}

// A part from a parametric grid (i over ns, j over nt) for hand-made scenes.
template <typename At>
MeshPart gridPart(PartKind kind, int ns, int nt, At at) {
  MeshPart part;
  part.kind = kind;
  for (int i = 0; i <= ns; ++i)
    for (int j = 0; j <= nt; ++j)
      part.vertices.push_back(at(i, j).template cast<float>());
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < nt; ++j) {
      const auto a = static_cast<std::uint32_t>(i * (nt + 1) + j);
      const auto b = a + static_cast<std::uint32_t>(nt + 1);
      part.triangles.push_back({a, b, b + 1});
      part.triangles.push_back({a, b + 1, a + 1});
    }
  }
  part.normals.assign(part.vertices.size(), Eigen::Vector3f::UnitX());
  return part;
}

MeshPart flatSoil(double x) {
  return gridPart(PartKind::kSoil, 1, 1, [x](int i, int j) {
    return Eigen::Vector3d(x, -50.0 + 100.0 * j, 0.01 + 60.0 * i);
  });
}

TEST(MeshRenderer, DepthTruthIsWhereThePixelRayMeetsTheMeshes) {
  auto scene = buildScene(buildMeshScene(earlySpec(3)));
  ASSERT_TRUE(scene);
  const MeshCamera camera = scaled(calibratedCameras()[0], 0.25);
  MeshRenderOptions options;
  const MeshFrame frame = renderMeshFrame(*scene, camera, pixelRayMap(camera), options);
  int checked = 0;
  int plants = 0;
  for (int v = 3; v < camera.size.height; v += 7) {
    for (int u = 5; u < camera.size.width; u += 11) {
      const Eigen::Vector3d ray = pixelRay(camera, u, v);
      const RayHit hit = castRay(*scene, camera.position, ray);
      const float depth = frame.depth.at<float>(v, u);
      if (hit.part < 0) {
        EXPECT_EQ(depth, 0.0F) << u << "," << v;
        continue;
      }
      // castRay's distance is along the unit direction; the ray's camera z is 1 per unit of it.
      const double expected = hit.distance / ray.norm();
      EXPECT_NEAR(depth, expected, 1e-4 * expected + 1e-5) << u << "," << v;
      const MeshPart& part = scene->part(static_cast<unsigned>(hit.part));
      EXPECT_EQ(frame.plant.at<std::uint16_t>(v, u), part.plant_id) << u << "," << v;
      EXPECT_EQ(frame.plot.at<std::uint8_t>(v, u), static_cast<std::uint8_t>(part.plot));
      EXPECT_EQ(frame.vegetation.at<std::uint8_t>(v, u) != 0,
                isPlantPart(part.kind) || part.kind == PartKind::kFarCanopy);
      plants += part.plant_id != 0 ? 1 : 0;
      ++checked;
    }
  }
  EXPECT_GT(checked, 800);
  EXPECT_GT(plants, 100);  // the check covered plants, not only soil
}

TEST(MeshRenderer, FlatSoilShowsTheDepthTheCalibrationPredicts) {
  MeshScene flat;
  flat.parts.push_back(flatSoil(0.0));
  auto scene = buildScene(std::move(flat));
  ASSERT_TRUE(scene);
  // The bottom camera, 0.55 m above the plane: its lower half sees the soil.
  const MeshCamera camera = scaled(calibratedCameras()[0], 0.25);
  MeshRenderOptions options;
  options.samples_per_pixel = 1;
  const MeshFrame frame = renderMeshFrame(*scene, camera, pixelRayMap(camera), options);
  // Points on the plane, projected forward through the distortion model (cv::projectPoints, not
  // the renderer's inverse): the depth map, interpolated there, holds the point's depth.
  const Eigen::Matrix3d camera_from_plot = camera.plot_from_camera.transpose();
  std::vector<cv::Point3d> points;
  for (double z = 0.8; z <= 6.0; z += 0.2)
    for (double y = -0.8 * z; y <= 0.8 * z; y += 0.1 * z) {
      const Eigen::Vector3d c = camera_from_plot * (Eigen::Vector3d(0.0, y, z) - camera.position);
      points.emplace_back(c.x(), c.y(), c.z());
    }
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.camera_matrix,
                    camera.distortion, pixels);
  int checked = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double u = pixels[i].x;
    const double v = pixels[i].y;
    if (u < 1 || v < 1 || u > camera.size.width - 2 || v > camera.size.height - 2)
      continue;
    const int u0 = static_cast<int>(std::floor(u));
    const int v0 = static_cast<int>(std::floor(v));
    const double fu = u - u0;
    const double fv = v - v0;
    auto d = [&](int du, int dv) { return frame.depth.at<float>(v0 + dv, u0 + du); };
    const double depth =
        (1 - fv) * ((1 - fu) * d(0, 0) + fu * d(1, 0)) + fv * ((1 - fu) * d(0, 1) + fu * d(1, 1));
    EXPECT_NEAR(depth, points[i].z, 1e-3 * points[i].z) << u << "," << v;
    ++checked;
  }
  EXPECT_GT(checked, 200);
  // Above the horizon only sky.
  EXPECT_EQ(frame.depth.at<float>(0, camera.size.width / 2), 0.0F);
}

TEST(MeshRenderer, AStraightBarImagesAsTheCurveTheCalibrationsK1Makes) {
  // A thin horizontal bar along the row, 0.35 m above the bottom camera, 1.3 m away, against
  // the sky: straight in 3D, curved in the image by the lens.
  const MeshCamera camera = scaled(calibratedCameras()[0], 0.5);
  ASSERT_LT(camera.distortion.at<double>(0), -0.05);  // barrel: the calibration's k1
  const double x0 = camera.position.x() + 0.35;
  const double z0 = 1.3;
  const double r = 0.006;
  MeshScene bar;
  MeshPart part = gridPart(PartKind::kStem, 200, 12, [&](int i, int j) {
    const double a = 2.0 * std::numbers::pi * j / 12;
    return Eigen::Vector3d(x0 + r * std::cos(a), -1.2 + 2.4 * i / 200.0, z0 + r * std::sin(a));
  });
  part.plant_id = 1;
  bar.parts.push_back(std::move(part));
  auto scene = buildScene(std::move(bar));
  ASSERT_TRUE(scene);
  MeshRenderOptions options;
  const MeshFrame frame = renderMeshFrame(*scene, camera, pixelRayMap(camera), options);
  // The bar's centre row in every column where it shows.
  std::vector<cv::Point2d> path;
  for (int u = 0; u < camera.size.width; ++u) {
    double sum = 0.0;
    int count = 0;
    for (int v = 0; v < camera.size.height; ++v) {
      if (frame.plant.at<std::uint16_t>(v, u) == 1) {
        sum += v;
        ++count;
      }
    }
    if (count > 0)
      path.emplace_back(u, sum / count);
  }
  ASSERT_GT(path.size(), static_cast<std::size_t>(camera.size.width * 0.9));
  // Where the calibration puts the bar's axis: project points of it forward.
  const Eigen::Matrix3d camera_from_plot = camera.plot_from_camera.transpose();
  std::vector<cv::Point3d> axis;
  for (double y = -1.2; y <= 1.2; y += 0.005) {
    const Eigen::Vector3d c = camera_from_plot * (Eigen::Vector3d(x0, y, z0) - camera.position);
    axis.emplace_back(c.x(), c.y(), c.z());
  }
  std::vector<cv::Point2d> projected;
  cv::projectPoints(axis, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.camera_matrix,
                    camera.distortion, projected);
  auto expectedRow = [&](double u) {
    for (std::size_t i = 1; i < projected.size(); ++i) {
      const cv::Point2d& a = projected[i - 1];
      const cv::Point2d& b = projected[i];
      if ((a.x - u) * (b.x - u) <= 0 && a.x != b.x)
        return a.y + (u - a.x) / (b.x - a.x) * (b.y - a.y);
    }
    return std::nan("");
  };
  double worst = 0.0;
  for (const cv::Point2d& p : path) {
    const double expected = expectedRow(p.x);
    if (std::isnan(expected))
      continue;
    worst = std::max(worst, std::abs(p.y - expected));
  }
  // px at half resolution: the centre row of a 6 px band of whole pixels is good to half a pixel.
  EXPECT_LT(worst, 0.6);
  // And the path is not straight, as it would be through a pinhole: the chord between its ends
  // misses its middle by the sagitta k1 makes. Barrel distortion pulls the ends towards the
  // image centre (down, here), so the middle lies above (at a smaller row than) the chord.
  auto sagitta = [](double u0, double v0, double u1, double v1, double um, double vm) {
    return vm - (v0 + (um - u0) / (u1 - u0) * (v1 - v0));
  };
  // Each of the three points averaged over nine columns, measured and expected alike.
  auto averaged = [&](std::size_t centre, bool measured_path) {
    cv::Point2d sum(0, 0);
    for (std::size_t i = centre - 4; i <= centre + 4; ++i)
      sum += cv::Point2d(path[i].x, measured_path ? path[i].y : expectedRow(path[i].x));
    return sum / 9.0;
  };
  double measured = 0.0;
  double expected = 0.0;
  for (bool measured_path : {true, false}) {
    const cv::Point2d a = averaged(4, measured_path);
    const cv::Point2d b = averaged(path.size() - 5, measured_path);
    const cv::Point2d m = averaged(path.size() / 2, measured_path);
    (measured_path ? measured : expected) = sagitta(a.x, a.y, b.x, b.y, m.x, m.y);
  }
  EXPECT_LT(expected, -3.0);
  EXPECT_NEAR(measured, expected, 0.3);
}

TEST(MeshRenderer, RightCameraSeesTheLeftsTruthWhereTheCalibrationsRAndTPutIt) {
  // The bottom head at a quarter size: each left pixel's truth point, moved by the calibration's
  // R and T (OpenCV's convention, x_right = R x_left + T) and projected with the right camera's
  // own matrix and distortion, is what the right camera's truth shows there (but where the
  // other view is occluded). Through the calibration's rectification the two pixels share a row
  // and Q gives the point back: what the pipeline relies on.
  auto scene = buildScene(buildMeshScene(earlySpec(8)));
  ASSERT_TRUE(scene);
  const auto cameras = calibratedCameras();
  const MeshCamera left = scaled(cameras[0], 0.25);
  const MeshCamera right = scaled(cameras[1], 0.25);
  MeshRenderOptions options;
  options.samples_per_pixel = 1;
  const MeshFrame l = renderMeshFrame(*scene, left, pixelRayMap(left), options);
  const MeshFrame r = renderMeshFrame(*scene, right, pixelRayMap(right), options);
  const stereo::StereoCalibration calibration = calibratedRig().heads[0].stereo;
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(left.camera_matrix, left.distortion, right.camera_matrix, right.distortion,
                    left.size, calibration.R, calibration.T, r1, r2, p1, p2, q,
                    cv::CALIB_ZERO_DISPARITY, 0);
  const cv::Matx33d rotation(calibration.R);
  const cv::Vec3d translation(calibration.T);
  int compared = 0;
  int agreed = 0;
  double worst_row = 0.0;
  double worst_point = 0.0;
  for (int v = 2; v < left.size.height; v += 5) {
    for (int u = 3; u < left.size.width; u += 5) {
      const float depth = l.depth.at<float>(v, u);
      if (depth <= 0.0F || depth > 3.0F)
        continue;
      std::vector<cv::Point2d> pixel{{static_cast<double>(u), static_cast<double>(v)}};
      std::vector<cv::Point2d> normalised;
      cv::undistortPoints(
          pixel, normalised, left.camera_matrix, left.distortion, cv::noArray(), cv::noArray(),
          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-9));
      const cv::Vec3d in_left(normalised[0].x * depth, normalised[0].y * depth, depth);
      const cv::Vec3d in_right = rotation * in_left + translation;
      std::vector<cv::Point2d> projected;
      cv::projectPoints(std::vector<cv::Point3d>{cv::Point3d(in_right)}, cv::Vec3d(0, 0, 0),
                        cv::Vec3d(0, 0, 0), right.camera_matrix, right.distortion, projected);
      const int ur = static_cast<int>(std::floor(projected[0].x));
      const int vr = static_cast<int>(std::floor(projected[0].y));
      if (ur < 0 || vr < 0 || ur + 1 >= right.size.width || vr + 1 >= right.size.height)
        continue;
      // Compared where the right view shows one smooth surface around the point (interpolated
      // between the four pixel centres around it); elsewhere an edge or an occlusion decides.
      const float d00 = r.depth.at<float>(vr, ur);
      const float d10 = r.depth.at<float>(vr, ur + 1);
      const float d01 = r.depth.at<float>(vr + 1, ur);
      const float d11 = r.depth.at<float>(vr + 1, ur + 1);
      const float lo = std::min({d00, d10, d01, d11});
      const float hi = std::max({d00, d10, d01, d11});
      if (lo <= 0.0F || hi - lo > 0.01F * lo)
        continue;
      const double fu = projected[0].x - ur;
      const double fv = projected[0].y - vr;
      const double interpolated =
          (1 - fv) * ((1 - fu) * d00 + fu * d10) + fv * ((1 - fu) * d01 + fu * d11);
      // Nearer: something occludes the point in the right view (stems before the soil).
      // Further would mean the point is not where the right camera looks: a misplaced camera.
      if (interpolated < in_right[2] * (1.0 - 0.002))
        continue;
      ++compared;
      if (std::abs(interpolated - in_right[2]) < 0.002 * in_right[2])
        ++agreed;
      std::vector<cv::Point2d> rect_left;
      std::vector<cv::Point2d> rect_right;
      cv::undistortPoints(pixel, rect_left, left.camera_matrix, left.distortion, r1, p1);
      cv::undistortPoints(projected, rect_right, right.camera_matrix, right.distortion, r2, p2);
      worst_row = std::max(worst_row, std::abs(rect_left[0].y - rect_right[0].y));
      const double disparity = rect_left[0].x - rect_right[0].x;
      const cv::Matx44d qm(q);
      const cv::Vec4d h = qm * cv::Vec4d(rect_left[0].x, rect_left[0].y, disparity, 1.0);
      const cv::Vec3d reprojected(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
      const cv::Vec3d expected = cv::Matx33d(r1) * in_left;
      worst_point = std::max(worst_point, cv::norm(reprojected - expected));
    }
  }
  ASSERT_GT(compared, 1000);
  EXPECT_GT(agreed, 0.99 * compared) << agreed << " of " << compared;
  EXPECT_LT(worst_row, 0.05);    // px: the pair is rectified by the files as written
  EXPECT_LT(worst_point, 1e-3);  // m
}

TEST(MeshRenderer, SameSeedSameBytes) {
  const MeshCamera camera = scaled(calibratedCameras()[2], 0.25);
  const cv::Mat rays = pixelRayMap(camera);
  MeshRenderOptions options;
  options.noise_key = 99;
  auto first = buildScene(buildMeshScene(earlySpec(5)));
  auto second = buildScene(buildMeshScene(earlySpec(5)));
  ASSERT_TRUE(first && second);
  const MeshFrame a = renderMeshFrame(*first, camera, rays, options);
  const MeshFrame b = renderMeshFrame(*second, camera, rays, options);
  EXPECT_EQ(cv::norm(a.raw, b.raw, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.plant, b.plant, cv::NORM_INF), 0.0);
  // Another noise key changes the noise, not the scene.
  options.noise_key = 100;
  const MeshFrame c = renderMeshFrame(*first, camera, rays, options);
  EXPECT_GT(cv::norm(a.raw, c.raw, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, c.depth, cv::NORM_INF), 0.0);
  // Another seed changes the scene.
  auto other = buildScene(buildMeshScene(earlySpec(6)));
  ASSERT_TRUE(other);
  options.noise_key = 99;
  const MeshFrame d = renderMeshFrame(*other, camera, rays, options);
  EXPECT_GT(cv::norm(a.depth, d.depth, cv::NORM_L1), 0.0);
}

TEST(MeshRenderer, BayerFilterPassesTheSkysColoursWhereThePatternSays) {
  MeshScene empty;
  empty.parts.push_back(flatSoil(-100.0));  // far below: the camera sees only sky
  auto scene = buildScene(std::move(empty));
  ASSERT_TRUE(scene);
  const MeshCamera camera = scaled(calibratedCameras()[4], 0.25);
  MeshRenderOptions options;
  options.vignetting = 0.0;
  options.sky_gradient_dn = 0.0;
  options.sky_dn = Eigen::Vector3d(200.0, 120.0, 40.0);  // B, G, R
  options.pixel_format = core::PixelFormat::kBayerRG8;
  const MeshFrame frame = renderMeshFrame(*scene, camera, pixelRayMap(camera), options);
  double sum[2][2] = {{0, 0}, {0, 0}};
  for (int v = 0; v < frame.raw.rows; ++v)
    for (int u = 0; u < frame.raw.cols; ++u)
      sum[v % 2][u % 2] += frame.raw.at<std::uint8_t>(v, u);
  const double n = frame.raw.total() / 4.0;
  EXPECT_NEAR(sum[0][0] / n, 40.0, 0.5);   // R
  EXPECT_NEAR(sum[0][1] / n, 120.0, 0.5);  // G
  EXPECT_NEAR(sum[1][0] / n, 120.0, 0.5);  // G
  EXPECT_NEAR(sum[1][1] / n, 200.0, 0.5);  // B
}

TEST(MeshSession, TruthMapsBesideEachFrameAndTruthThatFitsTheMeshes) {
  testing_support::ScopedTempDir dir("mesh_session");
  PlotSeries series;
  series.count = 1;
  series.seed = 11;
  series.renderer = SceneRenderer::kMesh;
  series.stages = {GrowthStage::kEarly};
  auto recorded =
      recordSyntheticPlots(dir / "session", dir / "session" / "calib", series, {"plot-1"});
  ASSERT_TRUE(recorded.ok()) << recorded.error().message;
  ASSERT_EQ(recorded->size(), 1U);
  ASSERT_TRUE(recorded->front().mesh.has_value());

  auto reader = recording::SessionReader::open(dir / "session");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  ASSERT_EQ(reader->sets().size(), 1U);

  std::ifstream in(dir / "session" / "truth.jsonl");
  std::string text;
  ASSERT_TRUE(std::getline(in, text));
  const nlohmann::json line = nlohmann::json::parse(text);
  for (const char* field : {"plot",
                            "set",
                            "plant_height_m",
                            "height_m",
                            "width_m",
                            "vvi",
                            "z_min_m",
                            "z_max_m",
                            "visible_plant_area_m2",
                            "renderer",
                            "stage",
                            "status",
                            "vai",
                            "ega_m2",
                            "total_volume_m3",
                            "visible_area_in_box_m2",
                            "total_plant_area_m2",
                            "ground_x_m",
                            "view_top_m",
                            "exceeds_view",
                            "full",
                            "stereo_view",
                            "plants",
                            "plot_codes",
                            "truth_maps"}) {
    EXPECT_TRUE(line.contains(field)) << field;
  }
  EXPECT_EQ(line.at("status"), "ok");
  EXPECT_EQ(line.at("stage"), "early");
  EXPECT_FALSE(line.at("exceeds_view").get<bool>());

  // The same scene again: the truth must lie inside what the meshes span.
  const MeshScene scene = buildMeshScene(*recorded->front().mesh);
  double top = -1e9;
  double z_lo = 1e9;
  double z_hi = -1e9;
  for (const MeshPart& part : scene.parts) {
    if (part.plot != PlotCode::kThis || !isPlantPart(part.kind))
      continue;
    for (const Eigen::Vector3f& v : part.vertices) {
      top = std::max(top, static_cast<double>(v.x()));
      z_lo = std::min(z_lo, static_cast<double>(v.z()));
      z_hi = std::max(z_hi, static_cast<double>(v.z()));
    }
  }
  const double ground = line.at("ground_x_m").get<double>();
  EXPECT_NEAR(ground, scene.ground_x_m, 1e-12);
  const double height = line.at("height_m").get<double>();
  double lowest_plant = 1e9;
  for (const MeshPlant& plant : scene.plants)
    if (plant.plot == PlotCode::kThis)
      lowest_plant = std::min(lowest_plant, plant.height_m);
  EXPECT_GT(height, 0.8 * lowest_plant);
  EXPECT_LE(ground + height, top + 1e-6);
  EXPECT_GE(line.at("z_min_m").get<double>(), z_lo - 0.01);  // voxel centres: up to half a cm
  EXPECT_LE(line.at("z_max_m").get<double>(), z_hi + 0.01);
  EXPECT_GT(line.at("width_m").get<double>(), 0.1);
  EXPECT_LE(line.at("width_m").get<double>(), z_hi - z_lo + 0.01);
  EXPECT_GT(line.at("vvi").get<double>(), 0.0);
  EXPECT_LT(line.at("vvi").get<double>(), 1.0);
  EXPECT_GT(line.at("vai").get<double>(), 0.0);
  EXPECT_LE(line.at("visible_plant_area_m2").get<double>(),
            line.at("total_plant_area_m2").get<double>());
  EXPECT_GE(line.at("full").at("height_m").get<double>(), height - 0.02);
  // What both cameras of a head see is a part of what some camera sees, and most of it.
  const auto& stereo_view = line.at("stereo_view");
  EXPECT_EQ(stereo_view.at("status"), "ok");
  const double seen_area = line.at("visible_plant_area_m2").get<double>();
  const double stereo_area = stereo_view.at("visible_plant_area_m2").get<double>();
  EXPECT_LT(stereo_area, seen_area) << "every plot has plant only one camera of a pair sees";
  EXPECT_GT(stereo_area, 0.5 * seen_area);
  EXPECT_NEAR(stereo_view.at("height_m").get<double>(), height, 0.05);
  // Every plant of the plot, with stem diameters that shrink upwards and are stem-sized.
  const auto& plants = line.at("plants");
  EXPECT_EQ(plants.size(), 20U);  // 3 m at 0.15 m, none missing (the series' first plot)
  for (const auto& plant : plants) {
    const auto& stem = plant.at("stem");
    ASSERT_GE(stem.size(), 2U);
    for (const auto& section : stem) {
      EXPECT_GT(section.at("diameter_m").get<double>(), 0.005);
      EXPECT_LT(section.at("diameter_m").get<double>(), 0.05);
    }
    EXPECT_GT(stem.front().at("diameter_m").get<double>(),
              stem.back().at("diameter_m").get<double>());
  }

  // The truth maps: present for all six cameras, the frame's size, consistent with each other.
  const auto& maps = line.at("truth_maps");
  ASSERT_EQ(maps.size(), 6U);
  for (const auto& [camera, names] : maps.items()) {
    SCOPED_TRACE(camera);
    auto depth = stereo::readPfm(dir / "session" / names.at("depth").get<std::string>());
    ASSERT_TRUE(depth.ok()) << depth.error().message;
    const cv::Mat plant = cv::imread(
        (dir / "session" / names.at("plant").get<std::string>()).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat veg =
        cv::imread((dir / "session" / names.at("vegetation").get<std::string>()).string(),
                   cv::IMREAD_UNCHANGED);
    const cv::Mat plot = cv::imread(
        (dir / "session" / names.at("plot").get<std::string>()).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(depth->size(), cv::Size(1624, 1224));
    ASSERT_EQ(plant.type(), CV_16UC1);
    ASSERT_EQ(plant.size(), depth->size());
    ASSERT_EQ(veg.size(), depth->size());
    ASSERT_EQ(plot.size(), depth->size());
    int plant_pixels = 0;
    for (int v = 0; v < plant.rows; v += 4) {
      for (int u = 0; u < plant.cols; u += 4) {
        const bool is_plant = plant.at<std::uint16_t>(v, u) != 0;
        plant_pixels += is_plant && plot.at<std::uint8_t>(v, u) == 1 ? 1 : 0;
        if (is_plant) {
          EXPECT_EQ(veg.at<std::uint8_t>(v, u), 255);
          EXPECT_GT(depth->at<float>(v, u), 0.3F);
        }
      }
    }
    // The bottom head sees the early plot's 0.5–1 m plants; the top head looks over them.
    if (camera.starts_with("bottom")) {
      EXPECT_GT(plant_pixels, 10000);
    }
  }
}

}  // namespace
}  // namespace fieldrig::sim
