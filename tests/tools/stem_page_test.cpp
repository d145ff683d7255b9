// The stem page's API without a browser or a socket: a recorded session with two saved
// measurements, the sessions list, a frame as PNG, the CSV export, and "undo the last save" down
// to nothing; labels with line breaks and control characters; the head of a request confined to
// the calibration folder; files that cannot be used named at start. (The page itself is driven in
// headless Chromium by stem_ui_browser_test, its server under load by stem_ui_server_test.)
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <random>

#include "fieldrig/recording/session_writer.h"
#include "fieldrig/stem/measurement_log.h"
#include "fieldrig/stereo/calibration.h"
#include "stem_page/stem_page.h"
#include "support/stem_campaign.h"
#include "support/stem_session.h"
#include "support/temp_dir.h"

namespace fieldrig::stem_page {
namespace {

namespace fs = std::filesystem;
namespace http = boost::beast::http;
using Json = nlohmann::json;

void writeSession(const fs::path& dir) {
  recording::SessionWriter writer;
  ASSERT_TRUE(writer.open(dir, recording::SessionInfo{}).ok());
  recording::FrameSetRecord set;
  set.trigger_id = 5;
  set.location_id = "plot-0007";
  const cv::Mat grey(48, 64, CV_8UC1, cv::Scalar(90));
  const char* names[2] = {"bottom_left", "bottom_right"};
  for (int camera = 0; camera < 2; ++camera) {
    recording::FrameView frame;
    frame.camera_index = camera;
    frame.camera_name = names[camera];
    frame.width = grey.cols;
    frame.height = grey.rows;
    frame.stride = grey.cols;
    frame.pixel_format = core::PixelFormat::kMono8;
    frame.pixels = std::span<const std::uint8_t>(grey.data, grey.total());
    set.frames.push_back(frame);
  }
  const recording::WriteOutcome outcome = writer.write(set);
  ASSERT_TRUE(outcome.ok()) << outcome.message;
  writer.close();
}

stem::MeasurementRecord saved(const std::string& session, const std::string& label, int repeat,
                              double diameter) {
  stem::MeasurementRecord r;
  r.session = session;
  r.trigger_id = 5;
  r.head = "bottom";
  r.stem_label = label;
  r.diameter_mm = diameter;
  r.time = "2026-07-01T12:00:00.000Z";
  r.repeat = repeat;
  return r;
}

TEST(StemPage, ListsServesFramesExportsAndUndoesTheLastSave) {
  testing_support::ScopedTempDir dir("stem_page_api");
  const fs::path session = dir / "session_a";
  writeSession(session);
  const fs::path csv = session / "stem_measurements.csv";
  ASSERT_TRUE(stem::appendMeasurement(csv, saved("session_a", "s1", 1, 21.0)).ok());
  ASSERT_TRUE(stem::appendMeasurement(csv, saved("session_a", "s1", 2, 23.0)).ok());

  auto page = StemPage::open({{session.string()}, "", ""});
  ASSERT_TRUE(page.ok()) << page.error().message;
  auto send = [&](http::verb method, const std::string& target) {
    return (*page)->handle(HttpRequest{method, target, ""});
  };

  const HttpReply html = send(http::verb::get, "/");
  EXPECT_EQ(html.status, http::status::ok);
  EXPECT_NE(html.body.find("window.stemUi"), std::string::npos) << "not the embedded page.html";

  const Json sessions = Json::parse(send(http::verb::get, "/api/sessions").body);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0]["name"], "session_a");
  EXPECT_EQ(sessions[0]["sets"][0]["location_id"], "plot-0007");
  EXPECT_EQ(sessions[0]["sets"][0]["heads"], Json::array({"bottom"}));
  EXPECT_EQ(send(http::verb::post, "/api/sessions").status, http::status::method_not_allowed);

  const HttpReply png = send(http::verb::get, "/api/sessions/session_a/sets/0/bottom/right.png");
  EXPECT_EQ(png.status, http::status::ok);
  EXPECT_EQ(png.content_type, "image/png");
  EXPECT_EQ(png.body.substr(0, 4), "\x89PNG");

  const HttpReply exported = send(http::verb::get, "/api/sessions/session_a/measurements.csv");
  EXPECT_EQ(exported.body.substr(0, exported.body.find('\n')), stem::csvHeader());
  EXPECT_EQ(std::count(exported.body.begin(), exported.body.end(), '\n'), 3);
  ASSERT_EQ(exported.headers.size(), 1u);
  EXPECT_EQ(exported.headers[0].first, "Content-Disposition");
  EXPECT_NE(exported.headers[0].second.find("stem_measurements.csv"), std::string::npos);

  const HttpReply undone = send(http::verb::delete_, "/api/sessions/session_a/measurements/last");
  ASSERT_EQ(undone.status, http::status::ok) << undone.body;
  const Json after = Json::parse(undone.body);
  ASSERT_EQ(after["rows"].size(), 1u);
  EXPECT_EQ(after["rows"][0]["repeat"], 1);
  EXPECT_EQ(after["summary"][0]["count"], 1);
  EXPECT_EQ(stem::readMeasurementLog(csv)->size(), 1u);

  EXPECT_EQ(send(http::verb::delete_, "/api/sessions/session_a/measurements/last").status,
            http::status::ok);
  const HttpReply nothing_left =
      send(http::verb::delete_, "/api/sessions/session_a/measurements/last");
  EXPECT_EQ(nothing_left.status, http::status::not_found);
  EXPECT_NE(nothing_left.body.find("has no saved measurement"), std::string::npos);
  EXPECT_TRUE(stem::readMeasurementLog(csv)->empty());
}

Json measureBody(const stem::Points4& clicks, const std::string& head, const Json& label) {
  Json points = Json::array();
  for (const cv::Point2d& p : clicks) {
    points.push_back(p.x);
    points.push_back(p.y);
  }
  Json body = {{"set", 0}, {"head", head}, {"points", points}};
  if (!label.is_null())
    body["label"] = label;
  return body;
}

// A label typed with a line break is saved, listed and exported as typed, and every later save,
// list and undo still works. Before, the CSV was read one physical line per row: after such a
// label every list, save and undo of the session failed with 500.
TEST(StemPage, ALabelWithALineBreakRoundTripsAndTheSessionStaysUsable) {
  testing_support::ScopedTempDir dir("stem_page_line_break");
  testing_support::StemCase c = testing_support::makeStemCases({22}, {1.0}, 31).front();
  const sim::RenderedStereoPair pair = sim::renderCylinderPair(c.geometry, c.scene);
  ASSERT_TRUE(stereo::saveStereoCalibration(pair.calibration, dir / "calibration").ok());
  const fs::path session = dir / "session_b";
  testing_support::writeStemSession(session, pair, dir / "calibration");
  auto page = StemPage::open({{session.string()}, "", ""});
  ASSERT_TRUE(page.ok()) << page.error().message;
  auto send = [&](http::verb method, const std::string& target, const Json& body = nullptr) {
    return (*page)->handle(HttpRequest{method, target, body.is_null() ? "" : body.dump()});
  };
  std::mt19937_64 rng(8);
  const std::string target = "/api/sessions/session_b/measurements";
  const std::string label = "row 3\nstem 7, \"tall\"";
  for (const std::string& typed : {label, std::string("plain")}) {
    const HttpReply saved =
        send(http::verb::post, target,
             measureBody(testing_support::jitteredClicks(c, 0.7, rng), "bottom", typed));
    ASSERT_EQ(saved.status, http::status::created) << typed << ": " << saved.body;
  }
  const Json listed = Json::parse(send(http::verb::get, target).body);
  ASSERT_EQ(listed["rows"].size(), 2u) << listed.dump();
  EXPECT_EQ(listed["rows"][0]["label"], label);
  EXPECT_EQ(listed["rows"][1]["label"], "plain");
  EXPECT_EQ(listed["summary"][0]["label"], label);
  const HttpReply exported = send(http::verb::get, target + ".csv");
  EXPECT_NE(exported.body.find(",\"row 3\nstem 7, \"\"tall\"\"\","), std::string::npos)
      << exported.body;

  const HttpReply undone = send(http::verb::delete_, target + "/last");
  ASSERT_EQ(undone.status, http::status::ok) << undone.body;
  const Json after = Json::parse(undone.body);
  ASSERT_EQ(after["rows"].size(), 1u);
  EXPECT_EQ(after["rows"][0]["label"], label);

  // Other control characters are refused, naming the field and the character.
  for (const std::string& bad : {std::string("stem\x01"), std::string("a\0b", 3),
                                 std::string("\x1b[31m"), std::string("del\x7f")}) {
    const HttpReply refused =
        send(http::verb::post, target,
             measureBody(testing_support::jitteredClicks(c, 0.7, rng), "bottom", bad));
    EXPECT_EQ(refused.status, http::status::bad_request) << refused.body;
    EXPECT_NE(refused.body.find("field 'label': control character 0x"), std::string::npos)
        << refused.body;
  }
  EXPECT_EQ(stem::readMeasurementLog(session / "stem_measurements.csv")->size(), 1u);
}

// The head of a request is joined to the calibration folder: it must be one of the set's heads,
// so "../x" or an absolute path never loads a calibration from outside --calib. Before, the
// request below read DIR/outside/intrinsics.yml and answered with what was wrong with it.
TEST(StemPage, AHeadIsOneOfTheSetsHeadsAndNeverLeavesTheCalibrationFolder) {
  testing_support::ScopedTempDir dir("stem_page_head");
  const fs::path session = dir / "session_a";
  writeSession(session);
  fs::create_directories(dir / "rig" / "bottom");
  fs::create_directories(dir / "outside");
  std::ofstream(dir / "outside" / "intrinsics.yml") << "not: [a calibration\n";
  auto page = StemPage::open({{session.string()}, (dir / "rig").string(), ""});
  ASSERT_TRUE(page.ok()) << page.error().message;
  const stem::Points4 clicks{cv::Point2d(10, 10), cv::Point2d(10, 20), cv::Point2d(20, 10),
                             cv::Point2d(20, 20)};
  for (const char* path :
       {"/api/sessions/session_a/measure", "/api/sessions/session_a/measurements"}) {
    for (const std::string& head : {std::string("../outside"), (dir / "outside").string(),
                                    std::string("."), std::string("bottom/../../outside")}) {
      const HttpReply reply = (*page)->handle(
          HttpRequest{http::verb::post, path, measureBody(clicks, head, "s1").dump()});
      EXPECT_EQ(reply.status, http::status::bad_request) << head << ": " << reply.body;
      EXPECT_NE(reply.body.find("is not a head name"), std::string::npos) << reply.body;
    }
    const HttpReply unknown = (*page)->handle(
        HttpRequest{http::verb::post, path, measureBody(clicks, "top", "s1").dump()});
    EXPECT_EQ(unknown.status, http::status::not_found) << unknown.body;
    EXPECT_NE(unknown.body.find("set 0 has no head 'top'"), std::string::npos) << unknown.body;
  }
  // A head the set has goes on to its calibration, inside --calib (missing there: 422).
  const HttpReply known =
      (*page)->handle(HttpRequest{http::verb::post, "/api/sessions/session_a/measure",
                                  measureBody(clicks, "bottom", "s1").dump()});
  EXPECT_EQ(known.status, http::status::unprocessable_entity) << known.body;
  EXPECT_NE(known.body.find((dir / "rig" / "bottom").string()), std::string::npos) << known.body;
  EXPECT_EQ(
      (*page)
          ->handle(HttpRequest{http::verb::get, "/api/sessions/session_a/sets/0/top/left.png", ""})
          .status,
      http::status::not_found);
}

// What the page writes to is checked when it starts: a measurement file that is a folder or
// holds a damaged row, or a calibration folder that is a file, is named then, instead of every
// save failing later.
TEST(StemPage, AMeasurementFileOrCalibrationFolderThatCannotBeUsedIsNamedAtStart) {
  testing_support::ScopedTempDir dir("stem_page_start");
  const fs::path session = dir / "session_a";
  writeSession(session);
  fs::create_directories(dir / "a_folder");
  auto folder = StemPage::open({{session.string()}, "", (dir / "a_folder").string()});
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().message.find("a_folder"), std::string::npos) << folder.error().message;

  std::ofstream(session / "stem_measurements.csv") << stem::csvHeader() << "\nsession_a,x\n";
  auto damaged = StemPage::open({{session.string()}, "", ""});
  ASSERT_FALSE(damaged.ok());
  EXPECT_NE(damaged.error().message.find("stem_measurements.csv:2:"), std::string::npos)
      << damaged.error().message;
  fs::remove(session / "stem_measurements.csv");

  std::ofstream(dir / "a_file") << "x";
  auto calib = StemPage::open({{session.string()}, (dir / "a_file").string(), ""});
  ASSERT_FALSE(calib.ok());
  EXPECT_NE(calib.error().message.find("a_file"), std::string::npos) << calib.error().message;
  EXPECT_TRUE(StemPage::open({{session.string()}, "", ""}).ok());
}

TEST(StemPage, ASessionThatCannotBeOpenedIsNamed) {
  testing_support::ScopedTempDir dir("stem_page_bad_session");
  auto page = StemPage::open({{(dir / "absent").string()}, "", ""});
  ASSERT_FALSE(page.ok());
  EXPECT_NE(page.error().message.find("absent"), std::string::npos) << page.error().message;
}

}  // namespace
}  // namespace fieldrig::stem_page
