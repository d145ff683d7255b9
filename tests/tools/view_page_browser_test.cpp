// `fieldrig view` in real headless Chromium (Debian's /usr/bin/chromium, driven by Playwright
// from npm: browser/view_page_browser.cjs): the in-cab page on a recorded session of three plots,
// the first processed, on a map with a location passed without a set and one never reached. The
// dots have the colours of their states, the plots table lists the processed plot, and its stem
// link opens the stem tool (`fieldrig stem-ui`, run here) on that plot's set. Screenshot to
// build/tests/tools/view_page/. Skips when Chromium is not installed.
#include <signal.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig::testing_support {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace std::chrono_literals;

constexpr const char* kChromium = "/usr/bin/chromium";
constexpr const char* kNode = "/usr/bin/node";

int servedPort(const std::string& line) {
  const std::string marker = "127.0.0.1:";
  const auto at = line.find(marker);
  return at == std::string::npos ? -1 : std::atoi(line.c_str() + at + marker.size());
}

TEST(ViewPageBrowser, RecordedSessionShowsCoverageColoursAndAStemLinkThatOpensThePlot) {
  if (!fs::exists(kChromium) || !fs::exists(kNode))
    GTEST_SKIP() << kChromium << " or " << kNode << " is not installed";
  const fs::path browser_dir = VIEW_BROWSER_DIR;
  ASSERT_TRUE(fs::exists(browser_dir / "node_modules" / "playwright-core"))
      << "playwright-core is not installed in " << browser_dir
      << " (the stem_browser_npm_ci fixture runs npm ci there)";
  ScopedTempDir dir("view_page_browser");
  const fs::path shots = fs::path(FIELDRIG_BINARY_DIR) / "tests" / "tools" / "view_page";
  fs::remove_all(shots);
  fs::create_directories(shots);

  const fs::path session = dir / "session";
  const CliRun made =
      runFieldrig({"sim", "plots", "--out", session.string(), "--count", "3"}, dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const CliRun processed = runFieldrig(
      {"process", session.string(), "--shard", "0/3", "--out", (session / "results").string()},
      dir.path());
  ASSERT_EQ(processed.exit_code, 0) << processed.err;
  std::ofstream(dir / "map.csv") << "id,lat,lon,heading,row\n"
                                    "plot-1,52.00000,5.00000,,1\n"
                                    "gap,52.00002,5.00000,,1\n"
                                    "plot-2,52.00004,5.00000,,1\n"
                                    "plot-3,52.00006,5.00000,,1\n"
                                    "beyond,52.00008,5.00000,,1\n";

  for (const char* name : {"stem", "view", "node"})
    fs::create_directories(dir / name);
  FieldrigProcess stem({"stem-ui", session.string(), "--port", "0"}, dir / "stem");
  ASSERT_TRUE(stem.waitForStdoutLines(1, 60s)) << stem.err();
  const int stem_port = servedPort(stem.outLines().front());
  ASSERT_GT(stem_port, 0) << stem.out();
  FieldrigProcess view({"view", session.string(), "--map", (dir / "map.csv").string(), "--port",
                        "0", "--stem-port", std::to_string(stem_port)},
                       dir / "view");
  ASSERT_TRUE(view.waitForStdoutLines(1, 60s)) << view.err();
  const int view_port = servedPort(view.outLines().front());
  ASSERT_GT(view_port, 0) << view.out();

  FieldrigProcess watcher({(browser_dir / "view_page_browser.cjs").string(),
                           "http://127.0.0.1:" + std::to_string(view_port) + "/", shots.string(),
                           Json{{"processed", "plot-1"}}.dump()},
                          dir / "node", kNode);
  const int watched = watcher.waitExit(180s);
  view.signal(SIGTERM);
  stem.signal(SIGTERM);
  ASSERT_EQ(watched, 0) << watcher.err() << watcher.out();
  const std::vector<std::string> lines = watcher.outLines();
  ASSERT_EQ(lines.size(), 1U) << watcher.out();
  const Json seen = Json::parse(lines.front());

  const std::string green = "rgb(46, 125, 50)", blue = "rgb(30, 136, 229)",
                    red = "rgb(211, 47, 47)", grey = "rgb(158, 158, 158)";
  const std::map<std::string, std::pair<std::string, std::string>> expected = {
      {"plot-1", {"processed", green}},
      {"gap", {"missed", red}},
      {"plot-2", {"recorded", blue}},
      {"plot-3", {"recorded", blue}},
      {"beyond", {"pending", grey}}};
  ASSERT_EQ(seen.at("dots").size(), expected.size()) << seen.dump();
  for (const Json& dot : seen.at("dots")) {
    const auto& [state, colour] = expected.at(dot.at(0).get<std::string>());
    EXPECT_EQ(dot.at(1), state) << dot.dump();
    EXPECT_EQ(dot.at(2), colour) << dot.dump();
  }
  EXPECT_EQ(seen.at("connection"), "recorded session");
  EXPECT_FALSE(seen.at("gps_visible").get<bool>());  // no live GPS in a recording
  ASSERT_EQ(seen.at("rows").size(), 1U) << seen.dump();
  EXPECT_EQ(seen.at("rows").at(0).at(1), "plot-1");
  EXPECT_NE(seen.at("selected").get<std::string>().find("plot-1"), std::string::npos)
      << seen.dump();
  EXPECT_EQ(seen.at("stem_href"),
            "http://127.0.0.1:" + std::to_string(stem_port) + "/?session=session&set=0");
  EXPECT_EQ(seen.at("stem_set"), 0);
  EXPECT_EQ(seen.at("stem_set_select"), "0");
  EXPECT_TRUE(seen.at("errors").empty()) << seen.dump();
  EXPECT_TRUE(fs::exists(shots / "view-session.png"));
}

}  // namespace
}  // namespace fieldrig::testing_support
