// fieldrigd's in-cab page end to end in real headless Chromium (Debian's /usr/bin/chromium,
// driven by Playwright from npm: browser/cab_page_browser.cjs). The synthetic field's drive,
// with 2.5 s of GPS silence cut into row 1, is replayed through fieldrigd in real time (its own
// pty); the page watches it. Then the daemon ends and another starts on the same port. Checked on
// the page: the dots turn from pending to processed (green) as the replay passes them, the
// location passed in the silence is red (missed), the gps_lost alarm shows within a second of
// the daemon raising it (in the list, with its meaning and what to do, and in the banner at the
// top), and the lost daemon is shown and its return recovered. Screenshots of three moments go to
// build/tests/tools/cab_page/. Skips when Chromium is not installed.
#include <signal.h>

#include <gtest/gtest.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "support/cli_process.h"
#include "support/daemon_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace std::chrono_literals;

constexpr const char* kChromium = "/usr/bin/chromium";
constexpr const char* kNode = "/usr/bin/node";

// The drive without its epochs from `from_s` to `to_s` seconds after its start: the receiver
// silent (the player plays the pause as captured). Epochs start at RMC sentences.
void writeDriveWithGap(const fs::path& drive, const fs::path& out, double from_s, double to_s) {
  std::ifstream in(drive);
  std::ofstream gapped(out);
  std::optional<double> first;
  bool dropping = false;
  for (std::string line; std::getline(in, line);) {
    if (line.size() > 17 && line.compare(3, 3, "RMC") == 0) {
      const double seconds = std::stod(line.substr(7, 2)) * 3600 +
                             std::stod(line.substr(9, 2)) * 60 + std::stod(line.substr(11, 5));
      if (!first)
        first = seconds;
      dropping = seconds - *first >= from_s && seconds - *first < to_s;
    }
    if (!dropping)
      gapped << line << "\n";
  }
}

std::set<std::string> plotsOf(const std::vector<std::string>& lines) {
  std::set<std::string> plots;
  for (const std::string& line : lines) {
    if (line.find("\"traits\"") != std::string::npos)
      plots.insert(Json::parse(line).at("location").get<std::string>());
  }
  return plots;
}

double isoMillis(const std::string& iso) {
  // "2026-07-14T15:30:07.123Z" → ms since the epoch (UTC).
  std::tm tm{};
  tm.tm_year = std::stoi(iso.substr(0, 4)) - 1900;
  tm.tm_mon = std::stoi(iso.substr(5, 2)) - 1;
  tm.tm_mday = std::stoi(iso.substr(8, 2));
  tm.tm_hour = std::stoi(iso.substr(11, 2));
  tm.tm_min = std::stoi(iso.substr(14, 2));
  const double seconds = std::stod(iso.substr(17, iso.size() - 18));
  return static_cast<double>(::timegm(&tm)) * 1000 + seconds * 1000;
}

TEST(CabPageBrowser, ReplayGpsLossMissedPlotAndDaemonRestartAsTheOperatorSeesThem) {
  if (!fs::exists(kChromium) || !fs::exists(kNode))
    GTEST_SKIP() << kChromium << " or " << kNode << " is not installed";
  const fs::path browser_dir = CAB_BROWSER_DIR;
  ASSERT_TRUE(fs::exists(browser_dir / "node_modules" / "playwright-core"))
      << "playwright-core is not installed in " << browser_dir
      << " (the stem_browser_npm_ci fixture runs npm ci there)";
  const fs::path field = testing_support::daemonField();
  ASSERT_TRUE(fs::exists(field / "drive.nmea")) << "the daemon_field fixture did not run";
  testing_support::ScopedTempDir dir("cab_page_browser");
  const fs::path shots = fs::path(FIELDRIG_BINARY_DIR) / "tests" / "tools" / "cab_page";
  fs::remove_all(shots);
  fs::create_directories(shots);

  // Row 1's plots cross at 3.25, 5.25, 7.25 … s of the drive: R01P03 falls in the silence.
  writeDriveWithGap(field / "drive.nmea", dir / "gap.nmea", 6.0, 8.5);
  const fs::path first_config =
      testing_support::writeReplayConfig(dir.path(), "first", field, "", "", {});
  {
    std::ofstream more(first_config, std::ios::app);
    more << "  realtime: true\n";  // under replay:, the config's last section
  }
  for (const char* name : {"d1", "d2", "node"})
    fs::create_directories(dir / name);
  auto first = std::make_unique<testing_support::FieldrigProcess>(
      std::vector<std::string>{"replay", "--config", first_config.string(), "--nmea",
                               (dir / "gap.nmea").string()},
      dir / "d1", testing_support::kFieldrigdBinary);
  ASSERT_TRUE(first->waitForStderr("status_url", 60s)) << first->err();
  const int port = testing_support::statusPort(first->err());
  ASSERT_GT(port, 0) << first->err();
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";

  const Json test_case = {{"locations", 12}, {"missed", "R01P03"}, {"timeout_s", 300}};
  testing_support::FieldrigProcess watcher(
      {(browser_dir / "cab_page_browser.cjs").string(), url, shots.string(), test_case.dump()},
      dir / "node", kNode);

  // The first daemon ends by itself at the end of its drive; the page is left without it.
  ASSERT_EQ(first->waitExit(180s), 0) << first->err();
  const std::string first_out = first->out();
  const std::set<std::string> first_plots = plotsOf(testing_support::splitLines(first_out));
  const std::string first_log = first->err();
  first.reset();
  // Once the page shows the daemon gone, a new daemon on the same port, as after a restart by
  // systemd.
  ASSERT_TRUE(watcher.waitForStdoutLines(1, 120s)) << watcher.err();
  const fs::path second_config =
      testing_support::writeReplayConfig(dir.path(), "second", field, "", "", {});
  {
    std::string text = testing_support::readWholeFile(second_config);
    text.replace(text.find("port: 0"), 7, "port: " + std::to_string(port));
    std::ofstream(second_config) << text << "  realtime: true\n";
  }
  testing_support::FieldrigProcess second({"replay", "--config", second_config.string()},
                                          dir / "d2", testing_support::kFieldrigdBinary);
  ASSERT_TRUE(second.waitForStderr("status_url", 60s)) << second.err();
  const int watched = watcher.waitExit(240s);
  second.signal(SIGTERM);
  EXPECT_EQ(second.waitExit(60s), 0) << second.err();
  ASSERT_EQ(watched, 0) << watcher.err() << watcher.out();
  const std::vector<std::string> watched_lines = watcher.outLines();
  ASSERT_EQ(watched_lines.size(), 2U) << watcher.out();
  const Json seen = Json::parse(watched_lines.back());

  // Every location the first run triggered was seen pending, then green once processed (blue,
  // recorded, when live processing fell behind on a slow machine and skipped it: the summary
  // counts those).
  const std::vector<std::string> first_lines = testing_support::splitLines(first_out);
  ASSERT_FALSE(first_lines.empty()) << first_log;
  const Json summary = Json::parse(first_lines.back()).at("summary");
  ASSERT_EQ(summary.at("triggers"), 11) << first_log;  // all but the one in the silence
  EXPECT_EQ(summary.at("missed"), 1) << first_log;
  EXPECT_EQ(first_plots.size() + summary.at("sets_skipped_for_processing").get<std::size_t>(), 11U)
      << first_log;
  const std::string green = "rgb(46, 125, 50)", blue = "rgb(30, 136, 229)",
                    red = "rgb(211, 47, 47)", grey = "rgb(158, 158, 158)";
  for (const auto& [plot, steps] : seen.at("transitions").items()) {
    SCOPED_TRACE(plot);
    EXPECT_EQ(steps.front().at(0), "pending");
    EXPECT_EQ(steps.front().at(1), grey);
    if (plot == "R01P03")
      continue;
    const bool processed = first_plots.count(plot) > 0;
    bool shown = false;
    for (const Json& step : steps) {
      shown = shown || (processed ? step.at(0) == "processed" && step.at(1) == green
                                  : step.at(0) == "recorded" && step.at(1) == blue);
    }
    EXPECT_TRUE(shown) << (processed ? "processed" : "recorded") << ": " << steps.dump();
  }
  EXPECT_EQ(seen.at("transitions").size(), 12U) << seen.dump();
  // The last plot's six images (three heads, left and right), 240 pixels wide, shown.
  const Json thumbnails = seen.at("first_run_view").at("thumbnails");
  ASSERT_EQ(thumbnails.size(), 6U) << seen.at("first_run_view").dump();
  for (const Json& width : thumbnails)
    EXPECT_EQ(width, 240) << thumbnails.dump();
  // The plot passed in the silence: red, missed, in the first run.
  EXPECT_EQ(first_plots.count("R01P03"), 0U);
  bool missed_red = false;
  for (const Json& step : seen.at("transitions").at("R01P03"))
    missed_red = missed_red || (step.at(0) == "missed" && step.at(1) == red);
  EXPECT_TRUE(missed_red) << seen.at("transitions").at("R01P03").dump();
  // The GPS loss: its alarm on the page within a second of the daemon raising it, with what
  // it means and what to do.
  ASSERT_TRUE(seen.at("alarms").contains("gps_lost")) << seen.dump();
  const Json& lost = seen.at("alarms").at("gps_lost");
  const double shown_after_ms =
      lost.at("seen_at").get<double>() - isoMillis(lost.at("time").get<std::string>());
  EXPECT_LT(shown_after_ms, 1000.0) << lost.dump();
  EXPECT_NE(lost.at("text").get<std::string>().find("check the receiver and its cable"),
            std::string::npos)
      << lost.dump();
  // And in the banner at the top, in sight on the smallest screen.
  ASSERT_TRUE(seen.contains("gps_lost_banner")) << seen.dump();
  const Json& banner = seen.at("gps_lost_banner");
  EXPECT_LT(banner.at("seen_at").get<double>() - isoMillis(lost.at("time").get<std::string>()),
            1000.0)
      << banner.dump();
  EXPECT_NE(banner.at("text").get<std::string>().find("check the receiver"), std::string::npos)
      << banner.dump();
  ASSERT_TRUE(seen.at("alarms").contains("missed")) << seen.dump();
  // The daemon's end shown, its successor's run followed.
  EXPECT_NE(seen.at("lost_note").get<std::string>().find("no contact since"), std::string::npos)
      << seen.dump();
  EXPECT_GT(seen.at("regained_seen_at").get<double>(), seen.at("lost_seen_at").get<double>());
  EXPECT_NE(seen.at("regained_note").get<std::string>().find("reconnected"), std::string::npos)
      << seen.dump();
  EXPECT_TRUE(seen.at("page_errors").empty()) << seen.at("page_errors").dump();
  for (const Json& shot : seen.at("screenshots")) {
    const fs::path png = shots / shot.get<std::string>();
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_GT(fs::file_size(png), 10000U) << png;
  }
  EXPECT_EQ(seen.at("screenshots").size(), 3U);
  std::cout << "page loaded in " << seen.at("load_ms") << " ms, map and connection after "
            << seen.at("ready_ms") << " ms; gps_lost shown " << shown_after_ms
            << " ms after the daemon raised it; screenshots in " << shots << "\n";
}

}  // namespace
}  // namespace fieldrig
