// One way to write a file that must survive a crash: whole writes, durable appends, atomic
// replacement. POSIX; every function returns 0 / an empty string on success, else the errno /
// a message naming the path ("PATH: reason").
#pragma once

#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace fieldrig::core {

// Writes all `size` bytes, retrying short and interrupted writes; 0 or the errno.
int writeFully(int fd, const void* data, std::size_t size);

// fsync of a folder, so that the names created or renamed in it survive a power loss; 0 or errno.
int syncDirectory(const std::filesystem::path& dir);

// Reads a whole file; nullopt with `error` set ("PATH: reason") when it cannot.
std::optional<std::string> readWholeFile(const std::filesystem::path& path, std::string& error);

// Writes `text` to `path` through a temporary file beside it (PATH.tmp.XXXXXX, a name of its own),
// fsync and rename, so that a reader sees the old or the new content, never a mix. Empty on
// success, else "PATH: reason".
std::string replaceFileAtomically(const std::filesystem::path& path, std::string_view text);

// Files that belong together (a calibration's two): every temporary file is written and synced
// before the first rename, so a write that fails (a full disk) leaves all the old files as they
// were. Only a crash between the renames, or a rename that fails after another went through (a
// target that became a folder), can leave some new and some old.
struct FileContent {
  std::filesystem::path path;
  std::string_view text;
};
std::string replaceFilesTogether(std::initializer_list<FileContent> files);

// Writes `data` to `path` and checks that every byte and the close went through; no fsync: for
// outputs that are remade by running again (rendered images, maps, clouds). A plain file (or a
// new one) is written beside under a name of its own (PATH.tmp.XXXXXX) and renamed over it, so a
// failed write leaves the old file whole and no partial one; anything else (a symbolic link such
// as /dev/stdout, a device, a pipe) is written through in place.
// Empty on success, else "PATH: reason".
std::string writeWholeFile(const std::filesystem::path& path, std::string_view data);

// Appends `text` (whole lines, by convention) to `path`, creating it, and waits until the data is
// on the disk (fdatasync): after a crash the file holds every append that returned, and at most a
// torn last line of one that did not. Empty on success, else "PATH: reason".
std::string appendDurably(const std::filesystem::path& path, std::string_view text);

}  // namespace fieldrig::core
