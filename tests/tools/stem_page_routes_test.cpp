// The stem page's route table: patterns with {names}, percent-decoded segments, 404 and 405, JSON
// errors from handlers, and every spelling of a path that tries to leave the served tree refused
// before a handler runs.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "stem_page/route_table.h"

namespace fieldrig::stem_page {
namespace {

namespace http = boost::beast::http;
using Json = nlohmann::json;

class RouteTableTest : public ::testing::Test {
 protected:
  RouteTable table_{{
      {http::verb::get, "/", [this](auto&, auto&) { return called("page"); }},
      {http::verb::get, "/api/items/{id}",
       [this](const PathParams& p, auto&) { return called("get " + p.at("id")); }},
      {http::verb::post, "/api/items/{id}",
       [this](const PathParams& p, const HttpRequest& r) {
         return called("post " + p.at("id") + " " + r.body);
       }},
      {http::verb::delete_, "/api/items/{id}/last",
       [](auto&, auto&) -> HttpReply { reject(http::status::not_found, "nothing to delete"); }},
      {http::verb::get, "/api/broken",
       [](auto&, auto&) -> HttpReply { throw std::runtime_error("disk on fire"); }},
  }};
  std::vector<std::string> calls_;

  HttpReply called(const std::string& what) {
    calls_.push_back(what);
    return {http::status::ok, "text/plain", what, {}};
  }
  HttpReply send(http::verb method, const std::string& target, const std::string& body = "") {
    return table_.dispatch(HttpRequest{method, target, body});
  }
  static std::string error(const HttpReply& reply) {
    return Json::parse(reply.body).at("error").get<std::string>();
  }
};

TEST_F(RouteTableTest, MatchesMethodAndPatternAndDecodesTheParameters) {
  EXPECT_EQ(send(http::verb::get, "/").body, "page");
  EXPECT_EQ(send(http::verb::get, "/api/items/42").body, "get 42");
  EXPECT_EQ(send(http::verb::get, "/api/items/a%20b?zoom=2").body, "get a b");
  EXPECT_EQ(send(http::verb::post, "//api/items/7/", "{}").body, "post 7 {}");
  EXPECT_EQ(calls_.size(), 4u);
}

TEST_F(RouteTableTest, UnknownPathIs404AndOtherMethodIs405NamingTheAllowedOnes) {
  const HttpReply missing = send(http::verb::get, "/api/other");
  EXPECT_EQ(missing.status, http::status::not_found);
  EXPECT_EQ(missing.content_type, "application/json");
  EXPECT_NE(error(missing).find("/api/other"), std::string::npos);
  const HttpReply wrong_method = send(http::verb::put, "/api/items/1");
  EXPECT_EQ(wrong_method.status, http::status::method_not_allowed);
  EXPECT_NE(error(wrong_method).find("GET, POST"), std::string::npos) << error(wrong_method);
  EXPECT_TRUE(calls_.empty());
}

TEST_F(RouteTableTest, HandlerErrorsBecomeJsonReplies) {
  const HttpReply rejected = send(http::verb::delete_, "/api/items/1/last");
  EXPECT_EQ(rejected.status, http::status::not_found);
  EXPECT_EQ(error(rejected), "nothing to delete");
  const HttpReply thrown = send(http::verb::get, "/api/broken");
  EXPECT_EQ(thrown.status, http::status::internal_server_error);
  EXPECT_EQ(error(thrown), "internal error: disk on fire");
}

TEST_F(RouteTableTest, EveryWayOutOfTheTreeIsRefusedBeforeAHandlerRuns) {
  for (const char* target :
       {"/../etc/passwd", "/api/items/..", "/api/items/.", "/api/items/%2e%2e", "/api/items/%2E%2e",
        "/api/items/%2F..%2Fetc", "/api/items/a%5Cb", "/api/items/a%00", "/%2e%2e/api/items/1"}) {
    const HttpReply reply = send(http::verb::get, target);
    EXPECT_EQ(reply.status, http::status::bad_request) << target;
    EXPECT_NE(error(reply).find("path traversal"), std::string::npos) << target;
  }
  for (const char* target : {"/api/items/%zz", "/api/items/%4"}) {
    const HttpReply reply = send(http::verb::get, target);
    EXPECT_EQ(reply.status, http::status::bad_request) << target;
    EXPECT_NE(error(reply).find("percent-encoding"), std::string::npos) << target;
  }
  EXPECT_TRUE(calls_.empty());
}

TEST(IsPlainName, TakesANameThatStaysInItsFolderOnly) {
  for (const char* name : {"bottom", "head 2", "a.b", "..a", "%2e%2e"})
    EXPECT_TRUE(isPlainName(name)) << name;
  for (const std::string& name :
       {std::string(), std::string("."), std::string(".."), std::string("../x"),
        std::string("/etc"), std::string("a\\b"), std::string("a\0b", 3)})
    EXPECT_FALSE(isPlainName(name)) << name;
}

// A session folder's name or a hand-edited CSV may hold bytes that are not UTF-8: the reply
// carries a replacement character instead of failing (nlohmann::json throws on them by default).
TEST(JsonReply, ReplacesBytesThatAreNotUtf8) {
  const HttpReply reply = jsonReply({{"name", "plot\xff"}});
  EXPECT_EQ(reply.status, http::status::ok);
  EXPECT_EQ(Json::parse(reply.body).at("name"), "plot\xef\xbf\xbd");
}

}  // namespace
}  // namespace fieldrig::stem_page
