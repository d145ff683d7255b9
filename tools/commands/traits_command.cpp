// `fieldrig traits --cloud FILE [--frame plot|camera] [--config FILE] [--area depth_map|paper]
// --json`: the traits of one plot cloud as one JSON object.
// Built into both `fieldrig-commands` and the light `fieldrig-traits` (tools/CMakeLists.txt), so it
// links the traits and their options file only; `traits synth` is in traits_synth_command.cpp.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/command_helpers.h"
#include "fieldrig/config/traits_config.h"
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

  traits_app->callback([traits_app, args, &exit_code] {
    if (!traits_app->get_subcommands().empty())
      return;  // `traits synth` (registerTraitsSynthCommand) ran instead
    if (args->cloud.empty()) {
      std::cerr << "fieldrig traits: --cloud FILE is required\n" << traits_app->help();
      exit_code = kExitBadInput;
      return;
    }
    exit_code = runTraits(*args);
  });
}

}  // namespace fieldrig::tools
