#include "fieldrig/sim/plot_generator.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <random>

namespace fieldrig::sim {
namespace {

using Vec3 = Eigen::Vector3d;
using SurfaceFn = std::function<Vec3(double s, double t)>;

// Densely samples surfaces: each parametric grid is split into triangles and each triangle gets
// samples in proportion to its area, so a sample's weight is its share of true surface area.
class SurfaceSampler {
 public:
  SurfaceSampler(double spacing, std::mt19937& rng, std::vector<PlotSample>& out)
      : per_m2_(1.0 / (spacing * spacing)), rng_(rng), out_(out) {}

  void addGrid(const SurfaceFn& fn, int ns, int nt, double s0, double s1, double t0, double t1,
               SurfaceLabel label) {
    std::vector<Vec3> grid(static_cast<std::size_t>((ns + 1) * (nt + 1)));
    for (int i = 0; i <= ns; ++i)
      for (int j = 0; j <= nt; ++j)
        grid[static_cast<std::size_t>(i * (nt + 1) + j)] =
            fn(s0 + (s1 - s0) * i / ns, t0 + (t1 - t0) * j / nt);
    auto at = [&](int i, int j) -> const Vec3& {
      return grid[static_cast<std::size_t>(i * (nt + 1) + j)];
    };
    for (int i = 0; i < ns; ++i) {
      for (int j = 0; j < nt; ++j) {
        addTriangle(at(i, j), at(i + 1, j), at(i + 1, j + 1), label);
        addTriangle(at(i, j), at(i + 1, j + 1), at(i, j + 1), label);
      }
    }
  }

  double area(SurfaceLabel label) const { return area_[static_cast<std::size_t>(label)]; }

 private:
  void addTriangle(const Vec3& a, const Vec3& b, const Vec3& c, SurfaceLabel label) {
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (area <= 0.0)
      return;
    area_[static_cast<std::size_t>(label)] += area;
    const double expected = area * per_m2_;
    int count = static_cast<int>(expected);
    if (uniform_(rng_) < expected - count)
      ++count;
    if (count == 0)
      return;
    const float weight = static_cast<float>(area / count);
    for (int k = 0; k < count; ++k) {
      double u = uniform_(rng_);
      double v = uniform_(rng_);
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      const Vec3 p = a + u * (b - a) + v * (c - a);
      out_.push_back({p.cast<float>(), weight, label});
    }
  }

  double per_m2_;
  std::mt19937& rng_;
  std::vector<PlotSample>& out_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::array<double, 6> area_{};
};

struct Plant {
  double y = 0.0;
  double z = 0.0;
  double height = 0.0;
};

void addPlant(SurfaceSampler& sampler, const PlotSpec& spec, const Plant& plant, bool background,
              std::mt19937& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double r = spec.stem_radius_m;
  const double stem_top = 0.88 * plant.height;
  const SurfaceLabel stem_label = background ? SurfaceLabel::kBackground : SurfaceLabel::kStem;
  const SurfaceLabel leaf_label = background ? SurfaceLabel::kBackground : SurfaceLabel::kLeaf;
  const SurfaceLabel whorl_label = background ? SurfaceLabel::kBackground : SurfaceLabel::kWhorl;
  const double two_pi = 2.0 * std::numbers::pi;
  sampler.addGrid(
      [&](double a, double x) {
        return Vec3(x, plant.y + r * std::cos(a), plant.z + r * std::sin(a));
      },
      16, std::max(4, static_cast<int>(stem_top / 0.05)), 0.0, two_pi, 0.0, stem_top, stem_label);
  // The whorl (or panicle): a spindle on top of the stem up to the plant's height.
  const double whorl_radius = 0.035;
  sampler.addGrid(
      [&](double a, double u) {
        const double radius =
            r + (whorl_radius - r) * std::pow(std::sin(std::numbers::pi * u), 0.7);
        return Vec3(stem_top + u * (plant.height - stem_top), plant.y + radius * std::cos(a),
                    plant.z + radius * std::sin(a));
      },
      16, 10, 0.0, two_pi, 0.0, 1.0, whorl_label);
  // Arching leaves: the midrib leaves the stem at a steep angle and droops with constant
  // curvature; the blade is twisted so that the leaves show every orientation to the cameras.
  const int leaves = std::clamp(spec.leaves_per_plant, 0, 30);
  const double scale = plant.height / 2.0;
  for (int k = 0; k < leaves; ++k) {
    const double attach =
        (0.15 + 0.7 * (leaves > 1 ? static_cast<double>(k) / (leaves - 1) : 0.5)) * stem_top;
    const double phi = two_pi * uni(rng);
    const double theta0 = 0.9 + 0.4 * uni(rng);
    const double length = spec.leaf_length_m * std::min(1.3, scale) *
                          (0.6 + 0.4 * std::sin(std::numbers::pi * (k + 1.0) / (leaves + 1.0))) *
                          (0.85 + 0.3 * uni(rng));
    const double kappa = 1.6 + 0.8 * uni(rng);  // total turn of the midrib, radians
    const double twist = 0.3 + 0.9 * uni(rng);
    const Vec3 up(1.0, 0.0, 0.0);
    const Vec3 dir(0.0, std::cos(phi), std::sin(phi));
    const Vec3 side = dir.cross(up).normalized();
    const Vec3 base(attach, plant.y, plant.z);
    const double width = spec.leaf_width_m * (0.8 + 0.4 * uni(rng));
    auto midrib = [=](double s) {
      const double turn = kappa * s;
      const double along =
          turn < 1e-9 ? s * std::cos(theta0) : (std::sin(theta0) - std::sin(theta0 - turn)) / kappa;
      const double rise =
          turn < 1e-9 ? s * std::sin(theta0) : (std::cos(theta0 - turn) - std::cos(theta0)) / kappa;
      Vec3 p = base + length * (along * dir + rise * up);
      p.x() = std::max(p.x(), 0.03);
      return p;
    };
    sampler.addGrid(
        [=](double s, double t) {
          const double theta = theta0 - kappa * s;
          const Vec3 tangent = std::cos(theta) * dir + std::sin(theta) * up;
          const Vec3 normal = tangent.cross(side).normalized();
          const double psi = twist * s;
          const Vec3 lateral = std::cos(psi) * side + std::sin(psi) * normal;
          const double w = width * (0.25 + 0.75 * std::pow(std::sin(std::numbers::pi * s), 0.6));
          return Vec3(midrib(s) + t * w * lateral);
        },
        30, 4, 0.0, 1.0, -0.5, 0.5, leaf_label);
  }
}

double soilHeight(const PlotSpec& spec, double y, double z) {
  const double tilt = std::tan(spec.ground_tilt_deg * std::numbers::pi / 180.0);
  const double bump =
      spec.soil_roughness_m * std::sin(7.0 * y + 1.3) * std::sin(5.0 * (z - spec.row_depth_m));
  return tilt * (z - spec.row_depth_m) + bump;
}

bool isRowPlant(SurfaceLabel label) {
  return label == SurfaceLabel::kStem || label == SurfaceLabel::kLeaf ||
         label == SurfaceLabel::kWhorl;
}

std::array<std::uint8_t, 3> colorOf(SurfaceLabel label, std::mt19937& rng) {
  std::uniform_int_distribution<int> jitter(-12, 12);
  auto c = [&](int v) { return static_cast<std::uint8_t>(std::clamp(v + jitter(rng), 0, 255)); };
  switch (label) {
    case SurfaceLabel::kSoil:
      return {c(110), c(85), c(60)};
    case SurfaceLabel::kStem:
      return {c(95), c(150), c(60)};
    case SurfaceLabel::kLeaf:
      return {c(60), c(140), c(50)};
    case SurfaceLabel::kWhorl:
      return {c(150), c(140), c(70)};
    case SurfaceLabel::kBackground:
      return {c(50), c(110), c(45)};
    case SurfaceLabel::kOutlier:
      break;
  }
  std::uniform_int_distribution<int> any(0, 255);
  return {static_cast<std::uint8_t>(any(rng)), static_cast<std::uint8_t>(any(rng)),
          static_cast<std::uint8_t>(any(rng))};
}

}  // namespace

PlotCloud generatePlot(const PlotSpec& spec) {
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<PlotSample> samples;
  SurfaceSampler sampler(std::max(spec.sample_spacing_m, 5e-4), rng, samples);
  PlotCloud cloud;
  PlotTruth& truth = cloud.truth;
  truth.base_depth_m = spec.row_depth_m;
  truth.ground_x_m = soilHeight(spec, 0.0, spec.row_depth_m);

  const double half = spec.row_length_m / 2.0;
  const int plants = std::clamp(
      static_cast<int>(std::lround(spec.row_length_m / std::max(spec.plant_spacing_m, 0.02))), 1,
      200);
  double tallest = spec.plant_height_m;
  if (spec.plants) {
    for (int i = 0; i < plants; ++i) {
      if (std::find(spec.missing_plants.begin(), spec.missing_plants.end(), i) !=
          spec.missing_plants.end())
        continue;
      Plant plant;
      plant.y = -half + (i + 0.5) * spec.plant_spacing_m + 0.02 * (uni(rng) - 0.5);
      plant.z = spec.row_depth_m + 0.03 * (uni(rng) - 0.5);
      plant.height = spec.plant_height_m * (0.97 + 0.06 * uni(rng)) *
                     (i == spec.tall_plant ? spec.tall_plant_factor : 1.0);
      tallest = std::max(tallest, plant.height);
      truth.plant_y_m.push_back(plant.y);
      truth.plant_height_m.push_back(plant.height);
      addPlant(sampler, spec, plant, false, rng);
    }
    // The next row behind, seen through the gaps; a crop by depth must remove it.
    for (int i = 0; i < plants + 4; ++i) {
      Plant plant;
      plant.y = -half - 2 * spec.plant_spacing_m + (i + 0.5) * spec.plant_spacing_m;
      plant.z = spec.row_depth_m + spec.background_row_offset_m;
      plant.height = spec.plant_height_m * (0.9 + 0.2 * uni(rng));
      addPlant(sampler, spec, plant, true, rng);
    }
  }
  truth.total_plant_area_m2 = sampler.area(SurfaceLabel::kStem) +
                              sampler.area(SurfaceLabel::kLeaf) +
                              sampler.area(SurfaceLabel::kWhorl);
  if (spec.soil) {
    const double y0 = -half - 0.5;
    const double y1 = half + 0.5;
    const double z0 = 0.3;
    const double z1 = spec.row_depth_m + spec.background_row_offset_m + 0.5;
    sampler.addGrid([&](double y, double z) { return Vec3(soilHeight(spec, y, z), y, z); },
                    static_cast<int>((y1 - y0) / 0.02), static_cast<int>((z1 - z0) / 0.02), y0, y1,
                    z0, z1, SurfaceLabel::kSoil);
  }

  // Visibility: one z-buffer per head. Samples are splatted over the pixels their spacing covers
  // so that the surface behind cannot show through gaps between samples.
  const int heads = std::clamp(spec.camera_heads, 1, 6);
  const double f = spec.row_depth_m / std::max(spec.pixel_at_row_m, 1e-4);
  const double tan_u = (half + 0.1) / spec.row_depth_m;
  const double tan_v = 1.5;
  const int width = 2 * static_cast<int>(std::ceil(f * tan_u)) + 1;
  const int height = 2 * static_cast<int>(std::ceil(f * tan_v)) + 1;
  const double depth_tolerance = 0.012;
  std::vector<int> first_head(samples.size(), -1);
  std::vector<float> zbuf(static_cast<std::size_t>(width) * height);
  const double camera_top = 1.1 * tallest;
  for (int head = 0; head < heads; ++head) {
    const double cx = camera_top * (head + 0.5) / heads;
    std::fill(zbuf.begin(), zbuf.end(), std::numeric_limits<float>::infinity());
    auto project = [&](const Eigen::Vector3f& p, int& u, int& v) {
      if (p.z() < 0.1F)
        return false;
      u = static_cast<int>(std::floor(f * p.y() / p.z())) + width / 2;
      v = static_cast<int>(std::floor(f * (p.x() - cx) / p.z())) + height / 2;
      return u >= 0 && u < width && v >= 0 && v < height;
    };
    for (const PlotSample& s : samples) {
      int u = 0;
      int v = 0;
      if (!project(s.position, u, v))
        continue;
      const int radius = static_cast<int>(f * spec.sample_spacing_m / s.position.z());
      for (int dv = -radius; dv <= radius; ++dv) {
        for (int du = -radius; du <= radius; ++du) {
          const int uu = u + du;
          const int vv = v + dv;
          if (uu < 0 || uu >= width || vv < 0 || vv >= height)
            continue;
          float& z = zbuf[static_cast<std::size_t>(vv) * width + uu];
          z = std::min(z, s.position.z());
        }
      }
    }
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (first_head[i] >= 0)
        continue;
      int u = 0;
      int v = 0;
      if (!project(samples[i].position, u, v))
        continue;
      if (samples[i].position.z() <=
          zbuf[static_cast<std::size_t>(v) * width + u] + depth_tolerance)
        first_head[i] = head;
    }
  }

  std::normal_distribution<double> noise(0.0, spec.depth_noise_m);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (first_head[i] < 0)
      continue;
    const PlotSample& s = samples[i];
    if (isRowPlant(s.label)) {
      truth.visible_plant_area_m2 += s.area_m2;
      truth.visible_plant_samples.push_back(s);
    }
    const double cx = camera_top * (first_head[i] + 0.5) / heads;
    const Vec3 p = s.position.cast<double>();
    const Vec3 ray = (p - Vec3(cx, 0.0, 0.0)).normalized();
    cloud.points.push_back((p + noise(rng) * ray).cast<float>());
    cloud.labels.push_back(s.label);
    cloud.colors.push_back(colorOf(s.label, rng));
  }
  const auto outliers = static_cast<std::size_t>(std::max(0.0, spec.outlier_fraction) *
                                                 static_cast<double>(cloud.points.size()));
  for (std::size_t i = 0; i < outliers; ++i) {
    cloud.points.emplace_back(static_cast<float>(-0.2 + uni(rng) * (tallest + 0.4)),
                              static_cast<float>((uni(rng) - 0.5) * (spec.row_length_m + 0.6)),
                              static_cast<float>(0.4 + uni(rng) * (spec.row_depth_m + 0.4)));
    cloud.labels.push_back(SurfaceLabel::kOutlier);
    cloud.colors.push_back(colorOf(SurfaceLabel::kOutlier, rng));
  }
  return cloud;
}

void subsamplePlot(PlotCloud& cloud, std::size_t count, std::uint32_t seed) {
  if (cloud.points.size() <= count)
    return;
  std::vector<std::size_t> order(cloud.points.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::mt19937 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(count);
  std::sort(order.begin(), order.end());
  PlotCloud kept;
  kept.truth = std::move(cloud.truth);
  for (std::size_t i : order) {
    kept.points.push_back(cloud.points[i]);
    kept.colors.push_back(cloud.colors[i]);
    kept.labels.push_back(cloud.labels[i]);
  }
  cloud = std::move(kept);
}

}  // namespace fieldrig::sim
