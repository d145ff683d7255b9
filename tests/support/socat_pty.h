// A real pseudo-terminal pair made by socat, for tests of serial code: one end stands in for
// the receiver's device (/dev/ttyUSB0), the test writes NMEA into the other. Killing socat is an
// unplug; restarting it with the same link names is a replug.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "support/fd_io.h"

namespace fieldrig::testing_support {

namespace socat_detail {
namespace fs = std::filesystem;
using namespace std::chrono_literals;
// How long socat may take to create its links on a shared, small machine.
constexpr auto kTimeout = std::chrono::seconds{10};
}  // namespace socat_detail

using namespace socat_detail;

inline std::optional<std::string> findSocat() {
  std::vector<std::string> dirs{"/usr/bin", "/bin", "/usr/local/bin"};
  if (const char* path = std::getenv("PATH")) {
    std::stringstream split(path);
    for (std::string dir; std::getline(split, dir, ':');)
      dirs.insert(dirs.begin(), dir);
  }
  for (const std::string& dir : dirs) {
    const std::string candidate = dir + "/socat";
    if (::access(candidate.c_str(), X_OK) == 0)
      return candidate;
  }
  return std::nullopt;
}

// A socat process joining two ptys whose slave ends are reachable through stable links.
class SocatPty {
 public:
  explicit SocatPty(fs::path dir) : dir_(std::move(dir)) {}
  ~SocatPty() { kill(); }
  SocatPty(const SocatPty&) = delete;
  SocatPty& operator=(const SocatPty&) = delete;

  fs::path device() const { return dir_ / "gps"; }
  fs::path feed() const { return dir_ / "feed"; }

  // Starts socat and waits until both links point at live ptys; returns an error text or "".
  std::string start() {
    const std::optional<std::string> socat = findSocat();
    if (!socat) {
      return "socat not found (PATH, /usr/bin): the serial tests need it to make a pty pair; "
             "install it with `apt-get install socat` (the project's test command does)";
    }
    const std::string log = (dir_ / "socat.log").string();
    const std::string gps = "pty,raw,echo=0,link=" + device().string();
    const std::string feed_end = "pty,raw,echo=0,link=" + feed().string();
    std::vector<std::string> args{*socat, "-d", "-d", gps, feed_end};
    std::vector<char*> argv;
    for (std::string& arg : args)
      argv.push_back(arg.data());
    argv.push_back(nullptr);
    const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (log_fd < 0)
      return "cannot create " + log;

    const pid_t parent = ::getpid();
    pid_t pid = ::fork();
    if (pid == 0) {
      // Only async-signal-safe calls here: the parent has other threads. If the test process
      // dies, socat dies with it instead of holding ptys forever.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent)
        ::_exit(127);
      ::dup2(log_fd, STDOUT_FILENO);
      ::dup2(log_fd, STDERR_FILENO);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(log_fd);
    if (pid < 0)
      return std::string("fork failed: ") + std::strerror(errno);
    pid_ = pid;

    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    std::error_code ec;
    while (!(fs::exists(device(), ec) && fs::exists(feed(), ec))) {
      int wstatus = 0;
      if (::waitpid(pid_, &wstatus, WNOHANG) == pid_) {
        pid_ = -1;
        return "socat exited early; its log:\n" + readLog();
      }
      if (std::chrono::steady_clock::now() > deadline) {
        return "socat's pty links did not appear; its log:\n" + readLog();
      }
      std::this_thread::sleep_for(2ms);
    }
    return {};
  }

  // SIGKILL, as a yanked cable gives no warning. socat cannot remove its links then; they are
  // removed here as udev removes /dev/ttyUSB0, so that a dangling link cannot meet a pty number
  // reused by another process while the "device" is absent.
  void kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
    std::error_code ec;
    fs::remove(device(), ec);
    fs::remove(feed(), ec);
  }

  std::string readLog() const {
    std::ifstream in(dir_ / "socat.log");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  fs::path dir_;
  pid_t pid_ = -1;
};

// The writing end: what the receiver would send.
class Feed {
 public:
  explicit Feed(const fs::path& path)
      : fd_(::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC)) {}
  ~Feed() {
    if (fd_ >= 0)
      ::close(fd_);
  }
  Feed(const Feed&) = delete;
  Feed& operator=(const Feed&) = delete;

  bool ok() const { return fd_ >= 0; }

  bool write(std::string_view bytes) { return writeAll(fd_, bytes); }

  // Odd chunk sizes so that sentences straddle reads; the pauses let the reader catch up and
  // split the stream at the chunk boundaries rather than the kernel's.
  bool writeChunked(std::string_view bytes, std::chrono::microseconds pause) {
    static constexpr std::array<std::size_t, 9> kSizes{1, 7, 64, 3, 129, 17, 2, 41, 250};
    for (std::size_t k = 0; !bytes.empty(); ++k) {
      const std::size_t size = std::min(kSizes[k % kSizes.size()], bytes.size());
      if (!write(bytes.substr(0, size)))
        return false;
      bytes.remove_prefix(size);
      if (pause.count() > 0)
        std::this_thread::sleep_for(pause);
    }
    return true;
  }

 private:
  int fd_;
};

}  // namespace fieldrig::testing_support
