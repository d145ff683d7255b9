// fieldrigd on the live serial path, through a real pseudo-terminal (socat) standing in for the
// receiver: the synthetic field's drive is fed in real time with the faults of a field day. The
// GPS goes silent mid-row, then sends invalid fixes (no triggers; a gps_lost alarm within about a
// second; the location passed meanwhile reported missed; recovery when valid fixes return), and
// the serial device is unplugged and replugged (serial_lost, then reopened and read again).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "support/cli_process.h"
#include "support/daemon_run.h"
#include "support/field_plans.h"
#include "support/socat_pty.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using namespace std::chrono_literals;
using testing_support::FieldrigProcess;
using testing_support::ScopedTempDir;
using Json = nlohmann::json;
namespace fs = std::filesystem;

// One 10 Hz epoch of the drive: its seconds since the drive's start and its sentences.
struct Epoch {
  double t = 0;
  std::vector<std::string> lines;
};

std::vector<Epoch> readEpochs(const fs::path& nmea) {
  std::vector<Epoch> epochs;
  std::ifstream in(nmea);
  std::optional<double> first;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (line.size() < 17 || line.compare(3, 3, "RMC") != 0) {
      if (!epochs.empty())
        epochs.back().lines.push_back(line);
      continue;
    }
    // $GNRMC,hhmmss.ss,…
    const double hh = std::stod(line.substr(7, 2)), mm = std::stod(line.substr(9, 2)),
                 ss = std::stod(line.substr(11, 5));
    const double seconds = hh * 3600 + mm * 60 + ss;
    if (!first)
      first = seconds;
    epochs.push_back({seconds - *first, {line}});
  }
  return epochs;
}

// The sentence with its fix made invalid (RMC status V, GGA quality 0) and its checksum redone.
std::string invalidated(const std::string& line) {
  std::vector<std::string> fields;
  const std::string body = line.substr(1, line.find('*') - 1);
  std::stringstream split(body);
  for (std::string field; std::getline(split, field, ',');)
    fields.push_back(field);
  if (body.compare(2, 3, "RMC") == 0 && fields.size() > 2)
    fields[2] = "V";
  if (body.compare(2, 3, "GGA") == 0 && fields.size() > 6)
    fields[6] = "0";
  std::string joined;
  for (std::size_t i = 0; i < fields.size(); ++i)
    joined += (i ? "," : "") + fields[i];
  unsigned checksum = 0;
  for (char c : joined)
    checksum ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X", checksum);
  return "$" + joined + tail;
}

TEST(DaemonLive, GpsLossAndSerialUnplugAreAlarmedSurvivedAndRecovered) {
  const fs::path field = testing_support::daemonField();
  ASSERT_TRUE(fs::exists(field / "drive.nmea")) << "the daemon_field fixture did not run";
  if (!testing_support::findSocat())
    GTEST_SKIP() << "socat is not installed";
  ScopedTempDir dir("daemon_live");
  testing_support::SocatPty pty(dir.path() / "pty");
  fs::create_directories(dir.path() / "pty");
  ASSERT_EQ(pty.start(), "");
  const fs::path config = testing_support::writeReplayConfig(
      dir.path(), "run", field, "",
      "gps:\n  serial:\n    reopen_initial_ms: 100\n    reopen_max_ms: 400\n");
  FieldrigProcess daemon({"replay", "--config", config.string(), "--nmea", pty.device().string()},
                         dir.path(), testing_support::kFieldrigdBinary);
  ASSERT_TRUE(daemon.waitForStderr("status_url", 30s)) << daemon.err();
  const int port = testing_support::statusPort(daemon.err());
  ASSERT_GT(port, 0) << daemon.err();
  auto status = [&] { return Json::parse(testing_support::httpGet(port, "/status")); };

  const std::vector<Epoch> epochs = readEpochs(field / "drive.nmea");
  ASSERT_GT(epochs.size(), 170U);
  auto feed = std::make_unique<testing_support::Feed>(pty.feed());
  ASSERT_TRUE(feed->ok());
  const auto start = std::chrono::steady_clock::now();
  auto at = [&](double t) { return start + std::chrono::microseconds(static_cast<long>(t * 1e6)); };
  // Row 1's plots cross at 3.25, 5.25, 7.25, 9.25, 11.25 and 13.25 s of the drive.
  constexpr double kSilenceFrom = 6.0, kInvalidFrom = 7.5, kValidFrom = 8.5;
  constexpr double kUnplugAt = 13.6, kReplugAt = 14.6, kEnd = 16.0;
  bool saw_lost = false;
  double lost_after_s = 0;
  bool unplugged = false;
  for (const Epoch& epoch : epochs) {
    if (epoch.t >= kEnd)
      break;
    if (epoch.t >= kSilenceFrom && epoch.t < kInvalidFrom) {
      // Silence: the alarm must come within about a second.
      if (!saw_lost && std::chrono::steady_clock::now() > at(kSilenceFrom)) {
        const Json s = status();
        if (s.at("gps").at("lost").get<bool>()) {
          saw_lost = true;
          lost_after_s =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - at(kSilenceFrom))
                  .count();
        }
      }
      std::this_thread::sleep_until(at(epoch.t));
      continue;
    }
    if (epoch.t >= kUnplugAt && epoch.t < kReplugAt) {
      if (!unplugged) {
        feed.reset();
        pty.kill();  // the cable is pulled
        unplugged = true;
      }
      std::this_thread::sleep_until(at(epoch.t));
      continue;
    }
    if (unplugged && epoch.t >= kReplugAt && !feed) {
      ASSERT_EQ(pty.start(), "");  // plugged in again: the same device name
      feed = std::make_unique<testing_support::Feed>(pty.feed());
      ASSERT_TRUE(feed->ok());
    }
    std::this_thread::sleep_until(at(epoch.t));
    for (const std::string& line : epoch.lines) {
      const std::string sent =
          epoch.t >= kInvalidFrom && epoch.t < kValidFrom ? invalidated(line) : line;
      ASSERT_TRUE(feed->write(sent + "\r\n"));
    }
  }
  std::this_thread::sleep_for(1s);
  const Json final_status = status();
  EXPECT_TRUE(saw_lost) << "gps.lost never showed during " << kInvalidFrom - kSilenceFrom
                        << " s of silence";
  EXPECT_LT(lost_after_s, 1.5);
  EXPECT_FALSE(final_status.at("gps").at("lost").get<bool>()) << final_status.dump();
  EXPECT_EQ(final_status.at("gps").at("serial"), "opened") << final_status.dump();
  // The planner's own uncertainty of its latest crossing: more than nothing (1 cm of simulated
  // noise), less than a plot's worth, and the two sigmas agree through the speed (2 m/s).
  const Json last = final_status.at("triggers").at("last");
  const double timing_sigma = last.at("timing_sigma_s").get<double>();
  const double along_sigma = last.at("along_track_sigma_m").get<double>();
  EXPECT_GT(along_sigma, 0.001) << last.dump();
  EXPECT_LT(along_sigma, 0.05) << last.dump();
  EXPECT_NEAR(timing_sigma * 2.0, along_sigma, along_sigma * 0.3) << last.dump();
  // Six sim cameras: no packets, so the GigE Vision counts are not known (null), per camera too.
  const Json packets = final_status.at("packets");
  EXPECT_TRUE(packets.at("resent").is_null()) << packets.dump();
  EXPECT_TRUE(packets.at("missing").is_null()) << packets.dump();
  ASSERT_EQ(packets.at("cameras").size(), 6u) << packets.dump();
  for (const auto& [name, camera] : packets.at("cameras").items())
    EXPECT_TRUE(camera.at("resent").is_null()) << name;
  ASSERT_TRUE(daemon.signal(SIGTERM));
  ASSERT_EQ(daemon.waitExit(30s), 0) << daemon.err();

  std::set<std::string> fired;
  for (const std::string& text : daemon.outLines()) {
    if (text.find("\"traits\"") != std::string::npos)
      fired.insert(Json::parse(text).at("location").get<std::string>());
  }
  EXPECT_TRUE(fired.count("R01P01") && fired.count("R01P02")) << "before the loss";
  EXPECT_FALSE(fired.count("R01P03")) << "fired without valid fixes";
  EXPECT_TRUE(fired.count("R01P05") && fired.count("R01P06")) << "after the recovery";
  const Json missed = final_status.at("triggers").at("missed_locations");
  EXPECT_NE(std::find(missed.begin(), missed.end(), "R01P03"), missed.end()) << missed.dump();
  const std::string log = daemon.err();
  EXPECT_NE(log.find("alarm gps_lost"), std::string::npos) << log;
  EXPECT_NE(log.find("alarm gps_recovered"), std::string::npos) << log;
  EXPECT_NE(log.find("alarm missed at R01P03"), std::string::npos) << log;
  EXPECT_NE(log.find("alarm serial_lost"), std::string::npos) << log;
}

TEST(DaemonLive, ProcessingSlowerThanTheDriveLosesNothingAndFieldrigProcessCompletesIt) {
  const fs::path field = testing_support::daemonField();
  ASSERT_TRUE(fs::exists(field / "drive.nmea")) << "the daemon_field fixture did not run";
  ScopedTempDir dir("daemon_slow");
  // A burst no processor keeps up with: 20 plots 0.9 m apart driven at 6 m/s (a set every
  // 0.15 s for 3 s, played in real time through the daemon's pty; the cameras allowed 10 Hz),
  // into a one-set queue, processed with the paper's surface area (MLS + greedy triangulation).
  // A set takes about 1 s to process here; keeping up would take 0.15 s, so live processing falls
  // behind and skips on any machine this runs on. The sim cameras replay the field's 12 sets in
  // turn, whatever the map.
  const fs::path fast_nmea = dir.path() / "fast.nmea";
  const fs::path fast_map = dir.path() / "fast-map.csv";
  gps::FieldPlan plan =
      testing_support::fieldPlan({42.0106, -93.7385}, {42.0110, -93.7385}, 1, 0.5, 1.0);
  plan.plots_per_row = 20;
  plan.alley_length_m = 0.4;
  const auto drive = testing_support::runFieldrig(
      testing_support::withFieldPlan({"sim", "drive"}, plan,
                                     {"--speed", "6", "--seed", "7", "--out-nmea",
                                      fast_nmea.string(), "--out-map", fast_map.string()}),
      dir.path());
  ASSERT_EQ(drive.exit_code, 0) << drive.err;
  const std::string slow_processing =
      "gps:\n  planner:\n    min_trigger_interval_s: 0.1\n"
      "pipeline:\n  queue_sets: 1\n  traits:\n    area_method: paper\n";
  const fs::path config =
      testing_support::writeReplayConfig(dir.path(), "run", field, "", slow_processing, fast_map);
  const auto run = testing_support::runDaemon(
      {"replay", "--config", config.string(), "--realtime", "--nmea", fast_nmea.string()},
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json summary = Json::parse(run.out_lines.back()).at("summary");
  // Which locations trigger is not this test's business: with both cores busy, the kernel has
  // been seen to hold the pty's bytes back for 1-4 s (reported with issue 12), and a
  // location passed meanwhile is missed. What is: every triggered set recorded, and each either
  // processed or skipped and counted.
  const int recorded = summary.at("sets_recorded").get<int>();
  EXPECT_EQ(recorded, summary.at("triggers").get<int>());
  EXPECT_GE(recorded, 6) << run.err;
  const int processed = summary.at("sets_processed").get<int>();
  const int skipped = summary.at("sets_skipped_for_processing").get<int>();
  EXPECT_GT(skipped, 0) << "processing kept up: the test did not test the skip";
  EXPECT_EQ(processed + skipped, recorded);
  EXPECT_NE(run.err.find("fieldrig process"), std::string::npos) << "the log says how to finish";

  // Offline, the same processor finishes what was skipped, into the same results.
  const fs::path traits = dir.path() / "slow-traits.yaml";
  std::ofstream(traits) << "area_method: paper\n";
  const fs::path session = dir.path() / "run" / "session";
  const auto completed = testing_support::runFieldrig(
      {"process", session.string(), "--traits-config", traits.string(), "--map", fast_map.string()},
      dir.path());
  ASSERT_EQ(completed.exit_code, 0) << completed.err;
  const Json offline = Json::parse(completed.out_lines.back()).at("summary");
  EXPECT_EQ(offline.at("already_done"), processed);
  EXPECT_EQ(offline.at("sets"), skipped);
  EXPECT_EQ(offline.at("plots_in_results"), recorded);
  std::ifstream results(session / "results" / "plots.jsonl");
  std::set<std::string> plots;
  for (std::string line; std::getline(results, line);)
    plots.insert(Json::parse(line).at("location").get<std::string>());
  EXPECT_EQ(plots.size(), static_cast<std::size_t>(recorded));
}

}  // namespace
}  // namespace fieldrig
