// A small HTTP/1.1 server (Boost.Beast, asynchronous) for a local page or a status port: it reads
// each request, hands it to one handler and writes the reply. It knows nothing of paths; the
// handler does (the stem page's RouteTable, the daemon's StatusServer).
//
// No client can stop it serving others. A request must arrive whole within `request_timeout`
// (an idle keep-alive connection is closed then too) and a reply be taken within
// `write_timeout`; headers and bodies are bounded; at most `max_connections` are open at once,
// and one more closes the connection that has waited longest for its client, so the newest client
// is served even behind thousands of idle ones. When accepting fails (no file descriptor left) it
// waits and tries again, instead of spinning.
//
// Thread contract: run() serves on the calling thread and `threads - 1` more, so the handler may
// run on several threads at once and must be thread-safe; stop() may be called from any thread.
#pragma once

#include <boost/asio/ip/address.hpp>
#include <boost/beast/http/status.hpp>
#include <boost/beast/http/verb.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::daemon {

struct HttpRequest {
  boost::beast::http::verb method = boost::beast::http::verb::get;
  std::string target;  // as sent: path and query, still percent-encoded
  std::string body;
};

struct HttpReply {
  boost::beast::http::status status = boost::beast::http::status::ok;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>>
      headers;  // more fields: Allow, Content-Disposition
};

struct HttpServerOptions {
  std::string name = "fieldrig";  // the Server header
  std::chrono::milliseconds request_timeout{20'000};
  std::chrono::milliseconds write_timeout{20'000};
  // 0: a quarter of the open-files limit, at most 256, so that connections never take the file
  // descriptors the handler needs.
  std::size_t max_connections = 0;
  std::size_t body_limit = 1 << 20;
  std::size_t header_limit = 16 << 10;
  bool keep_alive = true;  // false: one request per connection
  int threads = 2;
};

class HttpServer {
 public:
  using Handler = std::function<HttpReply(const HttpRequest&)>;

  // Listens on address:port (port 0: any free port); the error names the address and why.
  static core::Result<std::unique_ptr<HttpServer>> listen(const boost::asio::ip::address& address,
                                                          std::uint16_t port,
                                                          HttpServerOptions options = {});
  ~HttpServer();

  std::uint16_t port() const;
  std::size_t maxConnections() const;
  // Serves until stop(). An exception from the handler is answered 500, naming it.
  void run(Handler handler);
  void stop();

  struct Impl;

 private:
  explicit HttpServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldrig::daemon
