#include "fieldrig/daemon/status_server.h"

#include <boost/asio/ip/address.hpp>
#include <thread>

#include "fieldrig/daemon/http_server.h"

namespace fieldrig::daemon {
namespace {

namespace http = boost::beast::http;

// One request per connection, small and quick: a request larger than 8 KiB or slower than 5 s
// is dropped.
HttpServerOptions statusServerOptions() {
  HttpServerOptions options;
  options.name = "fieldrigd";
  options.request_timeout = std::chrono::seconds{5};
  options.write_timeout = std::chrono::seconds{5};
  options.body_limit = 8 << 10;
  options.header_limit = 8 << 10;
  options.keep_alive = false;
  options.threads = 1;
  return options;
}

HttpReply answer(const StatusServer::Snapshot& snapshot, const HttpRequest& request) {
  HttpReply reply;
  if (request.method != http::verb::get && request.method != http::verb::head) {
    reply = {
        http::status::method_not_allowed, "text/plain", "read-only\n", {{"Allow", "GET, HEAD"}}};
  } else if (request.target == "/status" || request.target == "/status.json") {
    reply = {http::status::ok, "application/json", snapshot().dump() + "\n", {}};
  } else if (request.target == "/healthz") {
    reply = {http::status::ok, "text/plain", "ok\n", {}};
  } else {
    reply = {http::status::not_found,
             "text/plain",
             "fieldrigd serves /status (JSON) and /healthz\n",
             {}};
  }
  if (request.method == http::verb::head)
    reply.body.clear();
  return reply;
}

}  // namespace

struct StatusServer::Impl {
  std::unique_ptr<HttpServer> server;
  std::thread thread;
};

core::Result<std::unique_ptr<StatusServer>> StatusServer::start(const std::string& address,
                                                                std::uint16_t port,
                                                                Snapshot snapshot) {
  boost::system::error_code error;
  const auto ip = boost::asio::ip::make_address(address, error);
  if (error)
    return core::Error{"status.address '" + address + "': not an IP address"};
  auto server = HttpServer::listen(ip, port, statusServerOptions());
  if (!server)
    return core::Error{"status server: " + server.error().message};
  auto impl = std::make_unique<Impl>();
  impl->server = std::move(*server);
  impl->thread = std::thread([server = impl->server.get(), snapshot = std::move(snapshot)] {
    server->run([&snapshot](const HttpRequest& request) { return answer(snapshot, request); });
  });
  return std::unique_ptr<StatusServer>(new StatusServer(std::move(impl)));
}

StatusServer::StatusServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

StatusServer::~StatusServer() {
  impl_->server->stop();
  if (impl_->thread.joinable())
    impl_->thread.join();
}

std::uint16_t StatusServer::port() const {
  return impl_->server->port();
}

}  // namespace fieldrig::daemon
