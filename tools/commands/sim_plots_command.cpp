// `fieldrig sim plots --out SESSION [--calib-out DIR] [--count N] [--seed S]`: a recorded session
// of synthetic row plots, as the tractor would record it — six raw Bayer frames per plot from an
// ideal three-head rig — with the rig's calibration and each plot's truth (SESSION/truth.jsonl).
// `fieldrig simulate --plots N --rows R --seed S --out DIR`: a whole synthetic field to replay
// through fieldrigd: DIR/drive.nmea, DIR/map.csv, DIR/source-session and DIR/truth.jsonl.
// The scenes and their truth are sim/field's (synthetic_field.h).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <tuple>

#include "commands/command_helpers.h"
#include "fieldrig/sim/synthetic_field.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// --height-min and --height-max: the plants' height in the first plot and in the last.
void addHeightRangeOptions(CLI::App& command, double& min_m, double& max_m) {
  for (auto [name, value, description] :
       {std::tuple{"--height-min", &min_m, "Plant height of the first plot, m"},
        std::tuple{"--height-max", &max_m, "Plant height of the last plot, m"}}) {
    command.add_option(name, *value, description)
        ->capture_default_str()
        ->check(finiteRange(0.3, 2.8));
  }
}

struct PlotsArgs {
  std::string out, calib_out;
  sim::PlotSeries series;
};

int runPlots(const PlotsArgs& args) {
  const fs::path session_dir(args.out);
  const fs::path calib_dir =
      args.calib_out.empty() ? session_dir / "calib" : fs::path(args.calib_out);
  std::vector<std::string> locations;
  for (int index = 0; index < args.series.count; ++index)
    locations.push_back("plot-" + std::to_string(index + 1));
  auto recorded = sim::recordSyntheticPlots(session_dir, calib_dir, args.series, locations);
  if (!recorded)
    return fail("fieldrig sim plots: ", recorded.error().message, kExitRuntime);
  Json summary;
  summary["session"] = session_dir.string();
  summary["calib"] = calib_dir.string();
  summary["plots"] = recorded->size();
  summary["truth"] = (session_dir / "truth.jsonl").string();
  return printJsonLine(summary);
}

struct FieldArgs {
  std::string out;
  sim::FieldSpec spec;
};

int runSimulate(const FieldArgs& args) {
  auto files = sim::writeSyntheticField(args.out, args.spec, [](const sim::RecordedPlot& plot) {
    std::cerr << "fieldrig simulate: rendered " << plot.location_id << " (set " << plot.set_index
              << ")\n";
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
  addHeightRangeOptions(*plots, args->series.height_min_m, args->series.height_max_m);
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
  addHeightRangeOptions(*simulate, args->spec.height_min_m, args->spec.height_max_m);
  simulate->add_option("--speed", args->spec.speed_mps, "Ground speed, m/s")
      ->capture_default_str()
      ->check(finiteRange(0.5, 5.0));
}

}  // namespace fieldrig::tools
