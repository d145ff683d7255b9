// A page's HTTP routes as a table: method + path pattern → handler. A pattern's segments are
// literals or {names} ("/api/sessions/{session}/measure"). A request's path is split into
// percent-decoded segments first, and one that would leave the served tree ("." or "..", a slash,
// backslash or NUL inside a segment, in any spelling) is refused with 400 before any route sees
// it. No matching path is 404; a path that matches only for other methods is 405.
//
// Handlers report a bad request by throwing HttpError (reject()); every error reply is JSON
// {"error": "…"}. Thread contract: immutable after construction; dispatch() may run on several
// threads at once (the handlers do their own locking).
#pragma once

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/daemon/http_server.h"

namespace fieldrig::stem_page {

using daemon::HttpReply;
using daemon::HttpRequest;

struct HttpError {
  boost::beast::http::status status;
  std::string message;
};

// A name that stays in the folder it is joined to: not empty, not "." or "..", and without a
// slash, backslash or NUL. The route table holds every path segment of a request to it; handlers
// hold to it every name from a request body that they join to a folder.
bool isPlainName(std::string_view name);

[[noreturn]] inline void reject(boost::beast::http::status status, const std::string& message) {
  throw HttpError{status, message};
}

HttpReply jsonReply(const nlohmann::ordered_json& body,
                    boost::beast::http::status status = boost::beast::http::status::ok);

// The {name} segments of the matched pattern, decoded.
using PathParams = std::map<std::string, std::string, std::less<>>;

struct Route {
  using Handler = std::function<HttpReply(const PathParams&, const HttpRequest&)>;
  boost::beast::http::verb method;
  std::string pattern;
  Handler handler;
};

class RouteTable {
 public:
  explicit RouteTable(std::vector<Route> routes);

  HttpReply dispatch(const HttpRequest& request) const;

 private:
  struct CompiledRoute {
    Route route;
    std::vector<std::string> segments;  // "{name}" or a literal
  };
  HttpReply route(const HttpRequest& request) const;

  std::vector<CompiledRoute> routes_;
};

}  // namespace fieldrig::stem_page
