#include "fieldrig/stereo/calibration.h"

#include <yaml-cpp/yaml.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "fieldrig/core/durable_file.h"

namespace fieldrig::stereo {
namespace {

using core::Error;

// Reads a CV_64F matrix of the given shape (cols < 0: any column count) from `storage`.
bool readMatrix(const cv::FileStorage& storage, const std::string& key, int rows, int cols,
                cv::Mat& out, const std::filesystem::path& file, std::string& error) {
  const cv::FileNode node = storage[key];
  if (node.empty()) {
    error = file.string() + ": field '" + key + "' is missing";
    return false;
  }
  core::Result<cv::Mat> matrix = readCalibrationMatrix(node);
  if (!matrix) {
    error = file.string() + ": field '" + key + "' " + matrix.error().message;
    return false;
  }
  if (matrix->rows != rows || (cols >= 0 && matrix->cols != cols)) {
    error = file.string() + ": field '" + key + "' is " + std::to_string(matrix->rows) + "x" +
            std::to_string(matrix->cols) + ", expected " + std::to_string(rows) + "x" +
            (cols >= 0 ? std::to_string(cols) : std::string("N"));
    return false;
  }
  out = std::move(*matrix);
  return true;
}

bool isDistortionLength(int n) {
  return n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

// Six significant digits: enough to recognise the value in the file, without to_string's
// "0.000000" for small ones.
std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

Error fieldError(const std::string& field, const std::string& what) {
  return Error{"field '" + field + "': " + what};
}

// M1/M2: [fx s cx; 0 fy cy; 0 0 1]. fx, fy > 0 make it invertible (det = fx·fy).
core::Result<void> checkCameraMatrix(const cv::Mat& m, const std::string& field,
                                     cv::Size image_size) {
  const double fx = m.at<double>(0, 0);
  const double fy = m.at<double>(1, 1);
  const double cx = m.at<double>(0, 2);
  const double cy = m.at<double>(1, 2);
  for (const auto& [name, focal] : {std::pair{"fx", fx}, {"fy", fy}}) {
    if (focal == 0)
      return fieldError(field, std::string("singular camera matrix (") + name + " = 0)");
    if (focal < 0) {
      return fieldError(field, std::string(name) + " = " + number(focal) +
                                   " is not a focal length (positive pixels)");
    }
  }
  // Exact zeros and one are what every calibration tool writes; 1e-9 only forgives rounding.
  constexpr double kExact = 1e-9;
  if (std::abs(m.at<double>(1, 0)) > kExact || std::abs(m.at<double>(2, 0)) > kExact ||
      std::abs(m.at<double>(2, 1)) > kExact || std::abs(m.at<double>(2, 2) - 1) > kExact) {
    return fieldError(field,
                      "is not a camera matrix [fx s cx; 0 fy cy; 0 0 1]: its lower part is [" +
                          number(m.at<double>(1, 0)) + "; " + number(m.at<double>(2, 0)) + " " +
                          number(m.at<double>(2, 1)) + " " + number(m.at<double>(2, 2)) + "]");
  }
  const double aspect = fx / fy;
  if (aspect > kMaxFocalAspect || aspect < 1 / kMaxFocalAspect) {
    return fieldError(field, "fx / fy = " + number(fx) + " / " + number(fy) +
                                 " is implausible (pixels are not that far from square; allowed " +
                                 number(1 / kMaxFocalAspect) + " to " + number(kMaxFocalAspect) +
                                 ")");
  }
  const std::string principal_point = "principal point (" + number(cx) + ", " + number(cy) + ")";
  if (image_size.empty()) {
    if (!(cx > 0 && cy > 0))
      return fieldError(field, principal_point + " is not inside any image");
    return {};
  }
  const double margin_x = kPrincipalPointMargin * image_size.width;
  const double margin_y = kPrincipalPointMargin * image_size.height;
  if (cx < -margin_x || cx > image_size.width + margin_x || cy < -margin_y ||
      cy > image_size.height + margin_y) {
    return fieldError(field,
                      principal_point + " lies outside the " + sizeText(image_size) + " image");
  }
  return {};
}

// Reads image_width/image_height: both or neither; whole, positive, within kMaxImageSide.
core::Result<cv::Size> readImageSize(const cv::FileStorage& storage) {
  const cv::FileNode width = storage["image_width"];
  const cv::FileNode height = storage["image_height"];
  if (width.empty() && height.empty())
    return cv::Size();
  if (width.empty() || height.empty()) {
    return Error{std::string("field '") + (width.empty() ? "image_width" : "image_height") +
                 "' is missing (the other one is given)"};
  }
  cv::Size size;
  for (const auto& [name, node, side] :
       {std::tuple{"image_width", width, &size.width}, {"image_height", height, &size.height}}) {
    if (!node.isInt())
      return fieldError(name, "is not a whole number of pixels");
    *side = static_cast<int>(node);
    if (*side <= 0 || *side > kMaxImageSide) {
      return fieldError(name, std::to_string(*side) + " is outside 1.." +
                                  std::to_string(kMaxImageSide) + " pixels");
    }
  }
  return size;
}

core::Result<void> withFile(const std::filesystem::path& file, core::Result<void> checked) {
  if (checked)
    return {};
  return Error{file.string() + ": " + checked.error().message};
}

}  // namespace

core::Result<void> checkRotation(const cv::Matx33d& rotation) {
  const double off = cv::norm(rotation * rotation.t() - cv::Matx33d::eye());
  if (!(off <= kRotationTolerance)) {
    return Error{"not a rotation: not orthonormal (|R*R^T - I| = " + number(off) + " > " +
                 number(kRotationTolerance) + ")"};
  }
  const double det = cv::determinant(rotation);
  if (det < 0)
    return Error{"not a rotation: a reflection (det = " + number(det) + ")"};
  return {};
}

core::Result<void> checkIntrinsics(const StereoCalibration& calibration) {
  const cv::Size size = calibration.image_size;
  if (!size.empty() && (size.width <= 0 || size.height <= 0 || size.width > kMaxImageSide ||
                        size.height > kMaxImageSide)) {
    return Error{"image size " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                 " is outside 1.." + std::to_string(kMaxImageSide) + " pixels a side"};
  }
  for (const auto& [field, matrix] : {std::pair{"M1", calibration.M1}, {"M2", calibration.M2}}) {
    if (matrix.rows != 3 || matrix.cols != 3 || matrix.type() != CV_64F)
      return fieldError(field, "is not a 3x3 matrix of doubles");
    if (!cv::checkRange(matrix))
      return fieldError(field, "holds NaN or infinite values");
    if (auto checked = checkCameraMatrix(matrix, field, size); !checked)
      return checked;
  }
  for (const auto& [field, matrix] : {std::pair{"D1", calibration.D1}, {"D2", calibration.D2}}) {
    if (!cv::checkRange(matrix))
      return fieldError(field, "holds NaN or infinite values");
  }
  return {};
}

core::Result<void> checkExtrinsics(const StereoCalibration& calibration) {
  const std::pair<const char*, const cv::Mat*> all[] = {
      {"R", &calibration.R},   {"T", &calibration.T},   {"R1", &calibration.R1},
      {"R2", &calibration.R2}, {"P1", &calibration.P1}, {"P2", &calibration.P2},
      {"Q", &calibration.Q}};
  for (const auto& [field, matrix] : all) {
    if (matrix->empty() || matrix->type() != CV_64F)
      return fieldError(field, "is missing or not a matrix of doubles");
    if (!cv::checkRange(*matrix))
      return fieldError(field, "holds NaN or infinite values");
  }
  for (const auto& [field, matrix] :
       {std::pair{"R", calibration.R}, {"R1", calibration.R1}, {"R2", calibration.R2}}) {
    if (auto rotation = checkRotation(cv::Matx33d(matrix)); !rotation)
      return fieldError(field, rotation.error().message);
  }
  const double baseline = calibration.baseline();
  if (baseline == 0)
    return fieldError("T", "zero baseline (the two cameras are at one place)");
  if (baseline < kMinBaselineM || baseline > kMaxBaselineM) {
    return fieldError("T", "baseline " + number(baseline) + " m is implausible (allowed " +
                               number(kMinBaselineM) + " to " + number(kMaxBaselineM) +
                               " m; T is in metres)");
  }
  for (const auto& [field, matrix] : {std::pair{"P1", calibration.P1}, {"P2", calibration.P2}}) {
    const double focal = matrix.at<double>(0, 0);
    if (!(focal > 0) || !(matrix.at<double>(1, 1) > 0)) {
      return fieldError(field, "rectified focal length (" + number(focal) + ", " +
                                   number(matrix.at<double>(1, 1)) + ") is not positive");
    }
  }
  // Q = [1 0 0 -cx; 0 1 0 -cy; 0 0 0 f; 0 0 -1/Tx (cx - cx')/Tx], Tx the rectified baseline,
  // which is |T|: rectification only rotates T onto the x (or y) axis.
  const cv::Mat& q = calibration.Q;
  if (q.at<double>(2, 3) == 0)
    return fieldError("Q", "singular: Q(2,3), the rectified focal length, is 0");
  if (q.at<double>(3, 2) == 0)
    return fieldError("Q", "singular: Q(3,2), -1/baseline, is 0");
  const double q_baseline = 1 / std::abs(q.at<double>(3, 2));
  // 1 %: far above rounding, far below the difference between two heads' calibrations.
  if (std::abs(q_baseline - baseline) > 0.01 * baseline) {
    return fieldError("Q", "its baseline (1/|Q(3,2)| = " + number(q_baseline) + " m) is not T's (" +
                               number(baseline) + " m): Q and T come from different calibrations");
  }
  return {};
}

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

core::Result<void> openCalibrationFile(const std::filesystem::path& file,
                                       cv::FileStorage& storage) {
  // Checked first so that OpenCV does not log its own error for a missing file.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    return Error{file.string() + ": cannot open"};
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec)
    return Error{file.string() + ": cannot read its size: " + ec.message()};
  if (size > kMaxCalibrationFileBytes) {
    return Error{file.string() + ": " + std::to_string(size) +
                 " bytes, more than a calibration file holds (at most " +
                 std::to_string(kMaxCalibrationFileBytes) + ")"};
  }
  std::string text(static_cast<std::size_t>(size), '\0');
  std::ifstream in(file, std::ios::binary);
  if (!in || !in.read(text.data(), static_cast<std::streamsize>(text.size())))
    return Error{file.string() + ": cannot read"};
  int line = 1;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n')
      ++line;
    else if ((byte < 0x20 && c != '\t' && c != '\r') || byte == 0x7f) {
      char code[8];
      std::snprintf(code, sizeof code, "0x%02x", byte);
      return Error{file.string() + ":" + std::to_string(line) + ": control character " + code +
                   ": a damaged file, not OpenCV YAML"};
    }
  }
  // OpenCV's YAML parser loops for ever on some malformed files (fuzzing found one: a "---e:as"
  // document marker followed by an indented list), so a conforming YAML parser reads the text
  // first and OpenCV only ever sees well-formed YAML whose top is a map. OpenCV's header
  // "%YAML:1.0" is not a YAML 1.2 directive: it becomes a comment, keeping the line numbers.
  if (text.starts_with("%YAML:"))
    text[0] = '#';
  try {
    if (!YAML::Load(text).IsMap())
      return Error{file.string() + ": not a map of fields (OpenCV YAML)"};
  } catch (const YAML::Exception& e) {
    return Error{file.string() + ":" + std::to_string(e.mark.line + 1) +
                 ": not readable as YAML (" + e.msg + ")"};
  }
  try {
    storage.open(file.string(), cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
    if (!storage.isOpened())
      return Error{file.string() + ": cannot open"};
    if (!storage.root().isMap())
      return Error{file.string() + ": not a map of fields (OpenCV YAML)"};
  } catch (const std::exception& e) {  // cv::Exception, and std::length_error from its parser
    return Error{file.string() + ": not a readable OpenCV YAML file"};
  }
  return {};
}

core::Result<cv::Mat> readCalibrationMatrix(const cv::FileNode& node) {
  const auto side = [&](const char* key) -> std::optional<int> {
    const cv::FileNode value = node[key];
    if (!value.isInt())
      return std::nullopt;
    const int n = static_cast<int>(value);
    if (n < 1 || n > kMaxCalibrationMatrixSide)
      return std::nullopt;
    return n;
  };
  if (!node.isMap() || !node["sizes"].empty())
    return Error{"is not a matrix (rows, cols, dt, data)"};
  const std::optional<int> rows = side("rows");
  const std::optional<int> cols = side("cols");
  if (!rows || !cols) {
    return Error{"is not a matrix of 1 to " + std::to_string(kMaxCalibrationMatrixSide) +
                 " rows and columns"};
  }
  const cv::FileNode data = node["data"];
  if (!data.isSeq() || data.size() != static_cast<std::size_t>(*rows * *cols)) {
    return Error{"does not hold its " + std::to_string(*rows) + "x" + std::to_string(*cols) +
                 " values"};
  }
  cv::Mat matrix;
  try {
    node >> matrix;  // its size is checked above: nothing large is allocated
  } catch (const std::exception&) {
    matrix.release();
  }
  if (matrix.empty() || matrix.rows != *rows || matrix.cols != *cols || matrix.channels() != 1)
    return Error{"is not a matrix (rows, cols, dt, data)"};
  cv::Mat out;
  matrix.convertTo(out, CV_64F);
  if (!cv::checkRange(out))
    return Error{"holds NaN or infinite values"};
  return out;
}

namespace {

core::Result<StereoCalibration> loadCheckedFiles(const std::filesystem::path& intrinsics,
                                                 const std::filesystem::path& extrinsics) {
  StereoCalibration calibration;
  std::string error;
  {
    cv::FileStorage storage;
    if (auto opened = openCalibrationFile(intrinsics, storage); !opened)
      return opened.error();
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
    core::Result<cv::Size> image_size = readImageSize(storage);
    if (!image_size)
      return Error{intrinsics.string() + ": " + image_size.error().message};
    calibration.image_size = *image_size;
    if (auto checked = withFile(intrinsics, checkIntrinsics(calibration)); !checked)
      return checked.error();
  }
  {
    cv::FileStorage storage;
    if (auto opened = openCalibrationFile(extrinsics, storage); !opened)
      return opened.error();
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
  if (auto checked = withFile(extrinsics, checkExtrinsics(calibration)); !checked)
    return checked.error();
  return calibration;
}

}  // namespace

core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& intrinsics,
                                                      const std::filesystem::path& extrinsics) {
  // A node of another type than the one asked for throws inside OpenCV; whatever escapes the
  // checks above is still a damaged file, not a crash.
  try {
    return loadCheckedFiles(intrinsics, extrinsics);
  } catch (const std::exception& e) {
    return Error{intrinsics.string() + " / " + extrinsics.string() +
                 ": not a readable calibration (" + e.what() + ")"};
  }
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
  std::string intrinsics_text, extrinsics_text;
  try {
    cv::FileStorage storage(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    storage << "M1" << calibration.M1 << "D1" << calibration.D1 << "M2" << calibration.M2 << "D2"
            << calibration.D2;
    // Without a size (OpenCV's own sample files have none) the keys stay out: 0 would be refused
    // when the file is loaded again.
    if (!calibration.image_size.empty()) {
      storage << "image_width" << calibration.image_size.width << "image_height"
              << calibration.image_size.height;
    }
    intrinsics_text = storage.releaseAndGetString();
    cv::FileStorage out(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    out << "R" << calibration.R << "T" << calibration.T << "R1" << calibration.R1 << "R2"
        << calibration.R2 << "P1" << calibration.P1 << "P2" << calibration.P2 << "Q"
        << calibration.Q;
    extrinsics_text = out.releaseAndGetString();
  } catch (const cv::Exception& e) {
    return Error{directory.string() + ": writing the calibration failed: " + e.what()};
  }
  // The two files are one calibration: both are written before either replaces the old one, so
  // a write that fails (a full disk) leaves the old pair, never a new intrinsics.yml beside the
  // old extrinsics.yml.
  const std::filesystem::path absolute = std::filesystem::absolute(directory);
  if (std::string failed =
          core::replaceFilesTogether({{absolute / "intrinsics.yml", intrinsics_text},
                                      {absolute / "extrinsics.yml", extrinsics_text}});
      !failed.empty())
    return Error{std::move(failed)};
  return directory;
}

std::string sizeText(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

}  // namespace fieldrig::stereo
