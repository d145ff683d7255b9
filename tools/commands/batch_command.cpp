// `fieldrig batch plan|submit|status|merge|run|task`: a season of recorded sessions reprocessed as
// a Slurm array job, or locally with the same plan (daemon/batch_job.h holds the plan, the tasks,
// the progress on disk and the merge; this file runs sbatch, squeue, sacct and child processes).
//   plan SESSIONS... --out JOBDIR [--calib DIR] [--traits-config F] [--shards N] [--sbatch-option
//   O] submit JOBDIR          sbatch --array with the tasks neither done nor queued; job id
//   recorded status JOBDIR          per task: done, running, pending, failed, not_started (squeue,
//   sacct
//                          when accounting is on, and the results on disk); bad sessions by path
//   merge JOBDIR [--allow-absent]   one table per season; absent plots are named, and refused
//   run JOBDIR [--jobs N]  the tasks not done, N at a time, as child processes (no Slurm)
//   task JOBDIR K          one task (what the array script runs)
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "commands/command_helpers.h"
#include "fieldrig/core/durable_file.h"
#include "fieldrig/daemon/batch_job.h"

extern char** environ;

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct BatchArgs {
  std::vector<std::string> sessions;
  std::string out, calib, traits_config, job_dir;
  std::vector<std::string> sbatch_options;
  std::size_t shards = 1;
  std::size_t jobs = 1;
  std::size_t task = 0;
  bool allow_absent = false;
};

fs::path selfExecutable() {
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path("fieldrig") : self;
}

struct CommandOutput {
  int exit_code = -1;
  std::string out;
};

// Runs a shell command line (arguments already quoted), capturing stdout; stderr is discarded
// when `quiet` (sacct without accounting says so on every call).
CommandOutput capture(const std::string& command, bool quiet) {
  CommandOutput result;
  const std::string line = command + (quiet ? " 2>/dev/null" : "");
  FILE* pipe = ::popen(line.c_str(), "r");
  if (!pipe)
    return result;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    result.out.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string shellQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text)
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct Submission {
  std::string job_id;
  std::set<std::size_t> tasks;
};

std::vector<Submission> readSubmissions(const fs::path& job_dir) {
  std::vector<Submission> submissions;
  std::string error;
  const auto content = core::readWholeFile(daemon::batchSubmissionsFile(job_dir), error);
  if (!content)
    return submissions;
  std::istringstream in(*content);
  for (std::string text; std::getline(in, text);) {
    const Json line = Json::parse(text, nullptr, false);
    if (!line.is_object() || !line.contains("job_id") || !line.contains("tasks"))
      continue;
    Submission submission;
    submission.job_id = line["job_id"].get<std::string>();
    for (const Json& task : line["tasks"])
      submission.tasks.insert(task.get<std::size_t>());
    submissions.push_back(std::move(submission));
  }
  return submissions;
}

// What Slurm says of the job folder's array tasks: the newest submission's state per task.
struct SchedulerView {
  std::map<std::size_t, std::string> active;  // task → PENDING, RUNNING…
  std::map<std::size_t, std::string> ended;   // task → sacct's final state (with accounting)
  std::string source;                         // "squeue", "squeue+sacct", "none"
  bool queue_known = false;                   // squeue answered (or nothing was submitted)
};

SchedulerView querySlurm(const std::vector<Submission>& submissions) {
  SchedulerView view;
  view.source = "none";
  view.queue_known = submissions.empty();
  if (submissions.empty())
    return view;
  std::set<std::string> ours;
  std::string ids;
  for (const Submission& submission : submissions) {
    ours.insert(submission.job_id);
    ids += (ids.empty() ? "" : ",") + submission.job_id;
  }
  // Newest job that holds each task wins: a resubmission replaces the killed task.
  std::map<std::string, std::size_t> job_order;
  for (std::size_t i = 0; i < submissions.size(); ++i)
    job_order[submissions[i].job_id] = i;
  const CommandOutput queue = capture("squeue -h -r -o '%i %T'", true);
  if (queue.exit_code == 0) {
    view.source = "squeue";
    view.queue_known = true;
    for (const daemon::SchedulerTaskState& state : daemon::parseSlurmTaskStates(queue.out)) {
      if (ours.count(state.job_id) && daemon::slurmStateActive(state.state))
        view.active[state.task] = state.state;
    }
  }
  const CommandOutput accounting =
      capture("sacct -n -P -X -o JobID,State -j " + shellQuoted(ids), true);
  if (accounting.exit_code == 0 && !accounting.out.empty()) {
    view.source += "+sacct";
    std::map<std::size_t, std::size_t> newest;
    for (const daemon::SchedulerTaskState& state : daemon::parseSlurmTaskStates(accounting.out)) {
      if (!job_order.count(state.job_id) || daemon::slurmStateActive(state.state))
        continue;
      const std::size_t order = job_order[state.job_id];
      if (!newest.count(state.task) || newest[state.task] <= order) {
        newest[state.task] = order;
        view.ended[state.task] = state.state;
      }
    }
  }
  return view;
}

core::Result<daemon::BatchPlan> readPlanOrSay(const std::string& job_dir) {
  return daemon::readBatchPlan(job_dir);
}

int runPlan(const BatchArgs& args) {
  const char* who = "fieldrig batch plan: ";
  daemon::BatchPlanRequest request;
  request.sessions = args.sessions;
  request.calib = args.calib;
  request.traits_config = args.traits_config;
  request.shards = args.shards;
  request.fieldrig_binary = selfExecutable();
  request.sbatch_options = args.sbatch_options;
  auto plan = daemon::makeBatchPlan(request);
  if (!plan)
    return fail(who, plan.error().message);
  const fs::path job_dir = fs::absolute(args.out).lexically_normal();
  if (auto written = daemon::writeBatchJob(*plan, job_dir); !written)
    return fail(who, written.error().message);
  Json tasks = Json::array();
  for (std::size_t task = 0; task < plan->tasks.size(); ++task)
    tasks.push_back(plan->taskSets(task));
  return printJsonLine({{"job_dir", job_dir.string()},
                        {"sessions", plan->sessions.size()},
                        {"sets", plan->totalSets()},
                        {"tasks", plan->tasks.size()},
                        {"sets_per_task", tasks},
                        {"parameter_hash", plan->parameter_hash},
                        {"sbatch", (job_dir / "job.sbatch").string()}});
}

// The tasks that still have sets to process.
std::vector<std::size_t> unfinishedTasks(const daemon::BatchPlan& plan, const fs::path& job_dir) {
  std::vector<std::size_t> tasks;
  for (std::size_t task = 0; task < plan.tasks.size(); ++task) {
    if (daemon::batchTaskSetsDone(plan, job_dir, task) < plan.taskSets(task))
      tasks.push_back(task);
  }
  return tasks;
}

// A planned session that is missing or damaged, named by path on stderr; true when all are fine.
bool sessionsUsable(const daemon::BatchPlan& plan, const char* who) {
  bool usable = true;
  for (const daemon::BatchSession& session : plan.sessions) {
    if (std::string problem = daemon::checkBatchSession(session); !problem.empty()) {
      std::cerr << who << problem << '\n';
      usable = false;
    }
  }
  return usable;
}

int runSubmit(const BatchArgs& args) {
  const char* who = "fieldrig batch submit: ";
  auto plan = readPlanOrSay(args.job_dir);
  if (!plan)
    return fail(who, plan.error().message);
  const fs::path job_dir = fs::absolute(args.job_dir).lexically_normal();
  if (!sessionsUsable(*plan, who))
    return kExitBadInput;
  // A task still queued or running is not submitted again: two copies would write one folder.
  const SchedulerView view = querySlurm(readSubmissions(job_dir));
  if (!view.queue_known) {
    return fail(who,
                "squeue did not answer: cannot tell which tasks still run, so none is "
                "submitted again",
                kExitRuntime);
  }
  std::vector<std::size_t> tasks;
  for (std::size_t task : unfinishedTasks(*plan, job_dir)) {
    if (!view.active.count(task))
      tasks.push_back(task);
  }
  if (tasks.empty()) {
    return printJsonLine(
        {{"submitted", false},
         {"reason", view.active.empty() ? "every task is done" : "the unfinished tasks are queued"},
         {"active_tasks", view.active.size()}});
  }
  std::string array;
  for (std::size_t task : tasks)
    array += (array.empty() ? "" : ",") + std::to_string(task);
  const CommandOutput sbatch = capture(
      "sbatch --parsable --array=" + array + " " + shellQuoted((job_dir / "job.sbatch").string()),
      false);
  std::string job_id = sbatch.out.substr(0, sbatch.out.find_first_of(";\n"));
  if (sbatch.exit_code != 0 || job_id.empty() ||
      job_id.find_first_not_of("0123456789") != std::string::npos) {
    return fail(who, "sbatch failed (exit " + std::to_string(sbatch.exit_code) + "): " + sbatch.out,
                kExitRuntime);
  }
  const Json line = {{"job_id", job_id}, {"tasks", tasks}};
  if (std::string failed =
          core::appendDurably(daemon::batchSubmissionsFile(job_dir), line.dump() + "\n");
      !failed.empty()) {
    return fail(who, failed + " (job " + job_id + " is submitted)", kExitRuntime);
  }
  return printJsonLine({{"submitted", true}, {"job_id", job_id}, {"tasks", tasks}});
}

int runStatus(const BatchArgs& args) {
  const char* who = "fieldrig batch status: ";
  auto plan = readPlanOrSay(args.job_dir);
  if (!plan)
    return fail(who, plan.error().message);
  const fs::path job_dir = fs::absolute(args.job_dir).lexically_normal();
  std::size_t session_problems = 0;
  for (const daemon::BatchSession& session : plan->sessions) {
    if (std::string problem = daemon::checkBatchSession(session); !problem.empty()) {
      printJsonLine({{"session", session.path.string()}, {"problem", problem}});
      ++session_problems;
    }
  }
  const std::vector<Submission> submissions = readSubmissions(job_dir);
  const SchedulerView view = querySlurm(submissions);
  std::map<std::string, std::size_t> counts;
  std::size_t sets_done = 0;
  Json job_ids = Json::array();
  for (const Submission& submission : submissions)
    job_ids.push_back(submission.job_id);
  for (std::size_t task = 0; task < plan->tasks.size(); ++task) {
    const std::size_t sets = plan->taskSets(task);
    const std::size_t done = daemon::batchTaskSetsDone(*plan, job_dir, task);
    sets_done += done;
    bool submitted = false;
    for (const Submission& submission : submissions)
      submitted = submitted || submission.tasks.count(task) > 0;
    Json line = {{"task", task}, {"sets", sets}, {"done", done}};
    std::string state;
    if (done == sets) {
      state = "done";
    } else if (const auto active = view.active.find(task); active != view.active.end()) {
      state = active->second == "PENDING" ? "pending" : "running";
      line["slurm_state"] = active->second;
    } else if (submitted) {
      // Ended (cancelled, failed, timed out, node lost, or finished with sets missing).
      state = "failed";
      if (const auto ended = view.ended.find(task); ended != view.ended.end())
        line["slurm_state"] = ended->second;
      line["log"] =
          (daemon::batchLogsDir(job_dir) / ("task-" + std::to_string(task) + ".out")).string();
    } else {
      state = done > 0 ? "incomplete" : "not_started";
    }
    line["state"] = state;
    ++counts[state];
    printJsonLine(line);
  }
  Json summary = {{"tasks", plan->tasks.size()}, {"sets", plan->totalSets()},
                  {"sets_done", sets_done},      {"scheduler", view.source},
                  {"job_ids", job_ids},          {"session_problems", session_problems}};
  for (const char* state : {"done", "running", "pending", "failed", "incomplete", "not_started"})
    summary[state] = counts[state];
  printJsonLine({{"summary", summary}});
  return session_problems > 0 || counts["failed"] > 0 ? kExitRuntime : kExitOk;
}

int runMerge(const BatchArgs& args) {
  const char* who = "fieldrig batch merge: ";
  auto plan = readPlanOrSay(args.job_dir);
  if (!plan)
    return fail(who, plan.error().message);
  const fs::path job_dir = fs::absolute(args.job_dir).lexically_normal();
  auto merge = daemon::mergeBatch(*plan, job_dir);
  if (!merge)
    return fail(who, merge.error().message, kExitRuntime);
  for (const daemon::AbsentPlot& plot : merge->absent) {
    std::cerr << who << "absent: " << plot.session << " plot " << plot.plot << " (trigger id "
              << plot.trigger_id << ", task " << plot.task << ")\n";
  }
  Json summary = {{"plots", merge->plots},
                  {"plots_planned", plan->totalSets()},
                  {"absent", merge->absent.size()},
                  {"parameter_hash", plan->parameter_hash}};
  if (!merge->absent.empty() && !args.allow_absent) {
    std::cerr << who << merge->absent.size() << " of " << plan->totalSets()
              << " plots are absent; nothing written (run the unfinished tasks, or give "
                 "--allow-absent to write the table with the absent plots listed in its "
                 "provenance)\n";
    summary["written"] = false;
    printJsonLine({{"summary", summary}});
    return kExitRuntime;
  }
  if (auto written = daemon::writeBatchMerge(*merge, job_dir); !written)
    return fail(who, written.error().message, kExitRuntime);
  const fs::path merged = job_dir / "merged";
  summary["written"] = true;
  summary["jsonl"] = (merged / "season.jsonl").string();
  summary["csv"] = (merged / "season.csv").string();
  summary["geojson"] = (merged / "season.geojson").string();
  summary["provenance"] = (merged / "provenance.json").string();
  return printJsonLine({{"summary", summary}});
}

// Starts `fieldrig batch task JOBDIR K` with stdout and stderr appended to `log`; the pid or -1.
pid_t spawnTask(const fs::path& job_dir, std::size_t task, const fs::path& log) {
  const std::string self = selfExecutable().string();
  const std::string dir = job_dir.string();
  const std::string index = std::to_string(task);
  std::vector<char*> argv = {const_cast<char*>(self.c_str()),  const_cast<char*>("batch"),
                             const_cast<char*>("task"),        const_cast<char*>(dir.c_str()),
                             const_cast<char*>(index.c_str()), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int failed = posix_spawn(&pid, self.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return failed == 0 ? pid : -1;
}

int runLocal(const BatchArgs& args) {
  const char* who = "fieldrig batch run: ";
  auto plan = readPlanOrSay(args.job_dir);
  if (!plan)
    return fail(who, plan.error().message);
  const fs::path job_dir = fs::absolute(args.job_dir).lexically_normal();
  if (!sessionsUsable(*plan, who))
    return kExitBadInput;
  const std::vector<std::size_t> tasks = unfinishedTasks(*plan, job_dir);
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, failed = 0;
  const auto logOf = [&job_dir](std::size_t task) {
    return daemon::batchLogsDir(job_dir) / ("task-" + std::to_string(task) + ".local.log");
  };
  while (next < tasks.size() || !running.empty()) {
    while (next < tasks.size() && running.size() < args.jobs) {
      const std::size_t task = tasks[next++];
      const pid_t pid = spawnTask(job_dir, task, logOf(task));
      if (pid < 0) {
        printJsonLine({{"task", task}, {"started", false}});
        ++failed;
        continue;
      }
      running[pid] = task;
    }
    if (running.empty())
      break;
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0)
      break;
    const auto found = running.find(pid);
    if (found == running.end())
      continue;
    const std::size_t task = found->second;
    running.erase(found);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    failed += code == 0 ? 0 : 1;
    printJsonLine({{"task", task}, {"exit", code}, {"log", logOf(task).string()}});
  }
  printJsonLine({{"summary",
                  {{"tasks_run", tasks.size()},
                   {"failed", failed},
                   {"tasks_already_done", plan->tasks.size() - tasks.size()}}}});
  return failed > 0 ? kExitRuntime : kExitOk;
}

int runTask(const BatchArgs& args) {
  const char* who = "fieldrig batch task: ";
  auto plan = readPlanOrSay(args.job_dir);
  if (!plan)
    return fail(who, plan.error().message);
  if (args.task >= plan->tasks.size()) {
    return fail(
        who, "task " + std::to_string(args.task) + ": the plan has " +
                 std::to_string(plan->tasks.size()) + " tasks" +
                 (plan->tasks.empty() ? std::string()
                                      : " (0 to " + std::to_string(plan->tasks.size() - 1) + ")"));
  }
  const fs::path job_dir = fs::absolute(args.job_dir).lexically_normal();
  auto done = daemon::runBatchTask(*plan, job_dir, args.task,
                                   [](const Json& line) { std::cout << line.dump() << std::endl; });
  if (!done)
    return fail(who, "task " + std::to_string(args.task) + ": " + done.error().message,
                kExitRuntime);
  return printJsonLine({{"summary",
                         {{"task", args.task},
                          {"sets", done->sets},
                          {"already_done", done->already_done},
                          {"load_s", done->load_seconds},
                          {"process_s", done->process_seconds}}}});
}

void addJobDir(CLI::App* app, BatchArgs& args) {
  app->add_option("jobdir", args.job_dir, "Job folder written by `fieldrig batch plan`")
      ->required();
}

}  // namespace

void registerBatchCommand(CLI::App& app, int& exit_code) {
  CLI::App* batch = addCommandGroup(
      app, "batch",
      "Many sessions reprocessed as a Slurm array job (or locally), resumable, merged per season");

  const auto [plan, plan_args] = addSubcommand(
      *batch, "plan", "Write a job folder: sessions, sets, parameters and the sbatch script",
      exit_code, runPlan);
  plan->add_option("sessions", plan_args->sessions, "Session folders")->required();
  plan->add_option("--out", plan_args->out, "Job folder")->required();
  plan->add_option("--calib", plan_args->calib,
                   "Calibration folder for every session (default: each session's own)");
  plan->add_option("--traits-config", plan_args->traits_config,
                   "Traits options (YAML or JSON: the keys of pipeline.traits)");
  plan->add_option("--shards", plan_args->shards, "Number of tasks (array size)")
      ->capture_default_str()
      ->check(finiteRange<std::size_t>(1, 100000));
  plan->add_option("--sbatch-option", plan_args->sbatch_options,
                   "An extra #SBATCH line for the script, e.g. --time=02:00:00 (repeatable)");

  const auto [submit, submit_args] = addSubcommand(
      *batch, "submit", "sbatch the tasks neither done nor queued; the job id is recorded",
      exit_code, runSubmit);
  addJobDir(submit, *submit_args);

  const auto [status, status_args] = addSubcommand(
      *batch, "status", "Each task done, running, pending or failed; missing or damaged sessions",
      exit_code, runStatus);
  addJobDir(status, *status_args);

  const auto [merge, merge_args] = addSubcommand(
      *batch, "merge", "Join the tasks' results into JOBDIR/merged/season.{jsonl,csv,geojson}",
      exit_code, runMerge);
  addJobDir(merge, *merge_args);
  merge->add_flag("--allow-absent", merge_args->allow_absent,
                  "Write the table even when plots are absent (they are listed in its provenance)");

  const auto [run, run_args] =
      addSubcommand(*batch, "run", "Run the unfinished tasks locally, N at a time (no Slurm)",
                    exit_code, runLocal);
  addJobDir(run, *run_args);
  run->add_option("--jobs", run_args->jobs, "Tasks run at once")
      ->capture_default_str()
      ->check(finiteRange<std::size_t>(1, 1024));

  const auto [task, task_args] = addSubcommand(
      *batch, "task", "Run one task of the plan (what each array task runs)", exit_code, runTask);
  addJobDir(task, *task_args);
  task->add_option("task", task_args->task, "Task index, 0 <= K < shards")
      ->required()
      ->check(CLI::NonNegativeNumber);
}

}  // namespace fieldrig::tools
