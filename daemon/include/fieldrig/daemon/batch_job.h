// A season reprocessed as a batch job (`fieldrig batch`): a plan that cuts the sets of many
// recorded sessions into tasks of equal work, the job folder that holds it, one task's run, the
// progress found on disk, and the merge of every task's results into one table per season.
//
// The job folder:
//   plan.json             sessions (absolute paths, set counts, trigger ids, plots), parameters,
//                         their hash, and each task's pieces (a session and a range of its sets)
//   job.sbatch            the Slurm array script: task K runs `fieldrig batch task JOBDIR K`
//   tasks/task-K/S-NAME/  task K's results for session S (plots.jsonl, .csv, .geojson): no two
//                         tasks share a folder, so no two tasks write the same file
//   submissions.jsonl     one line per `batch submit` (job id, tasks)
//   logs/                 the tasks' stdout and stderr
//   merged/season.{jsonl,csv,geojson}, merged/provenance.json
//
// A task resumes: the sets its folders already hold are skipped (daemon::processSession), so a
// task killed mid-way and run again finishes the rest. The merge orders plots by the plan (session,
// then set), never by the order tasks ran in: the same plan gives byte-identical merged files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::daemon {

struct BatchSession {
  std::filesystem::path path;              // absolute
  std::string name;                        // the folder's name; unique within a plan
  std::vector<std::uint64_t> trigger_ids;  // by position in the index
  std::vector<std::string> plots;          // plot id of each position (as the results name it)
  std::filesystem::path calibration_dir;   // absolute
};

// A contiguous run of one session's sets: positions [first, first + count).
struct BatchPiece {
  std::size_t session = 0;
  std::size_t first = 0;
  std::size_t count = 0;
};

struct CalibrationFile {
  std::string path;  // absolute
  std::string sha256;
};

struct BatchPlan {
  std::string software_version;
  std::filesystem::path fieldrig_binary;  // what the sbatch script runs
  std::string calib;          // --calib as given (absolute), or empty: each session's own
  std::string traits_config;  // absolute, or empty
  std::string traits_config_sha256;
  std::vector<CalibrationFile> calibration;  // every file of every calibration folder used
  std::string parameter_hash;                // SHA-256 of version, traits options, calibration
  std::vector<std::string> sbatch_options;   // extra `#SBATCH` lines (--time=…, --partition=…)
  std::vector<BatchSession> sessions;
  std::vector<std::vector<BatchPiece>> tasks;

  std::size_t totalSets() const;
  std::size_t taskSets(std::size_t task) const;
};

struct BatchPlanRequest {
  std::vector<std::string> sessions;
  std::string calib;
  std::string traits_config;
  std::size_t shards = 1;
  std::filesystem::path fieldrig_binary;
  std::vector<std::string> sbatch_options;
};

// Reads every session's index and calibration; the error names the session, file or option.
// The sets of all sessions, in order, are cut into `shards` contiguous runs whose sizes differ
// by at most one; a run crossing a session's end becomes two pieces.
core::Result<BatchPlan> makeBatchPlan(const BatchPlanRequest& request);

nlohmann::ordered_json batchPlanToJson(const BatchPlan& plan);
core::Result<BatchPlan> batchPlanFromJson(const nlohmann::ordered_json& json,
                                          const std::string& source);

std::filesystem::path batchPlanFile(const std::filesystem::path& job_dir);
std::filesystem::path batchPieceDir(const std::filesystem::path& job_dir, const BatchPlan& plan,
                                    std::size_t task, const BatchPiece& piece);
std::filesystem::path batchLogsDir(const std::filesystem::path& job_dir);
std::filesystem::path batchSubmissionsFile(const std::filesystem::path& job_dir);

// The Slurm array script of the plan (array 0..N-1, one CPU per task, logs in JOBDIR/logs).
std::string batchSbatchScript(const BatchPlan& plan, const std::filesystem::path& job_dir);

// Writes plan.json and job.sbatch (atomic replacements) and the folders. Refuses a folder that
// holds another plan's results (a different parameter hash or sets), naming it.
core::Result<void> writeBatchJob(const BatchPlan& plan, const std::filesystem::path& job_dir);
core::Result<BatchPlan> readBatchPlan(const std::filesystem::path& job_dir);

struct BatchTaskSummary {
  std::size_t sets = 0;          // processed by this run
  std::size_t already_done = 0;  // skipped: written by an earlier run of the task
  double load_seconds = 0.0;     // opening sessions, calibration, processors
  double process_seconds = 0.0;
};

// Runs task `task`: each piece through the plot processor into its folder, resuming.
// `on_line` sees each plot's result line. The error names the session or file that failed.
core::Result<BatchTaskSummary> runBatchTask(
    const BatchPlan& plan, const std::filesystem::path& job_dir, std::size_t task,
    const std::function<void(const nlohmann::ordered_json&)>& on_line);

// The sets of a task found in its folders (by trigger id; a torn or foreign line counts nothing).
std::size_t batchTaskSetsDone(const BatchPlan& plan, const std::filesystem::path& job_dir,
                              std::size_t task);

// What is wrong with a planned session now (missing, unreadable, its index changed since the
// plan), naming its path; empty when it is fine.
std::string checkBatchSession(const BatchSession& session);

struct AbsentPlot {
  std::string session;  // path
  std::string plot;
  std::uint64_t trigger_id = 0;
  std::size_t task = 0;
};

struct BatchMerge {
  nlohmann::ordered_json provenance;
  std::string jsonl, csv, geojson;
  std::vector<AbsentPlot> absent;
  std::size_t plots = 0;
};

// Joins the tasks' results in plan order. Each merged line is the session's result line with
// the session's name first; the provenance (software version, parameter hash, calibration
// checksums, sessions, and the absent plots) heads each file. The error names a results file
// that cannot be read.
core::Result<BatchMerge> mergeBatch(const BatchPlan& plan, const std::filesystem::path& job_dir);

// Writes the merge into JOBDIR/merged (atomic replacements).
core::Result<void> writeBatchMerge(const BatchMerge& merge, const std::filesystem::path& job_dir);

// The state Slurm reports for the tasks of array jobs, from `squeue -h -r -o '%i %T'` or
// `sacct -n -P -X -o JobID,State` output: "JOB_TASK STATE" (or "|"-separated) per line; lines of
// other jobs, and pending ranges such as "123_[2-3]", are expanded or skipped as they say.
struct SchedulerTaskState {
  std::string job_id;
  std::size_t task = 0;
  std::string state;  // RUNNING, PENDING, CANCELLED, FAILED, COMPLETED…
};
std::vector<SchedulerTaskState> parseSlurmTaskStates(const std::string& text);
// Whether a Slurm state means the task may still write (pending, running, completing…).
bool slurmStateActive(const std::string& state);

}  // namespace fieldrig::daemon
