// A small HTTP/1.1 server (Boost.Beast, blocking, keep-alive) for a local tool's page: it reads
// each request, hands it to one handler and writes the reply. It knows nothing of paths; the
// handler (a RouteTable) does.
//
// Thread contract: run() takes over the calling thread to accept connections and serves each
// connection on a thread of its own, so the handler must be thread-safe.
#pragma once

#include <boost/asio/ip/address.hpp>
#include <boost/beast/http/status.hpp>
#include <boost/beast/http/verb.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "fieldrig/core/result.h"

namespace fieldrig::stem_page {

struct HttpRequest {
  boost::beast::http::verb method = boost::beast::http::verb::get;
  std::string target;  // as sent: path and query, still percent-encoded
  std::string body;
};

struct HttpReply {
  boost::beast::http::status status = boost::beast::http::status::ok;
  std::string content_type = "application/json";
  std::string body;
  std::string disposition;  // Content-Disposition, when the reply is a download
};

class HttpServer {
 public:
  using Handler = std::function<HttpReply(const HttpRequest&)>;

  // Listens on address:port (port 0: any free port); the error names the address and why.
  static core::Result<std::unique_ptr<HttpServer>> listen(const boost::asio::ip::address& address,
                                                          std::uint16_t port);
  ~HttpServer();

  std::uint16_t port() const;
  // Serves until the process ends. Request bodies are limited to 1 MiB.
  [[noreturn]] void run(const Handler& handler);

  struct Impl;

 private:
  explicit HttpServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldrig::stem_page
