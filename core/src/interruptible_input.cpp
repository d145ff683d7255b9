#include "fieldrig/core/interruptible_input.h"

#include <fcntl.h>
#include <linux/magic.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace fieldrig::core {
namespace {

constexpr std::size_t kChunkBytes = 64 * 1024;
constexpr int kPollTimeoutMs = 250;

std::string errnoText(int error) {
  return std::strerror(error);
}

}  // namespace

Result<std::unique_ptr<InterruptibleInput>> InterruptibleInput::open(
    const std::filesystem::path& path) {
  // Non-blocking, so that opening a FIFO with no writer yet does not wait (poll() waits instead,
  // where an interrupt can reach it).
  const int file = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (file < 0) {
    const int error = errno;
    return Error{path.string() + ": cannot open: " + errnoText(error)};
  }
  struct stat info {};
  if (::fstat(file, &info) != 0 || S_ISDIR(info.st_mode)) {
    const int error = errno;
    ::close(file);
    return Error{path.string() + ": " +
                 (S_ISDIR(info.st_mode) ? std::string("a folder, not a file") : errnoText(error))};
  }
  // Only a named FIFO can be opened before its writer: an anonymous pipe (`/dev/stdin` of a
  // shell pipeline, `<(…)`) was made with its writer, so there as in a file, reading 0 is the end.
  struct statfs filesystem {};
  const bool anonymous_pipe = ::fstatfs(file, &filesystem) == 0 &&
                              static_cast<unsigned long>(filesystem.f_type) == PIPEFS_MAGIC;
  const bool named_fifo = S_ISFIFO(info.st_mode) && !anonymous_pipe;
  const int wake = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake < 0) {
    const int error = errno;
    ::close(file);
    return Error{path.string() + ": eventfd: " + errnoText(error)};
  }
  return std::unique_ptr<InterruptibleInput>(new InterruptibleInput(file, wake, path, named_fifo));
}

InterruptibleInput::InterruptibleInput(int file, int wake, std::filesystem::path path,
                                       bool named_fifo)
    : file_(file),
      wake_(wake),
      path_(std::move(path)),
      named_fifo_(named_fifo),
      chunk_(kChunkBytes) {}

InterruptibleInput::~InterruptibleInput() {
  ::close(file_);
  ::close(wake_);
}

void InterruptibleInput::interrupt() noexcept {
  interrupted_.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  // Only fails when the counter would overflow: it is readable already.
  [[maybe_unused]] const ssize_t written = ::write(wake_, &one, sizeof one);
}

InterruptibleInput::Buffer::int_type InterruptibleInput::Buffer::underflow() {
  InterruptibleInput& in = owner_;
  for (;;) {
    if (in.interrupted())
      return traits_type::eof();
    const ssize_t got = ::read(in.file_, in.chunk_.data(), in.chunk_.size());
    const int error = errno;
    if (got > 0) {
      in.writer_seen_ = true;
      setg(in.chunk_.data(), in.chunk_.data(), in.chunk_.data() + got);
      return traits_type::to_int_type(in.chunk_[0]);
    }
    // A named FIFO reads 0 while no writer has come yet, as well as after the last one left:
    // only the second is the end.
    if (got == 0 && (!in.named_fifo_ || in.writer_seen_))
      return traits_type::eof();
    if (got < 0) {
      if (error == EAGAIN)
        in.writer_seen_ = true;  // an empty pipe with a writer: it can only end now
      else if (error != EINTR) {
        in.read_error_ = in.path_.string() + ": read: " + errnoText(error);
        return traits_type::eof();
      }
    }
    // Nothing yet. Linux does not report the hang-up of a FIFO whose writer opened before the
    // reader did, so the wait has a timeout, after which read() looks again.
    pollfd waits[2] = {{in.file_, POLLIN, 0}, {in.wake_, POLLIN, 0}};
    if (::poll(waits, 2, kPollTimeoutMs) < 0 && errno != EINTR) {
      const int poll_error = errno;
      in.read_error_ = in.path_.string() + ": poll: " + errnoText(poll_error);
      return traits_type::eof();
    }
    // A writer came and went (nothing may have been written): the next read's 0 is the end.
    if ((waits[0].revents & POLLHUP) != 0)
      in.writer_seen_ = true;
  }
}

}  // namespace fieldrig::core
