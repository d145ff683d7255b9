// `fieldrig stem-ui SESSION_DIR… [--port P] [--bind A] [--calib DIR] [--out CSV]`: the stem
// measurement tool for the field team, a local web page served with Boost.Beast. The page (one
// static file embedded in the binary, stem_ui_page.cpp) browses the sessions' FrameSets and
// heads, shows the left and right images, and talks to the JSON API below:
//   GET    /api/sessions                                  sessions, their sets and heads
//   GET    /api/sessions/S/sets/I/HEAD/{left,right}.png   a frame as grey PNG
//   POST   /api/sessions/S/measure        {set, head, points:[8]}          measure only
//   POST   /api/sessions/S/measurements   {set, head, label, points:[8]}   measure and save
//   GET    /api/sessions/S/measurements   saved rows and mean/SD per stem
//   DELETE /api/sessions/S/measurements/last                               undo the last save
//   GET    /api/sessions/S/measurements.csv                                 export
// Bad requests get 4xx with {"error": "…"}: unknown session/set/head (404), path traversal,
// malformed JSON or numbers (400), a measurement that cannot be saved (422).
// Thread contract: one thread per connection; the shared state is guarded by one mutex.
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <cctype>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands/commands.h"
#include "commands/stem_support.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/stem/measurement_log.h"
#include "fieldrig/stem/stem_measurer.h"

namespace fieldrig::tools {

// The page, from stem_ui_page.cpp.
extern const char* const kStemUiPage;

namespace {

namespace fs = std::filesystem;
namespace http = boost::beast::http;
using tcp = boost::asio::ip::tcp;
using Json = nlohmann::ordered_json;

struct UiArgs {
  std::vector<std::string> sessions;
  int port = 8765;
  std::string bind = "127.0.0.1";
  std::string calib;
  std::string out;
};

struct HttpError {
  http::status status;
  std::string message;
};

struct Reply {
  http::status status = http::status::ok;
  std::string content_type = "application/json";
  std::string body;
  std::string disposition;
};

Reply jsonReply(const Json& body, http::status status = http::status::ok) {
  return {status, "application/json", body.dump(), ""};
}

std::string nowIso8601() {
  const auto now = std::chrono::system_clock::now();
  return core::formatIso8601(std::chrono::time_point_cast<core::Nanoseconds>(now), 3);
}

// "%2e%2e" and friends decoded, so that traversal is caught whatever its spelling.
std::optional<std::string> percentDecode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%') {
      if (i + 2 >= text.size() || !std::isxdigit(static_cast<unsigned char>(text[i + 1])) ||
          !std::isxdigit(static_cast<unsigned char>(text[i + 2])))
        return std::nullopt;
      out += static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

struct OpenSession {
  std::string name;
  std::unique_ptr<recording::SessionReader> reader;
  fs::path csv;
};

class StemUiServer {
 public:
  explicit StemUiServer(UiArgs args) : args_(std::move(args)) {}

  // Opens every session; the error names the one that cannot be opened.
  core::Result<bool> open() {
    for (const std::string& dir : args_.sessions) {
      core::Result<recording::SessionReader> reader = recording::SessionReader::open(dir);
      if (!reader)
        return core::Error{reader.error().message};
      OpenSession session;
      session.name = fs::path(dir).lexically_normal().filename().string();
      if (session.name.empty())
        session.name = fs::path(dir).lexically_normal().parent_path().filename().string();
      for (int suffix = 2; findSession(session.name) != nullptr; ++suffix)
        session.name = fs::path(dir).filename().string() + "_" + std::to_string(suffix);
      session.reader = std::make_unique<recording::SessionReader>(std::move(*reader));
      session.csv =
          args_.out.empty() ? fs::path(dir) / "stem_measurements.csv" : fs::path(args_.out);
      sessions_.push_back(std::move(session));
    }
    return true;
  }

  Reply handle(http::verb method, const std::string& target, const std::string& body) {
    try {
      return route(method, target, body);
    } catch (const HttpError& error) {
      return jsonReply({{"error", error.message}}, error.status);
    } catch (const std::exception& error) {
      return jsonReply({{"error", std::string("internal error: ") + error.what()}},
                       http::status::internal_server_error);
    }
  }

 private:
  [[noreturn]] static void reject(http::status status, const std::string& message) {
    throw HttpError{status, message};
  }

  OpenSession* findSession(const std::string& name) {
    for (OpenSession& session : sessions_) {
      if (session.name == name)
        return &session;
    }
    return nullptr;
  }

  OpenSession& session(const std::string& name) {
    OpenSession* found = findSession(name);
    if (found == nullptr)
      reject(http::status::not_found, "unknown session '" + name + "'");
    return *found;
  }

  static std::vector<std::string> headsOf(const recording::IndexedSet& set) {
    std::vector<std::string> heads;
    for (const recording::IndexedFrame& frame : set.frames) {
      const std::string& name = frame.camera_name;
      if (name.size() > 5 && name.compare(name.size() - 5, 5, "_left") == 0) {
        const std::string head = name.substr(0, name.size() - 5);
        for (const recording::IndexedFrame& other : set.frames) {
          if (other.camera_name == head + "_right")
            heads.push_back(head);
        }
      }
    }
    return heads;
  }

  const recording::IndexedSet& set(const OpenSession& s, const std::string& text) {
    std::uint64_t index = 0;
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
        text.size() > 18)
      reject(http::status::bad_request, "set: '" + text + "' is not a set index");
    index = std::stoull(text);
    const recording::IndexedSet* found = s.reader->bySetIndex(index);
    if (found == nullptr)
      reject(http::status::not_found, "session '" + s.name + "' has no set " + text);
    return *found;
  }

  const recording::IndexedFrame& frame(const recording::IndexedSet& set, const std::string& head,
                                       const std::string& side) {
    for (const recording::IndexedFrame& f : set.frames) {
      if (f.camera_name == head + "_" + side) {
        if (f.status != recording::FrameStatus::kOk || f.file.empty())
          reject(http::status::not_found, "frame " + f.camera_name + " of set " +
                                              std::to_string(set.set_index) + " has no image");
        return f;
      }
    }
    reject(http::status::not_found,
           "set " + std::to_string(set.set_index) + " has no camera '" + head + "_" + side + "'");
  }

  cv::Mat greyFrame(const OpenSession& s, const recording::IndexedFrame& f) {
    core::Result<recording::Image> image = s.reader->loadFrame(f);
    if (!image)
      reject(http::status::not_found, image.error().message);
    cv::Mat raw(image->height, image->width, CV_8UC1, image->pixels.data());
    return toGrey(raw, f.pixel_format).clone();
  }

  // The head's calibration: DIR/HEAD of the rig's calibration folder (--calib DIR, else the
  // session's reference named calib_dir, as `fieldrig cloud` and `process` take it), else the
  // session's calibration references named HEAD, head_HEAD or stereo_HEAD (a folder with
  // intrinsics.yml and extrinsics.yml; relative paths are relative to the session folder).
  stereo::StereoCalibration calibration(const OpenSession& s, const std::string& head) {
    std::vector<fs::path> candidates;
    if (const auto rig_dir = daemon::sessionCalibrationDir(args_.calib, *s.reader))
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

  // Measurers (decoded images + calibration) of recently used pairs.
  const stem::StemMeasurer& measurer(const OpenSession& s, const recording::IndexedSet& set,
                                     const std::string& head) {
    const std::string key = s.name + "/" + std::to_string(set.set_index) + "/" + head;
    for (auto it = measurers_.begin(); it != measurers_.end(); ++it) {
      if (it->first == key) {
        measurers_.splice(measurers_.begin(), measurers_, it);
        return measurers_.front().second;
      }
    }
    const stereo::StereoCalibration cal = calibration(s, head);
    const cv::Mat left = greyFrame(s, frame(set, head, "left"));
    const cv::Mat right = greyFrame(s, frame(set, head, "right"));
    core::Result<stem::StemMeasurer> created = stem::StemMeasurer::create(cal, left, right);
    if (!created)
      reject(http::status::unprocessable_entity, created.error().message);
    measurers_.emplace_front(key, std::move(*created));
    while (measurers_.size() > 6)
      measurers_.pop_back();
    return measurers_.front().second;
  }

  static Json parseBody(const std::string& body) {
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

  static MeasureRequest measureRequest(const Json& json) {
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

  Json measurementsJson(const OpenSession& s) {
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

  Reply route(http::verb method, const std::string& target, const std::string& body) {
    const std::string path = target.substr(0, target.find('?'));
    std::vector<std::string> parts;
    std::stringstream in(path);
    for (std::string raw; std::getline(in, raw, '/');) {
      if (raw.empty())
        continue;
      const std::optional<std::string> part = percentDecode(raw);
      if (!part)
        reject(http::status::bad_request, "malformed percent-encoding in the path");
      if (*part == ".." || *part == "." || part->find_first_of("/\\") != std::string::npos ||
          part->find('\0') != std::string::npos)
        reject(http::status::bad_request, "path traversal is not allowed: " + path);
      parts.push_back(*part);
    }
    if (parts.empty() || (parts.size() == 1 && parts[0] == "index.html")) {
      if (method != http::verb::get)
        reject(http::status::method_not_allowed, "only GET here");
      return {http::status::ok, "text/html; charset=utf-8", kStemUiPage, ""};
    }
    if (parts[0] != "api")
      reject(http::status::not_found, "no such page: " + path);
    std::lock_guard<std::mutex> lock(mutex_);
    if (parts.size() == 2 && parts[1] == "sessions") {
      Json list = Json::array();
      for (const OpenSession& s : sessions_) {
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
    if (parts.size() < 3 || parts[1] != "sessions")
      reject(http::status::not_found, "no such API: " + path);
    OpenSession& s = session(parts[2]);
    // /api/sessions/S/sets/I/HEAD/left.png
    if (parts.size() == 7 && parts[3] == "sets" && method == http::verb::get) {
      const recording::IndexedSet& st = set(s, parts[4]);
      const std::string& side = parts[6];
      if (side != "left.png" && side != "right.png")
        reject(http::status::not_found, "images are left.png and right.png");
      const cv::Mat grey = greyFrame(s, frame(st, parts[5], side.substr(0, side.find('.'))));
      std::vector<std::uint8_t> png;
      cv::imencode(".png", grey, png, {cv::IMWRITE_PNG_COMPRESSION, 1});
      return {http::status::ok, "image/png", std::string(png.begin(), png.end()), ""};
    }
    if (parts.size() == 4 && parts[3] == "measure") {
      if (method != http::verb::post)
        reject(http::status::method_not_allowed, "measure takes POST");
      const MeasureRequest r = measureRequest(parseBody(body));
      const stem::StemMeasurement m =
          measurer(s, set(s, r.set), r.head).measure(r.points, stem::MeasureOptions{});
      return jsonReply(measurementJson(m));
    }
    if (parts.size() == 4 && parts[3] == "measurements.csv" && method == http::verb::get) {
      std::ifstream file(s.csv, std::ios::binary);
      std::stringstream content;
      if (file)
        content << file.rdbuf();
      else
        content << stem::csvHeader() << '\n';
      return {http::status::ok, "text/csv; charset=utf-8", content.str(),
              "attachment; filename=\"stem_measurements.csv\""};
    }
    if (parts.size() == 4 && parts[3] == "measurements") {
      if (method == http::verb::get)
        return jsonReply(measurementsJson(s));
      if (method != http::verb::post)
        reject(http::status::method_not_allowed, "measurements takes GET or POST");
      const Json json = parseBody(body);
      const MeasureRequest r = measureRequest(json);
      if (!json.contains("label") || !json["label"].is_string() ||
          json["label"].get<std::string>().empty() || json["label"].get<std::string>().size() > 100)
        reject(http::status::bad_request, "field 'label': expected the stem's label (1-100 chars)");
      const recording::IndexedSet& st = set(s, r.set);
      const stem::StemMeasurement m =
          measurer(s, st, r.head).measure(r.points, stem::MeasureOptions{});
      if (!m.ok())
        reject(http::status::unprocessable_entity, "not saved: " + m.message);
      core::Result<std::vector<stem::MeasurementRecord>> records = stem::readMeasurementLog(s.csv);
      if (!records)
        reject(http::status::internal_server_error, records.error().message);
      stem::MeasurementRecord record;
      record.session = s.name;
      record.set_index = st.set_index;
      record.trigger_id = st.trigger_id;
      record.head = r.head;
      record.stem_label = json["label"].get<std::string>();
      record.points = r.points;
      record.disparity_px = m.disparity_px;
      record.ncc = m.ncc;
      record.diameter_mm = m.diameter_mm;
      record.time = nowIso8601();
      record.repeat = stem::nextRepeat(*records, s.name, record.stem_label);
      core::Result<bool> appended = stem::appendMeasurement(s.csv, record);
      if (!appended)
        reject(http::status::internal_server_error, appended.error().message);
      Json out = measurementsJson(s);
      out["saved"] = {{"label", record.stem_label},
                      {"repeat", record.repeat},
                      {"diameter_mm", record.diameter_mm}};
      return jsonReply(out, http::status::created);
    }
    if (parts.size() == 5 && parts[3] == "measurements" && parts[4] == "last" &&
        method == http::verb::delete_) {
      core::Result<std::vector<stem::MeasurementRecord>> records = stem::readMeasurementLog(s.csv);
      if (!records)
        reject(http::status::internal_server_error, records.error().message);
      std::vector<stem::MeasurementRecord> kept = std::move(*records);
      auto last = kept.end();
      for (auto it = kept.begin(); it != kept.end(); ++it) {
        if (it->session == s.name)
          last = it;
      }
      if (last == kept.end())
        reject(http::status::not_found, "session '" + s.name + "' has no saved measurement");
      kept.erase(last);
      const fs::path temp = s.csv.string() + ".tmp";
      {
        std::ofstream out(temp, std::ios::trunc);
        out << stem::csvHeader() << '\n';
        for (const stem::MeasurementRecord& r : kept)
          out << stem::toCsvRow(r) << '\n';
        if (!out)
          reject(http::status::internal_server_error, temp.string() + ": write failed");
      }
      fs::rename(temp, s.csv);
      return jsonReply(measurementsJson(s));
    }
    reject(http::status::not_found, "no such API: " + path);
  }

  UiArgs args_;
  std::vector<OpenSession> sessions_;
  std::mutex mutex_;  // guards measurers_ and the CSV files
  std::list<std::pair<std::string, stem::StemMeasurer>> measurers_;
};

void serveConnection(tcp::socket socket, StemUiServer& server) {
  boost::beast::flat_buffer buffer;
  boost::beast::error_code ec;
  for (;;) {
    http::request_parser<http::string_body> parser;
    parser.body_limit(1 << 20);
    http::read(socket, buffer, parser, ec);
    if (ec)
      break;
    const http::request<http::string_body>& request = parser.get();
    const Reply reply =
        server.handle(request.method(), std::string(request.target()), request.body());
    http::response<http::string_body> response{reply.status, request.version()};
    response.set(http::field::server, "fieldrig stem-ui");
    response.set(http::field::content_type, reply.content_type);
    response.set(http::field::cache_control, "no-store");
    if (!reply.disposition.empty())
      response.set(http::field::content_disposition, reply.disposition);
    response.keep_alive(request.keep_alive());
    response.body() = reply.body;
    response.prepare_payload();
    http::write(socket, response, ec);
    if (ec || !request.keep_alive())
      break;
  }
  socket.shutdown(tcp::socket::shutdown_send, ec);
}

int runUi(const UiArgs& args) {
  auto server = std::make_shared<StemUiServer>(args);
  if (core::Result<bool> opened = server->open(); !opened) {
    std::cerr << "fieldrig stem-ui: " << opened.error().message << '\n';
    return kExitBadInput;
  }
  boost::asio::io_context io;
  boost::system::error_code ec;
  const boost::asio::ip::address address = boost::asio::ip::make_address(args.bind, ec);
  if (ec) {
    std::cerr << "fieldrig stem-ui: --bind: '" << args.bind << "' is not an IP address\n";
    return kExitBadInput;
  }
  if (args.port < 0 || args.port > 65535) {
    std::cerr << "fieldrig stem-ui: --port: " << args.port << " is not a port\n";
    return kExitBadInput;
  }
  tcp::acceptor acceptor(io);
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(args.port));
  acceptor.open(endpoint.protocol(), ec);
  if (!ec)
    acceptor.set_option(boost::asio::socket_base::reuse_address(true), ec);
  if (!ec)
    acceptor.bind(endpoint, ec);
  if (!ec)
    acceptor.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) {
    std::cerr << "fieldrig stem-ui: cannot listen on " << args.bind << ":" << args.port << ": "
              << ec.message() << '\n';
    return kExitRuntime;
  }
  // Tests and scripts read the port (useful with --port 0) from this first line.
  std::cout << "fieldrig stem-ui: serving http://" << args.bind << ":"
            << acceptor.local_endpoint().port() << "/" << std::endl;
  for (;;) {
    tcp::socket socket(io);
    acceptor.accept(socket, ec);
    if (ec)
      continue;
    std::thread([server, s = std::move(socket)]() mutable {
      serveConnection(std::move(s), *server);
    }).detach();
  }
}

}  // namespace

void registerStemUiCommand(CLI::App& app, int& exit_code) {
  CLI::App* command = app.add_subcommand(
      "stem-ui", "Serve the stem measurement page for recorded sessions (http://127.0.0.1:PORT/)");
  auto args = std::make_shared<UiArgs>();
  command->add_option("sessions", args->sessions, "Session folders")->required();
  command->add_option("--port", args->port, "TCP port (0: any free port)")->capture_default_str();
  command->add_option("--bind", args->bind, "Address to listen on")->capture_default_str();
  command->add_option("--calib", args->calib,
                      "Calibration folder: DIR/{bottom,middle,top}/{intrinsics,extrinsics}.yml");
  command->add_option("--out", args->out,
                      "CSV of the measurements (default: SESSION_DIR/stem_measurements.csv)");
  command->callback([args, &exit_code] { exit_code = runUi(*args); });
}

}  // namespace fieldrig::tools
