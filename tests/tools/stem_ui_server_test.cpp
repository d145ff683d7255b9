// `fieldrig stem-ui` as the built binary, under the 1,024 open-files limit a login shell gives,
// behind 2,000 connections that send nothing (issue 17). Before, one thread per connection with
// no timeout held a file descriptor for each: accepting failed at the limit, and the server spun
// on the error and answered nobody.
#include <sys/resource.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/http_client.h"
#include "support/temp_dir.h"

namespace fieldrig::testing_support {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kIdleConnections = 2000;

// The port from the first stdout line, "fieldrig stem-ui: serving http://127.0.0.1:PORT/".
int servedPort(const std::string& line) {
  const std::string marker = "127.0.0.1:";
  const auto at = line.find(marker);
  return at == std::string::npos ? -1 : std::atoi(line.c_str() + at + marker.size());
}

std::size_t openFiles(pid_t pid) {
  std::error_code ec;
  std::size_t count = 0;
  for (auto it = fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec);
       !ec && it != fs::directory_iterator(); it.increment(ec))
    ++count;
  return count;
}

TEST(StemUiServer, KeepsServingBehind2000IdleConnectionsUnderA1024FileLimit) {
  // This process holds the 2,000 client ends: it needs more than the server is given.
  rlimit limit{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &limit), 0);
  const rlim_t needed = kIdleConnections + 200;
  if (limit.rlim_max != RLIM_INFINITY && limit.rlim_max < needed)
    GTEST_SKIP() << "the hard open-files limit " << limit.rlim_max << " is below " << needed;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur < needed) {
    limit.rlim_cur = needed;
    ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &limit), 0);
  }

  ScopedTempDir dir("stem_ui_server");
  const fs::path session = dir / "session";
  const CliRun made =
      runFieldrig({"sim", "plots", "--out", session.string(), "--count", "1"}, dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.err;

  FieldrigProcess server({"-c", "ulimit -n 1024 && exec " + shellQuote(kFieldrigBinary) +
                                    " stem-ui " + shellQuote(session.string()) + " --port 0"},
                         dir.path(), "/bin/sh");
  ASSERT_TRUE(server.waitForStdoutLines(1)) << server.err();
  const int port = servedPort(server.outLines().front());
  ASSERT_GT(port, 0) << server.out();

  std::vector<HttpClient> idle;
  idle.reserve(kIdleConnections);
  int connected = 0;
  for (int i = 0; i < kIdleConnections; ++i) {
    idle.emplace_back(port);
    connected += idle.back().connected() ? 1 : 0;
  }
  EXPECT_EQ(connected, kIdleConnections);

  const auto start = std::chrono::steady_clock::now();
  HttpClient client(port);
  ASSERT_TRUE(client.send(httpRequestText("GET", "/api/sessions")));
  const HttpClientReply reply = client.readReply(20s);
  const auto elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start);
  ASSERT_EQ(reply.status, 200) << server.err();
  const auto sessions = nlohmann::json::parse(reply.body);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0]["name"], "session");
  // The same connection goes on serving (keep-alive), and so does a new one.
  ASSERT_TRUE(client.send(httpRequestText("GET", "/")));
  EXPECT_EQ(client.readReply(10s).status, 200);
  HttpClient another(port);
  ASSERT_TRUE(another.send(httpRequestText("GET", "/api/sessions", "", true)));
  EXPECT_EQ(another.readReply(10s).status, 200);

  // The server held no more than its cap of connections (a quarter of 1,024) and its own files.
  const std::size_t files = openFiles(server.pid());
  EXPECT_LT(files, 400u);
  std::cout << "answered in " << elapsed.count() << " s behind " << connected
            << " idle connections; the server has " << files << " files open\n";
}

}  // namespace
}  // namespace fieldrig::testing_support
