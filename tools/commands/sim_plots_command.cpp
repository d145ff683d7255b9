// `fieldrig sim plots --out SESSION [--calib-out DIR] [--count N] [--seed S]`: a recorded session
// of synthetic row plots, as the tractor would record it — six raw Bayer frames per plot from an
// ideal three-head rig — with the rig's calibration and each plot's truth (SESSION/truth.jsonl).
// `fieldrig simulate --plots N --rows R --seed S --out DIR`: a whole synthetic field to replay
// through fieldrigd: DIR/drive.nmea, DIR/map.csv, DIR/source-session and DIR/truth.jsonl.
// Both take `--renderer splat|mesh` (splat by default: the splatted sample clouds through the
// ideal rig; mesh: Embree-rendered triangle-mesh plants through the calibrated, distorted rig,
// with per-pixel truth beside each frame) and, for the mesh renderer, `--stage` (early, mid,
// mature, or a comma-separated list splitting the plots into blocks; given alone it selects the
// mesh renderer), and `--traits-config FILE`: the trait definitions the truth lines are computed
// with (those the session will be processed with). The scenes and their truth are sim/field's
// (synthetic_field.h).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <tuple>

#include "commands/command_helpers.h"
#include "fieldrig/config/traits_config.h"
#include "fieldrig/sim/synthetic_field.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// The scene options both commands share, as given on the command line.
struct SceneArgs {
  std::string renderer;
  std::vector<std::string> stages;
  bool no_truth_maps = false;
  std::string traits_config;
  CLI::Option* renderer_option = nullptr;
  CLI::Option* stage_option = nullptr;
  CLI::Option* height_min_option = nullptr;
  CLI::Option* height_max_option = nullptr;
};

// --height-min and --height-max: the plants' height in the first plot and in the last.
void addHeightRangeOptions(CLI::App& command, double& min_m, double& max_m, SceneArgs& scene) {
  for (auto [name, value, description, option] :
       {std::tuple{"--height-min", &min_m,
                   "Plant height of the first plot, m (mesh: of each stage's first plot; default "
                   "the stage's range)",
                   &scene.height_min_option},
        std::tuple{"--height-max", &max_m,
                   "Plant height of the last plot, m (up to 2.8 with the splat renderer)",
                   &scene.height_max_option}}) {
    *option = command.add_option(name, *value, description)
                  ->capture_default_str()
                  ->check(finiteRange(0.3, 5.0));
  }
}

void addSceneOptions(CLI::App& command, SceneArgs& scene) {
  scene.renderer_option =
      command
          .add_option("--renderer", scene.renderer,
                      "splat (default: sample clouds, ideal rig) or mesh (Embree, calibrated "
                      "distorted rig, per-pixel truth)")
          ->check(CLI::IsMember({"splat", "mesh"}));
  scene.stage_option =
      command
          .add_option("--stage", scene.stages,
                      "Growth stage early|mid|mature (mesh default: mid), or a comma-separated "
                      "list splitting the plots in blocks (mesh renderer; selects it when "
                      "--renderer is not given)")
          ->delimiter(',')
          ->check(CLI::IsMember({"early", "mid", "mature"}));
  command.add_flag("--no-truth-maps", scene.no_truth_maps,
                   "Mesh renderer: no depth/plot/plant/vegetation maps beside the frames");
  command.add_option("--traits-config", scene.traits_config,
                     "Traits options (YAML, as `fieldrig process --traits-config`) the truth is "
                     "computed with (default: the shipped definitions)");
}

// Applies the scene options to the series' fields; the error names the flag.
std::optional<std::string> applySceneArgs(const SceneArgs& scene, sim::SceneRenderer& renderer,
                                          std::vector<sim::GrowthStage>& stages,
                                          bool& stage_heights, bool& truth_maps,
                                          traits::TraitsOptions& truth_traits) {
  const bool stage_given = scene.stage_option->count() > 0;
  renderer = sim::SceneRenderer::kSplat;
  if (scene.renderer_option->count() > 0)
    renderer = *sim::parseRenderer(scene.renderer);
  else if (stage_given)
    renderer = sim::SceneRenderer::kMesh;
  if (stage_given && renderer != sim::SceneRenderer::kMesh)
    return "--stage: growth stages need --renderer mesh (the splat renderer has none)";
  if (scene.no_truth_maps && renderer != sim::SceneRenderer::kMesh)
    return "--no-truth-maps: only the mesh renderer writes truth maps";
  if (stage_given) {
    stages.clear();
    for (const std::string& name : scene.stages)
      stages.push_back(*sim::parseStage(name));
  }
  stage_heights = scene.height_min_option->count() == 0 && scene.height_max_option->count() == 0;
  truth_maps = !scene.no_truth_maps;
  if (!scene.traits_config.empty()) {
    auto loaded = config::loadTraitsOptions(scene.traits_config);
    if (!loaded)
      return "--traits-config: " + loaded.error().message;
    truth_traits = *loaded;
  }
  return std::nullopt;
}

Json stageNames(const std::vector<sim::GrowthStage>& stages) {
  Json names = Json::array();
  for (sim::GrowthStage stage : stages)
    names.push_back(std::string(sim::stageName(stage)));
  return names;
}

struct PlotsArgs {
  std::string out, calib_out;
  sim::PlotSeries series;
  SceneArgs scene;
};

int runPlots(const PlotsArgs& args) {
  sim::PlotSeries series = args.series;
  if (auto error = applySceneArgs(args.scene, series.renderer, series.stages, series.stage_heights,
                                  series.truth_maps, series.truth_traits))
    return fail("fieldrig sim plots: ", *error);
  if (auto error = sim::validatePlotSeries(series))
    return fail("fieldrig sim plots: ", *error);
  const fs::path session_dir(args.out);
  const fs::path calib_dir =
      args.calib_out.empty() ? session_dir / "calib" : fs::path(args.calib_out);
  std::vector<std::string> locations;
  for (int index = 0; index < series.count; ++index)
    locations.push_back("plot-" + std::to_string(index + 1));
  auto recorded = sim::recordSyntheticPlots(session_dir, calib_dir, series, locations);
  if (!recorded)
    return fail("fieldrig sim plots: ", recorded.error().message, kExitRuntime);
  Json summary;
  summary["session"] = session_dir.string();
  summary["calib"] = calib_dir.string();
  summary["plots"] = recorded->size();
  summary["truth"] = (session_dir / "truth.jsonl").string();
  summary["renderer"] = std::string(sim::rendererName(series.renderer));
  if (series.renderer == sim::SceneRenderer::kMesh)
    summary["stages"] = stageNames(series.stages);
  return printJsonLine(summary);
}

struct FieldArgs {
  std::string out;
  sim::FieldSpec spec;
  SceneArgs scene;
};

int runSimulate(const FieldArgs& args) {
  sim::FieldSpec spec = args.spec;
  if (auto error = applySceneArgs(args.scene, spec.renderer, spec.stages, spec.stage_heights,
                                  spec.truth_maps, spec.truth_traits))
    return fail("fieldrig simulate: ", *error);
  if (auto error = sim::validatePlotSeries(sim::fieldPlotSeries(spec, spec.plots)))
    return fail("fieldrig simulate: ", *error);
  if (spec.rows > spec.plots) {
    return fail("fieldrig simulate: ", "--rows " + std::to_string(spec.rows) +
                                           " is more than --plots " + std::to_string(spec.plots) +
                                           " (every row needs a plot)");
  }
  if (auto error = sim::checkFieldFolder(args.out))
    return fail("fieldrig simulate: --out: ", *error);
  double seconds = 0.0;
  auto files = sim::writeSyntheticField(args.out, spec, [&](const sim::RecordedPlot& plot) {
    seconds += plot.render_seconds + plot.truth_seconds;
    std::cerr << "fieldrig simulate: rendered " << plot.location_id << " (set " << plot.set_index
              << ", " << plot.render_seconds << " s, truth " << plot.truth_seconds << " s)\n";
  });
  if (!files)
    return fail("fieldrig simulate: ", files.error().message, kExitRuntime);
  Json summary;
  summary["nmea"] = files->nmea.string();
  summary["map"] = files->map.string();
  summary["session"] = files->session.string();
  summary["calib"] = files->calibration.string();
  summary["truth"] = files->truth.string();
  summary["locations"] = files->locations;
  summary["plots"] = files->plots;
  summary["renderer"] = std::string(sim::rendererName(spec.renderer));
  if (spec.renderer == sim::SceneRenderer::kMesh)
    summary["stages"] = stageNames(spec.stages);
  summary["seconds_per_plot"] = files->plots > 0 ? seconds / static_cast<double>(files->plots) : 0;
  return printJsonLine(summary);
}

}  // namespace

void registerSimPlotsSubcommand(CLI::App& sim, int& exit_code) {
  const auto [plots, args] = addSubcommand(
      sim, "plots", "Record a session of synthetic row plots (six raw frames each) with its truth",
      exit_code, runPlots);
  plots->add_option("--out", args->out, "Session folder to write")->required();
  plots->add_option("--calib-out", args->calib_out,
                    "Calibration folder to write (default SESSION/calib)");
  plots->add_option("--count", args->series.count, "Number of plots")
      ->capture_default_str()
      ->check(finiteRange(1, 1000));
  plots->add_option("--seed", args->series.seed, "Scene seed")->capture_default_str();
  addHeightRangeOptions(*plots, args->series.height_min_m, args->series.height_max_m, args->scene);
  addSceneOptions(*plots, args->scene);
}

void registerSimulateCommand(CLI::App& app, int& exit_code) {
  const auto [simulate, args] = addSubcommand(
      app, "simulate",
      "Write a synthetic field to replay through fieldrigd: drive NMEA, map, session, truth",
      exit_code, runSimulate);
  simulate->add_option("--out", args->out, "Folder to write")->required();
  simulate->add_option("--plots", args->spec.plots, "Number of plots")
      ->capture_default_str()
      ->check(finiteRange(1, 2000));
  simulate->add_option("--rows", args->spec.rows, "Rows the plots are laid out in (serpentine)")
      ->capture_default_str()
      ->check(finiteRange(1, 200));
  simulate->add_option("--seed", args->spec.seed, "Seed of the drive noise and the scenes")
      ->capture_default_str();
  addHeightRangeOptions(*simulate, args->spec.height_min_m, args->spec.height_max_m, args->scene);
  simulate->add_option("--speed", args->spec.speed_mps, "Ground speed, m/s")
      ->capture_default_str()
      ->check(finiteRange(0.5, 5.0));
  addSceneOptions(*simulate, args->scene);
}

}  // namespace fieldrig::tools
