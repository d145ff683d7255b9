#include "stem_page/http_server.h"

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <thread>

namespace fieldrig::stem_page {
namespace {

namespace http = boost::beast::http;
using tcp = boost::asio::ip::tcp;

void serveConnection(tcp::socket socket, const HttpServer::Handler& handler) {
  boost::beast::flat_buffer buffer;
  boost::beast::error_code ec;
  for (;;) {
    http::request_parser<http::string_body> parser;
    parser.body_limit(1 << 20);
    http::read(socket, buffer, parser, ec);
    if (ec)
      break;
    const http::request<http::string_body>& request = parser.get();
    const HttpReply reply =
        handler(HttpRequest{request.method(), std::string(request.target()), request.body()});
    http::response<http::string_body> response{reply.status, request.version()};
    response.set(http::field::server, "fieldrig stem-ui");
    response.set(http::field::content_type, reply.content_type);
    response.set(http::field::cache_control, "no-store");
    if (!reply.disposition.empty())
      response.set(http::field::content_disposition, reply.disposition);
    response.keep_alive(request.keep_alive());
    response.body() = reply.body;
    response.prepare_payload();
    http::write(socket, response, ec);
    if (ec || !request.keep_alive())
      break;
  }
  socket.shutdown(tcp::socket::shutdown_send, ec);
}

}  // namespace

struct HttpServer::Impl {
  boost::asio::io_context io;
  tcp::acceptor acceptor{io};
};

HttpServer::HttpServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HttpServer::~HttpServer() = default;

core::Result<std::unique_ptr<HttpServer>> HttpServer::listen(
    const boost::asio::ip::address& address, std::uint16_t port) {
  auto impl = std::make_unique<Impl>();
  const tcp::endpoint endpoint(address, port);
  boost::system::error_code ec;
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec)
    impl->acceptor.set_option(boost::asio::socket_base::reuse_address(true), ec);
  if (!ec)
    impl->acceptor.bind(endpoint, ec);
  if (!ec)
    impl->acceptor.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return core::Error{"cannot listen on " + address.to_string() + ":" + std::to_string(port) +
                       ": " + ec.message()};
  }
  return std::unique_ptr<HttpServer>(new HttpServer(std::move(impl)));
}

std::uint16_t HttpServer::port() const {
  return impl_->acceptor.local_endpoint().port();
}

void HttpServer::run(const Handler& handler) {
  for (;;) {
    tcp::socket socket(impl_->io);
    boost::system::error_code ec;
    impl_->acceptor.accept(socket, ec);
    if (ec)
      continue;
    // Detached: the server never stops, and `handler` outlives every connection.
    std::thread([&handler, s = std::move(socket)]() mutable {
      serveConnection(std::move(s), handler);
    }).detach();
  }
}

}  // namespace fieldrig::stem_page
