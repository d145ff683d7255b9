#include "file_util.h"

#include "fieldrig/recording/checksum.h"

#include <fcntl.h>
#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace fieldrig::recording::detail {

std::string pgmHeader(int width, int height) {
  char text[48];
  const int n = std::snprintf(text, sizeof text, "P5\n%d %d\n255\n", width, height);
  return std::string(text, static_cast<std::size_t>(n));
}

std::optional<PgmHeader> parsePgmHeader(std::string_view data) {
  if (data.size() < 2 || data[0] != 'P' || data[1] != '5')
    return std::nullopt;
  std::size_t pos = 2;
  const auto is_space = [](char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  };
  // Three decimal fields separated by whitespace or comments, then exactly one whitespace byte.
  std::array<long long, 3> fields{};
  for (long long& field : fields) {
    for (;;) {
      while (pos < data.size() && is_space(data[pos]))
        ++pos;
      if (pos < data.size() && data[pos] == '#') {
        while (pos < data.size() && data[pos] != '\n')
          ++pos;
        continue;
      }
      break;
    }
    const std::size_t start = pos;
    field = 0;
    while (pos < data.size() && data[pos] >= '0' && data[pos] <= '9' && pos - start < 9)
      field = field * 10 + (data[pos++] - '0');
    if (pos == start)
      return std::nullopt;
  }
  if (pos >= data.size() || !is_space(data[pos]))
    return std::nullopt;
  PgmHeader header;
  header.width = static_cast<int>(fields[0]);
  header.height = static_cast<int>(fields[1]);
  header.max_value = static_cast<int>(fields[2]);
  header.header_bytes = pos + 1;
  return header;
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  // zlib takes a uInt length; frames are far below 4 GiB, but a span need not be.
  while (!bytes.empty()) {
    const std::size_t chunk = std::min<std::size_t>(bytes.size(), 1u << 30);
    crc = ::crc32(crc, bytes.data(), static_cast<uInt>(chunk));
    bytes = bytes.subspan(chunk);
  }
  return static_cast<std::uint32_t>(crc);
}

std::string sha256File(const std::filesystem::path& path, std::string& error) {
  const std::optional<std::string> content = readWholeFile(path, error);
  if (!content)
    return {};
  std::string hex = sha256Hex(*content);
  if (hex.empty())
    error = path.string() + ": SHA-256 failed";
  return hex;
}

core::Result<IndexScan> scanIndex(std::string_view content, const std::filesystem::path& path) {
  IndexScan scan;
  std::uint64_t line_number = 0;
  std::size_t pos = 0;
  while (pos < content.size()) {
    ++line_number;
    const std::size_t end = content.find('\n', pos);
    if (end == std::string_view::npos) {
      scan.torn_line = TornLine{line_number, pos, content.size() - pos};
      break;
    }
    std::string error;
    std::optional<IndexedSet> set = fromIndexLine(content.substr(pos, end - pos), error);
    if (!set)
      return core::Error{path.string() + ":" + std::to_string(line_number) + ": " + error};
    if (!scan.sets.empty() && set->set_index <= scan.sets.back().set_index) {
      return core::Error{path.string() + ":" + std::to_string(line_number) + ": set " +
                         std::to_string(set->set_index) + " does not follow set " +
                         std::to_string(scan.sets.back().set_index)};
    }
    scan.sets.push_back(std::move(*set));
    pos = end + 1;
    scan.whole_bytes = pos;
  }
  return scan;
}

std::string lineOf(std::string_view text, std::size_t byte) {
  const std::size_t end = std::min(byte, text.size());
  std::size_t line = 1;
  for (std::size_t i = 0; i + 1 < end; ++i)
    line += text[i] == '\n' ? 1 : 0;
  return std::to_string(line);
}

}  // namespace fieldrig::recording::detail

namespace fieldrig::recording {

std::string sha256Hex(std::string_view bytes) {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(),
                                                                  &EVP_MD_CTX_free);
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (!context || EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) != 1 ||
      EVP_DigestUpdate(context.get(), bytes.data(), bytes.size()) != 1 ||
      EVP_DigestFinal_ex(context.get(), digest.data(), &length) != 1) {
    return {};
  }
  std::string hex;
  char pair[3];
  for (unsigned int i = 0; i < length; ++i) {
    std::snprintf(pair, sizeof pair, "%02x", digest[i]);
    hex += pair;
  }
  return hex;
}

}  // namespace fieldrig::recording
