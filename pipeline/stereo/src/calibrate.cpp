#include "fieldrig/stereo/calibrate.h"

#include "fieldrig/core/durable_file.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fieldrig::stereo {
namespace {

struct Fit {
  StereoCalibration calibration;
  cv::Mat F;
  double rms = 0;
  cv::Mat per_view;  // N×2: left, right RMS
};

const cv::TermCriteria kSolverCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-6);

// Each camera's intrinsics alone first (full 5-coefficient model), then the pair refined jointly
// from that guess: the joint solve starting from good intrinsics converges where the sample's
// shared-focal-length model cannot fit both lenses.
Fit fitPairs(const std::vector<const PairCorners*>& used, const BoardSpec& board,
             cv::Size image_size) {
  const std::vector<cv::Point3f> object = boardPoints(board);
  std::vector<std::vector<cv::Point3f>> objects(used.size(), object);
  std::vector<std::vector<cv::Point2f>> left, right;
  for (const PairCorners* pair : used) {
    left.push_back(pair->left);
    right.push_back(pair->right);
  }
  Fit fit;
  StereoCalibration& c = fit.calibration;
  c.image_size = image_size;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::calibrateCamera(objects, left, image_size, c.M1, c.D1, rvecs, tvecs, 0, kSolverCriteria);
  cv::calibrateCamera(objects, right, image_size, c.M2, c.D2, rvecs, tvecs, 0, kSolverCriteria);
  cv::Mat E;
  fit.rms =
      cv::stereoCalibrate(objects, left, right, c.M1, c.D1, c.M2, c.D2, image_size, c.R, c.T, E,
                          fit.F, fit.per_view, cv::CALIB_USE_INTRINSIC_GUESS, kSolverCriteria);
  return fit;
}

cv::Matx44d toMatx44(const cv::Mat& R, const cv::Mat& T) {
  cv::Matx44d m = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col)
      m(r, col) = R.at<double>(r, col);
    m(r, 3) = T.at<double>(r, 0);
  }
  return m;
}

}  // namespace

std::optional<std::vector<cv::Point2f>> findBoardCorners(const cv::Mat& grey,
                                                         const BoardSpec& board) {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(grey, board.inner_corners, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return std::nullopt;
  }
  cv::cornerSubPix(grey, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 0.01));
  return corners;
}

std::vector<cv::Point3f> boardPoints(const BoardSpec& board) {
  std::vector<cv::Point3f> points;
  for (int row = 0; row < board.inner_corners.height; ++row) {
    for (int col = 0; col < board.inner_corners.width; ++col) {
      points.emplace_back(static_cast<float>(col * board.square_m),
                          static_cast<float>(row * board.square_m), 0.0f);
    }
  }
  return points;
}

double epipolarError(const StereoCalibration& calibration, const cv::Mat& F,
                     const std::vector<PairCorners>& pairs) {
  double error = 0;
  std::size_t points = 0;
  for (const PairCorners& pair : pairs) {
    if (!pair.found())
      continue;
    std::vector<cv::Point2f> left, right;
    cv::undistortPoints(pair.left, left, calibration.M1, calibration.D1, cv::noArray(),
                        calibration.M1);
    cv::undistortPoints(pair.right, right, calibration.M2, calibration.D2, cv::noArray(),
                        calibration.M2);
    std::vector<cv::Vec3f> lines_in_right, lines_in_left;
    cv::computeCorrespondEpilines(left, 1, F, lines_in_right);
    cv::computeCorrespondEpilines(right, 2, F, lines_in_left);
    for (std::size_t i = 0; i < left.size(); ++i) {
      const cv::Vec3f& l2 = lines_in_right[i];
      const cv::Vec3f& l1 = lines_in_left[i];
      error += std::fabs(right[i].x * l2[0] + right[i].y * l2[1] + l2[2]) +
               std::fabs(left[i].x * l1[0] + left[i].y * l1[1] + l1[2]);
    }
    points += left.size();
  }
  return points ? error / static_cast<double>(points) : 0;
}

core::Result<HeadCalibrationReport> calibrateHead(const std::vector<PairCorners>& pairs,
                                                  const BoardSpec& board, cv::Size image_size,
                                                  const CalibrateOptions& options) {
  HeadCalibrationReport report;
  std::vector<const PairCorners*> used;
  for (const PairCorners& pair : pairs) {
    ViewReport view;
    view.name = pair.name;
    view.found = pair.found();
    if (view.found)
      used.push_back(&pair);
    report.views.push_back(view);
  }
  if (static_cast<int>(used.size()) < options.min_pairs) {
    return core::Error{"the board was found in both images of " + std::to_string(used.size()) +
                       " pairs; at least " + std::to_string(options.min_pairs) + " are needed"};
  }
  Fit fit = fitPairs(used, board, image_size);
  // Per-view errors of the first fit, then drop the views that do not fit.
  std::vector<double> worst;
  for (int i = 0; i < fit.per_view.rows; ++i) {
    worst.push_back(std::max(fit.per_view.at<double>(i, 0), fit.per_view.at<double>(i, 1)));
  }
  std::vector<double> sorted = worst;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                   sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::vector<const PairCorners*> kept;
  std::size_t used_index = 0;
  for (ViewReport& view : report.views) {
    if (!view.found)
      continue;
    view.error_left = fit.per_view.at<double>(static_cast<int>(used_index), 0);
    view.error_right = fit.per_view.at<double>(static_cast<int>(used_index), 1);
    const double limit = options.drop_factor * median;
    if (options.drop_factor > 0 && worst[used_index] > limit) {
      view.dropped_because = "per-view error " + std::to_string(worst[used_index]) + " px > " +
                             std::to_string(options.drop_factor) + " x median " +
                             std::to_string(median) + " px";
    } else {
      view.used = true;
      kept.push_back(used[used_index]);
    }
    ++used_index;
  }
  if (kept.size() != used.size() && static_cast<int>(kept.size()) >= options.min_pairs) {
    fit = fitPairs(kept, board, image_size);
  } else if (kept.size() != used.size()) {
    // Too few would remain: keep them all rather than fail.
    for (ViewReport& view : report.views) {
      if (view.found) {
        view.used = true;
        view.dropped_because.clear();
      }
    }
    kept = used;
  }
  StereoCalibration& c = fit.calibration;
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, image_size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, options.rectify_alpha, image_size);
  std::vector<PairCorners> kept_pairs;
  for (const PairCorners* pair : kept)
    kept_pairs.push_back(*pair);
  // A calibration the loader would refuse (a baseline in millimetres from a square given in mm,
  // a degenerate fit from poor views) is an error here, naming the field, and is never written
  // for a later command to trip over.
  for (const core::Result<void>& checked : {checkIntrinsics(c), checkExtrinsics(c)}) {
    if (!checked)
      return core::Error{"the calibration from these views is not usable: " +
                         checked.error().message};
  }
  report.calibration = c;
  report.rms = fit.rms;
  report.epipolar_error_px = epipolarError(c, fit.F, kept_pairs);
  report.pairs_used = static_cast<int>(kept.size());
  return report;
}

core::Result<cv::Matx44d> calibrateHeadToHead(
    const StereoCalibration& head_a, const StereoCalibration& head_b,
    const std::vector<std::vector<cv::Point2f>>& corners_a,
    const std::vector<std::vector<cv::Point2f>>& corners_b, const BoardSpec& board, double* rms) {
  if (corners_a.size() != corners_b.size() || corners_a.empty()) {
    return core::Error{
        "head-to-head calibration needs the same, non-zero number of board views "
        "from both heads (got " +
        std::to_string(corners_a.size()) + " and " + std::to_string(corners_b.size()) + ")"};
  }
  const std::size_t per_view = boardPoints(board).size();
  for (std::size_t i = 0; i < corners_a.size(); ++i) {
    if (corners_a[i].size() != per_view || corners_b[i].size() != per_view) {
      return core::Error{"view " + std::to_string(i) + ": the board's corners are incomplete"};
    }
  }
  std::vector<std::vector<cv::Point3f>> objects(corners_a.size(), boardPoints(board));
  cv::Mat M_a = head_a.M1.clone(), D_a = head_a.D1.clone();
  cv::Mat M_b = head_b.M1.clone(), D_b = head_b.D1.clone();
  cv::Mat R, T, E, F;
  // x_b = R x_a + T between the two left cameras (unrectified).
  const double error =
      cv::stereoCalibrate(objects, corners_a, corners_b, M_a, D_a, M_b, D_b, head_a.image_size, R,
                          T, E, F, cv::CALIB_FIX_INTRINSIC, kSolverCriteria);
  if (rms)
    *rms = error;
  // Head frame = rectified left camera: p_rect = R1 · p_camera.
  const cv::Matx44d camera_a_from_camera_b = toMatx44(R, T).inv();
  const cv::Matx44d rect_a_from_camera_a = toMatx44(head_a.R1, cv::Mat::zeros(3, 1, CV_64F));
  const cv::Matx44d camera_b_from_rect_b = toMatx44(head_b.R1.t(), cv::Mat::zeros(3, 1, CV_64F));
  return rect_a_from_camera_a * camera_a_from_camera_b * camera_b_from_rect_b;
}

core::Result<BoardPairs> findBoardInImagePairs(const std::vector<std::string>& left,
                                               const std::vector<std::string>& right,
                                               const BoardSpec& board) {
  BoardPairs found;
  for (std::size_t i = 0; i < left.size() && i < right.size(); ++i) {
    PairCorners pair;
    pair.name = std::filesystem::path(left[i]).filename().string() + "/" +
                std::filesystem::path(right[i]).filename().string();
    for (const auto& [file, corners] :
         {std::pair{&left[i], &pair.left}, std::pair{&right[i], &pair.right}}) {
      const cv::Mat grey = cv::imread(*file, cv::IMREAD_GRAYSCALE);
      if (grey.empty())
        return core::Error{*file + ": cannot read the image"};
      if (found.image_size.empty())
        found.image_size = grey.size();
      if (grey.size() != found.image_size) {
        return core::Error{*file + ": image is " + std::to_string(grey.cols) + "x" +
                           std::to_string(grey.rows) + ", the first was " +
                           std::to_string(found.image_size.width) + "x" +
                           std::to_string(found.image_size.height)};
      }
      if (auto corners_found = findBoardCorners(grey, board))
        *corners = std::move(*corners_found);
    }
    if (!pair.found()) {  // a pair counts only when both images show the board
      pair.left.clear();
      pair.right.clear();
    }
    found.pairs.push_back(std::move(pair));
  }
  return found;
}

core::Result<HeadToHeadReport> calibrateHeadToHead(StereoCalibration head_a,
                                                   const StereoCalibration& head_b,
                                                   const BoardPairs& pairs,
                                                   const BoardSpec& board) {
  if (head_a.image_size.empty())
    head_a.image_size = pairs.image_size;
  std::vector<std::vector<cv::Point2f>> corners_a, corners_b;
  for (const PairCorners& pair : pairs.pairs) {
    if (!pair.found())
      continue;
    corners_a.push_back(pair.left);
    corners_b.push_back(pair.right);
  }
  HeadToHeadReport report;
  auto transform = calibrateHeadToHead(head_a, head_b, corners_a, corners_b, board, &report.rms);
  if (!transform)
    return transform.error();
  report.b_to_a = *transform;
  report.views_used = static_cast<int>(corners_a.size());
  return report;
}

core::Result<std::filesystem::path> saveHeadToHead(const HeadToHeadReport& report,
                                                   const std::filesystem::path& file) {
  // What is written is what rig.yml's `*_to_bottom` takes: refused here rather than when the rig
  // is loaded next, far from the calibration that made it.
  const cv::Matx44d& t = report.b_to_a;
  if (!cv::checkRange(cv::Mat(t)) || !std::isfinite(report.rms))
    return core::Error{file.string() + ": the head-to-head transform is not finite; not written"};
  if (auto rotation = checkRotation(t.get_minor<3, 3>(0, 0)); !rotation)
    return core::Error{file.string() + ": the head-to-head transform: " + rotation.error().message +
                       "; not written"};
  if (t(3, 0) != 0 || t(3, 1) != 0 || t(3, 2) != 0 || t(3, 3) != 1)
    return core::Error{file.string() +
                       ": the head-to-head transform's bottom row is not "
                       "(0 0 0 1); not written"};
  std::string text;
  try {
    cv::FileStorage storage(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    storage << "b_to_a" << cv::Mat(report.b_to_a) << "rms" << report.rms;
    text = storage.releaseAndGetString();
  } catch (const cv::Exception&) {
    return core::Error{file.string() + ": cannot write"};
  }
  // Replaced whole, so that a crash leaves the old file or the new one.
  if (std::string failed = core::replaceFileAtomically(std::filesystem::absolute(file), text);
      !failed.empty())
    return core::Error{std::move(failed)};
  return file;
}

}  // namespace fieldrig::stereo
