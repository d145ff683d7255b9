// A row plot as triangle meshes: the plants of the imaged plot (stems whose diameter varies along
// them, curved tapering drooping leaves with a folded blade and wavy margins, a whorl or a
// panicle on top), the neighbouring plots of the same row, the rows behind, a distant canopy and
// soil with a planting ridge, a furrow, a slope and clods. Pure geometry (no Embree, no I/O),
// deterministic for a spec; the mesh renderer (mesh_renderer.h) ray-casts it and the truth
// (mesh_truth.h) samples it.
//
// The scene frame is the plot frame of the trait definitions: x up (0 at the soil level of the
// imaged plot's stem bases at the plot centre, before slope and roughness), y along the row (the
// plot's centre, i.e. the imaging location, at y = 0), z away from the cameras, which sit in
// the plane z = 0. Metres.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldrig::sim {

enum class GrowthStage { kEarly, kMid, kMature };

std::string_view stageName(GrowthStage stage);
std::optional<GrowthStage> parseStage(std::string_view name);

// The plant heights (soil to the top of the whorl or panicle) a stage's plots are drawn from:
// early 0.5–1.0 m (whorl, 6–8 leaves), mid 1.3–2.4 m (whorl, 10–14 leaves), mature 2.8–4.0 m
// (panicle, 14–18 leaves, the lowest dry).
struct HeightRange {
  double min_m = 0.0;
  double max_m = 0.0;
};
HeightRange stageHeights(GrowthStage stage);

// Which plot a surface belongs to, as the per-pixel plot map stores it.
enum class PlotCode : std::uint8_t {
  kNone = 0,        // soil, clods, sky
  kThis = 1,        // the plot imaged at this location
  kPrevious = 2,    // the plot before it along the row (−y)
  kNext = 3,        // the plot after it (+y)
  kBackground = 4,  // rows behind and the distant canopy
};

enum class PartKind : std::uint8_t { kSoil, kClod, kStem, kLeaf, kWhorl, kPanicle, kFarCanopy };

bool isPlantPart(PartKind kind);

// Lambertian reflectance (linear RGB) modulated by 3D value noise of the hit point: texture the
// stereo matcher can lock on to, identical from every camera.
struct Material {
  Eigen::Vector3f albedo{0.2F, 0.2F, 0.2F};
  float texture_contrast = 0.4F;  // reflectance × (1 ± contrast)
  float texture_cell_m = 0.004F;  // coarse octave; a second octave at a third of it
  float translucency = 0.0F;      // share of the sun a leaf lets through to its shaded side
};

// One triangle mesh with its smooth vertex normals, what it is and whose it is.
struct MeshPart {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> normals;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  PartKind kind = PartKind::kSoil;
  PlotCode plot = PlotCode::kNone;
  std::uint16_t plant_id = 0;  // 0: not a plant
  Material material;
};

// A stem's diameter at a known height above the soil at its base, and where its axis is there:
// what the stem tool's end-to-end check measures against.
struct StemSection {
  double height_m = 0.0;
  double diameter_m = 0.0;
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();
};

struct MeshPlant {
  std::uint16_t id = 0;  // as the per-pixel plant map stores it (1…)
  PlotCode plot = PlotCode::kThis;
  int index = 0;                                   // position along its plot's planting
  Eigen::Vector3d base = Eigen::Vector3d::Zero();  // stem axis at the soil
  double height_m = 0.0;  // agronomic: soil at the base to the top of the whorl or panicle
  double top_m = 0.0;     // the highest point of any of its parts above the soil at its base
  int leaves = 0;
  bool panicle = false;
  bool abnormal = false;  // the plot's occasional abnormally tall plant
  std::vector<StemSection> stem;
};

// One plot of a row: a genotype's planting.
struct PlotPlanting {
  GrowthStage stage = GrowthStage::kMid;
  double height_m = 2.0;     // the genotype's plant height (each plant ±3 %)
  double centre_y_m = 0.0;   // plot centre along the row
  double length_m = 3.0;     // planted length
  double spacing_m = 0.15;   // intra-row spacing
  std::vector<int> missing;  // planting positions left empty (non-emergent plants)
  int tall_plant = -1;       // position of an abnormally tall plant, -1 for none
  double tall_factor = 1.3;
  std::uint32_t seed = 1;
};

struct MeshPlotSpec {
  PlotPlanting plot;                     // the imaged plot (centre_y_m is taken as 0)
  std::optional<PlotPlanting> previous;  // the plot before it along the row
  std::optional<PlotPlanting> next;      // and after it
  double row_depth_m = 1.2;              // z of the row's stems
  double row_spacing_m = 2.286;          // 90-inch rows
  int background_rows = 2;               // rows of plants behind the imaged one
  bool far_canopy = true;                // a canopy band where the rows behind blur out
  double slope_along_deg = 0.0;          // soil slope along the row (rises towards +y)
  double slope_across_deg = 0.0;         // soil slope across the row (rises away from camera)
  double ridge_height_m = 0.04;          // the planting ridge under the row
  double furrow_depth_m = 0.05;          // the furrow between the cameras and the row
  double clods_per_m2 = 30.0;
  double soil_roughness_m = 0.005;
  double visible_half_width_m = 0.8;  // |y| the nearest row must cover, at z = 1 m
  std::uint32_t seed = 1;             // soil, clods, background rows
};

struct MeshScene {
  std::vector<MeshPart> parts;
  std::vector<MeshPlant> plants;  // every plant of the scene, by id (plants[id - 1])
  double ground_x_m = 0.0;        // soil under the imaged row at y = 0 (the definitions' x_min)
  double row_depth_m = 0.0;
  std::vector<double> stem_section_heights_m;  // the heights of MeshPlant::stem

  std::size_t triangleCount() const;
};

// Builds the scene. Counts and lengths are clamped to sane ranges; the spec is validated by the
// callers that take it from users (validateMeshPlotSpec).
MeshScene buildMeshScene(const MeshPlotSpec& spec);

// Soil height x at (y, z) without clods: slope, ridge, furrow and roughness.
double soilHeight(const MeshPlotSpec& spec, double y, double z);

// The error names the first field out of range ("row_depth_m 0.1 outside [0.6, 2.0]").
std::optional<std::string> validateMeshPlotSpec(const MeshPlotSpec& spec);

}  // namespace fieldrig::sim
