// Faults fieldrigd must survive, each through the real daemon process on a replay of the
// synthetic field (daemon_field fixture): bad configuration, map or calibration at start (a clear
// error, nothing written), a camera dropping frames (sets recorded and flagged, the run goes on),
// SIGTERM mid-run (the set in flight finished, the session closed whole), kill -9 and a restart
// (the session verifies and the daemon carries on into it), a full disk (recording stops cleanly
// with an alarm, what was written stays readable), and the status served while it runs.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <vector>

#include "fieldrig/recording/session_reader.h"
#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/daemon_run.h"
#include "support/temp_dir.h"
#include "support/tmpfs_mount.h"

namespace fieldrig {
namespace {

using namespace std::chrono_literals;
using testing_support::FieldrigProcess;
using testing_support::readWholeFile;
using testing_support::runDaemon;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;
using testing_support::writeReplayConfig;
using Json = nlohmann::json;
namespace fs = std::filesystem;

std::size_t plotLines(const std::vector<std::string>& lines) {
  std::size_t plots = 0;
  for (const std::string& line : lines)
    plots += line.find("\"traits\"") != std::string::npos ? 1 : 0;
  return plots;
}

Json summaryOf(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    if (line.rfind("{\"summary\"", 0) == 0)
      return Json::parse(line).at("summary");
  }
  return nullptr;
}

class DaemonFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    field_ = testing_support::daemonField();
    ASSERT_TRUE(fs::exists(field_ / "map.csv")) << "the daemon_field fixture did not run";
  }
  fs::path field_;
};

TEST_F(DaemonFaults, AnUnknownConfigKeyIsNamedWithItsLineAndNothingIsWritten) {
  ScopedTempDir dir("daemon_bad_key");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_, "",
                                            "pipeline:\n  queue_sets: 2\n  quue_sets: 3\n");
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("run.yaml:"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("pipeline.quue_sets"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a bad configuration wrote something";
  const auto check = runDaemon({"--check-config", config.string()}, dir.path());
  EXPECT_EQ(check.exit_code, 2);
  EXPECT_NE(check.err.find("pipeline.quue_sets"), std::string::npos) << check.err;
}

TEST_F(DaemonFaults, ABadMapLineIsNamedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_bad_map");
  std::string map = readWholeFile(field_ / "map.csv");
  map += "R09P09,not-a-latitude,-93.7,0,9,9,9\n";
  const fs::path bad_map = dir.path() / "bad_map.csv";
  std::ofstream(bad_map) << map;
  const fs::path config = writeReplayConfig(dir.path(), "run", field_, "", "");
  std::string text = readWholeFile(config);
  text = std::regex_replace(text, std::regex("map: .*\n"), "map: " + bad_map.string() + "\n");
  std::ofstream(config) << text;
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("bad_map.csv:"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a bad map wrote something";
}

TEST_F(DaemonFaults, AMissingCalibrationIsNamedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_bad_calib");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  std::string text = readWholeFile(config);
  text = std::regex_replace(text, std::regex("calibration: .*\n"),
                            "calibration: " + (dir.path() / "no-such-calib").string() + "\n");
  std::ofstream(config) << text;
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("no-such-calib"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a bad calibration wrote something";
}

// A folder as the NMEA input used to read as no fixes at all (an empty session and exit 0). Given
// on the command line, the error blamed the configuration file; it names the flag.
TEST_F(DaemonFaults, AnNmeaFolderIsNamedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_nmea_folder");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  const auto run =
      runDaemon({"replay", "--config", config.string(), "--nmea", field_.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--nmea: " + field_.string() + ": a folder, not an NMEA file"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find(config.string()), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a folder as NMEA wrote something";
}

// An empty override read as "not given" (`--recording ''` recorded into the configuration's
// folder), and spdlog read an unknown level as "off" (`--log-level loud` silenced the log).
TEST_F(DaemonFaults, AnEmptyOverrideOrAnUnknownLogLevelIsRefusedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_empty_override");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  const auto empty =
      runDaemon({"replay", "--config", config.string(), "--recording", ""}, dir.path());
  EXPECT_EQ(empty.exit_code, 2);
  EXPECT_NE(empty.err.find("fieldrigd replay: --recording: must not be empty"), std::string::npos)
      << empty.err;
  const auto loud =
      runDaemon({"replay", "--config", config.string(), "--log-level", "loud"}, dir.path());
  EXPECT_EQ(loud.exit_code, 2);
  EXPECT_NE(loud.err.find("--log-level"), std::string::npos) << loud.err;
  EXPECT_NE(loud.err.find("loud"), std::string::npos) << loud.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a refused option wrote something";
}

// spdlog's exception from a folder as the log file was an internal error (exit 4) naming no key,
// and --check-config said ok.
TEST_F(DaemonFaults, ALogFileThatIsAFolderIsNamedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_log_folder");
  const fs::path config = writeReplayConfig(
      dir.path(), "run", field_, "", "log:\n  level: info\n  file: " + dir.path().string() + "\n");
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("log.file: " + dir.path().string() + ": a folder, not a file"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a bad log file wrote something";
  const auto check = runDaemon({"--check-config", config.string()}, dir.path());
  EXPECT_EQ(check.exit_code, 2);
  EXPECT_NE(check.err.find("log.file"), std::string::npos) << check.err;
}

// The sim cameras wrap around to the first set when the replayed session runs out: a torn last
// index line gave the last plot the first plot's frames and traits, with exit 0 and no word.
TEST_F(DaemonFaults, AReplayedSessionWithATornLastLineIsSaidAndSoAreTheWrappedPlots) {
  ScopedTempDir dir("daemon_torn_source");
  const fs::path source = field_ / "source-session";
  const fs::path copy = dir.path() / "source";
  fs::create_directories(copy / "frames");
  fs::copy_file(source / "session.json", copy / "session.json");
  for (const fs::directory_entry& entry : fs::directory_iterator(source / "frames"))
    fs::create_symlink(entry.path(), copy / "frames" / entry.path().filename());
  std::string index = readWholeFile(source / "index.jsonl");
  const std::size_t last_line = index.rfind('\n', index.size() - 2) + 1;
  index.resize(last_line + (index.size() - last_line) / 2);
  std::ofstream(copy / "index.jsonl") << index;
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  const auto run =
      runDaemon({"replay", "--config", config.string(), "--session", copy.string(), "--no-status"},
                dir.path());
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("index.jsonl:"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("torn last line"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("sim cameras replay earlier sets' frames again"), std::string::npos)
      << run.err;
}

// A pipe as the NMEA input (here the daemon's stdin) whose writer stays open, as a logger's
// would: SIGTERM was logged and then did nothing until the writer closed.
TEST_F(DaemonFaults, SigtermEndsAReplayFromAPipeWhoseWriterStaysOpen) {
  ScopedTempDir dir("daemon_nmea_pipe");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  FieldrigProcess daemon(
      {"replay", "--config", config.string(), "--nmea", "/dev/stdin", "--no-status"}, dir.path(),
      testing_support::kFieldrigdBinary);
  const std::string drive = readWholeFile(field_ / "drive.nmea");
  // Half the drive; the pipe stays open, so the replay waits for more.
  ASSERT_TRUE(daemon.sendInput(drive.substr(0, drive.find('\n', drive.size() / 2) + 1)));
  ASSERT_TRUE(daemon.waitForStdoutLines(1, 60s)) << daemon.err();
  ASSERT_TRUE(daemon.signal(SIGTERM));
  ASSERT_EQ(daemon.waitExit(30s), 0) << "the signal did not end the read\n" << daemon.err();
  const Json summary = summaryOf(daemon.outLines());
  ASSERT_FALSE(summary.is_null()) << daemon.out();
  EXPECT_GT(summary.at("triggers").get<int>(), 0) << summary.dump();
  EXPECT_EQ(summary.at("sets_recorded"), summary.at("triggers")) << summary.dump();
  const auto verify = runFieldrig(
      {"session", "info", (dir.path() / "run" / "session").string(), "--verify"}, dir.path());
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
}

// A file with no valid fix (garbage, bad checksums, only status V) replayed to an empty session
// with exit 0 and no word; lines rejected beside good fixes were counted nowhere.
TEST_F(DaemonFaults, AnNmeaFileWithNoValidFixIsBadInputAndRejectedLinesAreCounted) {
  ScopedTempDir dir("daemon_nmea_no_fix");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  const fs::path garbage = dir.path() / "garbage.nmea";
  std::ofstream(garbage) << "hello tractor\n$GPRMC,bad*00\n"
                         << "$GPRMC,120000.00,V,,,,,,,140726,,,N*78\n";
  const auto run =
      runDaemon({"replay", "--config", config.string(), "--nmea", garbage.string(), "--no-status"},
                dir.path());
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("--nmea: " + garbage.string() + ": no valid fix in 3 lines"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("2 rejected"), std::string::npos) << run.err;
  const Json summary = summaryOf(run.out_lines);
  ASSERT_FALSE(summary.is_null()) << run.err;
  EXPECT_EQ(summary.at("nmea").at("lines"), 3) << summary.dump();
  EXPECT_EQ(summary.at("nmea").at("rejected_sentences"), 2) << summary.dump();
  EXPECT_EQ(summary.at("nmea").at("valid_fixes"), 0) << summary.dump();

  // Three damaged lines inside the good drive: the run goes on, and says so.
  const fs::path damaged = dir.path() / "damaged.nmea";
  std::ofstream(damaged) << "$GPRMC,bad*00\nnoise\n\x01\x02\n"
                         << readWholeFile(field_ / "drive.nmea");
  const auto good = runDaemon({"replay", "--config", config.string(), "--nmea", damaged.string(),
                               "--recording", (dir.path() / "second").string(), "--no-status"},
                              dir.path());
  EXPECT_EQ(good.exit_code, 0) << good.err;
  const Json good_summary = summaryOf(good.out_lines);
  ASSERT_FALSE(good_summary.is_null()) << good.err;
  EXPECT_EQ(good_summary.at("nmea").at("rejected_sentences"), 3) << good_summary.dump();
  EXPECT_GT(good_summary.at("nmea").at("valid_fixes").get<int>(), 0) << good_summary.dump();
  EXPECT_NE(good.err.find("sentences rejected: 3 in"), std::string::npos) << good.err;
}

// --check-config kept a list of checks of its own and passed configurations that the start then
// refused. It now runs the start's own checks: each of these is refused by both, naming the key
// or file, and neither writes anything.
TEST_F(DaemonFaults, CheckConfigRefusesWhatTheStartRefuses) {
  ScopedTempDir dir("daemon_check_agrees");
  const fs::path a_file = dir.path() / "a-file";
  std::ofstream(a_file) << "not a folder\n";
  const fs::path header_only_map = dir.path() / "header-only.csv";
  {
    const std::string map = readWholeFile(field_ / "map.csv");
    std::ofstream(header_only_map) << map.substr(0, map.find('\n') + 1);
  }
  const std::string good = readWholeFile(writeReplayConfig(dir.path(), "run", field_));
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  };
  const std::string map_line = "map: " + (field_ / "map.csv").string() + "\n";
  const struct {
    std::string name, config, named;
  } cases[] = {
      {"address", replaced("  port: 0\n", "  port: 0\n  address: not-an-ip\n"),
       "status.address: 'not-an-ip'"},
      {"no_map", replaced(map_line, "map: \"\"\n"), "map: no imaging-location map"},
      {"header_map", replaced(map_line, "map: " + header_only_map.string() + "\n"),
       header_only_map.string() + ": the map has no locations"},
      {"no_recording", replaced("  dir: run/session\n", "  dir: \"\"\n"), "recording.dir"},
      {"outputs_file", good + "outputs:\n  dir: " + a_file.string() + "\n",
       "outputs.dir: " + a_file.string() + ": " + a_file.string() + " is not a folder"},
      {"recording_file", replaced("  dir: run/session\n", "  dir: " + a_file.string() + "\n"),
       "recording.dir: " + a_file.string() + ": " + a_file.string() + " is not a folder"},
      {"record_into_source",
       replaced("  dir: run/session\n",
                "  dir: " + (field_ / "source-session" / "run").string() + "\n"),
       "inside the session being replayed"},
      {"no_session", replaced("source-session\n", "no-such-session\n"), "replay.session: "},
      {"under_a_file", replaced("  dir: run/session\n", "  dir: " + a_file.string() + "/sub\n"),
       "recording.dir: " + a_file.string() + "/sub: " + a_file.string() + " is not a folder"},
      {"huge_pool",
       replaced("cameras:\n", "cameras:\n  pool_sets: 1024\n  width: 16384\n  height: 16384\n"),
       "need more than this machine's"},
  };
  for (const auto& c : cases) {
    const fs::path config = dir.path() / (c.name + ".yaml");
    std::ofstream(config) << c.config;
    const auto check = runDaemon({"--check-config", config.string()}, dir.path());
    EXPECT_EQ(check.exit_code, 2) << c.name << "\n" << check.err;
    EXPECT_NE(check.err.find(c.named), std::string::npos) << c.name << "\n" << check.err;
    EXPECT_EQ(check.err.find(": ok"), std::string::npos) << c.name;
    const auto start = runDaemon({"replay", "--config", config.string()}, dir.path());
    EXPECT_EQ(start.exit_code, 2) << c.name << "\n" << start.err;
    EXPECT_NE(start.err.find(c.named), std::string::npos) << c.name << "\n" << start.err;
    EXPECT_FALSE(fs::exists(dir.path() / "run")) << c.name << " wrote something";
  }
}

// Cameras for a head the calibration does not have, and none for one it has: every plot went
// without that head, with exit 0 and an --check-config that said ok.
TEST_F(DaemonFaults, ACalibratedHeadWithoutCamerasIsNamedAndNothingIsWritten) {
  ScopedTempDir dir("daemon_heads");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  std::string text = readWholeFile(config);
  text = std::regex_replace(text, std::regex("driver: sim\n"),
                            "driver: sim\n  heads: [bottom, middle, roof]\n");
  std::ofstream(config) << text;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"replay", "--config", config.string()},
        std::vector<std::string>{"--check-config", config.string()}}) {
    const auto run = runDaemon(args, dir.path());
    EXPECT_EQ(run.exit_code, 2) << args.front();
    EXPECT_NE(run.err.find("cameras.heads (bottom, middle, roof) has no head 'top', which the "
                           "calibration has (bottom, middle, top)"),
              std::string::npos)
        << run.err;
  }
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a rig without the calibrated heads wrote";
}

TEST_F(DaemonFaults, AnUnknownCameraDriverIsNamedWithTheDriversItHasSimIncluded) {
  ScopedTempDir dir("daemon_bad_driver");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  std::string text = readWholeFile(config);
  text = std::regex_replace(text, std::regex("driver: sim\n"), "driver: gige\n");
  std::ofstream(config) << text;
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("unknown camera driver 'gige'"), std::string::npos) << run.err;
  const auto check = runDaemon({"--check-config", config.string()}, dir.path());
  EXPECT_EQ(check.exit_code, 2) << check.err;
  EXPECT_NE(check.err.find("unknown camera driver 'gige'"), std::string::npos) << check.err;
  // fieldrigd added the sim driver (drivers/ does not know it): the error lists it.
  const auto listed = run.err.find("this build has: ");
  ASSERT_NE(listed, std::string::npos) << run.err;
  EXPECT_NE(run.err.find("sim", listed), std::string::npos) << run.err;
  // The results folder, opened before the cameras, is not left behind.
  EXPECT_FALSE(fs::exists(dir.path() / "run")) << "a failed start left its folders";
}

TEST_F(DaemonFaults, ACameraDroppingFramesGivesFlaggedIncompleteSetsAndTheRunGoesOn) {
  ScopedTempDir dir("daemon_drops");
  // Every camera loses the frames of every fourth trigger: those sets arrive empty.
  const fs::path config = writeReplayConfig(dir.path(), "run", field_, "drop_every: 4");
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json summary = summaryOf(run.out_lines);
  ASSERT_FALSE(summary.is_null()) << run.err;
  EXPECT_EQ(summary.at("sets_recorded"), summary.at("triggers"));
  EXPECT_EQ(summary.at("sets_incomplete"), summary.at("triggers").get<int>() / 4);
  EXPECT_EQ(summary.at("sets_processed"), summary.at("triggers"));
  int flagged = 0;
  for (const std::string& text : run.out_lines) {
    if (text.find("\"traits\"") == std::string::npos)
      continue;
    const Json line = Json::parse(text);
    if (line.at("trigger_id").get<int>() % 4 == 0) {
      ++flagged;
      EXPECT_NE(line.at("traits").at("status"), "ok") << text;
      EXPECT_NE(line.at("problems").dump().find("missing"), std::string::npos) << text;
    } else {
      EXPECT_EQ(line.at("traits").at("status"), "ok") << text;
    }
  }
  EXPECT_EQ(flagged, summary.at("triggers").get<int>() / 4);
  const auto reader = recording::SessionReader::open(dir.path() / "run" / "session");
  ASSERT_TRUE(reader.ok()) << reader.error().message;
  int incomplete = 0;
  for (const recording::IndexedSet& set : reader->sets())
    incomplete += set.complete ? 0 : 1;
  EXPECT_EQ(incomplete, summary.at("sets_incomplete").get<int>());
}

TEST_F(DaemonFaults, SigtermMidRunFinishesTheSetInFlightAndClosesTheSession) {
  ScopedTempDir dir("daemon_sigterm");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  FieldrigProcess daemon({"replay", "--config", config.string()}, dir.path(),
                         testing_support::kFieldrigdBinary);
  ASSERT_TRUE(daemon.waitForStdoutLines(3, 60s)) << daemon.err();
  ASSERT_TRUE(daemon.signal(SIGTERM));
  ASSERT_EQ(daemon.waitExit(30s), 0) << daemon.err();
  const auto lines = daemon.outLines();
  const Json summary = summaryOf(lines);
  ASSERT_FALSE(summary.is_null()) << daemon.out();
  EXPECT_LT(summary.at("triggers").get<int>(), 12) << "the signal did not stop the replay";
  // Every triggered set recorded and processed: none was abandoned in flight, and none was
  // triggered after the signal into a full processing queue (skipped, seen under ASan).
  EXPECT_EQ(summary.at("sets_recorded"), summary.at("triggers")) << summary.dump();
  EXPECT_EQ(summary.at("sets_processed"), summary.at("triggers")) << summary.dump();
  EXPECT_EQ(summary.at("sets_skipped_for_processing"), 0) << summary.dump();
  EXPECT_EQ(plotLines(lines), summary.at("sets_processed").get<std::size_t>());
  const auto verify = runFieldrig(
      {"session", "info", (dir.path() / "run" / "session").string(), "--verify"}, dir.path());
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
}

// Once the NMEA has ended, the last sets are still processed and the results written: a SIGTERM
// then took the default action (exit 143, no summary, the results behind the recording). Four
// sets queued and the paper's slow area method keep the daemon closing for seconds.
TEST_F(DaemonFaults, SigtermWhileClosingStillFinishesTheResults) {
  ScopedTempDir dir("daemon_sigterm_closing");
  const fs::path config =
      writeReplayConfig(dir.path(), "run", field_, "",
                        "pipeline:\n  queue_sets: 4\n  traits:\n    area_method: paper\n");
  FieldrigProcess daemon({"replay", "--config", config.string(), "--no-status"}, dir.path(),
                         testing_support::kFieldrigdBinary);
  ASSERT_TRUE(daemon.waitForStderr("closing the session", 120s)) << daemon.err();
  if (!daemon.signal(SIGTERM))
    GTEST_SKIP() << "the daemon closed before the signal could be sent";
  ASSERT_EQ(daemon.waitExit(120s), 0) << daemon.err();
  EXPECT_NE(daemon.err().find("a stop signal while closing"), std::string::npos) << daemon.err();
  const Json summary = summaryOf(daemon.outLines());
  ASSERT_FALSE(summary.is_null()) << daemon.out();
  EXPECT_EQ(summary.at("triggers"), 12) << summary.dump();
  EXPECT_EQ(summary.at("sets_processed"), summary.at("sets_recorded")) << summary.dump();
  EXPECT_EQ(plotLines(daemon.outLines()), 12U);
}

TEST_F(DaemonFaults, KillNineThenRestartVerifiesAndCarriesOnIntoTheSession) {
  ScopedTempDir dir("daemon_kill9");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  const fs::path session = dir.path() / "run" / "session";
  std::size_t first_run_plots = 0;
  {
    FieldrigProcess daemon({"replay", "--config", config.string()}, dir.path(),
                           testing_support::kFieldrigdBinary);
    ASSERT_TRUE(daemon.waitForStdoutLines(4, 60s)) << daemon.err();
    ASSERT_TRUE(daemon.signal(SIGKILL));
    daemon.waitExit(10s);
    first_run_plots = plotLines(daemon.outLines());
  }
  const auto verify = runFieldrig({"session", "info", session.string(), "--verify"}, dir.path());
  ASSERT_EQ(verify.exit_code, 0) << verify.err;
  const auto before = recording::SessionReader::open(session);
  ASSERT_TRUE(before.ok()) << before.error().message;
  const std::size_t recorded_before = before->sets().size();
  EXPECT_GE(recorded_before, first_run_plots);

  const auto restart = runDaemon({"replay", "--config", config.string()}, dir.path());
  ASSERT_EQ(restart.exit_code, 0) << restart.err;
  const Json summary = summaryOf(restart.out_lines);
  ASSERT_FALSE(summary.is_null()) << restart.err;
  const auto after = recording::SessionReader::open(session);
  ASSERT_TRUE(after.ok()) << after.error().message;
  EXPECT_EQ(after->sets().size(), recorded_before + summary.at("sets_recorded").get<std::size_t>());
  std::set<std::uint64_t> trigger_ids;
  for (const recording::IndexedSet& set : after->sets())
    EXPECT_TRUE(trigger_ids.insert(set.trigger_id).second) << "trigger id reused after restart";
  const auto verify_after =
      runFieldrig({"session", "info", session.string(), "--verify"}, dir.path());
  EXPECT_EQ(verify_after.exit_code, 0) << verify_after.err;
  // The results folder carries both runs: every line whole.
  std::ifstream results(session / "results" / "plots.jsonl");
  std::size_t lines = 0;
  for (std::string line; std::getline(results, line); ++lines)
    EXPECT_TRUE(Json::accept(line)) << line;
  EXPECT_GE(lines, first_run_plots + summary.at("sets_processed").get<std::size_t>());
}

TEST_F(DaemonFaults, AFullDiskStopsRecordingWithAnAlarmAndKeepsWhatWasWritten) {
  ScopedTempDir dir("daemon_disk_full");
  // Six 1624×1224 frames are 12 MB a set: 40 MB hold three sets and the session's files.
  testing_support::TmpfsMount tmpfs(dir.path() / "small", "40m");
  if (!tmpfs.mounted())
    GTEST_SKIP() << "cannot mount a tmpfs here (" << tmpfs.error() << "): needs CAP_SYS_ADMIN";
  const fs::path config = writeReplayConfig(dir.path() / "small", "run", field_);
  const auto run = runDaemon({"replay", "--config", config.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("recording_stopped"), std::string::npos) << run.err;
  const Json summary = summaryOf(run.out_lines);
  ASSERT_FALSE(summary.is_null()) << run.err;
  EXPECT_TRUE(summary.at("recording_stopped").get<bool>());
  EXPECT_GT(summary.at("sets_recorded").get<int>(), 0);
  EXPECT_LT(summary.at("sets_recorded").get<int>(), 12);
  const auto verify = runFieldrig(
      {"session", "info", (dir.path() / "small" / "run" / "session").string(), "--verify"},
      dir.path());
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
}

TEST_F(DaemonFaults, StatusIsServedAsJsonWhileItRuns) {
  ScopedTempDir dir("daemon_status");
  const fs::path config = writeReplayConfig(dir.path(), "run", field_);
  FieldrigProcess daemon({"replay", "--config", config.string()}, dir.path(),
                         testing_support::kFieldrigdBinary);
  ASSERT_TRUE(daemon.waitForStderr("status_url", 30s)) << daemon.err();
  const int port = testing_support::statusPort(daemon.err());
  ASSERT_GT(port, 0) << daemon.err();
  ASSERT_TRUE(daemon.waitForStdoutLines(1, 60s)) << daemon.err();
  const std::string body = testing_support::httpGet(port, "/status");
  ASSERT_FALSE(body.empty());
  const Json status = Json::parse(body);
  EXPECT_EQ(status.at("mode"), "replay");
  EXPECT_GE(status.at("triggers").at("fired").get<int>(), 1);
  EXPECT_EQ(status.at("triggers").at("locations"), 12);
  EXPECT_TRUE(status.at("triggers").at("rows").contains("1"));
  EXPECT_GT(status.at("speed").at("max_speed_mps").get<double>(), 0.0);
  EXPECT_TRUE(status.at("disk").contains("free_bytes"));
  // The page's data: one state per location of the map, in the order of /map, at least one of
  // them past pending (a plot line came out); the tractor in the map's local frame.
  const std::string states = status.at("locations").at("states").get<std::string>();
  ASSERT_EQ(states.size(), 12U) << status.dump();
  EXPECT_EQ(states.find_first_not_of(".trpmi"), std::string::npos) << states;
  EXPECT_NE(states.find_first_not_of('.'), std::string::npos) << states;
  EXPECT_TRUE(status.at("gps").contains("east_m")) << status.dump();
  const Json map = Json::parse(testing_support::httpGet(port, "/map"));
  ASSERT_EQ(map.at("locations").size(), 12U);
  std::ifstream map_csv(field_ / "map.csv");
  std::string line;
  std::getline(map_csv, line);  // the header
  for (const Json& location : map.at("locations")) {
    ASSERT_TRUE(std::getline(map_csv, line));
    EXPECT_EQ(line.substr(0, line.find(',')), location.at(0).get<std::string>());
  }
  EXPECT_EQ(map.at("locations").at(0).at(2), 0.0);  // the first location is the origin
  EXPECT_NE(testing_support::httpGet(port, "/").find("<title>fieldrig"), std::string::npos);
  // The last processed set's six images as JPEG; nothing beyond them.
  EXPECT_EQ(status.at("thumbnails").at("count"), 6) << status.dump();
  for (int i = 0; i < 6; ++i) {
    const std::string jpeg =
        testing_support::httpGet(port, "/thumbnail/" + std::to_string(i) + ".jpg");
    ASSERT_GT(jpeg.size(), 100U) << i;
    EXPECT_EQ(jpeg.substr(0, 3), "\xFF\xD8\xFF") << i;
  }
  EXPECT_EQ(testing_support::httpGet(port, "/thumbnail/6.jpg"), "no such image\n");
  EXPECT_EQ(testing_support::httpGet(port, "/thumbnail/../../etc/passwd").find("root"),
            std::string::npos);
  EXPECT_EQ(testing_support::httpGet(port, "/healthz"), "ok\n");
  ASSERT_EQ(daemon.waitExit(120s), 0) << daemon.err();
}

}  // namespace
}  // namespace fieldrig
