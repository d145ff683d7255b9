// The HTTP server of the status port and the stem page, in this process with small limits:
// keep-alive, a handler's exception as 500, the request timeout (idle and half-sent requests),
// the body limit, the connection cap that closes the longest-waiting connection for a new one,
// and running out of file descriptors, where it must wait and go on instead of spinning.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "fieldrig/daemon/http_server.h"
#include "support/http_client.h"

namespace fieldrig::daemon {
namespace {

using testing_support::HttpClient;
using testing_support::httpRequestText;
using namespace std::chrono_literals;
namespace http = boost::beast::http;

HttpReply echo(const HttpRequest& request) {
  if (request.target == "/throw")
    throw std::runtime_error("disk on fire");
  return {http::status::ok,
          "text/plain",
          std::string(http::to_string(request.method)) + " " + request.target + " " + request.body,
          {}};
}

// A server on 127.0.0.1, any port, serving `echo` on a thread of its own until destroyed.
class RunningServer {
 public:
  explicit RunningServer(HttpServerOptions options) {
    auto server = HttpServer::listen(boost::asio::ip::make_address("127.0.0.1"), 0, options);
    if (!server)
      throw std::runtime_error(server.error().message);
    server_ = std::move(*server);
    thread_ = std::thread([this] { server_->run(echo); });
  }
  ~RunningServer() {
    server_->stop();
    thread_.join();
  }
  int port() const { return server_->port(); }

 private:
  std::unique_ptr<HttpServer> server_;
  std::thread thread_;
};

TEST(HttpServer, AnswersKeepAliveRequestsAndAHandlersExceptionAs500) {
  RunningServer server({});
  HttpClient client(server.port());
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(client.send(httpRequestText("GET", "/a")));
  const auto first = client.readReply();
  EXPECT_EQ(first.status, 200);
  EXPECT_EQ(first.body, "GET /a ");
  ASSERT_TRUE(client.send(httpRequestText("POST", "/b", "{\"x\":1}")));
  const auto second = client.readReply();
  EXPECT_EQ(second.status, 200);
  EXPECT_EQ(second.body, "POST /b {\"x\":1}");
  ASSERT_TRUE(client.send(httpRequestText("GET", "/throw")));
  const auto failed = client.readReply();
  EXPECT_EQ(failed.status, 500);
  EXPECT_NE(failed.body.find("internal error: disk on fire"), std::string::npos) << failed.body;
  // Still the same connection, still serving.
  ASSERT_TRUE(client.send(httpRequestText("GET", "/c", "", true)));
  EXPECT_EQ(client.readReply().status, 200);
  EXPECT_TRUE(client.closedWithin(2s));
}

TEST(HttpServer, OneRequestPerConnectionWhenKeepAliveIsOff) {
  HttpServerOptions options;
  options.keep_alive = false;
  RunningServer server(options);
  HttpClient client(server.port());
  ASSERT_TRUE(client.send(httpRequestText("GET", "/a")));
  EXPECT_EQ(client.readReply().status, 200);
  EXPECT_TRUE(client.closedWithin(2s));
}

// A connection that sends nothing, and one that sends half a request, are both closed when the
// request timeout passes: neither holds a connection (and its file descriptor) for good.
TEST(HttpServer, ClosesConnectionsWhoseRequestDoesNotArriveWholeInTime) {
  HttpServerOptions options;
  options.request_timeout = 300ms;
  RunningServer server(options);
  HttpClient idle(server.port());
  HttpClient half(server.port());
  ASSERT_TRUE(half.send("GET /a HTTP/1.1\r\nHost: loc"));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(idle.closedWithin(5s));
  EXPECT_TRUE(half.closedWithin(5s));
  EXPECT_GE(std::chrono::steady_clock::now() - start, 250ms);
  // An idle keep-alive connection is closed the same way after its last reply.
  HttpClient kept(server.port());
  ASSERT_TRUE(kept.send(httpRequestText("GET", "/a")));
  EXPECT_EQ(kept.readReply().status, 200);
  EXPECT_TRUE(kept.closedWithin(5s));
}

TEST(HttpServer, RefusesABodyOverTheLimitWith413) {
  HttpServerOptions options;
  options.body_limit = 1024;
  RunningServer server(options);
  HttpClient client(server.port());
  ASSERT_TRUE(client.send(httpRequestText("POST", "/a", std::string(5000, 'x'))));
  const auto reply = client.readReply();
  EXPECT_EQ(reply.status, 413);
  EXPECT_NE(reply.body.find("larger than 1024 bytes"), std::string::npos) << reply.body;
  EXPECT_TRUE(client.closedWithin(2s));

  HttpClient garbage(server.port());
  ASSERT_TRUE(garbage.send("NOT HTTP AT ALL\r\n\r\n"));
  EXPECT_EQ(garbage.readReply().status, 400);
}

// 40 connections that send nothing against a cap of 8: each one beyond the cap closes the one
// that has waited longest, so the newest client is answered at once, and no more than the cap
// (and the few being closed) stay open.
TEST(HttpServer, ServesTheNewestClientBehindMoreIdleConnectionsThanItsCap) {
  HttpServerOptions options;
  options.max_connections = 8;
  options.request_timeout = 60s;
  RunningServer server(options);
  std::vector<HttpClient> idle;
  for (int i = 0; i < 40; ++i) {
    idle.emplace_back(server.port());
    ASSERT_TRUE(idle.back().connected());
  }
  HttpClient client(server.port());
  ASSERT_TRUE(client.send(httpRequestText("GET", "/served")));
  const auto reply = client.readReply(10s);
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.body, "GET /served ");
  EXPECT_TRUE(idle.front().closedWithin(5s)) << "the longest-waiting connection is still open";
  int closed = 0;
  for (HttpClient& connection : idle)
    closed += connection.closedWithin(100ms) ? 1 : 0;
  EXPECT_GE(closed, 40 - 8);
}

// With 40 file descriptors and no cap of its own below that, accepting fails with EMFILE once
// the idle connections take them all. The server then closes the longest-waiting connection and
// accepts again after a pause; before, a server that only re-accepted spun on the error and
// never served the client. Run in a child process: the limit is the process's.
TEST(HttpServer, GoesOnServingWhenOutOfFileDescriptors) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(pipe_fds[0]);
    rlimit limit{40, 40};
    ::setrlimit(RLIMIT_NOFILE, &limit);
    HttpServerOptions options;
    options.max_connections = 1000;
    options.request_timeout = 60s;
    options.threads = 1;
    auto server = HttpServer::listen(boost::asio::ip::make_address("127.0.0.1"), 0, options);
    const int port = server ? (*server)->port() : -1;
    if (::write(pipe_fds[1], &port, sizeof port) != sizeof port || !server)
      ::_exit(1);
    (*server)->run(echo);
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  int port = -1;
  ASSERT_EQ(::read(pipe_fds[0], &port, sizeof port), static_cast<ssize_t>(sizeof port));
  ::close(pipe_fds[0]);
  ASSERT_GT(port, 0);
  {
    std::vector<HttpClient> idle;
    for (int i = 0; i < 80; ++i)
      idle.emplace_back(port);
    HttpClient client(port);
    ASSERT_TRUE(client.send(httpRequestText("GET", "/served")));
    const auto reply = client.readReply(20s);
    EXPECT_EQ(reply.status, 200);
    EXPECT_EQ(reply.body, "GET /served ");
  }
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
}

}  // namespace
}  // namespace fieldrig::daemon
