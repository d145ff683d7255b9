// `fieldrig disparity --left L --right R [--intrinsics I --extrinsics E] --out FILE.pfm`: the
// disparity of one image pair (rectified first when a calibration is given) as PFM. Prints one
// JSON line on success; bad input exits 2 with a message naming the file.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "commands/command_helpers.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/pair_disparity.h"

namespace fieldrig::tools {
namespace {

struct DisparityArgs {
  std::string left, right, intrinsics, extrinsics, out;
  int num_disparities = 128;
  int block_size = 5;
  bool wls = false;
  bool lr_check = false;
  int grow_uniqueness_ratio = -1;
};

int runDisparity(const DisparityArgs& args) {
  const char* who = "fieldrig disparity: ";
  const cv::Mat left = cv::imread(args.left, cv::IMREAD_COLOR);
  if (left.empty()) {
    std::cerr << who << args.left << ": cannot read the image\n";
    return kExitBadInput;
  }
  // The PFM replaces --out whole: given an input's path it would overwrite that input.
  for (const std::string& input : {args.left, args.right, args.intrinsics, args.extrinsics}) {
    std::error_code ec;
    if (!input.empty() && std::filesystem::equivalent(args.out, input, ec))
      return fail(who, "--out " + args.out + " is the input " + input + ": give another file");
  }
  const cv::Mat right = cv::imread(args.right, cv::IMREAD_COLOR);
  if (right.empty()) {
    std::cerr << who << args.right << ": cannot read the image\n";
    return kExitBadInput;
  }
  if (left.size() != right.size()) {
    std::cerr << who << args.right << ": image is " << right.cols << "x" << right.rows
              << " but the left image is " << left.cols << "x" << left.rows << '\n';
    return kExitBadInput;
  }
  stereo::MatcherOptions options;
  options.num_disparities = args.num_disparities;
  options.block_size = args.block_size;
  options.wls = args.wls;
  options.lr_check = args.lr_check;
  options.grow_uniqueness_ratio = args.grow_uniqueness_ratio;
  if (auto valid = stereo::validate(options, left.size(), stereo::OptionNames::kCommandLineFlags);
      !valid)
    return fail(who, valid.error().message);
  if (args.intrinsics.empty() != args.extrinsics.empty())
    return fail(who, "--intrinsics and --extrinsics go together");
  std::optional<stereo::StereoCalibration> calibration;
  if (!args.intrinsics.empty()) {
    auto loaded = stereo::loadStereoCalibration(args.intrinsics, args.extrinsics);
    if (!loaded)
      return fail(who, loaded.error().message);
    calibration = std::move(*loaded);
    if (calibration->image_size.empty())  // OpenCV's own files do not carry it
      calibration->image_size = left.size();
    if (calibration->image_size != left.size()) {
      std::cerr << who << args.intrinsics << ": calibration is for "
                << calibration->image_size.width << "x" << calibration->image_size.height
                << " images but " << args.left << " is " << left.cols << "x" << left.rows << '\n';
      return kExitBadInput;
    }
  }
  auto result =
      stereo::computePairDisparity(left, right, calibration ? &*calibration : nullptr, options);
  if (!result)
    return fail(who, result.error().message);
  if (auto written = stereo::writePfm(args.out, result->disparity); !written)
    return fail(who, written.error().message);
  nlohmann::ordered_json out;
  out["out"] = args.out;
  out["width"] = result->disparity.cols;
  out["height"] = result->disparity.rows;
  out["valid_fraction"] = result->valid_fraction;
  out["match_ms"] = result->match_ms;
  return printJsonLine(out);
}

}  // namespace

void registerDisparityCommand(CLI::App& app, int& exit_code) {
  const auto [cmd, args] =
      addSubcommand(app, "disparity",
                    "Disparity of the left image (PFM, pixels; invalid = -1), rectified first "
                    "when a calibration is given",
                    exit_code, runDisparity);
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
  cmd->add_option("--grow-uniqueness-ratio", args->grow_uniqueness_ratio,
                  "Match again at this uniqueness ratio and keep its matches in the first's "
                  "holes where their piece of disparity is confirmed by the first (-1: off)")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "Output .pfm")->required();
}

}  // namespace fieldrig::tools
