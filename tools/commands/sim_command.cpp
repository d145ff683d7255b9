// `fieldrig sim drive`: a simulated serpentine drive over a field plan, written as the NMEA the
// auto-guidance receiver would send, with the plan's imaging-location map beside it. Replay-based
// testing needs no tractor: `fieldrig triggers --map MAP --nmea NMEA` on the two files.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/command_helpers.h"
#include "commands/field_plan_options.h"
#include "fieldrig/core/durable_file.h"
#include "fieldrig/sim/drive_simulator.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;

using Json = nlohmann::ordered_json;

struct DriveArgs {
  FieldPlanArgs field;
  sim::DriveOptions drive;
  std::string start;  // ISO-8601; empty: the simulator's default
  std::string out_nmea;
  std::string out_map;
};

int runDrive(const DriveArgs& args) {
  constexpr std::string_view kName = "fieldrig sim drive: ";
  const auto plan = resolveFieldPlan(args.field);
  if (!plan)
    return fail(kName, plan.error().message);
  sim::DriveOptions options = args.drive;
  if (!args.start.empty()) {
    const auto start = core::parseIso8601(args.start);
    if (!start) {
      std::cerr << kName << "--start: '" << args.start << "' is not ISO-8601 UTC\n";
      return kExitBadInput;
    }
    options.start = *start;
  }
  const auto map = gps::generateLocations(*plan);
  if (!map)
    return fail(kName, map.error().message);
  // Each option was range-checked on its own; this also names the option of a value built from
  // several (and keeps the simulator's own rules in one place).
  if (const auto valid = sim::validate(options); !valid)
    return fail(kName, valid.error().message);
  const sim::DriveSimulator drive(*plan, options);
  // A drive and its map belong together: both are written, or neither (a drive left without its
  // map, or beside an older one, would replay against the wrong locations). A FIFO, a device or
  // a link such as /dev/stdout cannot be replaced by a rename: those are written in place.
  const std::string nmea = drive.nmea();
  const std::string csv = map->toCsv();
  auto replaceable = [](const std::string& path) {
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(path, ec);
    return status.type() == fs::file_type::not_found || status.type() == fs::file_type::regular;
  };
  // One file for both would lose the drive. Devices (/dev/null, a terminal) are written through
  // and may well be one.
  if (replaceable(args.out_nmea) && replaceable(args.out_map)) {
    std::error_code nmea_error, map_error;
    const fs::path nmea_path = fs::weakly_canonical(args.out_nmea, nmea_error);
    const fs::path map_path = fs::weakly_canonical(args.out_map, map_error);
    if (!nmea_error && !map_error && nmea_path == map_path) {
      std::cerr << kName << "--out-nmea and --out-map name the same file: " << args.out_map << '\n';
      return kExitBadInput;
    }
  }
  for (const std::string& out : {args.out_nmea, args.out_map}) {
    if (std::error_code ec; fs::is_directory(out, ec)) {
      std::cerr << kName << out << ": a folder, not a file; nothing was written\n";
      return kExitBadInput;
    }
  }
  std::string failed;
  if (replaceable(args.out_nmea) && replaceable(args.out_map)) {
    failed = core::replaceFilesTogether({{args.out_nmea, nmea}, {args.out_map, csv}});
  } else {
    failed = core::writeWholeFile(args.out_nmea, nmea);
    if (failed.empty())
      failed = core::writeWholeFile(args.out_map, csv);
  }
  if (!failed.empty()) {
    std::cerr << kName << failed << '\n';
    return kExitBadInput;
  }
  Json summary;
  summary["nmea"] = args.out_nmea;
  summary["map"] = args.out_map;
  summary["locations"] = map->size();
  summary["length_m"] = drive.lengthM();
  summary["start"] = core::formatIso8601(drive.start(), 2);
  summary["end"] = core::formatIso8601(drive.end(), 2);
  // An output written to stdout keeps it to itself: the summary goes to stderr.
  std::error_code ec;
  if (fs::equivalent(args.out_nmea, "/dev/stdout", ec) ||
      fs::equivalent(args.out_map, "/dev/stdout", ec)) {
    std::cerr << summary.dump() << '\n';
    return kExitOk;
  }
  return printJsonLine(summary);
}

}  // namespace

void registerSimCommand(CLI::App& app, int& exit_code) {
  CLI::App* sim = addCommandGroup(app, "sim", "Simulated data for hardware-free runs");
  const auto [drive, args] = addSubcommand(
      *sim, "drive", "Write the NMEA of a simulated serpentine drive and the plan's location map",
      exit_code, runDrive);
  addFieldPlanOptions(*drive, args->field);
  sim::DriveOptions& d = args->drive;
  drive->add_option("--speed", d.speed_mps, "Ground speed, m/s")
      ->capture_default_str()
      ->check(finiteRange(0.1, 30.0));
  drive->add_option("--rate", d.rate_hz, "Fix rate, Hz")
      ->capture_default_str()
      ->check(finiteRange(0.1, 100.0));
  drive->add_option("--noise", d.position_noise_m, "Position noise (SD per axis), m")
      ->capture_default_str()
      ->check(finiteRange(0.0, 100.0));
  drive->add_option("--headland", d.headland_m, "Straight run-in/out beyond each row end, m")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1000.0));
  drive
      ->add_option("--speed-slow-amplitude", d.speed_slow_amplitude,
                   "Slow speed breathing: amplitude as a fraction of --speed (0.15 = ±15 %)")
      ->capture_default_str()
      ->check(finiteRange(0.0, 0.5));
  drive->add_option("--speed-slow-period", d.speed_slow_period_s, "Slow speed breathing: period, s")
      ->capture_default_str()
      ->check(finiteRange(0.5, 3600.0));
  drive
      ->add_option("--speed-fast-amplitude", d.speed_fast_amplitude,
                   "Fast speed breathing: amplitude as a fraction of --speed")
      ->capture_default_str()
      ->check(finiteRange(0.0, 0.5));
  drive->add_option("--speed-fast-period", d.speed_fast_period_s, "Fast speed breathing: period, s")
      ->capture_default_str()
      ->check(finiteRange(0.5, 3600.0));
  drive
      ->add_option("--velocity-noise", d.velocity_noise_mps,
                   "Noise (SD per axis) of the velocity behind RMC speed and course, m/s")
      ->capture_default_str()
      ->check(finiteRange(0.0, 10.0));
  drive
      ->add_option("--correlated-noise", d.correlated_noise_m,
                   "Gauss-Markov position noise (SD per axis), m")
      ->capture_default_str()
      ->check(finiteRange(0.0, 100.0));
  drive
      ->add_option("--correlated-noise-tau", d.correlated_noise_tau_s,
                   "Gauss-Markov position noise: correlation time, s")
      ->capture_default_str()
      ->check(finiteRange(0.01, 3600.0));
  drive->add_option("--seed", d.seed, "Noise seed")->capture_default_str();
  drive->add_option("--talker", d.talker, "NMEA talker id")->capture_default_str();
  drive->add_option("--start", args->start, "GPS time of the first fix (ISO-8601 UTC)");
  drive->add_option("--out-nmea", args->out_nmea, "NMEA file to write")->required();
  drive->add_option("--out-map", args->out_map, "Location map to write")->required();
  registerSimPlotsSubcommand(*sim, exit_code);
}

}  // namespace fieldrig::tools
