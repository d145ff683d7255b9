// main()'s parse-and-run (runCommandLine, tools/commands/command_helpers.h) on a small app of its
// own: every way a run can fail is one stderr line naming the command, with its exit code — an
// option CLI11 refuses (2), and an exception nothing else handled, std::bad_alloc included (4).
// The real commands no longer let an exception escape on any input the suite knows, so this is
// the test that reaches the exit-4 path.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands/command_helpers.h"

namespace fieldrig::tools {
namespace {

struct Args {
  double rate = 1.0;
  std::string what;
};

int run(const Args& args) {
  if (args.what == "throw")
    throw std::runtime_error("disk on fire\nsecond line");
  if (args.what == "oom")
    throw std::bad_alloc();
  if (args.what == "int")
    throw 7;
  return args.what == "fail" ? kExitRuntime : kExitOk;
}

struct Outcome {
  int exit_code;
  std::string err;
};

// `fieldrig sim drive ARGS…` on an app with one nested subcommand.
Outcome runWith(std::vector<std::string> words) {
  CLI::App app{"test"};
  app.require_subcommand(1);
  int exit_code = kExitOk;
  std::string log_level = "warn";
  addLogLevelOption(app, log_level);
  CLI::App* sim = addCommandGroup(app, "sim", "group");
  const auto [drive, args] = addSubcommand(*sim, "drive", "a command", exit_code, run);
  drive->add_option("--rate", args->rate)->check(finiteRange(0.01, 1000.0));
  drive->add_option("--what", args->what);
  words.insert(words.begin(), "/some/path/fieldrig");
  std::vector<const char*> argv;
  for (const std::string& word : words)
    argv.push_back(word.c_str());
  std::ostringstream err;
  std::streambuf* const saved = std::cerr.rdbuf(err.rdbuf());
  const int code =
      runCommandLine(app, "fieldrig", static_cast<int>(argv.size()), argv.data(), exit_code);
  std::cerr.rdbuf(saved);
  return {code, err.str()};
}

TEST(RunCommandLine, GivesTheRunsExitCode) {
  EXPECT_EQ(runWith({"sim", "drive"}).exit_code, kExitOk);
  const Outcome failed = runWith({"sim", "drive", "--what", "fail"});
  EXPECT_EQ(failed.exit_code, kExitRuntime);
  EXPECT_EQ(failed.err, "");
}

// A command reads an empty string option as "not given"; an empty value must not pass for that.
TEST(RunCommandLine, AnEmptyValueIsRefusedNamingTheOption) {
  const Outcome empty = runWith({"sim", "drive", "--what", ""});
  EXPECT_EQ(empty.exit_code, kExitBadInput);
  EXPECT_EQ(empty.err,
            "fieldrig sim drive: --what: must not be empty (fieldrig sim drive --help lists the "
            "options)\n");
  EXPECT_EQ(runWith({"sim", "drive", "--what", "x"}).exit_code, kExitOk);
}

// spdlog reads a level it does not know as "off": `--log-level loud` silenced the log.
TEST(RunCommandLine, AnUnknownLogLevelIsRefused) {
  const Outcome loud = runWith({"--log-level", "loud", "sim", "drive"});
  EXPECT_EQ(loud.exit_code, kExitBadInput);
  EXPECT_EQ(loud.err.rfind("fieldrig sim drive: --log-level: loud not in", 0), 0u) << loud.err;
  EXPECT_EQ(runWith({"--log-level", "debug", "sim", "drive"}).exit_code, kExitOk);
  const Outcome empty = runWith({"--log-level", "", "sim", "drive"});
  EXPECT_EQ(empty.exit_code, kExitBadInput);
  EXPECT_EQ(empty.err.rfind("fieldrig sim drive: --log-level: must not be empty", 0), 0u)
      << empty.err;
}

TEST(RunCommandLine, AnOptionCli11RefusesIsOneLineNamingTheCommand) {
  const Outcome nan = runWith({"sim", "drive", "--rate", "nan"});
  EXPECT_EQ(nan.exit_code, kExitBadInput);
  EXPECT_EQ(nan.err,
            "fieldrig sim drive: --rate: must be a finite number in [0.01, 1000], got nan "
            "(fieldrig sim drive --help lists the options)\n");
  const Outcome unknown = runWith({"sim", "drive", "--bogus"});
  EXPECT_EQ(unknown.exit_code, kExitBadInput);
  EXPECT_EQ(unknown.err.rfind("fieldrig sim drive: ", 0), 0u) << unknown.err;
  EXPECT_NE(unknown.err.find("--bogus"), std::string::npos) << unknown.err;
  const Outcome none = runWith({});
  EXPECT_EQ(none.exit_code, kExitBadInput);
  EXPECT_EQ(none.err.rfind("fieldrig: ", 0), 0u) << none.err;
  for (const Outcome& outcome : {nan, unknown, none})
    EXPECT_EQ(std::count(outcome.err.begin(), outcome.err.end(), '\n'), 1) << outcome.err;
}

TEST(RunCommandLine, HelpIsExitZero) {
  std::ostringstream out;
  std::streambuf* const saved = std::cout.rdbuf(out.rdbuf());
  const Outcome help = runWith({"sim", "drive", "--help"});
  std::cout.rdbuf(saved);
  EXPECT_EQ(help.exit_code, kExitOk);
  EXPECT_NE(out.str().find("--rate"), std::string::npos) << out.str();
}

TEST(RunCommandLine, AnEscapingExceptionIsOneLineNamingTheCommandAndExit4) {
  const Outcome thrown = runWith({"sim", "drive", "--what", "throw"});
  EXPECT_EQ(thrown.exit_code, kExitInternal);
  EXPECT_EQ(thrown.err, "fieldrig sim drive: internal error: disk on fire second line\n");
  const Outcome oom = runWith({"sim", "drive", "--what", "oom"});
  EXPECT_EQ(oom.exit_code, kExitInternal);
  EXPECT_EQ(oom.err, "fieldrig sim drive: internal error: out of memory (std::bad_alloc)\n");
  const Outcome other = runWith({"sim", "drive", "--what", "int"});
  EXPECT_EQ(other.exit_code, kExitInternal);
  EXPECT_EQ(other.err,
            "fieldrig sim drive: internal error: an exception that is not a std::exception\n");
}

}  // namespace
}  // namespace fieldrig::tools
