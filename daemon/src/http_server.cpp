#include "fieldrig/daemon/http_server.h"

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <cerrno>
#include <list>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "fieldrig/core/exception_message.h"

namespace fieldrig::daemon {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

// How long to wait before accepting again after a failure such as "too many open files".
constexpr std::chrono::milliseconds kAcceptRetry{50};

std::size_t defaultMaxConnections() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
    return 256;
  return std::clamp<std::size_t>(static_cast<std::size_t>(limit.rlim_cur / 4), 4, 256);
}

class Connection;

// An open connection, as the server's list holds it.
struct ConnectionEntry {
  std::weak_ptr<Connection> connection;
  // When it began waiting for its client (a request, or the taking of a reply); nullopt while
  // its handler runs, and once it is being closed.
  std::optional<Clock::time_point> waiting_since;
};

}  // namespace

struct HttpServer::Impl {
  HttpServerOptions options;
  Handler handler;
  // The open connections, for the cap and for closing the longest-waiting one. Declared before
  // `io`: connections that io's pending handlers still own unregister here when io is destroyed.
  std::mutex mutex;
  std::list<ConnectionEntry> connections;  // guarded by mutex
  asio::io_context io;
  tcp::acceptor acceptor{io};
  asio::steady_timer retry{io};

  void accept();
  void onAccept(beast::error_code error, tcp::socket socket);
  void closeLongestWaiting();
};

namespace {

// One client's connection: read a request, answer it, and again while it keeps the connection
// alive. Its socket's executor is a strand, so its handlers never run at once.
class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(tcp::socket socket, HttpServer::Impl& server)
      : server_(server), stream_(std::move(socket)) {}

  ~Connection() {
    if (feed_ && subscription_ != 0)
      feed_->unsubscribe(subscription_);
    std::lock_guard lock(server_.mutex);
    if (self_)
      server_.connections.erase(*self_);
  }

  // Registers the connection (under the server's mutex) and starts reading on its strand.
  void start() {
    {
      std::lock_guard lock(server_.mutex);
      self_ = server_.connections.insert(server_.connections.end(), {weak_from_this(), {}});
    }
    asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
  }

  // From any thread: closes the socket on the connection's strand; the pending read or write
  // ends with operation_aborted and the connection goes away.
  void close() {
    asio::post(stream_.get_executor(), [self = shared_from_this()] {
      beast::error_code ignored;
      self->stream_.socket().close(ignored);
    });
  }

 private:
  void waiting(bool waiting) {
    std::lock_guard lock(server_.mutex);
    (*self_)->waiting_since = waiting ? std::optional(Clock::now()) : std::nullopt;
  }

  void read() {
    parser_.emplace();
    parser_->body_limit(server_.options.body_limit);
    parser_->header_limit(static_cast<std::uint32_t>(server_.options.header_limit));
    stream_.expires_after(server_.options.request_timeout);
    waiting(true);
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code error, std::size_t) { self->onRead(error); });
  }

  void onRead(beast::error_code error) {
    waiting(false);
    if (error) {
      // A request that broke the rules is told why; a client that went away or stayed silent
      // past the timeout is simply dropped.
      if (error == http::error::body_limit) {
        answer(errorReply(http::status::payload_too_large,
                          "request body larger than " + std::to_string(server_.options.body_limit) +
                              " bytes"),
               11, false);
      } else if (error == http::error::header_limit) {
        answer(errorReply(http::status::request_header_fields_too_large,
                          "request header larger than " +
                              std::to_string(server_.options.header_limit) + " bytes"),
               11, false);
      } else if (error.category() == http::make_error_code(http::error::bad_target).category() &&
                 error != http::error::end_of_stream && error != http::error::partial_message) {
        answer(errorReply(http::status::bad_request, "malformed request: " + error.message()), 11,
               false);
      } else {
        shutdown();
      }
      return;
    }
    const http::request<http::string_body>& request = parser_->get();
    HttpReply reply;
    try {
      reply = server_.handler(
          HttpRequest{request.method(), std::string(request.target()), request.body()});
    } catch (...) {
      reply = errorReply(http::status::internal_server_error,
                         "internal error: " + core::currentExceptionMessage());
    }
    if (reply.events) {
      stream(std::move(reply));
      return;
    }
    answer(std::move(reply), request.version(), server_.options.keep_alive && request.keep_alive());
  }

  static HttpReply errorReply(http::status status, const std::string& message) {
    return {status, "text/plain; charset=utf-8", message + "\n", {}};
  }

  void answer(HttpReply reply, unsigned version, bool keep_alive) {
    response_ = {};
    response_.result(reply.status);
    response_.version(version);
    response_.set(http::field::server, server_.options.name);
    response_.set(http::field::content_type, reply.content_type);
    response_.set(http::field::cache_control, "no-store");
    for (const auto& [name, value] : reply.headers)
      response_.set(name, value);
    response_.keep_alive(keep_alive);
    response_.body() = std::move(reply.body);
    response_.prepare_payload();
    stream_.expires_after(server_.options.write_timeout);
    waiting(true);
    http::async_write(
        stream_, response_,
        [self = shared_from_this(), keep_alive](beast::error_code error, std::size_t) {
          if (error || !keep_alive)
            self->shutdown();
          else
            self->read();
        });
  }

  void shutdown() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  // An event stream: the header by hand (HTTP/1.1 with no length: the body runs until the
  // connection closes), the reply's body, then the feed's latest message whenever it changes.
  // The connection counts as waiting from now on, so that at the cap a stream makes room before
  // a client whose request is under way.
  void stream(HttpReply reply) {
    feed_ = std::move(reply.events);
    std::string head = "HTTP/1.1 200 OK\r\nServer: " + server_.options.name +
                       "\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n"
                       "Connection: close\r\n";
    for (const auto& [name, value] : reply.headers)
      head += name + ": " + value + "\r\n";
    pending_ = std::make_shared<const std::string>(head + "\r\n" + reply.body);
    waiting(true);
    std::weak_ptr<Connection> weak = weak_from_this();
    const auto executor = stream_.get_executor();
    subscription_ = feed_->subscribe([weak, executor] {
      if (const auto self = weak.lock())
        asio::post(executor, [self] { self->writeEvents(); });
    });
    stream_.expires_never();
    watchClient();
    writeEvents();
  }

  // A read stays pending for the stream's life: it holds the connection while no write does, and
  // ends the stream when the client closes (or the server closes the socket). What a client
  // sends on a stream is read and ignored.
  void watchClient() {
    stream_.async_read_some(asio::buffer(ignored_),
                            [self = shared_from_this()](beast::error_code error, std::size_t) {
                              if (error)
                                self->endStream();
                              else
                                self->watchClient();
                            });
  }

  // On the strand: writes what is pending, else the feed's latest message if not yet sent.
  void writeEvents() {
    if (writing_ || closed_)
      return;
    if (!pending_) {
      auto [sequence, message] = feed_->latest();
      if (sequence == sent_sequence_ || !message)
        return;
      sent_sequence_ = sequence;
      pending_ = std::move(message);
    }
    writing_ = true;
    stream_.expires_after(server_.options.write_timeout);
    asio::async_write(stream_, asio::buffer(*pending_),
                      [self = shared_from_this()](beast::error_code error, std::size_t) {
                        self->writing_ = false;
                        self->pending_.reset();
                        if (error) {
                          self->endStream();
                          return;
                        }
                        self->stream_.expires_never();
                        self->writeEvents();
                      });
  }

  void endStream() {
    closed_ = true;
    if (feed_ && subscription_ != 0)
      feed_->unsubscribe(std::exchange(subscription_, 0));
    beast::error_code ignored;
    stream_.socket().close(ignored);
  }

  HttpServer::Impl& server_;
  // Its entry in server_.connections, once registered; guarded by server_.mutex.
  std::optional<std::list<ConnectionEntry>::iterator> self_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  http::response<http::string_body> response_;
  // An event stream's (see stream()); strand only, except subscription_ set once.
  std::shared_ptr<EventFeed> feed_;
  std::uint64_t subscription_ = 0;
  std::shared_ptr<const std::string> pending_;
  std::uint64_t sent_sequence_ = 0;
  bool writing_ = false;
  bool closed_ = false;
  std::array<char, 256> ignored_{};
};

}  // namespace

void EventFeed::publish(std::string message) {
  std::vector<Waker> wakers;
  {
    std::lock_guard lock(mutex_);
    ++sequence_;
    latest_ = std::make_shared<const std::string>(std::move(message));
    for (const auto& [id, waker] : wakers_)
      wakers.push_back(waker);
  }
  // Outside the lock: a waker only posts to its connection's strand.
  for (const Waker& waker : wakers)
    waker();
}

std::size_t EventFeed::subscribers() const {
  std::lock_guard lock(mutex_);
  return wakers_.size();
}

std::pair<std::uint64_t, std::shared_ptr<const std::string>> EventFeed::latest() const {
  std::lock_guard lock(mutex_);
  return {sequence_, latest_};
}

std::uint64_t EventFeed::subscribe(Waker waker) {
  std::lock_guard lock(mutex_);
  const std::uint64_t id = next_id_++;
  wakers_.emplace_back(id, std::move(waker));
  return id;
}

void EventFeed::unsubscribe(std::uint64_t id) {
  std::lock_guard lock(mutex_);
  std::erase_if(wakers_, [id](const auto& entry) { return entry.first == id; });
}

void HttpServer::Impl::accept() {
  acceptor.async_accept(asio::make_strand(io), [this](beast::error_code error, tcp::socket socket) {
    onAccept(error, std::move(socket));
  });
}

void HttpServer::Impl::onAccept(beast::error_code error, tcp::socket socket) {
  if (error == asio::error::operation_aborted)
    return;  // stopped
  if (error) {
    // Out of file descriptors (or another passing failure): the client waits in the listen
    // queue while a waiting connection makes room; accepting again at once would spin.
    if (error == asio::error::no_descriptors || error.value() == ENFILE)
      closeLongestWaiting();
    retry.expires_after(kAcceptRetry);
    retry.async_wait([this](beast::error_code waited) {
      if (!waited)
        accept();
    });
    return;
  }
  bool full = false;
  {
    std::lock_guard lock(mutex);
    full = connections.size() >= options.max_connections;
  }
  if (full)
    closeLongestWaiting();
  std::make_shared<Connection>(std::move(socket), *this)->start();
  accept();
}

void HttpServer::Impl::closeLongestWaiting() {
  // Only weak references are touched under the lock: the last reference to a connection may
  // be dropped here, and its destructor takes the lock.
  std::weak_ptr<Connection> oldest;
  {
    std::lock_guard lock(mutex);
    ConnectionEntry* found = nullptr;
    for (ConnectionEntry& entry : connections) {
      if (entry.waiting_since && (!found || *entry.waiting_since < *found->waiting_since))
        found = &entry;
    }
    if (found) {
      oldest = found->connection;
      found->waiting_since.reset();  // being closed: not chosen again before it is gone
    }
  }
  if (const std::shared_ptr<Connection> connection = oldest.lock())
    connection->close();
}

HttpServer::HttpServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HttpServer::~HttpServer() = default;

core::Result<std::unique_ptr<HttpServer>> HttpServer::listen(
    const boost::asio::ip::address& address, std::uint16_t port, HttpServerOptions options) {
  auto impl = std::make_unique<Impl>();
  if (options.max_connections == 0)
    options.max_connections = defaultMaxConnections();
  options.threads = std::max(options.threads, 1);
  impl->options = std::move(options);
  const tcp::endpoint endpoint(address, port);
  boost::system::error_code ec;
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec)
    impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec)
    impl->acceptor.bind(endpoint, ec);
  if (!ec)
    impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return core::Error{"cannot listen on " + address.to_string() + ":" + std::to_string(port) +
                       ": " + ec.message()};
  }
  return std::unique_ptr<HttpServer>(new HttpServer(std::move(impl)));
}

std::uint16_t HttpServer::port() const {
  return impl_->acceptor.local_endpoint().port();
}

std::size_t HttpServer::maxConnections() const {
  return impl_->options.max_connections;
}

void HttpServer::run(Handler handler) {
  impl_->handler = std::move(handler);
  impl_->accept();
  std::vector<std::thread> threads;
  for (int i = 1; i < impl_->options.threads; ++i)
    threads.emplace_back([this] { impl_->io.run(); });
  impl_->io.run();
  for (std::thread& thread : threads)
    thread.join();
}

void HttpServer::stop() {
  impl_->io.stop();
}

}  // namespace fieldrig::daemon
