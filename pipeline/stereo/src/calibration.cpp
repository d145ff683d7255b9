#include "fieldrig/stereo/calibration.h"

#include <opencv2/calib3d.hpp>
#include <string>

namespace fieldrig::stereo {
namespace {

using core::Error;

// Reads a CV_64F matrix of the given shape (cols < 0: any column count) from `storage`.
bool readMatrix(const cv::FileStorage& storage, const std::string& key, int rows, int cols,
                cv::Mat& out, const std::filesystem::path& file, std::string& error) {
  cv::FileNode node = storage[key];
  if (node.empty()) {
    error = file.string() + ": field '" + key + "' is missing";
    return false;
  }
  cv::Mat matrix;
  try {
    node >> matrix;
  } catch (const cv::Exception&) {
    matrix.release();
  }
  if (matrix.empty()) {
    error = file.string() + ": field '" + key + "' is not a matrix";
    return false;
  }
  if (matrix.rows != rows || (cols >= 0 && matrix.cols != cols)) {
    error = file.string() + ": field '" + key + "' is " + std::to_string(matrix.rows) + "x" +
            std::to_string(matrix.cols) + ", expected " + std::to_string(rows) + "x" +
            (cols >= 0 ? std::to_string(cols) : std::string("N"));
    return false;
  }
  matrix.convertTo(out, CV_64F);
  if (!cv::checkRange(out)) {
    error = file.string() + ": field '" + key + "' holds NaN or infinite values";
    return false;
  }
  return true;
}

bool isDistortionLength(int n) {
  return n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

}  // namespace

double StereoCalibration::baseline() const {
  return cv::norm(T);
}

double StereoCalibration::rectifiedFocalPx() const {
  return P1.at<double>(0, 0);
}

StereoCalibration StereoCalibration::scaled(double factor) const {
  // cv::Mat copies share pixels, and assigning a matrix expression to a Mat writes into the
  // buffer it already has: `out.M1 = scale * M1` on a shallow copy would rescale *this too.
  // Every matrix is therefore computed into a fresh buffer.
  StereoCalibration out;
  out.D1 = D1.clone();
  out.D2 = D2.clone();
  out.R = R.clone();
  out.T = T.clone();
  out.R1 = R1.clone();
  out.R2 = R2.clone();
  const cv::Mat scale = (cv::Mat_<double>(3, 3) << factor, 0, 0, 0, factor, 0, 0, 0, 1);
  out.M1 = cv::Mat(scale * M1);
  out.M2 = cv::Mat(scale * M2);
  out.P1 = cv::Mat(scale * P1);
  out.P2 = cv::Mat(scale * P2);
  // Q maps (x, y, d, 1) to homogeneous 3D (X, Y, Z, W). With pixels and disparities scaled by
  // `factor`, X, Y and Z scale by it (cx, cy, f do), so W must too: the disparity term scales
  // through d itself, the constant term (cx - cx')/Tx, which is non-zero unless the pair was
  // rectified with CALIB_ZERO_DISPARITY, has to be scaled here.
  out.Q = Q.clone();
  out.Q.at<double>(0, 3) *= factor;
  out.Q.at<double>(1, 3) *= factor;
  out.Q.at<double>(2, 3) *= factor;
  out.Q.at<double>(3, 3) *= factor;
  out.image_size =
      cv::Size(cvRound(image_size.width * factor), cvRound(image_size.height * factor));
  return out;
}

StereoCalibration idealStereoCalibration(double focal_px, cv::Size image_size, double baseline_m) {
  StereoCalibration c;
  c.image_size = image_size;
  c.M1 = (cv::Mat_<double>(3, 3) << focal_px, 0, (image_size.width - 1) / 2.0, 0, focal_px,
          (image_size.height - 1) / 2.0, 0, 0, 1);
  c.M2 = c.M1.clone();
  c.D1 = cv::Mat::zeros(1, 5, CV_64F);
  c.D2 = c.D1.clone();
  c.R = cv::Mat::eye(3, 3, CV_64F);
  c.T = (cv::Mat_<double>(3, 1) << -baseline_m, 0, 0);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, image_size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, 0);
  return c;
}

core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& intrinsics,
                                                      const std::filesystem::path& extrinsics) {
  StereoCalibration calibration;
  std::string error;
  {
    cv::FileStorage storage;
    // Checked first so that OpenCV does not log its own error for a missing file.
    std::error_code exists_error;
    if (!std::filesystem::is_regular_file(intrinsics, exists_error)) {
      return Error{intrinsics.string() + ": cannot open"};
    }
    try {
      storage.open(intrinsics.string(), cv::FileStorage::READ);
    } catch (const cv::Exception& e) {
      return Error{intrinsics.string() + ": not a readable OpenCV YAML/XML file"};
    }
    if (!storage.isOpened()) {
      return Error{intrinsics.string() + ": cannot open"};
    }
    if (!readMatrix(storage, "M1", 3, 3, calibration.M1, intrinsics, error) ||
        !readMatrix(storage, "D1", 1, -1, calibration.D1, intrinsics, error) ||
        !readMatrix(storage, "M2", 3, 3, calibration.M2, intrinsics, error) ||
        !readMatrix(storage, "D2", 1, -1, calibration.D2, intrinsics, error)) {
      return Error{error};
    }
    for (const auto& [key, matrix] : {std::pair{"D1", calibration.D1}, {"D2", calibration.D2}}) {
      if (!isDistortionLength(matrix.cols)) {
        return Error{intrinsics.string() + ": field '" + key + "' has " +
                     std::to_string(matrix.cols) + " coefficients; expected 4, 5, 8, 12 or 14"};
      }
    }
    int width = 0;
    int height = 0;
    if (!storage["image_width"].empty())
      storage["image_width"] >> width;
    if (!storage["image_height"].empty())
      storage["image_height"] >> height;
    calibration.image_size = cv::Size(width, height);
  }
  {
    cv::FileStorage storage;
    // Checked first so that OpenCV does not log its own error for a missing file.
    std::error_code exists_error;
    if (!std::filesystem::is_regular_file(extrinsics, exists_error)) {
      return Error{extrinsics.string() + ": cannot open"};
    }
    try {
      storage.open(extrinsics.string(), cv::FileStorage::READ);
    } catch (const cv::Exception& e) {
      return Error{extrinsics.string() + ": not a readable OpenCV YAML/XML file"};
    }
    if (!storage.isOpened()) {
      return Error{extrinsics.string() + ": cannot open"};
    }
    if (!readMatrix(storage, "R", 3, 3, calibration.R, extrinsics, error) ||
        !readMatrix(storage, "T", 3, 1, calibration.T, extrinsics, error) ||
        !readMatrix(storage, "R1", 3, 3, calibration.R1, extrinsics, error) ||
        !readMatrix(storage, "R2", 3, 3, calibration.R2, extrinsics, error) ||
        !readMatrix(storage, "P1", 3, 4, calibration.P1, extrinsics, error) ||
        !readMatrix(storage, "P2", 3, 4, calibration.P2, extrinsics, error) ||
        !readMatrix(storage, "Q", 4, 4, calibration.Q, extrinsics, error)) {
      return Error{error};
    }
  }
  if (calibration.baseline() <= 0) {
    return Error{extrinsics.string() + ": field 'T' gives a zero baseline"};
  }
  return calibration;
}

core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& directory) {
  return loadStereoCalibration(directory / "intrinsics.yml", directory / "extrinsics.yml");
}

core::Result<std::filesystem::path> saveStereoCalibration(const StereoCalibration& calibration,
                                                          const std::filesystem::path& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) {
    return Error{directory.string() + ": cannot create folder: " + ec.message()};
  }
  const auto intrinsics = directory / "intrinsics.yml";
  const auto extrinsics = directory / "extrinsics.yml";
  try {
    cv::FileStorage storage(intrinsics.string(), cv::FileStorage::WRITE);
    if (!storage.isOpened()) {
      return Error{intrinsics.string() + ": cannot write"};
    }
    storage << "M1" << calibration.M1 << "D1" << calibration.D1 << "M2" << calibration.M2 << "D2"
            << calibration.D2 << "image_width" << calibration.image_size.width << "image_height"
            << calibration.image_size.height;
    storage.release();
    cv::FileStorage out(extrinsics.string(), cv::FileStorage::WRITE);
    if (!out.isOpened()) {
      return Error{extrinsics.string() + ": cannot write"};
    }
    out << "R" << calibration.R << "T" << calibration.T << "R1" << calibration.R1 << "R2"
        << calibration.R2 << "P1" << calibration.P1 << "P2" << calibration.P2 << "Q"
        << calibration.Q;
    out.release();
  } catch (const cv::Exception& e) {
    return Error{directory.string() + ": writing the calibration failed: " + e.what()};
  }
  return directory;
}

}  // namespace fieldrig::stereo
