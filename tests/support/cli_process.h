// The built `fieldrig` binary running in the background while a test talks to it, for commands
// that run until their input ends or a signal comes (map record, live triggers): the test writes
// to its stdin (Enter presses), sends it signals and waits for text on its stdout and stderr.
// For a command that simply runs to completion, use runFieldrig (cli_run.h).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "support/cli_run.h"
#include "support/fd_io.h"

namespace fieldrig::testing_support {

// stdin is a pipe from the test; stdout and stderr go to files in `work_dir` (process.out,
// process.err), so that the process never blocks on a full pipe while the test is busy feeding
// it. One FieldrigProcess per `work_dir` at a time. Killed if still running when destroyed.
class FieldrigProcess {
 public:
  using Milliseconds = std::chrono::milliseconds;

  // `program` is the fieldrig binary unless a test runs a helper program of its own.
  FieldrigProcess(const std::vector<std::string>& args, const std::filesystem::path& work_dir,
                  const std::string& program = kFieldrigBinary)
      : out_path_(work_dir / "process.out"), err_path_(work_dir / "process.err") {
    std::vector<std::string> argv_text{program};
    argv_text.insert(argv_text.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& arg : argv_text)
      argv.push_back(arg.data());
    argv.push_back(nullptr);

    int in_pipe[2];
    if (::pipe2(in_pipe, O_CLOEXEC) != 0)
      throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    const int out_fd = ::open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int err_fd = ::open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (out_fd < 0 || err_fd < 0)
      throw std::runtime_error("cannot create the output files in " + work_dir.string());

    const pid_t parent = ::getpid();
    pid_ = ::fork();
    if (pid_ == 0) {
      // Only async-signal-safe calls here. If the test process dies, the command dies with it.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent)
        ::_exit(127);
      ::dup2(in_pipe[0], STDIN_FILENO);
      ::dup2(out_fd, STDOUT_FILENO);
      ::dup2(err_fd, STDERR_FILENO);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(in_pipe[0]);
    ::close(out_fd);
    ::close(err_fd);
    stdin_ = in_pipe[1];
    if (pid_ < 0)
      throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }

  ~FieldrigProcess() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (stdin_ >= 0)
      ::close(stdin_);
  }
  FieldrigProcess(const FieldrigProcess&) = delete;
  FieldrigProcess& operator=(const FieldrigProcess&) = delete;

  pid_t pid() const { return pid_; }

  // Writes `text` to the process's stdin; false if it could not be written whole.
  bool sendInput(std::string_view text) { return writeAll(stdin_, text); }

  // Sends `signal_number` (SIGINT, SIGUSR1…); false if the process is gone.
  bool signal(int signal_number) { return !exited() && ::kill(pid_, signal_number) == 0; }

  // What the process has written so far.
  std::string out() const { return readWholeFile(out_path_); }
  std::string err() const { return readWholeFile(err_path_); }
  std::vector<std::string> outLines() const { return splitLines(out()); }

  // Each wait returns false when the timeout passes, or the process exits, first.
  bool waitForStderr(std::string_view needle, Milliseconds timeout = std::chrono::seconds{10}) {
    return waitFor([&] { return err().find(needle) != std::string::npos; }, timeout);
  }
  bool waitForStdoutLines(std::size_t lines, Milliseconds timeout = std::chrono::seconds{10}) {
    return waitFor(
        [&] {
          const std::string text = out();
          return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) >= lines;
        },
        timeout);
  }

  // Waits for the exit; the exit code, or -1 on timeout or death by a signal.
  int waitExit(Milliseconds timeout = std::chrono::seconds{20}) {
    waitFor([&] { return exited(); }, timeout);
    if (!exited())
      return -1;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }

 private:
  bool exited() {
    if (!exited_ && ::waitpid(pid_, &status_, WNOHANG) == pid_)
      exited_ = true;
    return exited_;
  }

  template <typename Predicate>
  bool waitFor(Predicate done, Milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done()) {
      // Output written just before the exit is in the files once the exit is seen.
      if (exited())
        return done();
      if (std::chrono::steady_clock::now() > deadline)
        return false;
      std::this_thread::sleep_for(std::chrono::milliseconds{5});
    }
    return true;
  }

  std::filesystem::path out_path_;
  std::filesystem::path err_path_;
  pid_t pid_ = -1;
  int stdin_ = -1;
  int status_ = 0;
  bool exited_ = false;
};

}  // namespace fieldrig::testing_support
