// `fieldrig batch` without Slurm: a plan over two synthetic sessions of different lengths, its
// tasks run locally (`batch run --jobs 2`), the merge held against `fieldrig process` run serially
// on the same sessions, and bad input: a missing session, a session gone after the plan, plots
// absent from the merge. (tests/tools/batch_slurm_test.sh runs the same plan through real Slurm.)
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;
using testing_support::splitLines;
using Json = nlohmann::json;
namespace fs = std::filesystem;

class BatchCli : public ::testing::Test {
 protected:
  // Two sessions, 3 and 1 plots, rendered once for all the tests (rendering is the slow part).
  static void SetUpTestSuite() {
    sessions_ = new ScopedTempDir("batch_cli_sessions");
    for (const auto& [name, count] : {std::pair{"day-a", "3"}, std::pair{"day-b", "1"}}) {
      const auto made = runFieldrig({"sim", "plots", "--out", (root() / name).string(), "--count",
                                     count, "--seed", name == std::string("day-a") ? "3" : "4"},
                                    root());
      ASSERT_EQ(made.exit_code, 0) << made.err;
    }
  }
  static void TearDownTestSuite() {
    delete sessions_;
    sessions_ = nullptr;
  }
  static fs::path root() { return sessions_->path(); }

  static ScopedTempDir* sessions_;
};

ScopedTempDir* BatchCli::sessions_ = nullptr;

Json lastJson(const testing_support::CliRun& run) {
  return run.out_lines.empty() ? Json() : Json::parse(run.out_lines.back());
}

TEST_F(BatchCli, PlanBalancesSetsNotSessionsAndRefusesAnotherPlanInItsFolder) {
  ScopedTempDir dir("batch_cli_plan");
  const fs::path job = dir.path() / "job";
  const std::vector<std::string> plan = {"batch",
                                         "plan",
                                         (root() / "day-a").string(),
                                         (root() / "day-b").string(),
                                         "--out",
                                         job.string(),
                                         "--shards",
                                         "2"};
  const auto planned = runFieldrig(plan, dir.path());
  ASSERT_EQ(planned.exit_code, 0) << planned.err;
  const Json summary = lastJson(planned);
  EXPECT_EQ(summary.at("sets"), 4);
  // By sessions it would be 3 and 1; by sets, 2 and 2, the second crossing into day-b.
  EXPECT_EQ(summary.at("sets_per_task"), Json::parse("[2,2]"));
  const Json plan_file = Json::parse(readWholeFile(job / "plan.json"));
  EXPECT_EQ(
      plan_file.at("tasks"),
      Json::parse(R"([[{"session":0,"first":0,"count":2}],)"
                  R"([{"session":0,"first":2,"count":1},{"session":1,"first":0,"count":1}]])"));
  const std::string script = readWholeFile(job / "job.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-1"), std::string::npos) << script;
  EXPECT_NE(script.find("batch task '" + job.string() + "' \"$SLURM_ARRAY_TASK_ID\""),
            std::string::npos)
      << script;

  // A task already running (its lock held, here by this test) is not run a second time.
  fs::create_directories(job / "tasks" / "task-0");
  const int lock = ::open((job / "tasks" / "task-0" / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(lock, 0);
  ASSERT_EQ(::flock(lock, LOCK_EX), 0);
  const auto twice = runFieldrig({"batch", "task", job.string(), "0"}, dir.path());
  ::close(lock);
  EXPECT_EQ(twice.exit_code, 3);
  EXPECT_NE(twice.err.find("task 0 is already running"), std::string::npos) << twice.err;
  EXPECT_FALSE(fs::exists(job / "tasks" / "task-0" / "0-day-a" / "plots.jsonl"));

  // The same plan again is accepted (same hash); another one into the same folder is not.
  const auto again = runFieldrig(plan, dir.path());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(lastJson(again).at("parameter_hash"), summary.at("parameter_hash"));
  std::vector<std::string> other = plan;
  other.back() = "3";
  const auto refused = runFieldrig(other, dir.path());
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find((job / "plan.json").string()), std::string::npos) << refused.err;
}

TEST_F(BatchCli, LocalRunMergesToTheSerialResultAndIsIdempotent) {
  ScopedTempDir dir("batch_cli_run");
  const fs::path job = dir.path() / "job";
  const auto planned =
      runFieldrig({"batch", "plan", (root() / "day-a").string(), (root() / "day-b").string(),
                   "--out", job.string(), "--shards", "3"},
                  dir.path());
  ASSERT_EQ(planned.exit_code, 0) << planned.err;

  const auto run = runFieldrig({"batch", "run", job.string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(lastJson(run).at("summary").at("tasks_run"), 3);
  const auto status = runFieldrig({"batch", "status", job.string()}, dir.path());
  ASSERT_EQ(status.exit_code, 0) << status.err;
  const Json status_summary = lastJson(status).at("summary");
  EXPECT_EQ(status_summary.at("done"), 3);
  EXPECT_EQ(status_summary.at("sets_done"), 4);

  const auto merged = runFieldrig({"batch", "merge", job.string()}, dir.path());
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  const std::string jsonl = readWholeFile(job / "merged" / "season.jsonl");
  const std::string csv = readWholeFile(job / "merged" / "season.csv");

  // Serially, session by session: the merged lines are these with the session's name first.
  std::vector<std::string> expected;
  for (const char* name : {"day-a", "day-b"}) {
    const fs::path out = dir.path() / "serial" / name;
    const auto serial =
        runFieldrig({"process", (root() / name).string(), "--out", out.string()}, dir.path());
    ASSERT_EQ(serial.exit_code, 0) << serial.err;
    for (const std::string& line : splitLines(readWholeFile(out / "plots.jsonl")))
      expected.push_back(std::string("{\"session\":\"") + name + "\"," + line.substr(1));
  }
  std::vector<std::string> lines = splitLines(jsonl);
  ASSERT_EQ(lines.size(), 5U);
  const Json provenance = Json::parse(lines.front()).at("provenance");
  EXPECT_EQ(provenance.at("plots"), 4);
  EXPECT_TRUE(provenance.at("absent").empty());
  EXPECT_EQ(provenance.at("parameter_hash"), lastJson(planned).at("parameter_hash"));
  EXPECT_FALSE(provenance.at("calibration").empty());
  lines.erase(lines.begin());
  EXPECT_EQ(lines, expected);

  // Again: nothing is run twice, and the merge is byte for byte the same.
  const auto rerun = runFieldrig({"batch", "run", job.string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_EQ(lastJson(rerun).at("summary").at("tasks_run"), 0);
  ASSERT_EQ(runFieldrig({"batch", "merge", job.string()}, dir.path()).exit_code, 0);
  EXPECT_EQ(readWholeFile(job / "merged" / "season.jsonl"), jsonl);
  EXPECT_EQ(readWholeFile(job / "merged" / "season.csv"), csv);

  // A word where a trait's number belongs is refused, naming the plot and the field; the merged
  // files stay as they were.
  fs::path task_lines;
  for (const auto& entry : fs::recursive_directory_iterator(job / "tasks")) {
    if (entry.path().filename() == "plots.jsonl" && fs::file_size(entry.path()) > 0)
      task_lines = entry.path();
  }
  ASSERT_FALSE(task_lines.empty());
  const std::string original = readWholeFile(task_lines);
  std::ofstream(task_lines) << std::regex_replace(original, std::regex("\"height_m\":[^,]*"),
                                                  "\"height_m\":\"tall\"");
  const auto worded = runFieldrig({"batch", "merge", job.string()}, dir.path());
  EXPECT_EQ(worded.exit_code, 3);
  EXPECT_NE(worded.err.find("traits: 'height_m' is \"tall\", not a number"), std::string::npos)
      << worded.err;
  EXPECT_EQ(readWholeFile(job / "merged" / "season.jsonl"), jsonl);
}

TEST_F(BatchCli, MissingSessionsAndAbsentPlotsAreNamed) {
  ScopedTempDir dir("batch_cli_bad");
  const fs::path missing = dir.path() / "no-such-session";
  const auto refused = runFieldrig({"batch", "plan", (root() / "day-a").string(), missing.string(),
                                    "--out", (dir.path() / "refused").string()},
                                   dir.path());
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find(missing.string()), std::string::npos) << refused.err;

  // An sbatch option becomes a line of the job script: a line break would add a shell line.
  const auto injected =
      runFieldrig({"batch", "plan", (root() / "day-a").string(), "--out",
                   (dir.path() / "injected").string(), "--sbatch-option", "--time=1\nrm -rf /"},
                  dir.path());
  EXPECT_EQ(injected.exit_code, 2);
  EXPECT_NE(injected.err.find("--sbatch-option '--time=1\nrm -rf /': a control character"),
            std::string::npos)
      << injected.err;
  EXPECT_FALSE(fs::exists(dir.path() / "injected" / "job.sbatch"));
  // A plan that cannot be written whole (a full disk; here a 1 KiB file size limit) leaves no
  // job folder behind.
  const fs::path full = dir.path() / "full";
  const auto no_room = testing_support::runProgram(
      "bash",
      {"-c", "trap '' XFSZ; ulimit -f 1; exec \"$0\" \"$@\"", testing_support::kFieldrigBinary,
       "batch", "plan", (root() / "day-a").string(), (root() / "day-b").string(), "--out",
       full.string()},
      dir.path());
  EXPECT_NE(no_room.exit_code, 0);
  EXPECT_NE(no_room.err.find("File too large"), std::string::npos) << no_room.err;
  EXPECT_FALSE(fs::exists(full)) << "a half-made job folder";

  // A copy of day-b, to take away after the plan.
  const fs::path day_b = dir.path() / "day-b";
  fs::copy(root() / "day-b", day_b, fs::copy_options::recursive);
  const fs::path job = dir.path() / "job";
  ASSERT_EQ(runFieldrig({"batch", "plan", (root() / "day-a").string(), day_b.string(), "--out",
                         job.string(), "--shards", "2"},
                        dir.path())
                .exit_code,
            0);
  for (const std::string task : {"2", "-1"}) {
    const auto outside = runFieldrig({"batch", "task", job.string(), task}, dir.path());
    EXPECT_EQ(outside.exit_code, 2) << task << ": " << outside.err;
    EXPECT_TRUE(outside.out_lines.empty()) << task;
  }
  const auto two_tasks = runFieldrig({"batch", "task", job.string(), "2"}, dir.path());
  EXPECT_NE(two_tasks.err.find("task 2: the plan has 2 tasks (0 to 1)"), std::string::npos)
      << two_tasks.err;
  const auto run = runFieldrig({"batch", "run", job.string(), "--jobs", "2"}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;

  // Task 1's results for day-b lost: the merge names the plot and writes nothing.
  fs::remove_all(job / "tasks" / "task-1" / "1-day-b");
  const auto merge = runFieldrig({"batch", "merge", job.string()}, dir.path());
  EXPECT_EQ(merge.exit_code, 3);
  EXPECT_NE(merge.err.find("absent: " + day_b.string() + " plot plot-1"), std::string::npos)
      << merge.err;
  EXPECT_FALSE(fs::exists(job / "merged" / "season.jsonl"));
  // Asked for, the shorter table is written with the absent plot in its provenance.
  const auto partial = runFieldrig({"batch", "merge", job.string(), "--allow-absent"}, dir.path());
  ASSERT_EQ(partial.exit_code, 0) << partial.err;
  const std::vector<std::string> lines = splitLines(readWholeFile(job / "merged" / "season.jsonl"));
  ASSERT_EQ(lines.size(), 4U);
  const Json absent = Json::parse(lines.front()).at("provenance").at("absent");
  ASSERT_EQ(absent.size(), 1U);
  EXPECT_EQ(absent[0].at("session"), day_b.string());
  EXPECT_EQ(absent[0].at("plot"), "plot-1");

  // The session itself gone: status reports it by path, and the task is not done.
  fs::rename(day_b, dir.path() / "moved");
  const auto status = runFieldrig({"batch", "status", job.string()}, dir.path());
  EXPECT_EQ(status.exit_code, 3);
  ASSERT_FALSE(status.out_lines.empty());
  const Json problem = Json::parse(status.out_lines.front());
  EXPECT_EQ(problem.at("session"), day_b.string());
  EXPECT_NE(problem.at("problem").get<std::string>().find("session missing"), std::string::npos);
  const auto rerun = runFieldrig({"batch", "run", job.string()}, dir.path());
  EXPECT_EQ(rerun.exit_code, 2);
  EXPECT_NE(rerun.err.find(day_b.string()), std::string::npos) << rerun.err;
}

}  // namespace
}  // namespace fieldrig
