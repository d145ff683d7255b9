// The stereo subcommands:
//   fieldrig calibrate --left GLOB --right GLOB --board 9x6 --square 0.025 --out DIR
//   fieldrig calibrate --head-pair --left GLOB --right GLOB --calib-a DIR --calib-b DIR
//                      --board 9x6 --square 0.025 --out FILE.yml
//   fieldrig disparity --left L --right R [--intrinsics I --extrinsics E] --out FILE.pfm
//   fieldrig cloud --pairs L1,R1,L2,R2,L3,R3 --calib DIR --out plot.ply
//   fieldrig cloud SESSION --set ID [--calib DIR] --out plot.ply
// Each prints one JSON line on success; bad input exits 2 with a message naming the file.
#include <glob.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "commands/commands.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/stereo/calibrate.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/matcher.h"
#include "fieldrig/stereo/rectifier.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

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

std::optional<cv::Size> parseBoard(const std::string& text) {
  int cols = 0, rows = 0;
  char x = 0;
  std::istringstream in(text);
  if (!(in >> cols >> x >> rows) || (x != 'x' && x != 'X') || cols < 2 || rows < 2 || !in.eof()) {
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

// ---------------------------------------------------------------- calibrate

struct CalibrateArgs {
  std::string left, right, board = "9x6", out;
  double square = 0.025;
  double drop_factor = 2.5;
  bool head_pair = false;
  std::string calib_a, calib_b;
};

// Reads every image of the two lists and finds the board in each; the error names the file.
core::Result<std::vector<stereo::PairCorners>> detectPairs(const std::vector<std::string>& left,
                                                           const std::vector<std::string>& right,
                                                           const stereo::BoardSpec& board,
                                                           cv::Size& image_size) {
  std::vector<stereo::PairCorners> pairs;
  for (std::size_t i = 0; i < left.size(); ++i) {
    stereo::PairCorners pair;
    pair.name =
        fs::path(left[i]).filename().string() + "/" + fs::path(right[i]).filename().string();
    for (const auto& [file, corners] :
         {std::pair{&left[i], &pair.left}, std::pair{&right[i], &pair.right}}) {
      const cv::Mat grey = cv::imread(*file, cv::IMREAD_GRAYSCALE);
      if (grey.empty())
        return core::Error{*file + ": cannot read the image"};
      if (image_size.empty())
        image_size = grey.size();
      if (grey.size() != image_size) {
        return core::Error{*file + ": image is " + std::to_string(grey.cols) + "x" +
                           std::to_string(grey.rows) + ", the first was " +
                           std::to_string(image_size.width) + "x" +
                           std::to_string(image_size.height)};
      }
      if (auto found = stereo::findBoardCorners(grey, board))
        *corners = std::move(*found);
    }
    if (!pair.found()) {  // a pair counts only when both images show the board
      pair.left.clear();
      pair.right.clear();
    }
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

int runCalibrate(const CalibrateArgs& args) {
  const char* who = "fieldrig calibrate: ";
  const auto board_size = parseBoard(args.board);
  if (!board_size) {
    std::cerr << who << "--board '" << args.board << "' is not COLSxROWS (e.g. 9x6)\n";
    return kExitBadInput;
  }
  if (!(args.square > 0)) {
    std::cerr << who << "--square must be positive (metres)\n";
    return kExitBadInput;
  }
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
  cv::Size image_size;
  auto pairs = detectPairs(left, right, board, image_size);
  if (!pairs) {
    std::cerr << who << pairs.error().message << '\n';
    return kExitBadInput;
  }
  Json out;
  if (args.head_pair) {
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
    if (head_a->image_size.empty())
      head_a->image_size = image_size;
    std::vector<std::vector<cv::Point2f>> corners_a, corners_b;
    for (const stereo::PairCorners& pair : *pairs) {
      if (!pair.found())
        continue;
      corners_a.push_back(pair.left);
      corners_b.push_back(pair.right);
    }
    double rms = 0;
    auto transform =
        stereo::calibrateHeadToHead(*head_a, *head_b, corners_a, corners_b, board, &rms);
    if (!transform) {
      std::cerr << who << transform.error().message << '\n';
      return kExitBadInput;
    }
    try {
      cv::FileStorage storage(args.out, cv::FileStorage::WRITE);
      if (!storage.isOpened())
        throw cv::Exception();
      storage << "b_to_a" << cv::Mat(*transform) << "rms" << rms;
    } catch (const cv::Exception&) {
      std::cerr << who << args.out << ": cannot write\n";
      return kExitBadInput;
    }
    out["out"] = args.out;
    out["rms"] = rms;
    out["pairs_used"] = corners_a.size();
    out["b_to_a"] = matrixJson(*transform);
    std::cout << out.dump() << '\n';
    return kExitOk;
  }
  stereo::CalibrateOptions options;
  options.drop_factor = args.drop_factor;
  auto report = stereo::calibrateHead(*pairs, board, image_size, options);
  if (!report) {
    std::cerr << who << report.error().message << '\n';
    return kExitBadInput;
  }
  auto saved = stereo::saveStereoCalibration(report->calibration, args.out);
  if (!saved) {
    std::cerr << who << saved.error().message << '\n';
    return kExitBadInput;
  }
  out["out"] = args.out;
  out["rms"] = report->rms;
  out["epipolar_error_px"] = report->epipolar_error_px;
  out["pairs_used"] = report->pairs_used;
  out["pairs_given"] = pairs->size();
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
  std::cout << out.dump() << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------- disparity

struct DisparityArgs {
  std::string left, right, intrinsics, extrinsics, out;
  int num_disparities = 128;
  int block_size = 5;
  bool wls = false;
  bool lr_check = false;
};

int runDisparity(const DisparityArgs& args) {
  const char* who = "fieldrig disparity: ";
  cv::Mat left = cv::imread(args.left, cv::IMREAD_COLOR);
  if (left.empty()) {
    std::cerr << who << args.left << ": cannot read the image\n";
    return kExitBadInput;
  }
  cv::Mat right = cv::imread(args.right, cv::IMREAD_COLOR);
  if (right.empty()) {
    std::cerr << who << args.right << ": cannot read the image\n";
    return kExitBadInput;
  }
  if (left.size() != right.size()) {
    std::cerr << who << args.right << ": image is " << right.cols << "x" << right.rows
              << " but the left image is " << left.cols << "x" << left.rows << '\n';
    return kExitBadInput;
  }
  if (args.num_disparities <= 0 || args.num_disparities % 16 != 0) {
    std::cerr << who << "--num-disparities must be a positive multiple of 16\n";
    return kExitBadInput;
  }
  if (args.block_size < 1 || args.block_size % 2 == 0) {
    std::cerr << who << "--block-size must be odd\n";
    return kExitBadInput;
  }
  if (args.intrinsics.empty() != args.extrinsics.empty()) {
    std::cerr << who << "--intrinsics and --extrinsics go together\n";
    return kExitBadInput;
  }
  if (!args.intrinsics.empty()) {
    auto calibration = stereo::loadStereoCalibration(args.intrinsics, args.extrinsics);
    if (!calibration) {
      std::cerr << who << calibration.error().message << '\n';
      return kExitBadInput;
    }
    if (calibration->image_size.empty())
      calibration->image_size = left.size();
    if (calibration->image_size != left.size()) {
      std::cerr << who << args.intrinsics << ": calibration is for "
                << calibration->image_size.width << "x" << calibration->image_size.height
                << " images but " << args.left << " is " << left.cols << "x" << left.rows << '\n';
      return kExitBadInput;
    }
    auto rectifier = stereo::Rectifier::create(*calibration);
    if (!rectifier) {
      std::cerr << who << rectifier.error().message << '\n';
      return kExitBadInput;
    }
    cv::Mat left_rectified, right_rectified;
    rectifier->rectify(left, right, left_rectified, right_rectified);
    left = left_rectified;
    right = right_rectified;
  }
  stereo::MatcherOptions options;
  options.num_disparities = args.num_disparities;
  options.block_size = args.block_size;
  options.wls = args.wls;
  options.lr_check = args.lr_check;
  stereo::DisparityMatcher matcher(options);
  const auto start = Clock::now();
  const cv::Mat disparity = matcher.compute(left, right);
  const double ms = core::millisecondsSince(start);
  auto written = stereo::writePfm(args.out, disparity);
  if (!written) {
    std::cerr << who << written.error().message << '\n';
    return kExitBadInput;
  }
  const double valid = cv::countNonZero(disparity >= 0);
  Json out;
  out["out"] = args.out;
  out["width"] = disparity.cols;
  out["height"] = disparity.rows;
  out["valid_fraction"] = valid / static_cast<double>(disparity.total());
  out["match_ms"] = ms;
  std::cout << out.dump() << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------- cloud

struct CloudArgs {
  std::string session, pairs, calib, out;
  std::int64_t set = -1;
  bool wls = false;
};

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, ','))
    parts.push_back(part);
  return parts;
}

int runCloud(const CloudArgs& args) {
  const char* who = "fieldrig cloud: ";
  const auto start = Clock::now();
  if (args.session.empty() == args.pairs.empty()) {
    std::cerr << who << "give either a SESSION (with --set) or --pairs\n";
    return kExitBadInput;
  }
  std::optional<recording::SessionReader> reader;
  if (!args.session.empty()) {
    if (args.set < 0) {
      std::cerr << who << "--set is required with a SESSION\n";
      return kExitBadInput;
    }
    auto opened = recording::SessionReader::open(args.session);
    if (!opened) {
      std::cerr << who << opened.error().message << '\n';
      return kExitBadInput;
    }
    reader = std::move(*opened);
  }
  auto rig = daemon::loadRigFor(args.calib, reader ? &*reader : nullptr);
  if (!rig) {
    std::cerr << who << rig.error().message << '\n';
    return kExitBadInput;
  }
  std::vector<std::string> problems;
  std::vector<cloud::HeadFrames> frames;
  if (reader) {
    auto loaded = daemon::headFramesFromRecording(*reader, static_cast<std::uint64_t>(args.set),
                                                  *rig, problems);
    if (!loaded) {
      std::cerr << who << loaded.error().message << '\n';
      return kExitBadInput;
    }
    frames = std::move(*loaded);
  } else {
    const std::vector<std::string> files = splitCommas(args.pairs);
    if (files.size() != 2 * rig->heads.size()) {
      std::cerr << who << "--pairs names " << files.size() << " files; the rig in "
                << (fs::path(args.calib) / "rig.yml").string() << " has " << rig->heads.size()
                << " heads, so " << 2 * rig->heads.size() << " are needed (L1,R1,L2,R2,…)\n";
      return kExitBadInput;
    }
    for (std::size_t i = 0; i < rig->heads.size(); ++i) {
      cloud::HeadFrames head_frames;
      head_frames.pixel_format = rig->pixel_format;
      head_frames.left = cv::imread(files[2 * i], cv::IMREAD_UNCHANGED);
      head_frames.right = cv::imread(files[2 * i + 1], cv::IMREAD_UNCHANGED);
      for (const auto& [file, image] : {std::pair{&files[2 * i], &head_frames.left},
                                        std::pair{&files[2 * i + 1], &head_frames.right}}) {
        if (image->empty()) {
          std::cerr << who << *file << ": cannot read the image\n";
          return kExitBadInput;
        }
        if (image->depth() != CV_8U || (image->channels() != 1 && image->channels() != 3)) {
          std::cerr << who << *file << ": not an 8-bit raw or colour image\n";
          return kExitBadInput;
        }
      }
      frames.push_back(std::move(head_frames));
    }
  }
  cloud::CloudOptions options;
  options.matcher.wls = args.wls;
  auto builder = cloud::CloudBuilder::create(*rig, options);
  if (!builder) {
    std::cerr << who << builder.error().message << '\n';
    return kExitBadInput;
  }
  const cloud::FusionResult result = builder->build(frames);
  Json heads = Json::array();
  for (const cloud::HeadStatus& head : result.heads) {
    Json h;
    h["name"] = head.name;
    h["ok"] = head.ok;
    h["points"] = head.points;
    if (!head.ok) {
      h["problem"] = head.problem;
      std::cerr << who << "head left out: " << head.problem << '\n';
    }
    heads.push_back(std::move(h));
  }
  for (const std::string& problem : problems)
    std::cerr << who << problem << '\n';
  if (result.cloud.empty()) {
    std::cerr << who << "no head gave any point; nothing written\n";
    return kExitBadInput;
  }
  auto written = cloud::writePly(result.cloud, args.out);
  if (!written) {
    std::cerr << who << written.error().message << '\n';
    return kExitBadInput;
  }
  Json out;
  out["out"] = args.out;
  out["points"] = result.cloud.size();
  out["partial"] = result.partial();
  out["heads"] = std::move(heads);
  out["problems"] = problems;
  out["ms"] = core::millisecondsSince(start);
  std::cout << out.dump() << '\n';
  return kExitOk;
}

}  // namespace

void registerStereoCommands(CLI::App& app, int& exit_code) {
  {
    auto args = std::make_shared<CalibrateArgs>();
    CLI::App* cmd = app.add_subcommand(
        "calibrate",
        "Calibrate one stereo head from chessboard pairs (or, with --head-pair, the transform "
        "between two heads' left cameras); prints one JSON line");
    cmd->add_option("--left", args->left, "Left images (a glob such as 'dir/left*.jpg')")
        ->required();
    cmd->add_option("--right", args->right, "Right images (paired with --left in sorted order)")
        ->required();
    cmd->add_option("--board", args->board, "Inner corners COLSxROWS")->capture_default_str();
    cmd->add_option("--square", args->square, "Square size in metres")->capture_default_str();
    cmd->add_option("--out", args->out,
                    "Output folder (intrinsics.yml, extrinsics.yml); with --head-pair a YAML file")
        ->required();
    cmd->add_option("--drop-factor", args->drop_factor,
                    "Drop views whose error exceeds this × the median, then recalibrate; 0 keeps "
                    "all")
        ->capture_default_str();
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
  {
    auto args = std::make_shared<DisparityArgs>();
    CLI::App* cmd = app.add_subcommand(
        "disparity",
        "Disparity of the left image (PFM, pixels; invalid = -1), rectified first "
        "when a calibration is given");
    cmd->add_option("--left", args->left, "Left image")->required();
    cmd->add_option("--right", args->right, "Right image")->required();
    cmd->add_option("--intrinsics", args->intrinsics, "intrinsics.yml (M1 D1 M2 D2)");
    cmd->add_option("--extrinsics", args->extrinsics, "extrinsics.yml (R T R1 R2 P1 P2 Q)");
    cmd->add_option("--num-disparities", args->num_disparities, "Multiple of 16")
        ->capture_default_str();
    cmd->add_option("--block-size", args->block_size, "Odd SGBM block size")->capture_default_str();
    cmd->add_flag("--wls", args->wls, "Apply opencv_contrib's WLS filter (fills holes)");
    cmd->add_flag("--lr-check", args->lr_check,
                  "Match the right view too and drop inconsistent pixels");
    cmd->add_option("--out", args->out, "Output .pfm")->required();
    cmd->callback([args, &exit_code] { exit_code = runDisparity(*args); });
  }
  {
    auto args = std::make_shared<CloudArgs>();
    CLI::App* cmd = app.add_subcommand(
        "cloud", "Fused three-head point cloud of one FrameSet in the plot frame (binary PLY)");
    cmd->add_option("session", args->session, "Recorded session folder");
    cmd->add_option("--set", args->set, "Set index in the session");
    cmd->add_option("--pairs", args->pairs, "L1,R1,L2,R2,L3,R3 image files, heads in rig order");
    cmd->add_option("--calib", args->calib,
                    "Calibration folder (rig.yml + one folder per head); for a session, "
                    "defaults to its calibration reference named calib_dir");
    cmd->add_flag("--wls", args->wls, "Apply the WLS disparity filter");
    cmd->add_option("--out", args->out, "Output .ply")->required();
    cmd->callback([args, &exit_code] { exit_code = runCloud(*args); });
  }
}

}  // namespace fieldrig::tools
