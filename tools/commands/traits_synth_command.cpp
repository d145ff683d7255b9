// `fieldrig traits synth --out plot.ply [--truth truth.json] ...`: a synthetic row plot with its
// truth (sim/plots: the generator, and the trait definitions on its noise-free visible geometry).
// Apart from `traits --cloud` because it writes PLY through the cloud library (OpenCV, PCL's I/O),
// which the light `fieldrig-traits` does not link.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands/command_helpers.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/durable_file.h"
#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/traits/plot_report.h"
#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct SynthArgs {
  std::string out;
  std::string truth;
  std::string frame = "plot";
  sim::PlotSpec spec;  // the options below are bound to its fields, defaults included
  std::size_t points = 0;
  bool no_plants = false;
};

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
  if (args.truth.empty()) {
    if (auto saved = cloud::writePly(out, args.out); !saved) {
      std::cerr << "fieldrig traits synth: " << saved.error().message << '\n';
      return kExitBadInput;
    }
    return kExitOk;
  }
  Json truth = sim::plotTruthJson(plot, options);
  truth["points"] = out.size();
  truth["frame"] = args.frame;
  // The cloud and its truth replace the old pair together: one that cannot be written (a full
  // disk, a --truth in a folder that is not there) leaves the old pair, never a mixed one.
  const std::string cloud_bytes = cloud::plyBytes(out);
  const std::string truth_text = truth.dump(1) + "\n";
  if (std::string failed =
          core::replaceFilesTogether({{std::filesystem::path(args.out), cloud_bytes},
                                      {std::filesystem::path(args.truth), truth_text}});
      !failed.empty()) {
    std::cerr << "fieldrig traits synth: " << failed << '\n';
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

void registerTraitsSynthCommand(CLI::App& app, int& exit_code) {
  CLI::App* traits_app = app.get_subcommand("traits");
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
}

}  // namespace fieldrig::tools
