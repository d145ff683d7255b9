#include "stem_page/stem_page.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/core/rig_layout.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/stem/measurement_json.h"
#include "fieldrig/stem/measurement_log.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::stem_page {

// The page's bytes (page.html), generated at build time by embed_file.cmake.
std::string_view pageHtml();

namespace {

namespace fs = std::filesystem;
namespace http = boost::beast::http;
using Json = nlohmann::ordered_json;

constexpr std::size_t kCachedMeasurers = 6;

std::string nowIso8601() {
  const auto now = std::chrono::system_clock::now();
  return core::formatIso8601(std::chrono::time_point_cast<core::Nanoseconds>(now), 3);
}

// The heads of a set: the NAME of every NAME_left camera whose NAME_right is there too.
std::vector<std::string> headsOf(const recording::IndexedSet& set) {
  const std::string left_suffix = core::RigLayout::cameraName("", core::CameraSide::kLeft);
  std::vector<std::string> heads;
  for (const recording::IndexedFrame& frame : set.frames) {
    const std::string& name = frame.camera_name;
    if (name.size() <= left_suffix.size() ||
        name.compare(name.size() - left_suffix.size(), left_suffix.size(), left_suffix) != 0)
      continue;
    const std::string head = name.substr(0, name.size() - left_suffix.size());
    const std::string right = core::RigLayout::cameraName(head, core::CameraSide::kRight);
    for (const recording::IndexedFrame& other : set.frames) {
      if (other.camera_name == right)
        heads.push_back(head);
    }
  }
  return heads;
}

const recording::IndexedSet& setOf(const recording::SessionReader& reader,
                                   const std::string& session, const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 18)
    reject(http::status::bad_request, "set: '" + text + "' is not a set index");
  const recording::IndexedSet* found = reader.bySetIndex(std::stoull(text));
  if (found == nullptr)
    reject(http::status::not_found, "session '" + session + "' has no set " + text);
  return *found;
}

const recording::IndexedFrame& frameOf(const recording::IndexedSet& set, const std::string& head,
                                       core::CameraSide side) {
  const std::string camera = core::RigLayout::cameraName(head, side);
  for (const recording::IndexedFrame& f : set.frames) {
    if (f.camera_name == camera) {
      if (f.status != recording::FrameStatus::kOk || f.file.empty())
        reject(http::status::not_found, "frame " + f.camera_name + " of set " +
                                            std::to_string(set.set_index) + " has no image");
      return f;
    }
  }
  reject(http::status::not_found,
         "set " + std::to_string(set.set_index) + " has no camera '" + camera + "'");
}

// The head a request names, if the set has it: the name is joined to the calibration folder, so
// only a head whose two cameras the set recorded, and whose name stays in that folder, is taken.
const std::string& headOf(const recording::IndexedSet& set, const std::string& head) {
  if (!isPlainName(head))
    reject(http::status::bad_request, "field 'head': '" + head + "' is not a head name");
  for (const std::string& known : headsOf(set)) {
    if (known == head)
      return head;
  }
  reject(http::status::not_found,
         "set " + std::to_string(set.set_index) + " has no head '" + head + "'");
}

// A label is text a person typed: line breaks and tabs are kept (the CSV quotes them), other
// control characters are refused, as is an empty label or one over 100 bytes.
std::string labelOf(const Json& json) {
  if (!json.contains("label") || !json["label"].is_string())
    reject(http::status::bad_request, "field 'label': expected the stem's label (1-100 chars)");
  std::string label = json["label"].get<std::string>();
  if (label.empty() || label.size() > 100)
    reject(http::status::bad_request, "field 'label': expected the stem's label (1-100 chars)");
  for (const char c : label) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && c != '\n' && c != '\r' && c != '\t') || byte == 0x7f) {
      char code[8];
      std::snprintf(code, sizeof code, "0x%02x", byte);
      reject(http::status::bad_request,
             std::string("field 'label': control character ") + code + " is not allowed");
    }
  }
  return label;
}

cv::Mat greyFrame(const recording::SessionReader& reader, const recording::IndexedFrame& f) {
  core::Result<recording::Image> image = reader.loadFrame(f);
  if (!image)
    reject(http::status::not_found, image.error().message);
  cv::Mat raw(image->height, image->width, CV_8UC1, image->pixels.data());
  return stereo::toGrey(raw, f.pixel_format).clone();
}

Json parseBody(const std::string& body) {
  Json json = Json::parse(body, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    reject(http::status::bad_request, "request body: not a JSON object");
  return json;
}

struct MeasureRequest {
  std::string set;
  std::string head;
  stem::Points4 points;
};

MeasureRequest measureRequest(const Json& json) {
  MeasureRequest r;
  if (!json.contains("set") || !json["set"].is_number_unsigned())
    reject(http::status::bad_request, "field 'set': expected a set index");
  r.set = std::to_string(json["set"].get<std::uint64_t>());
  if (!json.contains("head") || !json["head"].is_string())
    reject(http::status::bad_request, "field 'head': expected a head name");
  r.head = json["head"].get<std::string>();
  if (!json.contains("points") || !json["points"].is_array() || json["points"].size() != 8)
    reject(http::status::bad_request, "field 'points': expected 8 numbers x1,y1,…,x4,y4");
  for (std::size_t i = 0; i < 8; ++i) {
    const Json& v = json["points"][i];
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      reject(http::status::bad_request,
             "field 'points[" + std::to_string(i) + "]': not a finite number");
  }
  for (std::size_t i = 0; i < 4; ++i) {
    r.points[i] =
        cv::Point2d(json["points"][2 * i].get<double>(), json["points"][2 * i + 1].get<double>());
  }
  return r;
}

}  // namespace

StemPage::StemPage(StemPageOptions options)
    : options_(std::move(options)),
      routes_({
          {http::verb::get, "/", [](auto&, auto&) { return page(); }},
          {http::verb::get, "/index.html", [](auto&, auto&) { return page(); }},
          {http::verb::get, "/api/sessions", locked(&StemPage::listSessions)},
          {http::verb::get, "/api/sessions/{session}/sets/{set}/{head}/{image}",
           locked(&StemPage::frameImage)},
          {http::verb::post, "/api/sessions/{session}/measure", locked(&StemPage::measure)},
          {http::verb::get, "/api/sessions/{session}/measurements",
           locked(&StemPage::measurements)},
          {http::verb::post, "/api/sessions/{session}/measurements",
           locked(&StemPage::saveMeasurement)},
          {http::verb::delete_, "/api/sessions/{session}/measurements/last",
           locked(&StemPage::removeLastMeasurement)},
          {http::verb::get, "/api/sessions/{session}/measurements.csv",
           locked(&StemPage::exportCsv)},
      }) {}

Route::Handler StemPage::locked(ApiHandler handler) {
  return [this, handler](const PathParams& params, const HttpRequest& request) {
    std::lock_guard lock(mutex_);
    return (this->*handler)(params, request);
  };
}

HttpReply StemPage::page() {
  return {http::status::ok, "text/html; charset=utf-8", std::string(pageHtml()), {}};
}

core::Result<std::unique_ptr<StemPage>> StemPage::open(StemPageOptions options) {
  std::unique_ptr<StemPage> page(new StemPage(std::move(options)));
  std::error_code ec;
  if (const std::string& calib = page->options_.calib;
      !calib.empty() && !fs::is_directory(calib, ec))
    return core::Error{"calibration folder '" + calib + "': not a folder"};
  for (const std::string& dir : page->options_.sessions) {
    core::Result<recording::SessionReader> reader = recording::SessionReader::open(dir);
    if (!reader)
      return reader.error();
    Session session;
    session.name = fs::path(dir).lexically_normal().filename().string();
    if (session.name.empty())
      session.name = fs::path(dir).lexically_normal().parent_path().filename().string();
    for (int suffix = 2; page->findSession(session.name) != nullptr; ++suffix)
      session.name = fs::path(dir).filename().string() + "_" + std::to_string(suffix);
    session.reader = std::make_unique<recording::SessionReader>(std::move(*reader));
    session.csv = page->options_.out.empty() ? fs::path(dir) / "stem_measurements.csv"
                                             : fs::path(page->options_.out);
    // A measurement file that cannot be read (a folder, a damaged row) is named now, not met as
    // an error on every list and save.
    if (auto records = stem::readMeasurementLog(session.csv); !records)
      return records.error();
    page->sessions_.push_back(std::move(session));
  }
  return page;
}

StemPage::Session* StemPage::findSession(const std::string& name) {
  for (Session& session : sessions_) {
    if (session.name == name)
      return &session;
  }
  return nullptr;
}

StemPage::Session& StemPage::session(const PathParams& params) {
  const std::string& name = params.at("session");
  Session* found = findSession(name);
  if (found == nullptr)
    reject(http::status::not_found, "unknown session '" + name + "'");
  return *found;
}

// The head's calibration: DIR/HEAD of the rig's calibration folder (--calib DIR, else the
// session's reference named calib_dir, as `fieldrig cloud` and `process` take it), else the
// session's calibration references named HEAD, head_HEAD or stereo_HEAD (a folder with
// intrinsics.yml and extrinsics.yml; relative paths are relative to the session folder).
stereo::StereoCalibration StemPage::calibration(const Session& s, const std::string& head) const {
  std::vector<fs::path> candidates;
  if (const auto rig_dir = daemon::sessionCalibrationDir(options_.calib, *s.reader))
    candidates.push_back(*rig_dir / head);
  for (const recording::CalibrationReference& ref : s.reader->metadata().calibration) {
    if (ref.name == head || ref.name == "head_" + head || ref.name == "stereo_" + head) {
      const fs::path path(ref.path);
      candidates.push_back(path.is_absolute() ? path : s.reader->dir() / path);
    }
  }
  if (candidates.empty()) {
    reject(http::status::unprocessable_entity,
           "no calibration for head '" + head + "': start stem-ui with --calib DIR (DIR/" + head +
               "/{intrinsics,extrinsics}.yml) or reference it in session.json");
  }
  core::Result<stereo::StereoCalibration> loaded =
      stereo::loadStereoCalibration(candidates.front());
  if (!loaded)
    reject(http::status::unprocessable_entity, loaded.error().message);
  return *loaded;
}

const stem::StemMeasurer& StemPage::measurer(const Session& s, const recording::IndexedSet& set,
                                             const std::string& head) {
  headOf(set, head);
  const std::string key = s.name + "/" + std::to_string(set.set_index) + "/" + head;
  for (auto it = measurers_.begin(); it != measurers_.end(); ++it) {
    if (it->first == key) {
      measurers_.splice(measurers_.begin(), measurers_, it);
      return measurers_.front().second;
    }
  }
  const stereo::StereoCalibration cal = calibration(s, head);
  const cv::Mat left = greyFrame(*s.reader, frameOf(set, head, core::CameraSide::kLeft));
  const cv::Mat right = greyFrame(*s.reader, frameOf(set, head, core::CameraSide::kRight));
  core::Result<stem::StemMeasurer> created = stem::StemMeasurer::create(cal, left, right);
  if (!created)
    reject(http::status::unprocessable_entity, created.error().message);
  measurers_.emplace_front(key, std::move(*created));
  while (measurers_.size() > kCachedMeasurers)
    measurers_.pop_back();
  return measurers_.front().second;
}

Json StemPage::measurementsJson(const Session& s) const {
  core::Result<std::vector<stem::MeasurementRecord>> records = stem::readMeasurementLog(s.csv);
  if (!records)
    reject(http::status::internal_server_error, records.error().message);
  Json rows = Json::array();
  for (const stem::MeasurementRecord& r : *records) {
    if (r.session != s.name)
      continue;
    Json points = Json::array();
    for (const cv::Point2d& p : r.points) {
      points.push_back(p.x);
      points.push_back(p.y);
    }
    rows.push_back({{"set", r.set_index},
                    {"trigger_id", r.trigger_id},
                    {"head", r.head},
                    {"label", r.stem_label},
                    {"points", points},
                    {"disparity_px", r.disparity_px},
                    {"ncc", r.ncc},
                    {"diameter_mm", r.diameter_mm},
                    {"time", r.time},
                    {"repeat", r.repeat}});
  }
  Json summary = Json::array();
  for (const stem::StemSummary& sum : stem::summarizeRepeats(*records)) {
    if (sum.session != s.name)
      continue;
    summary.push_back({{"label", sum.stem_label},
                       {"count", sum.count},
                       {"mean_mm", sum.mean_mm},
                       {"sd_mm", sum.sd_mm}});
  }
  return {{"session", s.name}, {"csv", s.csv.string()}, {"rows", rows}, {"summary", summary}};
}

HttpReply StemPage::listSessions(const PathParams&, const HttpRequest&) {
  Json list = Json::array();
  for (const Session& s : sessions_) {
    Json sets = Json::array();
    for (const recording::IndexedSet& set : s.reader->sets()) {
      sets.push_back({{"set", set.set_index},
                      {"trigger_id", set.trigger_id},
                      {"location_id", set.location_id ? Json(*set.location_id) : Json()},
                      {"time", core::formatIso8601(set.trigger_time, 3)},
                      {"heads", headsOf(set)}});
    }
    list.push_back({{"name", s.name}, {"sets", sets}});
  }
  return jsonReply(list);
}

HttpReply StemPage::frameImage(const PathParams& params, const HttpRequest&) {
  const Session& s = session(params);
  const recording::IndexedSet& set = setOf(*s.reader, s.name, params.at("set"));
  const std::string& image = params.at("image");
  if (image != "left.png" && image != "right.png")
    reject(http::status::not_found, "images are left.png and right.png");
  const core::CameraSide side =
      image == "left.png" ? core::CameraSide::kLeft : core::CameraSide::kRight;
  const cv::Mat grey = greyFrame(*s.reader, frameOf(set, headOf(set, params.at("head")), side));
  std::vector<std::uint8_t> png;
  cv::imencode(".png", grey, png, {cv::IMWRITE_PNG_COMPRESSION, 1});
  return {http::status::ok, "image/png", std::string(png.begin(), png.end()), {}};
}

HttpReply StemPage::measure(const PathParams& params, const HttpRequest& request) {
  const Session& s = session(params);
  const MeasureRequest r = measureRequest(parseBody(request.body));
  const stem::StemMeasurement m = measurer(s, setOf(*s.reader, s.name, r.set), r.head)
                                      .measure(r.points, stem::MeasureOptions{});
  return jsonReply(stem::toJson(m));
}

HttpReply StemPage::measurements(const PathParams& params, const HttpRequest&) {
  return jsonReply(measurementsJson(session(params)));
}

HttpReply StemPage::saveMeasurement(const PathParams& params, const HttpRequest& request) {
  const Session& s = session(params);
  const Json json = parseBody(request.body);
  const MeasureRequest r = measureRequest(json);
  const std::string label = labelOf(json);
  const recording::IndexedSet& set = setOf(*s.reader, s.name, r.set);
  const stem::StemMeasurement m =
      measurer(s, set, r.head).measure(r.points, stem::MeasureOptions{});
  if (!m.ok())
    reject(http::status::unprocessable_entity, "not saved: " + m.message);
  core::Result<std::vector<stem::MeasurementRecord>> records = stem::readMeasurementLog(s.csv);
  if (!records)
    reject(http::status::internal_server_error, records.error().message);
  stem::MeasurementRecord record;
  record.session = s.name;
  record.set_index = set.set_index;
  record.trigger_id = set.trigger_id;
  record.head = r.head;
  record.stem_label = label;
  record.points = r.points;
  record.disparity_px = m.disparity_px;
  record.ncc = m.ncc;
  record.diameter_mm = m.diameter_mm;
  record.time = nowIso8601();
  record.repeat = stem::nextRepeat(*records, s.name, record.stem_label);
  if (core::Result<void> appended = stem::appendMeasurement(s.csv, record); !appended)
    reject(http::status::internal_server_error, appended.error().message);
  Json out = measurementsJson(s);
  out["saved"] = {
      {"label", record.stem_label}, {"repeat", record.repeat}, {"diameter_mm", record.diameter_mm}};
  return jsonReply(out, http::status::created);
}

HttpReply StemPage::removeLastMeasurement(const PathParams& params, const HttpRequest&) {
  const Session& s = session(params);
  core::Result<std::optional<stem::MeasurementRecord>> removed =
      stem::removeLastMeasurement(s.csv, s.name);
  if (!removed)
    reject(http::status::internal_server_error, removed.error().message);
  if (!removed->has_value())
    reject(http::status::not_found, "session '" + s.name + "' has no saved measurement");
  return jsonReply(measurementsJson(s));
}

HttpReply StemPage::exportCsv(const PathParams& params, const HttpRequest&) {
  const Session& s = session(params);
  std::string error;
  std::optional<std::string> content = core::readWholeFile(s.csv, error);
  // No file yet is an empty log; a file that is there but cannot be read is not.
  if (std::error_code ec; !content && fs::exists(s.csv, ec))
    reject(http::status::internal_server_error, error);
  return {http::status::ok,
          "text/csv; charset=utf-8",
          content ? std::move(*content) : stem::csvHeader() + '\n',
          {{"Content-Disposition", "attachment; filename=\"stem_measurements.csv\""}}};
}

}  // namespace fieldrig::stem_page
