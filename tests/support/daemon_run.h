// Running the built fieldrigd in tests: to completion (runDaemon) or in the background
// (FieldrigProcess with kFieldrigdBinary), on the synthetic field the daemon_field CTest fixture
// makes once (`fieldrig simulate`), with a replay configuration written per test.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/fd_io.h"

namespace fieldrig::testing_support {

inline const std::string kFieldrigdBinary = FIELDRIG_BINARY_DIR "/daemon/fieldrigd";

// The synthetic field of the daemon_field fixture: 12 plots on 2 serpentine rows.
inline std::filesystem::path daemonField() {
  return std::filesystem::path(FIELDRIG_BINARY_DIR) / "tests" / "daemon" / "field";
}

// Runs `fieldrigd ARGS…` to completion.
inline CliRun runDaemon(const std::vector<std::string>& args,
                        const std::filesystem::path& work_dir) {
  return runProgram(kFieldrigdBinary, args, work_dir);
}

// DIR/NAME.yaml: replay of `field` into DIR/NAME/session, status on any free port. `extra` is
// appended (more keys, or a section of its own); `map` replaces the field's map when given.
inline std::filesystem::path writeReplayConfig(const std::filesystem::path& dir,
                                               const std::string& name,
                                               const std::filesystem::path& field,
                                               const std::string& camera_options = "",
                                               const std::string& extra = "",
                                               const std::filesystem::path& map = {}) {
  const std::filesystem::path path = dir / (name + ".yaml");
  std::ofstream out(path);
  out << "map: " << (map.empty() ? field / "map.csv" : map).string() << "\n"
      << "calibration: " << (field / "source-session" / "calib").string() << "\n"
      << "cameras:\n"
      << "  driver: sim\n"
      << "  frame_timeout_ms: 300\n"
      << (camera_options.empty() ? "" : "  options: {" + camera_options + "}\n") << "recording:\n"
      << "  dir: " << name << "/session\n"
      << "  fsync: none\n"
      << "status:\n"
      << "  port: 0\n"
      << "replay:\n"
      << "  nmea: " << (field / "drive.nmea").string() << "\n"
      << "  session: " << (field / "source-session").string() << "\n"
      << extra;
  return path;
}

// GET http://127.0.0.1:PORT/PATH: the body, or "" when nothing answered.
inline std::string httpGet(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return "";
  }
  writeAll(fd, "GET " + path + " HTTP/1.1\r\nHost: localhost\r\n\r\n");
  std::string response;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
    response.append(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  const auto body = response.find("\r\n\r\n");
  return body == std::string::npos ? "" : response.substr(body + 4);
}

// The status port fieldrigd announced on stderr ({"status_url":"http://127.0.0.1:PORT/status"}),
// or -1.
inline int statusPort(const std::string& stderr_text) {
  const std::string marker = "127.0.0.1:";
  const auto at = stderr_text.find("\"status_url\"");
  if (at == std::string::npos)
    return -1;
  const auto port = stderr_text.find(marker, at);
  return port == std::string::npos ? -1 : std::atoi(stderr_text.c_str() + port + marker.size());
}

}  // namespace fieldrig::testing_support
