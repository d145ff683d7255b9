#include "fieldrig/daemon/status_server.h"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include <chrono>
#include <thread>

namespace fieldrig::daemon {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

constexpr auto kRequestTimeout = std::chrono::seconds{5};

// One connection: read a request, answer it, close. Small and bounded: a request larger than
// 8 KiB or slower than the timeout is dropped.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket socket, const StatusServer::Snapshot& snapshot)
      : stream_(std::move(socket)), snapshot_(snapshot) {}

  void run() {
    parser_.body_limit(8 * 1024);
    parser_.header_limit(8 * 1024);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, parser_,
                     [self = shared_from_this()](beast::error_code error, std::size_t) {
                       if (!error)
                         self->answer();
                     });
  }

 private:
  void answer() {
    const auto& request = parser_.get();
    auto response = std::make_shared<http::response<http::string_body>>();
    response->version(request.version());
    response->keep_alive(false);
    response->set(http::field::server, "fieldrigd");
    response->set(http::field::cache_control, "no-store");
    const std::string target(request.target());
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      response->result(http::status::method_not_allowed);
      response->set(http::field::allow, "GET, HEAD");
      response->body() = "read-only\n";
    } else if (target == "/status" || target == "/status.json") {
      response->result(http::status::ok);
      response->set(http::field::content_type, "application/json");
      response->body() = snapshot_().dump() + "\n";
    } else if (target == "/healthz") {
      response->result(http::status::ok);
      response->set(http::field::content_type, "text/plain");
      response->body() = "ok\n";
    } else {
      response->result(http::status::not_found);
      response->set(http::field::content_type, "text/plain");
      response->body() = "fieldrigd serves /status (JSON) and /healthz\n";
    }
    if (request.method() == http::verb::head)
      response->body().clear();
    response->prepare_payload();
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code, std::size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                      });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::string_body> parser_;
  const StatusServer::Snapshot& snapshot_;
};

}  // namespace

struct StatusServer::Impl {
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  Snapshot snapshot;
  std::thread thread;

  void accept() {
    acceptor.async_accept(asio::make_strand(io),
                          [this](beast::error_code error, tcp::socket socket) {
                            if (error == asio::error::operation_aborted)
                              return;
                            if (!error)
                              std::make_shared<Session>(std::move(socket), snapshot)->run();
                            accept();
                          });
  }
};

core::Result<std::unique_ptr<StatusServer>> StatusServer::start(const std::string& address,
                                                                std::uint16_t port,
                                                                Snapshot snapshot) {
  auto impl = std::make_unique<Impl>();
  impl->snapshot = std::move(snapshot);
  beast::error_code error;
  const auto ip = asio::ip::make_address(address, error);
  if (error)
    return core::Error{"status.address '" + address + "': not an IP address"};
  const tcp::endpoint endpoint(ip, port);
  impl->acceptor.open(endpoint.protocol(), error);
  if (!error)
    impl->acceptor.set_option(asio::socket_base::reuse_address(true), error);
  if (!error)
    impl->acceptor.bind(endpoint, error);
  if (!error)
    impl->acceptor.listen(asio::socket_base::max_listen_connections, error);
  if (error) {
    return core::Error{"status server: cannot listen on " + address + ":" + std::to_string(port) +
                       ": " + error.message()};
  }
  impl->accept();
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->io.run(); });
  return std::unique_ptr<StatusServer>(new StatusServer(std::move(impl)));
}

StatusServer::StatusServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

StatusServer::~StatusServer() {
  asio::post(impl_->io, [impl = impl_.get()] {
    beast::error_code ignored;
    impl->acceptor.close(ignored);
    impl->io.stop();
  });
  if (impl_->thread.joinable())
    impl_->thread.join();
}

std::uint16_t StatusServer::port() const {
  return impl_->acceptor.local_endpoint().port();
}

}  // namespace fieldrig::daemon
