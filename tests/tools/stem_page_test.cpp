// The stem page's API without a browser or a socket: a recorded session with two saved
// measurements, the sessions list, a frame as PNG, the CSV export, and "undo the last save" down
// to nothing. (The page itself is driven in headless Chromium by stem_ui_browser_test.)
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "fieldrig/recording/session_writer.h"
#include "fieldrig/stem/measurement_log.h"
#include "stem_page/stem_page.h"
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
  EXPECT_NE(exported.disposition.find("stem_measurements.csv"), std::string::npos);

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

TEST(StemPage, ASessionThatCannotBeOpenedIsNamed) {
  testing_support::ScopedTempDir dir("stem_page_bad_session");
  auto page = StemPage::open({{(dir / "absent").string()}, "", ""});
  ASSERT_FALSE(page.ok());
  EXPECT_NE(page.error().message.find("absent"), std::string::npos) << page.error().message;
}

}  // namespace
}  // namespace fieldrig::stem_page
