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
#include <mutex>
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

// A feed of server-sent events (text/event-stream) that replies may open: each stream gets the
// feed's latest message whenever one is published. A stream that is still writing when more
// messages arrive gets only the newest afterwards, so a slow client never queues stale states
// and never holds the publisher up. Thread-safe.
class EventFeed {
 public:
  // `message` is complete SSE text ("event: NAME\ndata: ONE LINE\n\n").
  void publish(std::string message);
  std::size_t subscribers() const;

  // For HttpServer's streams: the latest message and its number (0: none yet), and the calls
  // made (on the publisher's thread) when a new one is published.
  std::pair<std::uint64_t, std::shared_ptr<const std::string>> latest() const;
  using Waker = std::function<void()>;
  std::uint64_t subscribe(Waker waker);
  void unsubscribe(std::uint64_t id);

 private:
  mutable std::mutex mutex_;
  std::uint64_t sequence_ = 0;
  std::shared_ptr<const std::string> latest_;
  std::uint64_t next_id_ = 1;
  std::vector<std::pair<std::uint64_t, Waker>> wakers_;
};

struct HttpReply {
  boost::beast::http::status status = boost::beast::http::status::ok;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>>
      headers;  // more fields: Allow, Content-Disposition
  // Set: the reply is an event stream (200, text/event-stream, no length, closed by either
  // side): `body` is sent first (e.g. "retry: 1000\n\n"), then the feed's messages until the
  // client goes, a write takes longer than write_timeout, or the server stops.
  std::shared_ptr<EventFeed> events = nullptr;
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
