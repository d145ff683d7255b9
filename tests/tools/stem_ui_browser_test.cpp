// `fieldrig stem-ui` end to end in real headless Chromium (Debian's /usr/bin/chromium, driven by
// Playwright from npm: browser/stem_ui_browser.cjs): a session recorded with SessionWriter from
// a rendered stereo pair (raw Bayer frames, calibration referenced in session.json), the server
// started as the built binary, four clicks, the diameter read from the page, two repeats saved,
// the CSV checked, a screenshot taken. Skips when Chromium is not installed.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "fieldrig/stem/measurement_log.h"
#include "support/cli_run.h"
#include "support/stem_campaign.h"
#include "support/stem_session.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;

constexpr const char* kChromium = "/usr/bin/chromium";

// The server as a child process; its first stdout line names the port.
class ServerProcess {
 public:
  ServerProcess(const std::vector<std::string>& args, const fs::path& log) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      std::vector<char*> argv;
      argv.push_back(const_cast<char*>(testing_support::kFieldrigBinary.c_str()));
      for (const std::string& arg : args)
        argv.push_back(const_cast<char*>(arg.c_str()));
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~ServerProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

 private:
  pid_t pid_ = -1;
};

std::string waitForUrl(const fs::path& log) {
  const std::string marker = "serving ";
  for (int i = 0; i < 200; ++i) {
    const std::string text = testing_support::readWholeFile(log);
    const auto at = text.find(marker);
    if (at != std::string::npos && text.find('\n', at) != std::string::npos)
      return text.substr(at + marker.size(), text.find('\n', at) - at - marker.size());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return "";
}

TEST(StemUiBrowser, MeasuresSavesAndSummarizesInHeadlessChromium) {
  if (!fs::exists(kChromium))
    GTEST_SKIP() << kChromium << " is not installed (Debian package chromium)";
  const fs::path browser_dir = STEM_BROWSER_DIR;
  ASSERT_TRUE(fs::exists(browser_dir / "node_modules" / "playwright-core"))
      << "playwright-core is not installed in " << browser_dir
      << " (the stem_browser_npm_ci fixture runs npm ci there)";

  testing_support::ScopedTempDir dir("stem_ui_browser");
  testing_support::StemCase c = testing_support::makeStemCases({22}, {1.0}, 31).front();
  c.geometry.distorted = true;
  c.geometry.right_rotation = cv::Vec3d(0.002, -0.006, 0.001);
  const sim::RenderedStereoPair pair = sim::renderCylinderPair(c.geometry, c.scene);
  ASSERT_TRUE(stereo::saveStereoCalibration(pair.calibration, dir / "calibration").ok());
  const fs::path session = dir / "session_2026-07-01";
  testing_support::writeStemSession(session, pair, dir / "calibration");

  ServerProcess server({"stem-ui", session.string(), "--port", "0"}, dir / "server.log");
  const std::string url = waitForUrl(dir / "server.log");
  ASSERT_FALSE(url.empty()) << testing_support::readWholeFile(dir / "server.log");
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;

  std::mt19937_64 rng(8);
  nlohmann::json test_case;
  test_case["session"] = "session_2026-07-01";
  test_case["label"] = "row3-stem7";
  test_case["repeats"] = nlohmann::json::array();
  for (int repeat = 0; repeat < 2; ++repeat) {
    nlohmann::json points = nlohmann::json::array();
    for (const cv::Point2d& p : testing_support::jitteredClicks(c, 0.7, rng)) {
      points.push_back(p.x);
      points.push_back(p.y);
    }
    test_case["repeats"].push_back(points);
  }
  const std::string command = "cd " + testing_support::shellQuote(browser_dir.string()) +
                              " && node stem_ui_browser.cjs " + testing_support::shellQuote(url) +
                              " " + testing_support::shellQuote(dir.path().string()) + " " +
                              testing_support::shellQuote(test_case.dump()) + " >" +
                              testing_support::shellQuote((dir / "node.out").string()) + " 2>" +
                              testing_support::shellQuote((dir / "node.err").string());
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << testing_support::readWholeFile(dir / "node.err")
      << testing_support::readWholeFile(dir / "server.log");
  const auto result = nlohmann::json::parse(testing_support::readWholeFile(dir / "node.out"));
  EXPECT_EQ(result["bad_requests_checked"], 10);
  ASSERT_EQ(result["diameters"].size(), 2u);
  for (const auto& diameter : result["diameters"])
    EXPECT_NEAR(diameter.get<double>(), 22.0, 0.5) << result.dump();
  for (const auto& ms : result["elapsed_ms"])
    EXPECT_LT(ms.get<double>(), 100.0);
  // The page's summary row: label, count, mean, SD.
  ASSERT_EQ(result["summary"].size(), 1u) << result.dump();
  EXPECT_EQ(result["summary"][0][0], "row3-stem7");
  EXPECT_EQ(result["summary"][0][1], "2");

  auto records = stem::readMeasurementLog(session / "stem_measurements.csv");
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const stem::MeasurementRecord& r = (*records)[static_cast<std::size_t>(i)];
    EXPECT_EQ(r.session, "session_2026-07-01");
    EXPECT_EQ(r.head, "bottom");
    EXPECT_EQ(r.stem_label, "row3-stem7");
    EXPECT_EQ(r.repeat, i + 1);
    EXPECT_EQ(r.trigger_id, 1u);
    EXPECT_NEAR(r.diameter_mm, result["diameters"][static_cast<std::size_t>(i)].get<double>(),
                0.006);
    EXPECT_GT(r.ncc, 0.5);
  }
  const fs::path screenshot = dir / "stem_ui.png";
  ASSERT_TRUE(fs::exists(screenshot));
  EXPECT_GT(fs::file_size(screenshot), 10000u);
  // Kept beside the test's output for people to look at.
  std::error_code ec;
  fs::copy_file(screenshot, fs::path(FIELDRIG_BINARY_DIR) / "tests" / "stem" / "stem_ui.png",
                fs::copy_options::overwrite_existing, ec);
}

}  // namespace
}  // namespace fieldrig
