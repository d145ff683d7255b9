// POSIX file helpers of the recording: whole writes, directory syncs, PGM headers, checksums,
// and the scan of index.jsonl that the writer (on reopen) and the reader share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/core/result.h"
#include "fieldrig/recording/session_format.h"

namespace fieldrig::recording::detail {

// Whole writes, folder syncs and atomic replacement are core's (one way to write a file that
// must survive a crash).
using core::readWholeFile;
using core::replaceFileAtomically;
using core::syncDirectory;
using core::writeFully;

// "P5\n<width> <height>\n255\n".
std::string pgmHeader(int width, int height);

struct PgmHeader {
  int width = 0;
  int height = 0;
  int max_value = 0;
  std::size_t header_bytes = 0;  // where the pixels start
};
// Parses a binary PGM header (whitespace and '#' comments allowed, as netpbm does).
std::optional<PgmHeader> parsePgmHeader(std::string_view data);

std::uint32_t crc32(std::span<const std::uint8_t> bytes);

// SHA-256 of a file's content as lowercase hex; empty with `error` set when it cannot be read.
std::string sha256File(const std::filesystem::path& path, std::string& error);

// index.jsonl split into sets. A line counts once its newline is written; bytes after the last
// newline are a torn line. A line that is not a valid set is an error naming PATH:LINE.
struct IndexScan {
  std::vector<IndexedSet> sets;
  std::optional<TornLine> torn_line;
  std::uint64_t whole_bytes = 0;  // bytes up to and including the last newline
};
core::Result<IndexScan> scanIndex(std::string_view content, const std::filesystem::path& path);

// The 1-based line number of byte `byte` (1-based, as nlohmann reports parse errors) of `text`.
std::string lineOf(std::string_view text, std::size_t byte);

}  // namespace fieldrig::recording::detail
