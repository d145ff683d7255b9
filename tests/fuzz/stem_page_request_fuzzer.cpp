// libFuzzer target for the stem page's API (tools/stem_page): requests, their JSON bodies included,
// through StemPage::handle, on a session this target records at start (one set, head "bottom": a
// textured background and a bright vertical stem, 4 px of disparity) with an ideal calibration.
// The body parsers (parseBody, measureRequest) are private to stem_page.cpp, so the page's own
// entry point is what is fuzzed: it also runs the route table, the measurement and the CSV log.
//
// An input is a sequence of requests cut at "=====" lines, each a method byte, then the target
// up to the first line break, then the body. The session's measurement CSV starts empty for every
// input, so that an input replays the same way.
//
// Besides crashes and sanitizer reports: every reply is 2xx or a 4xx the page documents (400, 404,
// 405, 422), never 500; every JSON reply parses, and every error reply is {"error": "…"} with a
// message; a measurement that is saved (201) is listed by the next GET of the measurements.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/recording/session_writer.h"
#include "fieldrig/stereo/calibration.h"
#include "fuzz_support.h"
#include "stem_page/stem_page.h"

namespace fieldrig::stem_page {
// The page itself (page.html, embedded by CMake) is not under test.
std::string_view pageHtml() {
  return "<!doctype html><title>stem page</title>";
}
}  // namespace fieldrig::stem_page

namespace {

namespace fs = std::filesystem;
namespace http = boost::beast::http;
using fieldrig::fuzz::check;
using fieldrig::stem_page::HttpReply;
using fieldrig::stem_page::HttpRequest;
using fieldrig::stem_page::StemPage;
using Json = nlohmann::json;

constexpr int kWidth = 96;
constexpr int kHeight = 64;
constexpr int kDisparityPx = 4;

// A textured background with a bright stem at x 40..49, seen from the right camera kDisparityPx
// further left.
std::vector<std::uint8_t> image(int shift) {
  std::mt19937 random(7);
  std::vector<std::uint8_t> texture(static_cast<std::size_t>(kWidth + kDisparityPx) * kHeight);
  for (std::uint8_t& pixel : texture)
    pixel = static_cast<std::uint8_t>(40 + random() % 80);
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(kWidth) * kHeight);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const int scene_x = x + shift;
      const bool stem = scene_x >= 40 && scene_x < 50;
      pixels[static_cast<std::size_t>(y * kWidth + x)] =
          stem ? static_cast<std::uint8_t>(200 + (scene_x - 40) * 4)
               : texture[static_cast<std::size_t>(y * (kWidth + kDisparityPx) + scene_x)];
    }
  }
  return pixels;
}

struct Page {
  fieldrig::fuzz::FuzzFolder folder{"stem_page_request"};
  fs::path session = folder.path() / "session";
  fs::path csv = session / "stem_measurements.csv";
  std::unique_ptr<StemPage> page;

  Page() {
    fieldrig::recording::SessionWriter writer;
    check(static_cast<bool>(writer.open(session, {})), "the fuzz session cannot be created");
    const std::vector<std::uint8_t> left = image(0);
    const std::vector<std::uint8_t> right = image(kDisparityPx);
    fieldrig::recording::FrameSetRecord set;
    set.trigger_id = 1;
    for (int camera = 0; camera < 2; ++camera) {
      fieldrig::recording::FrameView frame;
      frame.camera_index = camera;
      frame.camera_name = camera == 0 ? "bottom_left" : "bottom_right";
      frame.width = kWidth;
      frame.height = kHeight;
      frame.pixels = camera == 0 ? left : right;
      set.frames.push_back(frame);
    }
    check(writer.write(set).ok(), "the fuzz session's set cannot be written");
    writer.close();
    const fs::path calib = folder.path() / "calib";
    check(static_cast<bool>(fieldrig::stereo::saveStereoCalibration(
              fieldrig::stereo::idealStereoCalibration(120, cv::Size(kWidth, kHeight), 0.1),
              calib / "bottom")),
          "the fuzz calibration cannot be saved");
    auto opened = StemPage::open({{session.string()}, calib.string(), ""});
    check(static_cast<bool>(opened), "the stem page cannot open the fuzz session");
    page = std::move(*opened);
  }
};

HttpRequest request(std::string_view part) {
  static constexpr http::verb kMethods[] = {http::verb::get, http::verb::post, http::verb::delete_,
                                            http::verb::put};
  HttpRequest r;
  if (part.empty())
    return r;
  r.method = kMethods[static_cast<unsigned char>(part[0]) % 4];
  part.remove_prefix(1);
  const std::size_t end = part.find('\n');
  r.target = std::string(part.substr(0, end));
  r.body = end == std::string_view::npos ? "" : std::string(part.substr(end + 1));
  return r;
}

void checkReply(const HttpReply& reply) {
  const unsigned status = static_cast<unsigned>(reply.status);
  check(status == 200 || status == 201 || status == 400 || status == 404 || status == 405 ||
            status == 422,
        "a reply with a status the page does not document (500: an internal error)");
  if (reply.content_type != "application/json")
    return;
  const Json body = Json::parse(reply.body, nullptr, false);
  check(!body.is_discarded(), "a JSON reply that does not parse");
  if (status >= 400) {
    check(body.is_object() && body.contains("error") && body["error"].is_string() &&
              !body["error"].get<std::string>().empty(),
          "an error reply without its message");
  }
}

std::size_t rowCount(const StemPage& page) {
  HttpRequest list;
  list.target = "/api/sessions/session/measurements";
  const HttpReply reply = page.handle(list);
  checkReply(reply);
  check(reply.status == http::status::ok, "the saved measurements cannot be listed");
  return Json::parse(reply.body)["rows"].size();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const std::string sep(fieldrig::fuzz::kFileSeparator);
  const std::string points = "[40, 10, 49, 10, 49, 54, 40, 54]";
  const std::string measure = "{\"set\": 0, \"head\": \"bottom\", \"points\": " + points + "}";
  const std::string save =
      "{\"set\": 0, \"head\": \"bottom\", \"label\": \"R01P03-s1\", "
      "\"points\": " +
      points + "}";
  fieldrig::fuzz::writeSeed("measure", "\x01/api/sessions/session/measure\n" + measure);
  fieldrig::fuzz::writeSeed("save_list_undo",
                            "\x01/api/sessions/session/measurements\n" + save + sep +
                                "\x00/api/sessions/session/measurements\n" + sep +
                                "\x02/api/sessions/session/measurements/last\n" + sep +
                                "\x00/api/sessions/session/measurements.csv\n");
  fieldrig::fuzz::writeSeed("browse", "\x00/api/sessions\n" + sep +
                                          "\x00/api/sessions/session/sets/0/bottom/left.png\n" +
                                          sep + "\x00/api/sessions/session/sets/%2e%2e/x/y\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  static Page fixture;
  std::error_code ec;
  fs::remove(fixture.csv, ec);
  const std::string_view data(reinterpret_cast<const char*>(bytes), size);
  for (int i = 0; i < 8; ++i) {
    const std::string_view part = fieldrig::fuzz::part(data, i);
    if (part.empty())
      break;
    // Targets with bytes that are not UTF-8 included: error replies quote the path, and
    // jsonReply replaces what is not UTF-8 instead of throwing.
    const HttpRequest r = request(part);
    const std::size_t rows_before = r.method == http::verb::post ? rowCount(*fixture.page) : 0;
    const HttpReply reply = fixture.page->handle(r);
    checkReply(reply);
    if (reply.status == http::status::created)
      check(rowCount(*fixture.page) == rows_before + 1, "a saved measurement is not listed");
  }
  return 0;
}
