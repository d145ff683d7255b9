// `fieldrig traits --cloud FILE [--frame plot|camera] [--config FILE] [--area depth_map|paper]
// --json`: the traits of one plot cloud as one JSON object.
// `fieldrig traits synth --out plot.ply [--truth truth.json] ...`: a synthetic row plot with its
// truth (sim/plots: the generator, and the trait definitions on its noise-free visible geometry).
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/command_helpers.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/config/config.h"
#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/traits/cloud_io.h"
#include "fieldrig/traits/plot_report.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct TraitsArgs {
  std::string cloud;
  std::string frame = "plot";
  std::string config;
  std::string area;
  bool json = false;
};

struct SynthArgs {
  std::string out;
  std::string truth;
  std::string frame = "plot";
  sim::PlotSpec spec;  // the options below are bound to its fields, defaults included
  std::size_t points = 0;
  bool no_plants = false;
};

int runTraits(const TraitsArgs& args) {
  traits::TraitsOptions options;
  if (!args.config.empty()) {
    core::Result<traits::TraitsOptions> loaded = config::loadTraitsOptions(args.config);
    if (!loaded) {
      std::cerr << "fieldrig traits: " << loaded.error().message << '\n';
      return kExitBadInput;
    }
    options = *loaded;
  }
  if (args.area == "paper")
    options.area_method = traits::AreaMethod::kPaperMlsGpt;
  else if (args.area == "depth_map")
    options.area_method = traits::AreaMethod::kDepthMap;
  if (const auto problem = options.validate())
    return fail("fieldrig traits: ", args.config + ": " + problem->key + ": " + problem->message);
  core::Result<std::vector<Eigen::Vector3f>> cloud = traits::loadCloud(args.cloud);
  if (!cloud) {
    std::cerr << "fieldrig traits: " << cloud.error().message << '\n';
    return kExitBadInput;
  }
  const traits::InputFrame frame =
      args.frame == "camera" ? traits::InputFrame::kCamera : traits::InputFrame::kPlot;
  const traits::TraitsResult result = traits::computeTraits(*cloud, frame, options);
  Json out = traits::traitsToJson(result);
  out["cloud"] = args.cloud;
  out["frame"] = args.frame;
  if (args.json) {
    std::cout << out.dump() << '\n';
  } else {
    std::cout << "status " << out["status"].get<std::string>() << '\n';
    for (const char* key :
         {"height_m", "width_m", "vvi", "vai", "total_volume_m3", "total_area_m2", "ega_m2"})
      std::cout << key << ' ' << out[key].dump() << '\n';
    if (!result.message.empty())
      std::cout << "message " << result.message << '\n';
  }
  // Bad data is a result with a status, not a failure of the tool: exit 0 unless input unusable.
  return kExitOk;
}

int runSynth(const SynthArgs& args) {
  sim::PlotSpec spec = args.spec;
  spec.plants = !args.no_plants;
  sim::PlotCloud plot = sim::generatePlot(spec);
  if (args.points > 0)
    sim::subsamplePlot(plot, args.points, spec.seed);
  const traits::TraitsOptions options;
  const traits::InputFrame frame =
      args.frame == "camera" ? traits::InputFrame::kCamera : traits::InputFrame::kPlot;
  const std::vector<Eigen::Vector3f> points = sim::observedPoints(plot, frame, options);
  cloud::Cloud out;
  out.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pcl::PointXYZRGB p;
    p.getVector3fMap() = points[i];
    p.r = plot.colors[i][0];
    p.g = plot.colors[i][1];
    p.b = plot.colors[i][2];
    out.push_back(p);
  }
  if (auto saved = cloud::writePly(out, args.out); !saved) {
    std::cerr << "fieldrig traits synth: " << saved.error().message << '\n';
    return kExitBadInput;
  }
  if (!args.truth.empty()) {
    Json truth = sim::plotTruthJson(plot, options);
    truth["points"] = out.size();
    truth["frame"] = args.frame;
    core::Result<void> written = traits::writeText(args.truth, truth.dump(1) + "\n");
    if (!written) {
      std::cerr << "fieldrig traits synth: " << written.error().message << '\n';
      return kExitBadInput;
    }
  }
  return kExitOk;
}

}  // namespace

void registerTraitsCommand(CLI::App& app, int& exit_code) {
  CLI::App* traits_app =
      app.add_subcommand("traits", "Plot traits (height, width, VVI, VAI) of one plot cloud");
  traits_app->require_subcommand(0, 1);
  auto args = std::make_shared<TraitsArgs>();
  traits_app->add_option("--cloud", args->cloud, "Plot cloud (.ply or .pcd), metres")
      ->check(CLI::ExistingFile);
  traits_app->add_option("--frame", args->frame, "plot (x up, y row, z depth) or camera")
      ->check(CLI::IsMember({"plot", "camera"}))
      ->capture_default_str();
  traits_app
      ->add_option("--config", args->config,
                   "Traits options (YAML or JSON: the keys of pipeline.traits)")
      ->check(CLI::ExistingFile);
  traits_app->add_option("--area", args->area, "Surface for VAI: depth_map (default) or paper")
      ->check(CLI::IsMember({"depth_map", "paper"}));
  traits_app->add_flag("--json", args->json, "Print one JSON object");

  CLI::App* synth = traits_app->add_subcommand(
      "synth", "Write a synthetic row plot (binary PLY) and its truth (JSON)");
  auto synth_args = std::make_shared<SynthArgs>();
  synth->add_option("--out", synth_args->out, "Output cloud (.ply)")->required();
  synth->add_option("--truth", synth_args->truth, "Output truth (.json)");
  synth->add_option("--frame", synth_args->frame, "plot or camera")
      ->check(CLI::IsMember({"plot", "camera"}))
      ->capture_default_str();
  synth->add_option("--height", synth_args->spec.plant_height_m, "Plant height, m")
      ->check(finiteRange(0.2, 5.0))
      ->capture_default_str();
  synth->add_option("--noise", synth_args->spec.depth_noise_m, "Depth noise sigma, m")
      ->check(finiteRange(0.0, 0.05))
      ->capture_default_str();
  synth->add_option("--row-length", synth_args->spec.row_length_m, "Imaged row length, m")
      ->check(finiteRange(0.1, 10.0))
      ->capture_default_str();
  synth->add_option("--tall-plant", synth_args->spec.tall_plant, "Index of one abnormal tall plant")
      ->check(finiteRange(-1, 1000));
  synth->add_option("--missing", synth_args->spec.missing_plants, "Indices of missing plants")
      ->check(finiteRange(0, 1000));
  synth->add_option("--seed", synth_args->spec.seed, "Random seed")->capture_default_str();
  synth->add_option("--points", synth_args->points, "Keep this many points (random)")
      ->check(finiteRange<std::size_t>(0, 100'000'000));
  synth->add_flag("--no-plants", synth_args->no_plants, "Soil only");
  synth->callback([synth_args, &exit_code] { exit_code = runSynth(*synth_args); });

  traits_app->callback([traits_app, synth, args, &exit_code] {
    if (synth->parsed())
      return;
    if (args->cloud.empty()) {
      std::cerr << "fieldrig traits: --cloud FILE is required\n" << traits_app->help();
      exit_code = kExitBadInput;
      return;
    }
    exit_code = runTraits(*args);
  });
}

}  // namespace fieldrig::tools
