#include "fieldrig/daemon/batch_job.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "fieldrig/config/config.h"
#include "fieldrig/core/durable_file.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/daemon/session_processing.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/recording/checksum.h"
#include "fieldrig/recording/session_format.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/traits/plot_report.h"

namespace fieldrig::daemon {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using recording::sha256Hex;

std::string plotIdOf(const recording::IndexedSet& set) {
  return set.location_id.value_or("set-" + std::to_string(set.set_index));
}

fs::path absoluteClean(const fs::path& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  return (ec ? path : absolute).lexically_normal();
}

// Every regular file below a calibration folder, sorted, with its SHA-256.
core::Result<std::vector<CalibrationFile>> checksumFolder(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file())
      files.push_back(it->path());
  }
  if (ec)
    return core::Error{dir.string() + ": cannot list the calibration folder: " + ec.message()};
  std::sort(files.begin(), files.end());
  std::vector<CalibrationFile> sums;
  for (const fs::path& file : files) {
    std::string error;
    const std::optional<std::string> content = core::readWholeFile(file, error);
    if (!content)
      return core::Error{error};
    sums.push_back({file.string(), sha256Hex(*content)});
  }
  return sums;
}

std::string taskDirName(std::size_t task) {
  return "task-" + std::to_string(task);
}

// The trigger ids held by a results folder's plots.jsonl; lines that do not parse count nothing
// (the task's own resume reports them when it runs).
std::set<std::uint64_t> triggerIdsIn(const fs::path& dir) {
  std::set<std::uint64_t> ids;
  std::string error;
  const std::optional<std::string> content = core::readWholeFile(resultsFiles(dir).jsonl, error);
  if (!content)
    return ids;
  std::istringstream in(*content);
  for (std::string text; std::getline(in, text);) {
    if (in.eof())
      break;  // a torn last line
    const Json line = Json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (line.is_object() && line.contains("trigger_id") && line["trigger_id"].is_number_unsigned())
      ids.insert(line["trigger_id"].get<std::uint64_t>());
  }
  return ids;
}

std::string csvQuoted(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos)
    return text;
  std::string quoted = "\"";
  for (char c : text)
    quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

std::size_t BatchPlan::totalSets() const {
  std::size_t total = 0;
  for (const BatchSession& session : sessions)
    total += session.trigger_ids.size();
  return total;
}

std::size_t BatchPlan::taskSets(std::size_t task) const {
  std::size_t total = 0;
  for (const BatchPiece& piece : tasks.at(task))
    total += piece.count;
  return total;
}

namespace {

// An sbatch option becomes one "#SBATCH" line of the job script: a line break in it would start
// a shell line of its own there, run by every task.
std::optional<std::string> sbatchOptionProblem(const std::vector<std::string>& options) {
  for (const std::string& option : options) {
    for (const char c : option) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        return "--sbatch-option '" + option +
               "': a control character (a line break would start a line of its own in the job "
               "script)";
      }
    }
  }
  return std::nullopt;
}

}  // namespace

core::Result<BatchPlan> makeBatchPlan(const BatchPlanRequest& request) {
  if (request.sessions.empty())
    return core::Error{"no sessions given"};
  if (auto problem = sbatchOptionProblem(request.sbatch_options))
    return core::Error{std::move(*problem)};
  if (request.shards == 0)
    return core::Error{"--shards must be at least 1"};
  BatchPlan plan;
  plan.software_version = std::string(recording::softwareVersion());
  plan.fieldrig_binary = request.fieldrig_binary;
  plan.sbatch_options = request.sbatch_options;
  if (!request.calib.empty())
    plan.calib = absoluteClean(request.calib).string();
  Json parameters;
  parameters["software_version"] = plan.software_version;
  if (!request.traits_config.empty()) {
    plan.traits_config = absoluteClean(request.traits_config).string();
    auto loaded = config::loadTraitsOptions(plan.traits_config);
    if (!loaded)
      return core::Error{loaded.error().message};
    std::string error;
    const std::optional<std::string> content = core::readWholeFile(plan.traits_config, error);
    if (!content)
      return core::Error{error};
    plan.traits_config_sha256 = sha256Hex(*content);
  }
  parameters["traits_config_sha256"] = plan.traits_config_sha256;

  std::set<std::string> calibration_dirs;
  std::map<std::string, std::string> names;  // name → path, to refuse two sessions of one name
  for (const std::string& given : request.sessions) {
    const fs::path path = absoluteClean(given);
    auto opened = recording::SessionReader::open(path);
    if (!opened)
      return core::Error{"session " + given + ": " + opened.error().message};
    BatchSession session;
    session.path = path;
    session.name = path.filename().string();
    if (auto [at, inserted] = names.emplace(session.name, path.string()); !inserted) {
      return core::Error{"sessions " + at->second + " and " + path.string() +
                         " have the same folder name, which names their plots in the merge"};
    }
    for (const recording::IndexedSet& set : opened->sets()) {
      session.trigger_ids.push_back(set.trigger_id);
      session.plots.push_back(plotIdOf(set));
    }
    const std::optional<fs::path> calib = sessionCalibrationDir(plan.calib, *opened);
    if (!calib)
      return core::Error{"session " + given + ": no calibration: give --calib DIR"};
    session.calibration_dir = absoluteClean(*calib);
    if (auto rig = loadRigFor(plan.calib, &*opened); !rig)
      return core::Error{"session " + given + ": " + rig.error().message};
    calibration_dirs.insert(session.calibration_dir.string());
    plan.sessions.push_back(std::move(session));
  }
  for (const std::string& dir : calibration_dirs) {
    auto sums = checksumFolder(dir);
    if (!sums)
      return core::Error{sums.error().message};
    plan.calibration.insert(plan.calibration.end(), sums->begin(), sums->end());
  }
  // The hash is of what decides the traits, not of where the files are: content checksums only.
  Json calibration = Json::array();
  for (const CalibrationFile& file : plan.calibration)
    calibration.push_back(file.sha256);
  parameters["calibration_sha256"] = std::move(calibration);
  parameters["calib_per_session"] = plan.calib.empty();
  plan.parameter_hash = sha256Hex(parameters.dump());

  // Contiguous runs of equal work over all sets in order: task k takes global positions
  // [k·S/N, (k+1)·S/N).
  const std::size_t total = plan.totalSets();
  plan.tasks.resize(request.shards);
  std::size_t session = 0;
  std::size_t offset = 0;  // global position of the session's first set
  for (std::size_t task = 0; task < request.shards; ++task) {
    const std::size_t begin = task * total / request.shards;
    const std::size_t end = (task + 1) * total / request.shards;
    std::size_t at = begin;
    while (at < end) {
      while (at >= offset + plan.sessions[session].trigger_ids.size()) {
        offset += plan.sessions[session].trigger_ids.size();
        ++session;
      }
      const std::size_t session_end = offset + plan.sessions[session].trigger_ids.size();
      const std::size_t stop = std::min(end, session_end);
      plan.tasks[task].push_back({session, at - offset, stop - at});
      at = stop;
    }
  }
  return plan;
}

nlohmann::ordered_json batchPlanToJson(const BatchPlan& plan) {
  Json json;
  json["format"] = "fieldrig-batch-plan";
  json["format_version"] = 1;
  json["software_version"] = plan.software_version;
  json["fieldrig_binary"] = plan.fieldrig_binary.string();
  json["parameter_hash"] = plan.parameter_hash;
  json["calib"] = plan.calib;
  json["traits_config"] = plan.traits_config;
  json["traits_config_sha256"] = plan.traits_config_sha256;
  Json calibration = Json::array();
  for (const CalibrationFile& file : plan.calibration)
    calibration.push_back({{"path", file.path}, {"sha256", file.sha256}});
  json["calibration"] = std::move(calibration);
  json["sbatch_options"] = plan.sbatch_options;
  Json sessions = Json::array();
  for (const BatchSession& session : plan.sessions) {
    sessions.push_back({{"path", session.path.string()},
                        {"name", session.name},
                        {"calibration_dir", session.calibration_dir.string()},
                        {"sets", session.trigger_ids.size()},
                        {"trigger_ids", session.trigger_ids},
                        {"plots", session.plots}});
  }
  json["sessions"] = std::move(sessions);
  Json tasks = Json::array();
  for (const std::vector<BatchPiece>& pieces : plan.tasks) {
    Json task = Json::array();
    for (const BatchPiece& piece : pieces)
      task.push_back({{"session", piece.session}, {"first", piece.first}, {"count", piece.count}});
    tasks.push_back(std::move(task));
  }
  json["tasks"] = std::move(tasks);
  return json;
}

core::Result<BatchPlan> batchPlanFromJson(const nlohmann::ordered_json& json,
                                          const std::string& source) {
  BatchPlan plan;
  try {
    if (json.at("format").get<std::string>() != "fieldrig-batch-plan")
      return core::Error{source + ": not a fieldrig batch plan"};
    // A plan of a later format may mean fields this version would read wrongly or not at all.
    if (const Json& version = json.at("format_version"); version != 1) {
      return core::Error{source + ": format_version " + version.dump() +
                         ", but this fieldrig reads plans of format 1"};
    }
    plan.software_version = json.at("software_version").get<std::string>();
    plan.fieldrig_binary = json.at("fieldrig_binary").get<std::string>();
    plan.parameter_hash = json.at("parameter_hash").get<std::string>();
    plan.calib = json.at("calib").get<std::string>();
    plan.traits_config = json.at("traits_config").get<std::string>();
    plan.traits_config_sha256 = json.at("traits_config_sha256").get<std::string>();
    for (const Json& file : json.at("calibration"))
      plan.calibration.push_back(
          {file.at("path").get<std::string>(), file.at("sha256").get<std::string>()});
    plan.sbatch_options = json.at("sbatch_options").get<std::vector<std::string>>();
    if (auto problem = sbatchOptionProblem(plan.sbatch_options))
      return core::Error{source + ": " + *problem};
    for (const Json& in : json.at("sessions")) {
      BatchSession session;
      session.path = in.at("path").get<std::string>();
      session.name = in.at("name").get<std::string>();
      session.calibration_dir = in.at("calibration_dir").get<std::string>();
      session.trigger_ids = in.at("trigger_ids").get<std::vector<std::uint64_t>>();
      session.plots = in.at("plots").get<std::vector<std::string>>();
      if (session.plots.size() != session.trigger_ids.size())
        return core::Error{source + ": session " + session.name + ": plots and trigger_ids differ"};
      plan.sessions.push_back(std::move(session));
    }
    for (const Json& in : json.at("tasks")) {
      std::vector<BatchPiece> pieces;
      for (const Json& piece : in) {
        BatchPiece p{piece.at("session").get<std::size_t>(), piece.at("first").get<std::size_t>(),
                     piece.at("count").get<std::size_t>()};
        if (p.session >= plan.sessions.size() ||
            p.first + p.count > plan.sessions[p.session].trigger_ids.size())
          return core::Error{source + ": a task's piece lies outside its session"};
        pieces.push_back(p);
      }
      plan.tasks.push_back(std::move(pieces));
    }
  } catch (const std::exception& e) {
    return core::Error{source + ": " + e.what()};
  }
  return plan;
}

fs::path batchPlanFile(const fs::path& job_dir) {
  return job_dir / "plan.json";
}

fs::path batchPieceDir(const fs::path& job_dir, const BatchPlan& plan, std::size_t task,
                       const BatchPiece& piece) {
  return job_dir / "tasks" / taskDirName(task) /
         (std::to_string(piece.session) + "-" + plan.sessions.at(piece.session).name);
}

fs::path batchLogsDir(const fs::path& job_dir) {
  return job_dir / "logs";
}

fs::path batchSubmissionsFile(const fs::path& job_dir) {
  return job_dir / "submissions.jsonl";
}

std::string batchSbatchScript(const BatchPlan& plan, const fs::path& job_dir) {
  const auto quoted = [](const std::string& text) {
    std::string out = "'";
    for (char c : text)
      out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  std::ostringstream script;
  script << "#!/bin/bash\n"
         << "# fieldrig batch job, parameter hash " << plan.parameter_hash << ".\n"
         << "# Submit with `fieldrig batch submit " << job_dir.string()
         << "`: it passes --array with the tasks not yet done.\n"
         << "#SBATCH --job-name=fieldrig-batch\n"
         << "#SBATCH --array=0-" << (plan.tasks.empty() ? 0 : plan.tasks.size() - 1) << "\n"
         << "#SBATCH --ntasks=1\n"
         << "#SBATCH --cpus-per-task=1\n"
         << "#SBATCH --open-mode=append\n"
         << "#SBATCH --output=" << (batchLogsDir(job_dir) / "task-%a.out").string() << "\n";
  for (const std::string& option : plan.sbatch_options)
    script << "#SBATCH " << option << "\n";
  script << "exec " << quoted(plan.fieldrig_binary.string()) << " batch task "
         << quoted(job_dir.string()) << " \"$SLURM_ARRAY_TASK_ID\"\n";
  return script.str();
}

core::Result<void> writeBatchJob(const BatchPlan& plan, const fs::path& job_dir) {
  if (fs::exists(batchPlanFile(job_dir))) {
    auto existing = readBatchPlan(job_dir);
    if (!existing)
      return core::Error{existing.error().message};
    const Json old_json = batchPlanToJson(*existing);
    const Json new_json = batchPlanToJson(plan);
    // The same plan again is fine (its tasks resume); another plan would mix its results with
    // the old ones.
    if (old_json["parameter_hash"] != new_json["parameter_hash"] ||
        old_json["sessions"] != new_json["sessions"] || old_json["tasks"] != new_json["tasks"]) {
      return core::Error{batchPlanFile(job_dir).string() +
                         ": the folder holds another plan (parameters, sessions or shards "
                         "differ); use a new --out folder"};
    }
  }
  std::error_code ec;
  // A job that cannot be written whole (a full disk) leaves no folder that looks like one: the
  // folders made here are removed again (only when empty).
  std::vector<fs::path> made;
  for (const fs::path& dir : {batchLogsDir(job_dir), job_dir / "tasks", job_dir}) {
    if (!fs::exists(dir, ec))
      made.push_back(dir);
  }
  const auto removeEmptyFolders = [&] {
    for (const fs::path& dir : made)
      fs::remove(dir, ec);
  };
  for (const fs::path& dir : {job_dir / "tasks", batchLogsDir(job_dir)}) {
    fs::create_directories(dir, ec);
    if (ec) {
      const std::string reason = ec.message();
      removeEmptyFolders();
      return core::Error{dir.string() + ": cannot create folder: " + reason};
    }
  }
  // The plan and its script belong together: both are written before either replaces the old.
  const fs::path script = job_dir / "job.sbatch";
  const std::string plan_text = batchPlanToJson(plan).dump(1) + "\n";
  const std::string script_text = batchSbatchScript(plan, job_dir);
  if (std::string failed =
          core::replaceFilesTogether({{batchPlanFile(job_dir), plan_text}, {script, script_text}});
      !failed.empty()) {
    removeEmptyFolders();
    return core::Error{failed};
  }
  fs::permissions(script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add, ec);
  return {};
}

core::Result<BatchPlan> readBatchPlan(const fs::path& job_dir) {
  const fs::path file = batchPlanFile(job_dir);
  std::string error;
  const std::optional<std::string> content = core::readWholeFile(file, error);
  if (!content)
    return core::Error{error + " (is " + job_dir.string() +
                       " a job folder of `fieldrig batch plan`?)"};
  const Json json = Json::parse(*content, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded())
    return core::Error{file.string() + ": not JSON"};
  return batchPlanFromJson(json, file.string());
}

std::string checkBatchSession(const BatchSession& session) {
  std::error_code ec;
  if (!fs::is_directory(session.path, ec))
    return session.path.string() + ": session missing";
  auto opened = recording::SessionReader::open(session.path);
  if (!opened)
    return session.path.string() + ": session damaged: " + opened.error().message;
  const auto& sets = opened->sets();
  if (sets.size() < session.trigger_ids.size())
    return session.path.string() + ": session damaged: the index holds " +
           std::to_string(sets.size()) + " sets, the plan " +
           std::to_string(session.trigger_ids.size());
  for (std::size_t i = 0; i < session.trigger_ids.size(); ++i) {
    if (sets[i].trigger_id != session.trigger_ids[i])
      return session.path.string() + ": session changed since the plan: set " + std::to_string(i) +
             " has trigger id " + std::to_string(sets[i].trigger_id) + ", the plan " +
             std::to_string(session.trigger_ids[i]);
  }
  return {};
}

core::Result<BatchTaskSummary> runBatchTask(
    const BatchPlan& plan, const fs::path& job_dir, std::size_t task,
    const std::function<void(const nlohmann::ordered_json&)>& on_line) {
  if (task >= plan.tasks.size())
    return core::Error{"task " + std::to_string(task) + " is not in the plan (it has " +
                       std::to_string(plan.tasks.size()) + " tasks)"};
  // One run of a task at a time, whoever starts it (a Slurm resubmission, `batch run` on a login
  // node): a second one would append the same plots to the same files. The kernel drops the
  // lock when the process ends, however it ends.
  const fs::path task_dir = job_dir / "tasks" / taskDirName(task);
  std::error_code ec;
  fs::create_directories(task_dir, ec);
  const fs::path lock_path = task_dir / ".lock";
  const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd < 0)
    return core::Error{lock_path.string() + ": cannot open: " + std::strerror(errno)};
  struct LockCloser {
    int fd;
    ~LockCloser() { ::close(fd); }
  } closer{lock_fd};
  if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0)
    return core::Error{"task " + std::to_string(task) + " is already running (" +
                       lock_path.string() + " is locked)"};
  using Clock = std::chrono::steady_clock;
  BatchTaskSummary summary;
  pipeline::ProcessorOptions options;
  if (!plan.traits_config.empty()) {
    auto loaded = config::loadTraitsOptions(plan.traits_config);
    if (!loaded)
      return core::Error{loaded.error().message};
    options.traits = *loaded;
  }
  for (const BatchPiece& piece : plan.tasks[task]) {
    const Clock::time_point start = Clock::now();
    const BatchSession& session = plan.sessions[piece.session];
    if (std::string problem = checkBatchSession(session); !problem.empty())
      return core::Error{problem};
    auto reader = recording::SessionReader::open(session.path);
    if (!reader)
      return core::Error{session.path.string() + ": " + reader.error().message};
    auto rig = loadRigFor(plan.calib, &*reader);
    if (!rig)
      return core::Error{session.path.string() + ": " + rig.error().message};
    auto processor = pipeline::PlotProcessor::create(*rig, options);
    if (!processor)
      return core::Error{session.path.string() + ": " + processor.error().message};
    auto results = ResultsWriter::open(batchPieceDir(job_dir, plan, task, piece));
    if (!results)
      return core::Error{results.error().message};
    SessionProcessingOptions run;
    run.first_position = piece.first;
    run.end_position = piece.first + piece.count;
    const Clock::time_point loaded = Clock::now();
    std::string problems;
    auto done = processSession(*reader, *processor, nullptr, **results, run, on_line,
                               [&problems](const std::string& problem) { problems += problem; });
    if (!done)
      return core::Error{done.error().message};
    summary.sets += done->sets;
    summary.already_done += done->already_done;
    summary.load_seconds += std::chrono::duration<double>(loaded - start).count();
    summary.process_seconds += std::chrono::duration<double>(Clock::now() - loaded).count();
  }
  return summary;
}

std::size_t batchTaskSetsDone(const BatchPlan& plan, const fs::path& job_dir, std::size_t task) {
  std::size_t done = 0;
  for (const BatchPiece& piece : plan.tasks.at(task)) {
    const std::set<std::uint64_t> ids = triggerIdsIn(batchPieceDir(job_dir, plan, task, piece));
    const std::vector<std::uint64_t>& planned = plan.sessions[piece.session].trigger_ids;
    for (std::size_t i = piece.first; i < piece.first + piece.count; ++i)
      done += ids.count(planned[i]);
  }
  return done;
}

core::Result<BatchMerge> mergeBatch(const BatchPlan& plan, const fs::path& job_dir) {
  // Each session position → (task, piece), to read the line from the one folder that owns it.
  struct Owner {
    std::size_t task;
    const BatchPiece* piece;
  };
  std::vector<std::vector<Owner>> owners(plan.sessions.size());
  for (std::size_t s = 0; s < plan.sessions.size(); ++s)
    owners[s].resize(plan.sessions[s].trigger_ids.size(), Owner{0, nullptr});
  std::map<fs::path, std::map<std::uint64_t, Json>> lines_by_dir;
  for (std::size_t task = 0; task < plan.tasks.size(); ++task) {
    for (const BatchPiece& piece : plan.tasks[task]) {
      for (std::size_t i = piece.first; i < piece.first + piece.count; ++i)
        owners[piece.session][i] = Owner{task, &piece};
      const fs::path dir = batchPieceDir(job_dir, plan, task, piece);
      std::map<std::uint64_t, Json>& lines = lines_by_dir[dir];
      const fs::path file = resultsFiles(dir).jsonl;
      if (!fs::exists(file))
        continue;
      std::string error;
      const std::optional<std::string> content = core::readWholeFile(file, error);
      if (!content)
        return core::Error{error};
      std::istringstream in(*content);
      std::size_t line_number = 0;
      for (std::string text; std::getline(in, text);) {
        ++line_number;
        if (in.eof())
          break;  // torn by a killed task: that plot is absent until the task runs again
        Json line = Json::parse(text, nullptr, /*allow_exceptions=*/false);
        if (!line.is_object() || !line.contains("trigger_id") ||
            !line["trigger_id"].is_number_unsigned())
          return core::Error{file.string() + ":" + std::to_string(line_number) +
                             ": not a result line"};
        const auto trigger_id = line["trigger_id"].get<std::uint64_t>();
        lines[trigger_id] = std::move(line);
      }
    }
  }

  BatchMerge merge;
  std::vector<std::pair<std::string, traits::PlotRow>> rows;  // session name, row
  std::string jsonl_body;
  for (std::size_t s = 0; s < plan.sessions.size(); ++s) {
    const BatchSession& session = plan.sessions[s];
    for (std::size_t i = 0; i < session.trigger_ids.size(); ++i) {
      const Owner& owner = owners[s][i];
      const auto& lines = lines_by_dir[batchPieceDir(job_dir, plan, owner.task, *owner.piece)];
      const auto found = lines.find(session.trigger_ids[i]);
      if (found == lines.end()) {
        merge.absent.push_back(
            {session.path.string(), session.plots[i], session.trigger_ids[i], owner.task});
        continue;
      }
      Json merged;
      merged["session"] = session.name;
      for (const auto& [key, value] : found->second.items())
        merged[key] = value;
      jsonl_body += merged.dump() + "\n";
      const Json& line = found->second;
      auto row = traits::plotRowFromJson(
          line.at("plot").get<std::string>(), line.at("time").get<std::string>(),
          line.at("lat").get<double>(), line.at("lon").get<double>(), line.at("traits"));
      if (!row)
        return core::Error{"session " + session.path.string() + ", plot " + session.plots[i] +
                           ": " + row.error().message};
      rows.emplace_back(session.name, std::move(*row));
      ++merge.plots;
    }
  }

  Json provenance;
  provenance["software_version"] = plan.software_version;
  provenance["parameter_hash"] = plan.parameter_hash;
  provenance["traits_config"] = plan.traits_config;
  provenance["traits_config_sha256"] = plan.traits_config_sha256;
  Json calibration = Json::array();
  for (const CalibrationFile& file : plan.calibration)
    calibration.push_back({{"path", file.path}, {"sha256", file.sha256}});
  provenance["calibration"] = std::move(calibration);
  Json sessions = Json::array();
  for (const BatchSession& session : plan.sessions)
    sessions.push_back({{"name", session.name},
                        {"path", session.path.string()},
                        {"sets", session.trigger_ids.size()}});
  provenance["sessions"] = std::move(sessions);
  provenance["plots_planned"] = plan.totalSets();
  provenance["plots"] = merge.plots;
  Json absent = Json::array();
  for (const AbsentPlot& plot : merge.absent)
    absent.push_back({{"session", plot.session},
                      {"plot", plot.plot},
                      {"trigger_id", plot.trigger_id},
                      {"task", plot.task}});
  provenance["absent"] = std::move(absent);
  merge.provenance = provenance;

  merge.jsonl = Json{{"provenance", provenance}}.dump() + "\n" + jsonl_body;

  // CSV: a '#' line with the provenance, then the results table with the session first.
  std::string csv = "# provenance: " + provenance.dump() + "\n";
  const std::string header = traits::formatCsv(std::vector<traits::PlotRow>{});
  csv += "session," + header;
  for (const auto& [name, row] : rows) {
    const std::string table = traits::formatCsv(std::vector<traits::PlotRow>{row});
    csv += csvQuoted(name) + "," + table.substr(header.size());
  }
  merge.csv = std::move(csv);

  Json collection;
  collection["type"] = "FeatureCollection";
  collection["provenance"] = provenance;  // a foreign member (RFC 7946 section 6.1)
  Json features = Json::array();
  for (const auto& [name, row] : rows) {
    Json properties;
    properties["session"] = name;
    for (const auto& [key, value] : row.properties.items())
      properties[key] = value;
    Json feature;
    feature["type"] = "Feature";
    feature["id"] = name + "/" + row.properties.value("plot_id", std::string());
    feature["geometry"] = {{"type", "Point"}, {"coordinates", {row.lon_deg, row.lat_deg}}};
    feature["properties"] = std::move(properties);
    features.push_back(std::move(feature));
  }
  collection["features"] = std::move(features);
  merge.geojson = collection.dump(1) + "\n";
  return merge;
}

core::Result<void> writeBatchMerge(const BatchMerge& merge, const fs::path& job_dir) {
  const fs::path dir = job_dir / "merged";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    return core::Error{dir.string() + ": cannot create folder: " + ec.message()};
  const std::pair<const char*, const std::string*> files[] = {{"season.jsonl", &merge.jsonl},
                                                              {"season.csv", &merge.csv},
                                                              {"season.geojson", &merge.geojson}};
  for (const auto& [name, text] : files) {
    if (std::string failed = core::replaceFileAtomically(dir / name, *text); !failed.empty())
      return core::Error{failed};
  }
  if (std::string failed =
          core::replaceFileAtomically(dir / "provenance.json", merge.provenance.dump(1) + "\n");
      !failed.empty())
    return core::Error{failed};
  return {};
}

std::vector<SchedulerTaskState> parseSlurmTaskStates(const std::string& text) {
  std::vector<SchedulerTaskState> states;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::replace(line.begin(), line.end(), '|', ' ');
    std::istringstream fields(line);
    std::string id, state;
    if (!(fields >> id >> state))
      continue;
    const auto underscore = id.find('_');
    if (underscore == std::string::npos)
      continue;  // not an array task
    const std::string job = id.substr(0, underscore);
    std::string tasks = id.substr(underscore + 1);
    // sacct writes "CANCELLED by 0": the first word is the state.
    const auto expand = [&](const std::string& range) {
      const auto dash = range.find('-');
      try {
        std::size_t first = std::stoul(range.substr(0, dash));
        std::size_t last = dash == std::string::npos ? first : std::stoul(range.substr(dash + 1));
        for (std::size_t t = first; t <= last && t < first + 100000; ++t)
          states.push_back({job, t, state});
      } catch (const std::exception&) {
      }
    };
    if (!tasks.empty() && tasks.front() == '[') {
      // A pending range "[0-3%2]" or "[1,3]".
      tasks = tasks.substr(1, tasks.find_first_of("]%") - 1);
      std::istringstream parts(tasks);
      for (std::string part; std::getline(parts, part, ',');)
        expand(part);
    } else {
      expand(tasks);
    }
  }
  return states;
}

bool slurmStateActive(const std::string& state) {
  static const std::set<std::string> active = {
      "PENDING",  "RUNNING",   "CONFIGURING", "COMPLETING",   "SUSPENDED",  "REQUEUED",
      "RESIZING", "SIGNALING", "STAGE_OUT",   "REQUEUE_HOLD", "REQUEUE_FED"};
  return active.count(state) > 0;
}

}  // namespace fieldrig::daemon
