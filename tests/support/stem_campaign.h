// The accuracy campaign of the stem measurement, shared by its test (a small sample, asserting
// the targets) and its benchmark (the full table): rendered cylinders of known diameter and
// distance, four clicks per measurement placed on the true silhouette at random heights and
// jittered as a person's hand would, measured with and without edge refinement and with the
// plane (eq. 13) or cylinder model.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fieldrig/sim/cylinder_stereo_renderer.h"
#include "fieldrig/stem/stem_measurer.h"

namespace fieldrig::testing_support {

struct StemCase {
  sim::StereoRigGeometry geometry;
  sim::CylinderScene scene;
};

// Cylinders of 8–32 mm at 0.8–1.5 m: every combination of the lists, each with its own seed,
// lateral position, lean, and (every other one) lens distortion and a turned right camera.
inline std::vector<StemCase> makeStemCases(const std::vector<double>& diameters_mm,
                                           const std::vector<double>& depths_m,
                                           std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> lateral(-0.15, 0.15);
  std::uniform_real_distribution<double> lean(-0.08, 0.08);
  std::vector<StemCase> cases;
  for (double diameter : diameters_mm) {
    for (double depth : depths_m) {
      StemCase c;
      c.geometry.distorted = cases.size() % 2 == 1;
      if (c.geometry.distorted)
        c.geometry.right_rotation = cv::Vec3d(0.004, -0.012, 0.003);
      c.scene.diameter_m = diameter / 1000.0;
      c.scene.depth_m = depth;
      c.scene.axis_x_m = lateral(rng) * depth;
      c.scene.tilt_rad = lean(rng);
      c.scene.seed = rng();
      cases.push_back(c);
    }
  }
  return cases;
}

// Four clicks on the true silhouette: the left edge at two heights, the right edge at two
// others (a person does not click exactly across), each jittered by `jitter_px` (SD, x and y).
inline stem::Points4 jitteredClicks(const StemCase& c, double jitter_px, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> height(-0.045, 0.045);
  std::uniform_real_distribution<double> span(0.03, 0.06);
  std::normal_distribution<double> jitter(0.0, jitter_px);
  const double centre = height(rng);
  const double half = span(rng) / 2.0;
  std::uniform_real_distribution<double> wobble(-0.008, 0.008);
  stem::Points4 points{sim::silhouettePoint(c.geometry, c.scene, -1, centre - half + wobble(rng)),
                       sim::silhouettePoint(c.geometry, c.scene, -1, centre + half + wobble(rng)),
                       sim::silhouettePoint(c.geometry, c.scene, +1, centre - half + wobble(rng)),
                       sim::silhouettePoint(c.geometry, c.scene, +1, centre + half + wobble(rng))};
  for (cv::Point2d& p : points)
    p += cv::Point2d(jitter(rng), jitter(rng));
  // Any order: the tool sorts them.
  std::shuffle(points.begin(), points.end(), rng);
  return points;
}

struct MethodStats {
  double mae_mm = 0.0;      // mean |error| of single measurements
  double bias_mm = 0.0;     // mean error of single measurements
  double r = 0.0;           // Pearson r, per-stem means of the repeats against the truth
  double mean_sd_mm = 0.0;  // mean over stems of the SD of the repeats
  double max_sd_mm = 0.0;
  int refused = 0;  // measurements that did not return kOk
  int measured = 0;
  double mean_ms = 0.0;
  double max_ms = 0.0;
  // Where the matched patch's depth lies in front of the axis, in radii (the cylinder model's
  // near_surface_radii is this, measured): mean over the measurements.
  double patch_depth_radii = 0.0;
};

struct StemMethod {
  const char* name;
  stem::MeasureOptions options;
};

inline std::vector<StemMethod> stemMethods() {
  std::vector<StemMethod> methods;
  stem::MeasureOptions paper;
  paper.refine_edges = false;
  paper.cylinder_model = false;
  methods.push_back({"paper (clicks as given, eq. 13 plane)", paper});
  stem::MeasureOptions face = paper;
  face.cylinder_model = true;
  methods.push_back({"clicks as given, cylinder model", face});
  stem::MeasureOptions refined_plane;
  refined_plane.cylinder_model = false;
  methods.push_back({"sub-pixel edges, eq. 13 plane", refined_plane});
  methods.push_back({"sub-pixel edges, cylinder model (default)", stem::MeasureOptions{}});
  return methods;
}

// Measures every case `repeats` times with each method (the same clicks for every method).
inline std::vector<MethodStats> runStemCampaign(const std::vector<StemCase>& cases, int repeats,
                                                double jitter_px, std::uint64_t seed,
                                                const std::vector<StemMethod>& methods) {
  std::mt19937_64 rng(seed);
  const std::size_t n = methods.size();
  std::vector<MethodStats> stats(n);
  std::vector<std::vector<double>> stem_means(n), truths(n);
  std::vector<double> sum_sd(n, 0.0), sum_ms(n, 0.0);
  std::vector<int> stems_with_repeats(n, 0);
  for (const StemCase& c : cases) {
    const sim::RenderedStereoPair pair = sim::renderCylinderPair(c.geometry, c.scene);
    auto measurer = stem::StemMeasurer::create(pair.calibration, pair.left, pair.right);
    if (!measurer)
      continue;
    std::vector<stem::Points4> clicks;
    for (int k = 0; k < repeats; ++k)
      clicks.push_back(jitteredClicks(c, jitter_px, rng));
    const double truth = c.scene.diameter_m * 1000.0;
    for (std::size_t m = 0; m < n; ++m) {
      std::vector<double> values;
      for (const stem::Points4& points : clicks) {
        const stem::StemMeasurement result = measurer->measure(points, methods[m].options);
        sum_ms[m] += result.elapsed_ms;
        stats[m].max_ms = std::max(stats[m].max_ms, result.elapsed_ms);
        if (!result.ok()) {
          ++stats[m].refused;
          continue;
        }
        ++stats[m].measured;
        values.push_back(result.diameter_mm);
        stats[m].mae_mm += std::abs(result.diameter_mm - truth);
        stats[m].patch_depth_radii +=
            (c.scene.depth_m - result.patch_depth_m) / (c.scene.diameter_m / 2.0);
        stats[m].bias_mm += result.diameter_mm - truth;
      }
      if (values.empty())
        continue;
      double mean = 0.0;
      for (double v : values)
        mean += v;
      mean /= static_cast<double>(values.size());
      stem_means[m].push_back(mean);
      truths[m].push_back(truth);
      if (values.size() > 1) {
        double squares = 0.0;
        for (double v : values)
          squares += (v - mean) * (v - mean);
        const double sd = std::sqrt(squares / static_cast<double>(values.size() - 1));
        sum_sd[m] += sd;
        stats[m].max_sd_mm = std::max(stats[m].max_sd_mm, sd);
        ++stems_with_repeats[m];
      }
    }
  }
  for (std::size_t m = 0; m < n; ++m) {
    MethodStats& s = stats[m];
    const int total = s.measured + s.refused;
    if (s.measured > 0) {
      s.mae_mm /= s.measured;
      s.patch_depth_radii /= s.measured;
      s.bias_mm /= s.measured;
    }
    if (total > 0)
      s.mean_ms = sum_ms[m] / total;
    if (stems_with_repeats[m] > 0)
      s.mean_sd_mm = sum_sd[m] / stems_with_repeats[m];
    const std::vector<double>& x = truths[m];
    const std::vector<double>& y = stem_means[m];
    if (x.size() > 2) {
      double mx = 0.0, my = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        mx += x[i];
        my += y[i];
      }
      mx /= static_cast<double>(x.size());
      my /= static_cast<double>(y.size());
      double sxy = 0.0, sxx = 0.0, syy = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
      }
      s.r = sxy / std::sqrt(sxx * syy);
    }
  }
  return stats;
}

}  // namespace fieldrig::testing_support
