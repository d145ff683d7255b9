#include "fieldrig/core/durable_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

namespace fieldrig::core {

int writeFully(int fd, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, bytes, size);
    if (n < 0) {
      if (errno == EINTR)
        continue;
      return errno;
    }
    if (n == 0)
      return EIO;
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

// A bare file name ("drive.nmea") has an empty parent: its folder is the working directory.
int syncDirectory(const std::filesystem::path& dir) {
  const char* const name = dir.empty() ? "." : dir.c_str();
  const int fd = ::open(name, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    return errno;
  const int result = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return result;
}

std::optional<std::string> readWholeFile(const std::filesystem::path& path, std::string& error) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = path.string() + ": cannot open: " + std::strerror(errno);
    return std::nullopt;
  }
  std::string content;
  struct stat info {};
  if (::fstat(fd, &info) == 0 && info.st_size > 0)
    content.reserve(static_cast<std::size_t>(info.st_size));
  std::array<char, 65536> buffer;
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0) {
      error = path.string() + ": cannot read: " + std::strerror(errno);
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0)
      break;
    content.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  return content;
}

std::string replaceFileAtomically(const std::filesystem::path& path, std::string_view text) {
  return replaceFilesTogether({{path, text}});
}

namespace {

// Writes `data` to `path` (created or truncated); 0 or the errno.
int writeAndClose(const std::filesystem::path& path, std::string_view data, bool& created) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  created = fd >= 0;
  if (fd < 0)
    return errno;
  int error = writeFully(fd, data.data(), data.size());
  // close() reports what a network or full file system deferred.
  if (::close(fd) != 0 && error == 0)
    error = errno;
  return error;
}

// A new file beside a target, holding its new content until it is renamed over it.
struct TempBeside {
  std::string name;    // PATH.tmp.XXXXXX; removed again when the write failed
  std::string failed;  // "PATH: reason", or empty
};

// Opens a new file beside `path` under a name of its own (PATH.tmp. and six random characters),
// as mkstemp does, but with the mode a plain open gives, 0644 less the umask (mkstemp's 0600 and a
// fixed chmod would both ignore the crew's umask), and O_CLOEXEC and O_NOFOLLOW. The fd, or -1
// with errno set.
int openNewBeside(const std::filesystem::path& path, std::string& name) {
  static constexpr char kLetters[] =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  thread_local std::mt19937_64 random{std::random_device{}() ^
                                      static_cast<std::uint64_t>(::getpid())};
  for (int attempt = 0; attempt < 100; ++attempt) {
    name = path.string() + ".tmp.";
    for (int i = 0; i < 6; ++i)
      name += kLetters[random() % (sizeof(kLetters) - 1)];
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd >= 0 || errno != EEXIST)
      return fd;
  }
  return -1;  // errno is EEXIST
}

// Writes `data` into a file beside `path` under a name of its own, so that no file already there
// is truncated or followed through a link, and two writers never share one; synced when `sync`.
TempBeside writeBeside(const std::filesystem::path& path, std::string_view data, bool sync) {
  TempBeside temp;
  const int fd = openNewBeside(path, temp.name);
  if (fd < 0) {
    const int error = errno;
    temp.failed = path.string() + ": cannot create: " + std::strerror(error);
    temp.name.clear();
    return temp;
  }
  int error = writeFully(fd, data.data(), data.size());
  if (error == 0 && sync && ::fsync(fd) != 0)
    error = errno;
  // close() reports what a network or full file system deferred.
  if (::close(fd) != 0 && error == 0)
    error = errno;
  if (error != 0) {
    ::unlink(temp.name.c_str());
    temp.name.clear();
    temp.failed = path.string() + ": cannot write: " + std::strerror(error);
  }
  return temp;
}

}  // namespace

std::string replaceFilesTogether(std::initializer_list<FileContent> files) {
  std::vector<std::string> temps;
  std::string failed;
  for (const FileContent& file : files) {
    TempBeside temp = writeBeside(file.path, file.text, true);
    if (!temp.failed.empty()) {
      failed = std::move(temp.failed);
      break;
    }
    temps.push_back(std::move(temp.name));
  }
  std::size_t renamed = 0;
  for (const FileContent& file : files) {
    if (!failed.empty() || renamed == temps.size())
      break;
    if (::rename(temps[renamed].c_str(), file.path.c_str()) != 0) {
      const int error = errno;
      failed = file.path.string() + ": cannot write: " + std::strerror(error);
    } else {
      ++renamed;
    }
  }
  if (!failed.empty()) {
    for (std::size_t i = renamed; i < temps.size(); ++i)
      ::unlink(temps[i].c_str());
    return failed;
  }
  for (const FileContent& file : files) {
    if (const int sync_error = syncDirectory(file.path.parent_path()); sync_error != 0)
      return file.path.parent_path().string() + ": cannot sync: " + std::strerror(sync_error);
  }
  return {};
}

std::string writeWholeFile(const std::filesystem::path& path, std::string_view data) {
  // lstat: a symbolic link (/dev/stdout), a device or a pipe is written through in place; only a
  // plain file, or a new one, is replaced by a renamed temporary file.
  struct stat info {};
  const bool exists = ::lstat(path.c_str(), &info) == 0;
  if (exists && !S_ISREG(info.st_mode)) {
    bool created = false;
    const int error = writeAndClose(path, data, created);
    if (!created)
      return path.string() + ": cannot create: " + std::strerror(error);
    if (error != 0)
      return path.string() + ": cannot write: " + std::strerror(error);
    return {};
  }
  TempBeside temp = writeBeside(path, data, false);
  if (!temp.failed.empty())
    return temp.failed;
  if (::rename(temp.name.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.name.c_str());
    return path.string() + ": cannot write: " + std::strerror(error);
  }
  return {};
}

std::string appendDurably(const std::filesystem::path& path, std::string_view text) {
  const bool existed = std::filesystem::exists(path);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0)
    return path.string() + ": cannot open for appending: " + std::strerror(errno);
  int error = writeFully(fd, text.data(), text.size());
  if (error == 0 && ::fdatasync(fd) != 0)
    error = errno;
  ::close(fd);
  if (error != 0)
    return path.string() + ": cannot append: " + std::strerror(error);
  // A new file's name must reach the disk too, or a power loss can take the whole file.
  if (!existed) {
    if (const int sync_error = syncDirectory(path.parent_path()); sync_error != 0)
      return path.parent_path().string() + ": cannot sync: " + std::strerror(sync_error);
  }
  return {};
}

}  // namespace fieldrig::core
