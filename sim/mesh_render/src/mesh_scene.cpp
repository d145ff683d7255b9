#include "fieldrig/sim/mesh_scene.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

#include "value_noise.h"

namespace fieldrig::sim {
namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;
const Vec3 kUp(1.0, 0.0, 0.0);

// Horizontal unit vector at azimuth `a` in the (y, z) plane: 0 along +y, π/2 away from camera.
Vec3 horizontal(double a) {
  return {0.0, std::cos(a), std::sin(a)};
}

// Builds a part from parametric grids; normals are computed once the part is complete.
class PartBuilder {
 public:
  explicit PartBuilder(MeshPart& part) : part_(part) {}

  // A grid of (ns + 1) × (nt + 1) points at(i, j); with wrap_t the last column joins the first
  // (closed surfaces: no seam in the normals), so `at` is called for j < nt only.
  template <typename At>
  void grid(int ns, int nt, bool wrap_t, At at) {
    const auto first = static_cast<std::uint32_t>(part_.vertices.size());
    const int columns = wrap_t ? nt : nt + 1;
    for (int i = 0; i <= ns; ++i)
      for (int j = 0; j < columns; ++j)
        part_.vertices.push_back(at(i, j).template cast<float>());
    auto index = [&](int i, int j) {
      return first + static_cast<std::uint32_t>(i * columns + (wrap_t ? j % nt : j));
    };
    for (int i = 0; i < ns; ++i) {
      for (int j = 0; j < nt; ++j) {
        part_.triangles.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1)});
        part_.triangles.push_back({index(i, j), index(i + 1, j + 1), index(i, j + 1)});
      }
    }
  }

  // A fan closing a ring of `count` vertices starting at `first_ring` with an apex.
  void fan(std::uint32_t first_ring, int count, const Vec3& apex) {
    const auto centre = static_cast<std::uint32_t>(part_.vertices.size());
    part_.vertices.push_back(apex.cast<float>());
    for (int j = 0; j < count; ++j) {
      part_.triangles.push_back({first_ring + static_cast<std::uint32_t>(j),
                                 first_ring + static_cast<std::uint32_t>((j + 1) % count), centre});
    }
  }

 private:
  MeshPart& part_;
};

// Area-weighted vertex normals; degenerate triangles are dropped first.
void finishPart(MeshPart& part) {
  std::erase_if(part.triangles, [&](const std::array<std::uint32_t, 3>& t) {
    const Eigen::Vector3f& a = part.vertices[t[0]];
    return (part.vertices[t[1]] - a).cross(part.vertices[t[2]] - a).squaredNorm() < 1e-18F;
  });
  part.normals.assign(part.vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& t : part.triangles) {
    const Eigen::Vector3f& a = part.vertices[t[0]];
    const Eigen::Vector3f n = (part.vertices[t[1]] - a).cross(part.vertices[t[2]] - a);
    for (std::uint32_t v : t)
      part.normals[v] += n;
  }
  for (Eigen::Vector3f& n : part.normals) {
    const float length = n.norm();
    n = length > 0.0F ? Eigen::Vector3f(n / length) : Eigen::Vector3f::UnitX();
  }
}

struct PlantShape {
  GrowthStage stage = GrowthStage::kMid;
  double height = 2.0;
  Vec3 base = Vec3::Zero();
  double stem_radius = 0.012;  // at the base
  int leaves = 12;
  double leaf_length = 0.8;
  double leaf_width = 0.08;
  double azimuth = 0.0;  // of the leaves' plane (distichous, alternating)
  bool detailed = true;
};

// Everything random about a plant is drawn here, so that its geometry is a pure function of the
// shape and this generator.
struct PlantBuild {
  PlantBuild(const MeshPlotSpec& s, const PlantShape& p, std::mt19937& r, MeshScene& sc,
             MeshPlant& pl)
      : spec(s), shape(p), rng(r), scene(sc), plant(pl) {}

  const MeshPlotSpec& spec;
  PlantShape shape;
  std::mt19937& rng;
  MeshScene& scene;
  MeshPlant& plant;

  double uni() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }
  double gauss() { return std::normal_distribution<double>(0.0, 1.0)(rng); }

  // Stem geometry: a gently leaning axis, the radius tapering upwards with swollen nodes.
  double stem_top = 0.0;
  double peduncle_from = 0.0;  // mature: above this the stem is the thin peduncle
  Vec3 lean = Vec3::Zero();
  std::vector<double> nodes;

  Vec3 axis(double h) const {
    const double t = std::clamp(h / std::max(stem_top, 0.05), 0.0, 1.2);
    return shape.base + h * kUp + lean * t * t;
  }
  double radius(double h) const {
    const double r0 = shape.stem_radius;
    double r = r0 * (1.0 - 0.45 * std::clamp(h / std::max(stem_top, 0.05), 0.0, 1.0));
    if (peduncle_from > 0.0 && h > peduncle_from)
      r = std::max(0.45 * r0, r * std::exp(-(h - peduncle_from) / 0.03));
    for (double node : nodes)
      r *= 1.0 + 0.08 * std::exp(-std::pow((h - node) / 0.012, 2.0));
    return r;
  }

  void build();
  void addStem();
  void addLeaf(int k, double node_h, double length, double width, double elevation_deg,
               double droop, double azimuth, bool dry);
  void addWhorl();
  void addPanicle();
  MeshPart& newPart(PartKind kind, const Material& material) {
    MeshPart& part = scene.parts.emplace_back();
    part.kind = kind;
    part.plot = plant.plot;
    part.plant_id = plant.id;
    part.material = material;
    return part;
  }
};

Material leafMaterial(double jitter, bool dry) {
  Material m;
  if (dry) {
    m.albedo = Eigen::Vector3f(0.32F, 0.26F, 0.13F);
  } else {
    m.albedo = Eigen::Vector3f(0.085F, 0.20F, 0.05F);
  }
  m.albedo *= static_cast<float>(jitter);
  m.texture_contrast = 0.42F;
  m.texture_cell_m = 0.004F;
  m.translucency = dry ? 0.05F : 0.25F;
  return m;
}

void PlantBuild::build() {
  const double h = shape.height;
  if (shape.stage == GrowthStage::kMature) {
    const double panicle_length = 0.2 + 0.1 * uni();
    stem_top = h - panicle_length;
    peduncle_from = stem_top - (0.1 + 0.1 * uni());
  } else {
    stem_top = h - (0.1 + 0.05 * h);
  }
  const double lean_amount =
      std::clamp(0.012 * stem_top * gauss(), -0.05 * stem_top, 0.05 * stem_top);
  lean = lean_amount * horizontal(2.0 * kPi * uni());
  // Leaf nodes: short internodes at the bottom, longer above; the flag leaf of a mature plant
  // sits below its peduncle.
  const int n = shape.leaves;
  const double node_top = peduncle_from > 0.0 ? peduncle_from : stem_top - 0.02;
  for (int k = 0; k < n; ++k) {
    const double f = std::pow((k + 1.0) / n, 1.3);
    nodes.push_back(std::max(0.03, node_top * (0.04 + 0.96 * f)));
  }
  addStem();
  for (int k = 0; k < n; ++k) {
    const double rel = n > 1 ? static_cast<double>(k) / (n - 1) : 0.5;
    double length = shape.leaf_length *
                    (0.55 + 0.45 * std::pow(std::sin(kPi * (k + 1.0) / (n + 1.0)), 0.7)) *
                    (0.9 + 0.2 * uni());
    double width = shape.leaf_width * (0.7 + 0.3 * std::sin(kPi * (k + 1.0) / (n + 1.0))) *
                   (0.9 + 0.2 * uni());
    double elevation = 40.0 + 30.0 * rel + 8.0 * gauss();
    double droop = (0.6 + 1.6 * length) * (0.75 + 0.5 * uni()) * (1.0 - 0.4 * rel);
    bool dry = false;
    if (shape.stage != GrowthStage::kMature && k >= n - 2) {
      // The youngest leaves leave the whorl nearly upright: they often reach above it.
      length *= 0.55 + 0.15 * uni();
      width *= 0.8;
      elevation = 72.0 + 8.0 * uni();
      droop *= 0.4;
    }
    if (shape.stage == GrowthStage::kMature && k < 3) {
      dry = true;  // the lowest leaves of a mature plant are dry, some broken short
      droop *= 1.4;
      length *= 0.6 + 0.4 * uni();
    }
    const double azimuth = shape.azimuth + (k % 2 ? kPi : 0.0) + 0.35 * gauss();
    addLeaf(k, nodes[static_cast<std::size_t>(k)], length, width, elevation, droop, azimuth, dry);
  }
  if (shape.stage == GrowthStage::kMature)
    addPanicle();
  else
    addWhorl();

  for (double section : scene.stem_section_heights_m) {
    if (section > stem_top - 0.05)
      continue;
    plant.stem.push_back({section, 2.0 * radius(section), axis(section)});
  }
}

void PlantBuild::addStem() {
  Material m;
  m.albedo = Eigen::Vector3f(0.16F, 0.25F, 0.08F) * static_cast<float>(0.9 + 0.2 * uni());
  m.texture_contrast = 0.3F;
  m.texture_cell_m = 0.004F;
  MeshPart& part = newPart(PartKind::kStem, m);
  const int segments = shape.detailed ? 12 : 6;
  const double step = shape.detailed ? 0.025 : 0.1;
  const double h0 = -0.05;  // from below the soil, so slopes and clods never show its end
  const int rings = std::max(2, static_cast<int>(std::ceil((stem_top - h0) / step)));
  PartBuilder builder(part);
  builder.grid(rings, segments, true, [&](int i, int j) {
    const double hh = h0 + (stem_top - h0) * i / rings;
    const double a = 2.0 * kPi * j / segments;
    return Vec3(axis(hh) + radius(hh) * horizontal(a));
  });
  builder.fan(static_cast<std::uint32_t>(rings * segments), segments,
              axis(stem_top) + 0.3 * radius(stem_top) * kUp);
  finishPart(part);
}

void PlantBuild::addLeaf(int k, double node_h, double length, double width, double elevation_deg,
                         double droop, double azimuth, bool dry) {
  MeshPart& part = newPart(PartKind::kLeaf, leafMaterial(0.85 + 0.3 * uni(), dry));
  const int ns = shape.detailed ? 32 : 10;
  const int nt = shape.detailed ? 4 : 2;
  const double e0 = elevation_deg * kPi / 180.0;
  const double bend = 0.3 * gauss();  // the midrib curves sideways a little
  const double twist = (0.2 + 0.8 * uni()) * (uni() < 0.5 ? -1.0 : 1.0);
  const double fold = 0.15 + 0.2 * uni();  // V of the blade about the midrib, rise per half-width
  const double wave_amplitude = (shape.detailed ? 1.0 : 0.0) * (0.002 + 0.004 * uni());
  const double wave_length = 0.05 + 0.04 * uni();
  const double wave_phase = 2.0 * kPi * uni();
  // The midrib, integrated in ns steps from the stem surface.
  std::vector<Vec3> mid(static_cast<std::size_t>(ns + 1));
  std::vector<Vec3> tangent(mid.size());
  std::vector<Vec3> lateral(mid.size());
  mid[0] = axis(node_h) + radius(node_h) * horizontal(azimuth);
  for (int i = 0; i <= ns; ++i) {
    const double s = static_cast<double>(i) / ns;
    const double e = e0 - droop * std::pow(s, 1.4);
    const double a = azimuth + bend * s;
    const Vec3 t = std::cos(e) * horizontal(a) + std::sin(e) * kUp;
    const Vec3 side = horizontal(a + kPi / 2.0);
    const double psi = twist * s;
    // Lateral direction twisted about the midrib.
    const Vec3 normal = t.cross(side).normalized();
    tangent[static_cast<std::size_t>(i)] = t;
    lateral[static_cast<std::size_t>(i)] = std::cos(psi) * side + std::sin(psi) * normal;
    if (i > 0) {
      const double se = e0 - droop * std::pow((i - 0.5) / ns, 1.4);
      const Vec3 ts =
          std::cos(se) * horizontal(azimuth + bend * (i - 0.5) / ns) + std::sin(se) * kUp;
      mid[static_cast<std::size_t>(i)] = mid[static_cast<std::size_t>(i - 1)] + (length / ns) * ts;
    }
  }
  auto widthAt = [&](double s) {
    const double grow = 0.45 + 0.55 * std::sin(0.5 * kPi * std::min(s / 0.6, 1.0));
    const double taper = s < 0.6 ? 1.0 : std::pow((1.0 - s) / 0.4, 0.7);
    return width * grow * taper;
  };
  (void)k;
  PartBuilder builder(part);
  builder.grid(ns, nt, false, [&](int i, int j) {
    const double s = static_cast<double>(i) / ns;
    const double t = -1.0 + 2.0 * j / nt;
    const auto si = static_cast<std::size_t>(i);
    const Vec3 normal = tangent[si].cross(lateral[si]).normalized();
    const double half = 0.5 * widthAt(s);
    const double wave =
        wave_amplitude * t * t * std::sin(2.0 * kPi * s * length / wave_length + wave_phase + t);
    Vec3 p = mid[si] + lateral[si] * (t * half) + normal * (fold * std::abs(t) * half + wave);
    // Leaves rest on the soil rather than pass through it.
    const double floor = soilHeight(spec, p.y(), p.z()) + 0.01;
    p.x() = std::max(p.x(), floor);
    return p;
  });
  finishPart(part);
}

void PlantBuild::addWhorl() {
  Material m;
  m.albedo = Eigen::Vector3f(0.11F, 0.25F, 0.07F);
  m.texture_contrast = 0.35F;
  m.translucency = 0.15F;
  MeshPart& part = newPart(PartKind::kWhorl, m);
  const int segments = shape.detailed ? 12 : 6;
  const int rings = shape.detailed ? 10 : 4;
  const double from = stem_top - 0.03;
  const double r0 = 1.5 * radius(stem_top);
  PartBuilder builder(part);
  builder.grid(rings, segments, true, [&](int i, int j) {
    const double u = static_cast<double>(i) / rings;
    const double hh = from + u * (shape.height - from);
    // A rolled-leaf spindle: widest low, to a point; slightly spiralled.
    const double r =
        r0 * (0.75 + 0.5 * std::sin(kPi * std::min(u * 1.6, 1.0) / 2.0)) * std::pow(1.0 - u, 0.8);
    const double a = 2.0 * kPi * j / segments + 1.5 * u;
    return Vec3(axis(stem_top) + (hh - stem_top) * kUp + std::max(r, 1e-4) * horizontal(a));
  });
  finishPart(part);
}

void PlantBuild::addPanicle() {
  Material m;
  const bool red = uni() < 0.5;
  m.albedo = red ? Eigen::Vector3f(0.30F, 0.13F, 0.06F) : Eigen::Vector3f(0.38F, 0.30F, 0.16F);
  m.texture_contrast = 0.5F;
  m.texture_cell_m = 0.003F;
  MeshPart& part = newPart(PartKind::kPanicle, m);
  const int segments = shape.detailed ? 16 : 6;
  const int rings = shape.detailed ? 16 : 5;
  const double length = shape.height - stem_top;
  const double radius_max = 0.035 + 0.02 * uni();
  const auto key = static_cast<std::int64_t>(plant.id) * 131;
  PartBuilder builder(part);
  builder.grid(rings, segments, true, [&](int i, int j) {
    const double u = static_cast<double>(i) / rings;
    const double a = 2.0 * kPi * j / segments;
    // Grain clusters: the radius bulges and dents.
    const double bumps =
        detail::valueNoise(static_cast<float>(u * 7.0), static_cast<float>(j * 6.0 / segments),
                           static_cast<float>(key));
    const double r =
        radius_max * std::pow(std::sin(kPi * (0.06 + 0.94 * u)), 0.6) * (0.85 + 0.3 * bumps);
    return Vec3(axis(stem_top) + u * length * kUp + std::max(r, 1e-4) * horizontal(a));
  });
  finishPart(part);
}

std::uint32_t plantSeed(std::uint32_t seed, int index, int salt) {
  std::seed_seq seq{seed, static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(salt)};
  std::array<std::uint32_t, 1> out{};
  seq.generate(out.begin(), out.end());
  return out[0];
}

// The stage's leaf count, leaf size and stem radius for a plant of height h.
void stageShape(PlantShape& shape, std::mt19937& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double h = shape.height;
  switch (shape.stage) {
    case GrowthStage::kEarly:
      shape.leaves = 6 + static_cast<int>(3 * uni(rng));
      shape.leaf_length = 0.25 + 0.3 * h;
      shape.leaf_width = 0.045 + 0.015 * uni(rng);
      shape.stem_radius = 0.006 + 0.004 * h;
      break;
    case GrowthStage::kMid:
      shape.leaves = 10 + static_cast<int>(5 * uni(rng));
      shape.leaf_length = 0.55 + 0.15 * std::min(h, 2.4);
      shape.leaf_width = 0.07 + 0.02 * uni(rng);
      shape.stem_radius = 0.010 + 0.002 * h;
      break;
    case GrowthStage::kMature:
      shape.leaves = 14 + static_cast<int>(5 * uni(rng));
      shape.leaf_length = 0.85 + 0.15 * uni(rng);
      shape.leaf_width = 0.08 + 0.02 * uni(rng);
      shape.stem_radius = 0.012 + 0.002 * std::min(h, 4.0);
      break;
  }
  shape.stem_radius *= 0.85 + 0.3 * uni(rng);
}

void addPlanting(MeshScene& scene, const MeshPlotSpec& spec, const PlotPlanting& planting,
                 PlotCode code, double row_z, double detail_half_width, int salt) {
  const int positions = std::clamp(
      static_cast<int>(std::lround(planting.length_m / std::max(planting.spacing_m, 0.03))), 1,
      400);
  const double first = planting.centre_y_m - planting.length_m / 2.0;
  std::mt19937 plot_rng(plantSeed(planting.seed, -1, salt));
  const double azimuth_bias = 2.0 * kPi * std::uniform_real_distribution<double>(0, 1)(plot_rng);
  for (int i = 0; i < positions; ++i) {
    if (std::find(planting.missing.begin(), planting.missing.end(), i) != planting.missing.end())
      continue;
    if (scene.plants.size() >= 65535)
      return;
    std::mt19937 rng(plantSeed(planting.seed, i, salt));
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    PlantShape shape;
    shape.stage = planting.stage;
    const double y = first + (i + 0.5) * planting.spacing_m + 0.04 * (uni(rng) - 0.5);
    const double z = row_z + 0.03 * (uni(rng) - 0.5);
    shape.base = Vec3(soilHeight(spec, y, z), y, z);
    const bool tall = i == planting.tall_plant;
    shape.height =
        planting.height_m * (0.97 + 0.06 * uni(rng)) * (tall ? planting.tall_factor : 1.0);
    // Distichous leaves in a plane at a random angle, loosely following the plot's.
    shape.azimuth = azimuth_bias + 0.8 * (uni(rng) - 0.5) * kPi;
    shape.detailed = std::abs(y) < detail_half_width;
    stageShape(shape, rng);

    MeshPlant& plant = scene.plants.emplace_back();
    plant.id = static_cast<std::uint16_t>(scene.plants.size());
    plant.plot = code;
    plant.index = i;
    plant.base = shape.base;
    plant.height_m = shape.height;
    plant.leaves = shape.leaves;
    plant.panicle = shape.stage == GrowthStage::kMature;
    plant.abnormal = tall;
    const std::size_t first_part = scene.parts.size();
    PlantBuild build(spec, shape, rng, scene, plant);
    build.build();
    double top = -1e9;
    for (std::size_t p = first_part; p < scene.parts.size(); ++p)
      for (const Eigen::Vector3f& v : scene.parts[p].vertices)
        top = std::max(top, static_cast<double>(v.x()));
    scene.plants.back().top_m = top - shape.base.x();
  }
}

// Rows behind the imaged one: 3 m plots with 1 m alleys, a genotype each.
void addBackgroundRow(MeshScene& scene, const MeshPlotSpec& spec, int row) {
  const double z = spec.row_depth_m + row * spec.row_spacing_m;
  const double half = spec.visible_half_width_m * z + 1.0;
  const HeightRange range = stageHeights(spec.plot.stage);
  std::mt19937 rng(plantSeed(spec.seed, row, 7001));
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double offset = 4.0 * uni(rng);
  for (int segment = -static_cast<int>(half / 4.0) - 2; segment <= static_cast<int>(half / 4.0) + 1;
       ++segment) {
    PlotPlanting planting;
    planting.stage = spec.plot.stage;
    planting.centre_y_m = offset + 4.0 * segment;
    planting.length_m = 3.0;
    planting.height_m = range.min_m + (range.max_m - range.min_m) * uni(rng);
    planting.seed = plantSeed(spec.seed, row * 1000 + segment, 7002);
    if (planting.centre_y_m + 1.5 < -half || planting.centre_y_m - 1.5 > half)
      continue;
    addPlanting(scene, spec, planting, PlotCode::kBackground, z, 0.0, 100 + row);
  }
}

// Where the rows blur into one canopy: a wavy curtain of foliage up to about the stage's height.
void addFarCanopy(MeshScene& scene, const MeshPlotSpec& spec) {
  const double z0 = spec.row_depth_m + (spec.background_rows + 1) * spec.row_spacing_m;
  const double half = spec.visible_half_width_m * z0 + 2.0;
  const HeightRange range = stageHeights(spec.plot.stage);
  const double mean_top = 0.5 * (range.min_m + range.max_m);
  MeshPart& part = scene.parts.emplace_back();
  part.kind = PartKind::kFarCanopy;
  part.plot = PlotCode::kBackground;
  part.material.albedo = Eigen::Vector3f(0.06F, 0.15F, 0.04F);
  part.material.texture_contrast = 0.5F;
  part.material.texture_cell_m = 0.04F;
  const int ny = static_cast<int>(2.0 * half / 0.08);
  const int nx = 24;
  const auto key = static_cast<float>(spec.seed % 9973);
  PartBuilder builder(part);
  builder.grid(ny, nx, false, [&](int i, int j) {
    const double y = -half + 2.0 * half * i / ny;
    const double top =
        mean_top * (0.85 + 0.3 * detail::valueNoise(static_cast<float>(y / 1.3), key, 0.5F)) +
        0.08 * detail::valueNoise(static_cast<float>(y / 0.15), key, 2.5F);
    const double soil = soilHeight(spec, y, z0);
    const double u = static_cast<double>(j) / nx;
    const double x = soil - 0.05 + u * (top - soil + 0.05);
    const double z = z0 + 0.4 * (detail::valueNoise(static_cast<float>(y / 0.4),
                                                    static_cast<float>(x / 0.4), key) -
                                 0.5);
    return Vec3(x, y, z);
  });
  finishPart(part);
}

void addSoil(MeshScene& scene, const MeshPlotSpec& spec) {
  MeshPart& part = scene.parts.emplace_back();
  part.kind = PartKind::kSoil;
  part.material.albedo = Eigen::Vector3f(0.23F, 0.17F, 0.115F);
  part.material.texture_contrast = 0.5F;
  part.material.texture_cell_m = 0.006F;
  const double z_far =
      spec.far_canopy ? spec.row_depth_m + (spec.background_rows + 1) * spec.row_spacing_m + 1.0
                      : 40.0;
  // Rows of the grid closer together near the cameras: about constant angular size.
  std::vector<double> zs{0.2};
  while (zs.back() < z_far)
    zs.push_back(zs.back() + std::max(0.012, 0.016 * zs.back()));
  const int columns = 320;
  PartBuilder builder(part);
  builder.grid(static_cast<int>(zs.size()) - 1, columns, false, [&](int i, int j) {
    const double z = zs[static_cast<std::size_t>(i)];
    const double half = spec.visible_half_width_m * z + 1.5;
    const double y = -half + 2.0 * half * j / columns;
    return Vec3(soilHeight(spec, y, z), y, z);
  });
  finishPart(part);
}

// Clods: lumpy flattened icospheres half sunk into the soil, many small, few large.
void addClods(MeshScene& scene, const MeshPlotSpec& spec) {
  // Unit icosphere, subdivided once.
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> ico = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                           {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                           {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (Vec3& v : ico)
    v.normalize();
  {
    std::vector<std::array<std::uint32_t, 3>> finer;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> cache;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      for (const auto& [k, v] : cache)
        if (k == key)
          return v;
      ico.push_back((ico[a] + ico[b]).normalized());
      const auto index = static_cast<std::uint32_t>(ico.size() - 1);
      cache.emplace_back(key, index);
      return index;
    };
    for (const auto& f : faces) {
      const std::uint32_t ab = midpoint(f[0], f[1]);
      const std::uint32_t bc = midpoint(f[1], f[2]);
      const std::uint32_t ca = midpoint(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }
  MeshPart& part = scene.parts.emplace_back();
  part.kind = PartKind::kClod;
  part.material.albedo = Eigen::Vector3f(0.20F, 0.15F, 0.10F);
  part.material.texture_contrast = 0.5F;
  part.material.texture_cell_m = 0.005F;
  std::mt19937 rng(plantSeed(spec.seed, 0, 9001));
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double z0 = 0.25;
  const double z1 = spec.row_depth_m + 0.5;
  const double half = spec.visible_half_width_m * z1 + 0.5;
  const int count = std::clamp(
      static_cast<int>(std::max(0.0, spec.clods_per_m2) * (z1 - z0) * 2.0 * half), 0, 20000);
  for (int c = 0; c < count; ++c) {
    const double y = -half + 2.0 * half * uni(rng);
    const double z = z0 + (z1 - z0) * uni(rng);
    const double r = 0.008 + 0.03 * std::pow(uni(rng), 3.0);
    const Vec3 scale(0.6 * r * (0.8 + 0.4 * uni(rng)), r * (0.7 + 0.6 * uni(rng)),
                     r * (0.7 + 0.6 * uni(rng)));
    const double turn = 2.0 * kPi * uni(rng);
    const Vec3 centre(soilHeight(spec, y, z) - 0.3 * scale.x(), y, z);
    const auto first = static_cast<std::uint32_t>(part.vertices.size());
    for (const Vec3& v : ico) {
      const double lump = 0.75 + 0.5 * detail::valueNoise(static_cast<float>(v.x() * 1.7 + c),
                                                          static_cast<float>(v.y() * 1.7),
                                                          static_cast<float>(v.z() * 1.7));
      const Vec3 s = v.cwiseProduct(scale) * lump;
      const double cy = std::cos(turn) * s.y() - std::sin(turn) * s.z();
      const double cz = std::sin(turn) * s.y() + std::cos(turn) * s.z();
      part.vertices.push_back(
          Vec3(centre.x() + s.x(), centre.y() + cy, centre.z() + cz).cast<float>());
    }
    for (const auto& f : faces)
      part.triangles.push_back({first + f[0], first + f[1], first + f[2]});
  }
  finishPart(part);
}

}  // namespace

std::string_view stageName(GrowthStage stage) {
  switch (stage) {
    case GrowthStage::kEarly:
      return "early";
    case GrowthStage::kMid:
      return "mid";
    case GrowthStage::kMature:
      return "mature";
  }
  return "mid";
}

std::optional<GrowthStage> parseStage(std::string_view name) {
  for (GrowthStage stage : {GrowthStage::kEarly, GrowthStage::kMid, GrowthStage::kMature}) {
    if (name == stageName(stage))
      return stage;
  }
  return std::nullopt;
}

HeightRange stageHeights(GrowthStage stage) {
  switch (stage) {
    case GrowthStage::kEarly:
      return {0.5, 1.0};
    case GrowthStage::kMid:
      return {1.3, 2.4};
    case GrowthStage::kMature:
      return {2.8, 4.0};
  }
  return {1.3, 2.4};
}

bool isPlantPart(PartKind kind) {
  return kind == PartKind::kStem || kind == PartKind::kLeaf || kind == PartKind::kWhorl ||
         kind == PartKind::kPanicle;
}

std::size_t MeshScene::triangleCount() const {
  std::size_t count = 0;
  for (const MeshPart& part : parts)
    count += part.triangles.size();
  return count;
}

double soilHeight(const MeshPlotSpec& spec, double y, double z) {
  const double along = std::tan(spec.slope_along_deg * kPi / 180.0) * y;
  const double across = std::tan(spec.slope_across_deg * kPi / 180.0) * (z - spec.row_depth_m);
  const double ridge =
      spec.ridge_height_m * std::exp(-std::pow((z - spec.row_depth_m) / 0.22, 2.0));
  const double furrow =
      -spec.furrow_depth_m * std::exp(-std::pow((z - (spec.row_depth_m - 0.55)) / 0.15, 2.0));
  const auto key = static_cast<float>(spec.seed % 7919);
  const double undulation =
      0.015 *
      (detail::valueNoise(static_cast<float>(y / 0.7), static_cast<float>(z / 0.7), key) - 0.5);
  const double rough =
      2.0 * spec.soil_roughness_m *
      (detail::valueNoise(static_cast<float>(y / 0.04), static_cast<float>(z / 0.04), key + 3.0F) -
       0.5);
  return along + across + ridge + furrow + undulation + rough;
}

std::optional<std::string> validateMeshPlotSpec(const MeshPlotSpec& spec) {
  struct Check {
    const char* name;
    double value, lo, hi;
  };
  const Check checks[] = {
      {"plot.height_m", spec.plot.height_m, 0.2, 5.0},
      {"plot.length_m", spec.plot.length_m, 0.3, 20.0},
      {"plot.spacing_m", spec.plot.spacing_m, 0.03, 2.0},
      {"plot.tall_factor", spec.plot.tall_factor, 1.0, 2.0},
      {"row_depth_m", spec.row_depth_m, 0.6, 2.0},
      {"row_spacing_m", spec.row_spacing_m, 0.5, 5.0},
      {"background_rows", static_cast<double>(spec.background_rows), 0, 4},
      {"slope_along_deg", spec.slope_along_deg, -10.0, 10.0},
      {"slope_across_deg", spec.slope_across_deg, -10.0, 10.0},
      {"ridge_height_m", spec.ridge_height_m, 0.0, 0.2},
      {"furrow_depth_m", spec.furrow_depth_m, 0.0, 0.3},
      {"clods_per_m2", spec.clods_per_m2, 0.0, 500.0},
      {"soil_roughness_m", spec.soil_roughness_m, 0.0, 0.05},
      {"visible_half_width_m", spec.visible_half_width_m, 0.1, 3.0},
  };
  for (const Check& check : checks) {
    if (!(check.value >= check.lo && check.value <= check.hi)) {
      std::ostringstream out;
      out << check.name << " " << check.value << " outside [" << check.lo << ", " << check.hi
          << "]";
      return out.str();
    }
  }
  return std::nullopt;
}

MeshScene buildMeshScene(const MeshPlotSpec& spec) {
  MeshScene scene;
  scene.row_depth_m = spec.row_depth_m;
  scene.stem_section_heights_m = {0.1, 0.3, 0.5, 1.0, 1.5};
  PlotPlanting plot = spec.plot;
  plot.centre_y_m = 0.0;
  addPlanting(scene, spec, plot, PlotCode::kThis, spec.row_depth_m, 2.2, 0);
  if (spec.previous)
    addPlanting(scene, spec, *spec.previous, PlotCode::kPrevious, spec.row_depth_m, 2.2, 0);
  if (spec.next)
    addPlanting(scene, spec, *spec.next, PlotCode::kNext, spec.row_depth_m, 2.2, 0);
  for (int row = 1; row <= std::clamp(spec.background_rows, 0, 4); ++row)
    addBackgroundRow(scene, spec, row);
  if (spec.far_canopy)
    addFarCanopy(scene, spec);
  addSoil(scene, spec);
  addClods(scene, spec);

  // The definitions' ground: the soil under the imaged plot's stems within the imaged 1.5 m.
  double sum = 0.0;
  int count = 0;
  for (const MeshPlant& plant : scene.plants) {
    if (plant.plot == PlotCode::kThis && std::abs(plant.base.y()) <= 0.75) {
      sum += plant.base.x();
      ++count;
    }
  }
  scene.ground_x_m = count > 0 ? sum / count : soilHeight(spec, 0.0, spec.row_depth_m);
  return scene;
}

}  // namespace fieldrig::sim
