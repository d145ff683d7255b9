#include "stem_page/route_table.h"

#include <boost/beast/http/verb.hpp>
#include <cctype>
#include <optional>
#include <sstream>

namespace fieldrig::stem_page {
namespace {

namespace http = boost::beast::http;

// "%2e%2e" and friends decoded, so that traversal is caught whatever its spelling.
std::optional<std::string> percentDecode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%') {
      if (i + 2 >= text.size() || !std::isxdigit(static_cast<unsigned char>(text[i + 1])) ||
          !std::isxdigit(static_cast<unsigned char>(text[i + 2])))
        return std::nullopt;
      out += static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

std::vector<std::string> splitPath(const std::string& path) {
  std::vector<std::string> segments;
  std::stringstream in(path);
  for (std::string segment; std::getline(in, segment, '/');) {
    if (!segment.empty())
      segments.push_back(segment);
  }
  return segments;
}

bool isParameter(const std::string& segment) {
  return segment.size() > 2 && segment.front() == '{' && segment.back() == '}';
}

}  // namespace

bool isPlainName(std::string_view name) {
  return !name.empty() && name != "." && name != ".." &&
         name.find_first_of(std::string_view("/\\\0", 3)) == std::string_view::npos;
}

HttpReply jsonReply(const nlohmann::ordered_json& body, http::status status) {
  // Invalid UTF-8 (a session folder's name, a hand-edited CSV) is replaced, not thrown: a reply
  // must not fail on one bad byte in one field.
  return {status,
          "application/json",
          body.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace),
          {}};
}

RouteTable::RouteTable(std::vector<Route> routes) {
  for (Route& route : routes) {
    std::vector<std::string> segments = splitPath(route.pattern);
    routes_.push_back({std::move(route), std::move(segments)});
  }
}

HttpReply RouteTable::dispatch(const HttpRequest& request) const {
  try {
    return route(request);
  } catch (const HttpError& error) {
    return jsonReply({{"error", error.message}}, error.status);
  } catch (const std::exception& error) {
    return jsonReply({{"error", std::string("internal error: ") + error.what()}},
                     http::status::internal_server_error);
  }
}

HttpReply RouteTable::route(const HttpRequest& request) const {
  const std::string path = request.target.substr(0, request.target.find('?'));
  std::vector<std::string> segments;
  for (const std::string& raw : splitPath(path)) {
    const std::optional<std::string> segment = percentDecode(raw);
    if (!segment)
      reject(http::status::bad_request, "malformed percent-encoding in the path");
    if (!isPlainName(*segment))
      reject(http::status::bad_request, "path traversal is not allowed: " + path);
    segments.push_back(*segment);
  }
  std::string allowed;  // methods of the routes whose pattern matches
  for (const CompiledRoute& compiled : routes_) {
    if (compiled.segments.size() != segments.size())
      continue;
    PathParams params;
    bool matches = true;
    for (std::size_t i = 0; i < segments.size() && matches; ++i) {
      const std::string& expected = compiled.segments[i];
      if (isParameter(expected))
        params[expected.substr(1, expected.size() - 2)] = segments[i];
      else
        matches = expected == segments[i];
    }
    if (!matches)
      continue;
    if (compiled.route.method == request.method)
      return compiled.route.handler(params, request);
    allowed.append(allowed.empty() ? "" : ", ")
        .append(std::string(http::to_string(compiled.route.method)));
  }
  if (!allowed.empty())
    reject(http::status::method_not_allowed, path + " takes " + allowed);
  reject(http::status::not_found, "no such page: " + path);
}

}  // namespace fieldrig::stem_page
