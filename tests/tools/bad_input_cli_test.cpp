// The project's own bad-input campaign (issue 17): what a careless or hostile user gives each
// `fieldrig` command — NaN, infinity, negative or absurdly large numbers, a folder where a file
// belongs — must end with exit code 2 and a message naming the option or file, never a crash, a
// run without end or a success that ignored what it was told. Each case runs under `timeout`,
// so one that hangs fails as exit 124 instead of stopping the suite.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/sanitizer.h"
#include "support/temp_dir.h"

namespace fieldrig::testing_support {
namespace {

namespace fs = std::filesystem;

constexpr int kBadInput = 2;

// A case: the command line, with placeholders for the files the suite prepares — {map} and
// {nmea} (a simulated drive), {session} (one synthetic plot with its calibration), {cloud} (a
// synthetic plot cloud), {dir} (a folder), {out} (a path nothing is at yet), {config} and {ply}
// (files holding `config`) and {calib} (a folder whose rig.yml holds `config`) — the exit code and
// what stderr must contain.
struct BadInputCase {
  std::string name;
  std::vector<std::string> args;
  std::string stderr_names;
  std::string config = {};
  int exit_code = kBadInput;
};

void PrintTo(const BadInputCase& c, std::ostream* out) {
  *out << c.name;
}

// A field of 2 rows of 66 m: small enough for every command to be quick when the input is good.
const std::vector<std::string> kPlan = {"--row-start",    "42.0106,-93.7385",
                                        "--row-end",      "42.0112,-93.7385",
                                        "--rows",         "2",
                                        "--plot-length",  "3",
                                        "--alley-length", "1",
                                        "--row-spacing",  "2"};

std::vector<std::string> withPlan(std::vector<std::string> command,
                                  std::vector<std::string> changed) {
  std::vector<std::string> args = std::move(command);
  std::vector<std::string> plan = kPlan;
  // An option given in `changed` replaces the plan's own value.
  for (std::size_t i = 0; i + 1 < changed.size(); i += 2) {
    bool replaced = false;
    for (std::size_t j = 0; j + 1 < plan.size(); j += 2) {
      if (plan[j] == changed[i]) {
        plan[j + 1] = changed[i + 1];
        replaced = true;
      }
    }
    if (!replaced) {
      plan.push_back(changed[i]);
      plan.push_back(changed[i + 1]);
    }
  }
  args.insert(args.end(), plan.begin(), plan.end());
  return args;
}

std::vector<std::string> simDrive(std::vector<std::string> changed) {
  auto args = withPlan({"sim", "drive"}, std::move(changed));
  args.insert(args.end(), {"--out-nmea", "{out}.nmea", "--out-map", "{out}.csv"});
  return args;
}

std::vector<std::string> mapGenerate(std::vector<std::string> changed) {
  auto args = withPlan({"map", "generate"}, std::move(changed));
  args.insert(args.end(), {"--out", "{out}"});
  return args;
}

std::vector<std::string> triggers(std::vector<std::string> extra) {
  std::vector<std::string> args = {"triggers", "--map", "{map}", "--nmea", "{nmea}"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::vector<std::string> acquire(std::vector<std::string> extra) {
  std::vector<std::string> args = {"acquire", "--count", "2",  "--rate",   "10", "--out",
                                   "{out}",   "--width", "64", "--height", "48"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::vector<std::string> traitsWithConfig() {
  return {"traits", "--cloud", "{cloud}", "--config", "{config}", "--json"};
}

std::vector<BadInputCase> numberCases() {
  return {
      // sim drive: NaN made the fix clock never advance (hang) or the NMEA unreadable (exit 0).
      {"SimDriveRateNan", simDrive({"--rate", "nan"}), "--rate"},
      {"SimDriveNoiseNan", simDrive({"--noise", "nan"}), "--noise"},
      {"SimDriveSpeedInf", simDrive({"--speed", "inf"}), "--speed"},
      {"SimDriveHeadlandNegative", simDrive({"--headland", "-1"}), "--headland"},
      {"SimDriveRowsZero", simDrive({"--rows", "0"}), "--rows"},
      // map generate: two billion rows ran for hours.
      {"MapGenerateRowsHuge", mapGenerate({"--rows", "2000000000"}), "--rows"},
      {"MapGeneratePlotsNegative", mapGenerate({"--plots", "-1"}), "--plots"},
      {"MapGeneratePlotLengthNan", mapGenerate({"--plot-length", "nan"}), "--plot-length"},
      {"MapGenerateRowSpacingZero", mapGenerate({"--row-spacing", "0"}), "--row-spacing"},
      {"MapGenerateStartOffsetInf", mapGenerate({"--start-offset", "inf"}), "--start-offset"},
      {"MapGenerateTooManyPlotsThatFit",
       mapGenerate({"--rows", "500", "--plot-length", "0.1", "--alley-length", "0"}), "--rows"},
      {"MapGenerateRowEndFarAway", mapGenerate({"--row-end", "52.0,-93.7385"}), "--row-end"},
      // triggers: NaN or a huge lead or latency made every location "missed" with exit 0.
      {"TriggersLatencyNan", triggers({"--latency", "nan"}), "--latency"},
      {"TriggersLeadNan", triggers({"--lead", "nan"}), "--lead"},
      {"TriggersLeadHuge", triggers({"--lead", "1e9"}), "--lead"},
      {"TriggersLeadNegative", triggers({"--lead", "-5"}), "--lead"},
      {"TriggersCrossTrackNan", triggers({"--cross-track", "nan"}), "--cross-track"},
      {"TriggersHeadingToleranceNan", triggers({"--heading-tolerance", "nan"}),
       "--heading-tolerance"},
      {"TriggersMinSpeedNan", triggers({"--min-speed", "nan"}), "--min-speed"},
      {"TriggersMinIntervalInf", triggers({"--min-interval", "inf"}), "--min-interval"},
      {"TriggersBaudZero", triggers({"--baud", "0"}), "--baud"},
      // acquire: NaN rate hung; a negative timeout lost every frame with exit 0; 70000 pool sets
      // aborted in Boost.Lockfree.
      {"AcquireRateNan", acquire({"--rate", "nan"}), "--rate"},
      {"AcquireRateZero", acquire({"--rate", "0"}), "--rate"},
      {"AcquireFrameTimeoutNegative", acquire({"--frame-timeout-ms", "-1"}), "--frame-timeout-ms"},
      {"AcquirePoolSetsBeyondLockfree", acquire({"--pool-sets", "70000"}), "--pool-sets"},
      {"AcquireWidthHuge", acquire({"--width", "1000000"}), "--width"},
      {"AcquireHeightZero", acquire({"--height", "0"}), "--height"},
      {"AcquireCountZero", acquire({"--count", "0"}), "--count"},
      // The other commands' numbers.
      {"SimPlotsHeightNan",
       {"sim", "plots", "--out", "{out}", "--height-min", "nan"},
       "--height-min"},
      {"SimPlotsCountHuge", {"sim", "plots", "--out", "{out}", "--count", "2000000000"}, "--count"},
      {"SimulateSpeedNan", {"simulate", "--out", "{out}", "--speed", "nan"}, "--speed"},
      {"TraitsSynthHeightNan",
       {"traits", "synth", "--out", "{out}.ply", "--height", "nan"},
       "--height"},
      {"TraitsSynthNoiseInf",
       {"traits", "synth", "--out", "{out}.ply", "--noise", "inf"},
       "--noise"},
      {"TraitsSynthPointsNegative",
       {"traits", "synth", "--out", "{out}.ply", "--points", "-1"},
       "--points"},
      {"CalibrateSquareNan",
       {"calibrate", "--left", "{dir}/l*.png", "--right", "{dir}/r*.png", "--out", "{out}",
        "--square", "nan"},
       "--square"},
      {"CalibrateBoardHuge",
       {"calibrate", "--left", "{dir}/l*.png", "--right", "{dir}/r*.png", "--out", "{out}",
        "--board", "99999x99999"},
       "--board"},
      {"CalibrateDropFactorNegative",
       {"calibrate", "--left", "{dir}/l*.png", "--right", "{dir}/r*.png", "--out", "{out}",
        "--drop-factor", "-1"},
       "--drop-factor"},
      {"CloudSetNegative", {"cloud", "{session}", "--set", "-5", "--out", "{out}.ply"}, "--set"},
      {"StemUiPortHuge", {"stem-ui", "{session}", "--port", "70000"}, "--port"},
      {"ViewPortHuge", {"view", "{session}", "--port", "70000"}, "--port"},
      {"ViewStemPortZero", {"view", "{session}", "--stem-port", "0"}, "--stem-port"},
      {"MapRecordBaudNan",
       {"map", "record", "--nmea", "{nmea}", "--out", "{out}", "--baud", "nan"},
       "--baud"},
      {"MapRecordStartIdZero",
       {"map", "record", "--nmea", "{nmea}", "--out", "{out}", "--start-id", "0"},
       "--start-id"},
  };
}

std::vector<BadInputCase> traitsOptionCases() {
  return {
      // Each was taken silently: 2e9 slices threw std::bad_alloc, a 1e-9 m cell gave VAI 0 with
      // status ok.
      {"SlicesHuge", traitsWithConfig(), "slices", "slices: 2000000000\n"},
      {"SlicesNegative", traitsWithConfig(), "slices", "slices: -3\n"},
      {"DepthMapCellTiny", traitsWithConfig(), "depth_map_cell_m", "depth_map_cell_m: 1e-9\n"},
      {"RowLengthNegative", traitsWithConfig(), "row_length_m", "row_length_m: -1\n"},
      {"IcpIterationsHuge", traitsWithConfig(), "icp_iterations", "icp_iterations: 100000000\n"},
      {"OutlierMeanKZero", traitsWithConfig(), "outlier_mean_k", "outlier_mean_k: 0\n"},
      {"OutlierStddevMulNan", traitsWithConfig(), "outlier_stddev_mul",
       "outlier_stddev_mul: .nan\n"},
      {"OutlierMinNeighboursHuge", traitsWithConfig(), "outlier_min_neighbours",
       "outlier_min_neighbours: 27\n"},
      {"ProcessTraitsConfigSlicesHuge",
       {"process", "{session}", "--traits-config", "{config}", "--out", "{out}"},
       "slices",
       "slices: 2000000000\n"},
  };
}

std::vector<BadInputCase> pathCases() {
  return {
      // A folder where a file belongs: `nmea decode` decoded it as an empty log with exit 0.
      {"NmeaDecodeDirectory", {"nmea", "decode", "{dir}"}, "{dir}"},
      {"TriggersMapDirectory", {"triggers", "--map", "{dir}", "--nmea", "{nmea}"}, "{dir}"},
      {"TriggersNmeaDirectory", {"triggers", "--map", "{map}", "--nmea", "{dir}"}, "{dir}"},
      {"MapRecordOutDirectory", {"map", "record", "--nmea", "{nmea}", "--out", "{dir}"}, "{dir}"},
      {"ProcessMapDirectory",
       {"process", "{session}", "--map", "{dir}", "--out", "{out}"},
       "{dir}"},
      {"TraitsCloudDirectory", {"traits", "--cloud", "{dir}"}, "--cloud"},
      {"TraitsConfigDirectory", {"traits", "--cloud", "{cloud}", "--config", "{dir}"}, "--config"},
      // stem-ui: a folder as the measurement file, a file as the calibration folder. Before, the
      // page started and every save then failed with 500.
      {"StemUiOutDirectory", {"stem-ui", "{session}", "--port", "0", "--out", "{dir}"}, "{dir}"},
      {"StemUiCalibFile", {"stem-ui", "{session}", "--port", "0", "--calib", "{map}"}, "{map}"},
  };
}

// Damaged files, written from the case's text: {ply} a cloud, {calib} a calibration folder
// whose rig.yml it is.
std::vector<BadInputCase> damagedFileCases() {
  const std::string rig_head = "%YAML:1.0\nheads: [ bottom ]\n";
  return {
      // PCL's reader read a word as NaN and the traits went on with exit 0.
      {"TraitsPlyWithAWord",
       {"traits", "--cloud", "{ply}"},
       "cloud.ply:9: 'x1' is not a number",
       "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n1 2 3\n4 x1 6\n"},
      // PCL's reader failed an assert() (exit 134) on a colour out of order.
      {"TraitsPlyBlueBeforeRed",
       {"traits", "--cloud", "{ply}"},
       "cloud.ply:",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nproperty uchar blue\nend_header\n1 2\n"},
      // OpenCV allocated the declared 2^31 x 2^31 matrix before reading it.
      {"ProcessRigHugeMatrix",
       {"process", "{session}", "--calib", "{calib}", "--out", "{out}"},
       "field 'bottom_to_bottom'",
       rig_head + "bottom_to_bottom: !!opencv-matrix\n  rows: 2147483647\n"
                  "  cols: 2147483647\n  dt: d\n  data: [ 1 ]\n"},
      // A head name became a folder path outside the calibration folder.
      {"ProcessRigHeadNameIsAPath",
       {"process", "{session}", "--calib", "{calib}", "--out", "{out}"},
       "'../../x' is not a head name",
       "%YAML:1.0\nheads: [ \"../../x\" ]\n"},
      // OpenCV's parser threw std::length_error through the loader (exit 134).
      {"ProcessRigKeyWithoutName",
       {"process", "{session}", "--calib", "{calib}", "--out", "{out}"},
       "rig.yml: not a map of fields",
       "%YAML:1.0\n:1.0\n"},
      // OpenCV's parser looped for ever on this rig.yml (found by the calibration_yaml fuzzer).
      {"ProcessRigParserLoop",
       {"process", "{session}", "--calib", "{calib}", "--out", "{out}"},
       "rig.yml:5: not readable as YAML (illegal map value)",
       "%YAML:1.0\n---e:as\nhd\n   - bobototm_to_bottomosrotwb\n"
       "tom_to_bottom: !!ormat: BayerRG8\n"},
  };
}

// The files a case names, made by the binary itself when a case first needs them: CTest runs
// each case in a process of its own, so nothing is made that the case does not use.
class BadInputCli : public ::testing::TestWithParam<BadInputCase> {
 protected:
  static void SetUpTestSuite() {
    suite_dir_ = new ScopedTempDir("bad_input_cli");
    fs::create_directories(suite_dir_->path() / "a_folder");
  }
  static void TearDownTestSuite() {
    delete suite_dir_;
    suite_dir_ = nullptr;
  }

  static const fs::path& dir() { return suite_dir_->path(); }

  // Makes `made` with `command` unless it is there; the failure says which command failed.
  static void make(const fs::path& made, const std::vector<std::string>& command) {
    if (fs::exists(made))
      return;
    const CliRun run = runFieldrig(command, dir());
    ASSERT_EQ(run.exit_code, 0) << "preparing " << made << ": " << run.err;
  }

  static void prepare(const std::string& arg) {
    if (arg.find("{map}") != std::string::npos || arg.find("{nmea}") != std::string::npos) {
      auto drive = withPlan({"sim", "drive"}, {});
      drive.insert(drive.end(), {"--out-nmea", (dir() / "drive.nmea").string(), "--out-map",
                                 (dir() / "map.csv").string()});
      make(dir() / "map.csv", drive);
    }
    if (arg.find("{session}") != std::string::npos) {
      make(dir() / "session",
           {"sim", "plots", "--out", (dir() / "session").string(), "--count", "1"});
    }
    if (arg.find("{cloud}") != std::string::npos) {
      make(dir() / "plot.ply", {"traits", "synth", "--out", (dir() / "plot.ply").string(),
                                "--points", "20000", "--seed", "2"});
    }
  }

  static std::string substitute(std::string text, const fs::path& case_dir) {
    const std::pair<std::string, std::string> placeholders[] = {
        {"{map}", (dir() / "map.csv").string()},
        {"{nmea}", (dir() / "drive.nmea").string()},
        {"{session}", (dir() / "session").string()},
        {"{cloud}", (dir() / "plot.ply").string()},
        {"{dir}", (dir() / "a_folder").string()},
        {"{out}", (case_dir / "out").string()},
        {"{config}", (case_dir / "options.yaml").string()},
        {"{ply}", (case_dir / "cloud.ply").string()},
        {"{calib}", (case_dir / "calib").string()},
    };
    for (const auto& [token, value] : placeholders) {
      for (std::size_t at = text.find(token); at != std::string::npos;
           at = text.find(token, at + value.size()))
        text.replace(at, token.size(), value);
    }
    return text;
  }

  static ScopedTempDir* suite_dir_;
};

ScopedTempDir* BadInputCli::suite_dir_ = nullptr;

TEST_P(BadInputCli, ExitsWithBadInputNamingTheCulprit) {
  const BadInputCase& c = GetParam();
  const fs::path case_dir = dir() / c.name;
  fs::create_directories(case_dir);
  for (const std::string& arg : c.args) {
    prepare(arg);
    if (HasFatalFailure())
      return;
  }
  if (!c.config.empty()) {
    std::ofstream(case_dir / "options.yaml") << c.config;
    std::ofstream(case_dir / "cloud.ply", std::ios::binary) << c.config;
    fs::create_directories(case_dir / "calib");
    std::ofstream(case_dir / "calib" / "rig.yml", std::ios::binary) << c.config;
  }
  std::vector<std::string> args = {"60", kFieldrigBinary};
  for (const std::string& arg : c.args)
    args.push_back(substitute(arg, case_dir));
  const CliRun run = runProgram("timeout", args, case_dir);
  EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
  const std::string names = substitute(c.stderr_names, case_dir);
  EXPECT_NE(run.err.find(names), std::string::npos) << "stderr does not name " << names << ":\n"
                                                    << run.err;
  // Bad input is refused before anything is written.
  EXPECT_FALSE(fs::exists(case_dir / "out.csv")) << "a map was written";
}

std::string caseName(const ::testing::TestParamInfo<BadInputCase>& info) {
  return info.param.name;
}

INSTANTIATE_TEST_SUITE_P(Numbers, BadInputCli, ::testing::ValuesIn(numberCases()), caseName);
INSTANTIATE_TEST_SUITE_P(TraitsOptions, BadInputCli, ::testing::ValuesIn(traitsOptionCases()),
                         caseName);
INSTANTIATE_TEST_SUITE_P(Paths, BadInputCli, ::testing::ValuesIn(pathCases()), caseName);
INSTANTIATE_TEST_SUITE_P(DamagedFiles, BadInputCli, ::testing::ValuesIn(damagedFileCases()),
                         caseName);

// A 400 MB frame pool under a 600 MB address-space limit, with flags that are all in range: the
// pool's allocation fails, and the run ends as one line naming the command and the size, exit 2.
// Before, std::bad_alloc escaped and the process aborted (exit 134).
TEST(BadInputCliInternalError, AFramePoolThatCannotBeAllocatedIsOneLineNamingItsSize) {
  if (kAddressSanitizer)
    GTEST_SKIP() << "AddressSanitizer's shadow memory does not fit under ulimit -v";
  ScopedTempDir dir("bad_input_cli_oom");
  const std::string command =
      "ulimit -v 600000; exec " + shellQuote(kFieldrigBinary) +
      " acquire --count 1 --rate 10 --width 4096 --height 4096 --pool-sets 4 --out " +
      shellQuote((dir / "session").string());
  const CliRun run = runProgram("sh", {"-c", command}, dir.path());
  EXPECT_EQ(run.exit_code, 2) << run.err;
  ASSERT_EQ(run.err_lines.size(), 1U) << run.err;
  EXPECT_EQ(run.err_lines[0],
            "fieldrig acquire: rig: frame pool: cannot allocate 24 buffers of 16777216 bytes "
            "(402653184 bytes in all)");
}

TEST(BadInputCliHelp, ListsTheExitCodes) {
  ScopedTempDir dir("bad_input_cli_help");
  const CliRun run = runFieldrig({"--help"}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::string out;
  for (const std::string& line : run.out_lines)
    out += line + "\n";
  for (const char* code : {"0 ok", "2 bad input", "3 a failure while running", "4 internal error"})
    EXPECT_NE(out.find(code), std::string::npos) << code;
}

}  // namespace
}  // namespace fieldrig::testing_support
