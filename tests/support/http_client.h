// A plain-socket HTTP/1.1 client for tests of the project's servers, able to misbehave as
// clients do: connect and send nothing, send half a request, or send a whole one and read the
// reply with a deadline.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdlib>
#include <string>
#include <string_view>

#include "support/fd_io.h"

namespace fieldrig::testing_support {

struct HttpClientReply {
  int status = 0;  // 0: no whole reply before the deadline or the close
  std::string body;
};

// A request with a Content-Length, keeping the connection alive unless `close` is set.
inline std::string httpRequestText(std::string_view method, std::string_view target,
                                   std::string_view body = {}, bool close = false) {
  std::string text;
  text.append(method).append(" ").append(target).append(" HTTP/1.1\r\nHost: localhost\r\n");
  if (close)
    text.append("Connection: close\r\n");
  if (!body.empty() || method == "POST")
    text.append("Content-Type: application/json\r\nContent-Length: ")
        .append(std::to_string(body.size()))
        .append("\r\n");
  return text.append("\r\n").append(body);
}

// One TCP connection to 127.0.0.1:port, closed when destroyed.
class HttpClient {
 public:
  using Milliseconds = std::chrono::milliseconds;

  explicit HttpClient(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd_ >= 0 && ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~HttpClient() {
    if (fd_ >= 0)
      ::close(fd_);
  }
  HttpClient(HttpClient&& other) noexcept
      : fd_(other.fd_), received_(std::move(other.received_)), closed_(other.closed_) {
    other.fd_ = -1;
  }
  HttpClient(const HttpClient&) = delete;
  HttpClient& operator=(const HttpClient&) = delete;
  HttpClient& operator=(HttpClient&&) = delete;

  bool connected() const { return fd_ >= 0; }
  bool send(std::string_view bytes) { return fd_ >= 0 && writeAll(fd_, bytes); }

  // The next whole reply (status line, headers, Content-Length body), waiting at most `timeout`.
  HttpClientReply readReply(Milliseconds timeout = std::chrono::seconds{10}) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto header_end = received_.find("\r\n\r\n");
      if (header_end != std::string::npos) {
        const std::string head = received_.substr(0, header_end);
        std::size_t length = 0;
        if (const auto at = lowercase(head).find("\ncontent-length:"); at != std::string::npos)
          length = std::strtoul(head.c_str() + at + 16, nullptr, 10);
        if (received_.size() >= header_end + 4 + length) {
          HttpClientReply reply;
          if (head.rfind("HTTP/1.", 0) == 0 && head.size() > 12)
            reply.status = std::atoi(head.c_str() + 9);
          reply.body = received_.substr(header_end + 4, length);
          received_.erase(0, header_end + 4 + length);
          return reply;
        }
      }
      if (!receive(deadline))
        return {};
    }
  }

  // For streams (text/event-stream): waits at most `timeout` until what was received since the
  // last take() contains `needle`; then returns all of it up to and including `needle` and keeps
  // the rest. "" when it did not come.
  std::string takeUntil(std::string_view needle, Milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      if (const auto at = received_.find(needle); at != std::string::npos) {
        std::string taken = received_.substr(0, at + needle.size());
        received_.erase(0, at + needle.size());
        return taken;
      }
      if (!receive(deadline))
        return "";
    }
  }

  // True when the server closes the connection within `timeout` (whatever it sent before).
  bool closedWithin(Milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (receive(deadline)) {
    }
    return closed_;
  }

 private:
  static std::string lowercase(std::string text) {
    for (char& c : text)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
  }

  // Appends what arrives before `deadline`; false on the deadline, a close or an error.
  bool receive(std::chrono::steady_clock::time_point deadline) {
    if (fd_ < 0 || closed_)
      return false;
    const auto left =
        std::chrono::duration_cast<Milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      return false;
    pollfd wait{fd_, POLLIN, 0};
    if (::poll(&wait, 1, static_cast<int>(left.count())) <= 0)
      return false;
    char buffer[65536];
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n <= 0) {
      closed_ = true;
      return false;
    }
    received_.append(buffer, static_cast<std::size_t>(n));
    return true;
  }

  int fd_ = -1;
  std::string received_;
  bool closed_ = false;
};

}  // namespace fieldrig::testing_support
