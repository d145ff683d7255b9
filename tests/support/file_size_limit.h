// A file size limit (RLIMIT_FSIZE) for the guard's lifetime, with SIGXFSZ ignored: a write past
// it fails with EFBIG instead of killing the process. It stands in for a full disk in tests of
// what a failed write leaves behind, without filling a disk; the old limit is restored after.
#pragma once

#include <sys/resource.h>

#include <csignal>

namespace fieldrig::testing_support {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &previous_);
    rlimit limited = previous_;
    limited.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limited);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &previous_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit previous_{};
  void (*previous_handler_)(int) = nullptr;
};

}  // namespace fieldrig::testing_support
