// `fieldrig calibrate --left GLOB --right GLOB --board 9x6 --square 0.025 --out DIR`: one stereo
// head from chessboard pairs; `--head-pair --calib-a DIR --calib-b DIR --out FILE.yml`: the
// transform between two heads' left cameras from boards both saw at once. Prints one JSON line on
// success; bad input exits 2 with a message naming the file.
#include <glob.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "commands/command_helpers.h"
#include "fieldrig/stereo/calibrate.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct CalibrateArgs {
  std::string left, right, board = "9x6", out;
  double square = 0.025;
  double drop_factor = 2.5;
  bool head_pair = false;
  std::string calib_a, calib_b;
};

// Files matching a shell pattern, sorted (the shell may also have expanded it already: a plain
// existing file matches itself).
std::vector<std::string> expandGlob(const std::string& pattern) {
  std::vector<std::string> files;
  glob_t matches{};
  if (::glob(pattern.c_str(), 0, nullptr, &matches) == 0) {
    for (std::size_t i = 0; i < matches.gl_pathc; ++i)
      files.emplace_back(matches.gl_pathv[i]);
  }
  ::globfree(&matches);
  std::sort(files.begin(), files.end());
  return files;
}

// Printed calibration boards have tens of inner corners a side; thousands would make the corner
// search run for ever on every image.
constexpr int kMaxBoardCorners = 100;

std::optional<cv::Size> parseBoard(const std::string& text) {
  int cols = 0, rows = 0;
  char x = 0;
  std::istringstream in(text);
  if (!(in >> cols >> x >> rows) || (x != 'x' && x != 'X') || cols < 2 || rows < 2 ||
      cols > kMaxBoardCorners || rows > kMaxBoardCorners || !in.eof()) {
    return std::nullopt;
  }
  return cv::Size(cols, rows);
}

Json matrixJson(const cv::Matx44d& m) {
  Json rows = Json::array();
  for (int r = 0; r < 4; ++r)
    rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

int runHeadPair(const CalibrateArgs& args, const stereo::BoardPairs& pairs,
                const stereo::BoardSpec& board) {
  const char* who = "fieldrig calibrate: ";
  auto head_a = stereo::loadStereoCalibration(args.calib_a);
  if (!head_a) {
    std::cerr << who << "--calib-a: " << head_a.error().message << '\n';
    return kExitBadInput;
  }
  auto head_b = stereo::loadStereoCalibration(args.calib_b);
  if (!head_b) {
    std::cerr << who << "--calib-b: " << head_b.error().message << '\n';
    return kExitBadInput;
  }
  auto report = stereo::calibrateHeadToHead(*head_a, *head_b, pairs, board);
  if (!report)
    return fail(who, report.error().message);
  if (auto saved = stereo::saveHeadToHead(*report, args.out); !saved)
    return fail(who, saved.error().message);
  Json out;
  out["out"] = args.out;
  out["rms"] = report->rms;
  out["pairs_used"] = report->views_used;
  out["b_to_a"] = matrixJson(report->b_to_a);
  return printJsonLine(out);
}

int runHead(const CalibrateArgs& args, const stereo::BoardPairs& pairs,
            const stereo::BoardSpec& board) {
  const char* who = "fieldrig calibrate: ";
  stereo::CalibrateOptions options;
  options.drop_factor = args.drop_factor;
  auto report = stereo::calibrateHead(pairs.pairs, board, pairs.image_size, options);
  if (!report)
    return fail(who, report.error().message);
  auto saved = stereo::saveStereoCalibration(report->calibration, args.out);
  if (!saved)
    return fail(who, saved.error().message);
  Json out;
  out["out"] = args.out;
  out["rms"] = report->rms;
  out["epipolar_error_px"] = report->epipolar_error_px;
  out["pairs_used"] = report->pairs_used;
  out["pairs_given"] = pairs.pairs.size();
  out["baseline_m"] = report->calibration.baseline();
  Json views = Json::array();
  for (const stereo::ViewReport& view : report->views) {
    Json v;
    v["pair"] = view.name;
    v["found"] = view.found;
    v["used"] = view.used;
    v["error_left"] = view.error_left;
    v["error_right"] = view.error_right;
    if (!view.dropped_because.empty())
      v["dropped"] = view.dropped_because;
    views.push_back(std::move(v));
  }
  out["views"] = std::move(views);
  return printJsonLine(out);
}

int runCalibrate(const CalibrateArgs& args) {
  const char* who = "fieldrig calibrate: ";
  const auto board_size = parseBoard(args.board);
  if (!board_size) {
    std::cerr << who << "--board '" << args.board << "' is not COLSxROWS with each in [2, "
              << kMaxBoardCorners << "] (e.g. 9x6)\n";
    return kExitBadInput;
  }
  if (!(args.square > 0))
    return fail(who, "--square must be positive (metres)");
  const stereo::BoardSpec board{*board_size, args.square};
  const std::vector<std::string> left = expandGlob(args.left);
  const std::vector<std::string> right = expandGlob(args.right);
  if (left.empty() || right.empty()) {
    std::cerr << who << "no files match " << (left.empty() ? args.left : args.right) << '\n';
    return kExitBadInput;
  }
  if (left.size() != right.size()) {
    std::cerr << who << "--left matches " << left.size() << " files but --right matches "
              << right.size() << "; they are paired in sorted order\n";
    return kExitBadInput;
  }
  auto pairs = stereo::findBoardInImagePairs(left, right, board);
  if (!pairs)
    return fail(who, pairs.error().message);
  return args.head_pair ? runHeadPair(args, *pairs, board) : runHead(args, *pairs, board);
}

}  // namespace

void registerCalibrateCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate one stereo head from chessboard pairs (or, with --head-pair, the transform "
      "between two heads' left cameras); prints one JSON line");
  cmd->add_option("--left", args->left, "Left images (a glob such as 'dir/left*.jpg')")->required();
  cmd->add_option("--right", args->right, "Right images (paired with --left in sorted order)")
      ->required();
  cmd->add_option("--board", args->board, "Inner corners COLSxROWS")->capture_default_str();
  cmd->add_option("--square", args->square, "Square size in metres")
      ->capture_default_str()
      ->check(finiteRange(0.001, 1.0));
  cmd->add_option("--out", args->out,
                  "Output folder (intrinsics.yml, extrinsics.yml); with --head-pair a YAML file")
      ->required();
  cmd->add_option("--drop-factor", args->drop_factor,
                  "Drop views whose error exceeds this × the median, then recalibrate; 0 keeps "
                  "all")
      ->capture_default_str()
      ->check(finiteRange(0.0, 100.0));
  cmd->add_flag("--head-pair", args->head_pair,
                "--left are head A's left-camera images, --right head B's left-camera images "
                "of the same boards; writes B's frame → A's frame (b_to_a)");
  cmd->add_option("--calib-a", args->calib_a, "Head A's calibration folder (--head-pair)");
  cmd->add_option("--calib-b", args->calib_b, "Head B's calibration folder (--head-pair)");
  cmd->callback([args, &exit_code] {
    if (args->head_pair && (args->calib_a.empty() || args->calib_b.empty())) {
      std::cerr << "fieldrig calibrate: --head-pair needs --calib-a and --calib-b\n";
      exit_code = kExitBadInput;
      return;
    }
    exit_code = runCalibrate(*args);
  });
}

}  // namespace fieldrig::tools
