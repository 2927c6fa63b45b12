#include "server/http_request_parser.h"

#include <gtest/gtest.h>

#include <string>

namespace hpose::server {
namespace {

TEST(HttpRequestParserTest, FindsTheBlankLineThatEndsTheHead) {
  EXPECT_EQ(FindHttpHeadEnd("GET / HTTP/1.1\r\nHost: x\r\n\r\nbody"), 27u);
  EXPECT_EQ(FindHttpHeadEnd("GET / HTTP/1.1\nHost: x\n\nbody"), 24u);
  EXPECT_EQ(FindHttpHeadEnd("GET / HTTP/1.1\r\nHost: x\r\n"), std::string_view::npos);
  EXPECT_EQ(FindHttpHeadEnd("GET / HTTP/1.1\r\nHost: x\r\n\r"), std::string_view::npos);
  EXPECT_EQ(FindHttpHeadEnd(""), std::string_view::npos);
}

TEST(HttpRequestParserTest, ReadsMethodPathQueryAndHeaders) {
  const Result<HttpRequest> r = ParseHttpRequestHead(
      "GET /api/latest?estimator=depth&x=a%20b+c&flag&=v HTTP/1.1\r\n"
      "Host: 127.0.0.1:8080\r\n"
      "Accept:  text/html \t\r\n"
      "X-Empty:\r\n"
      "\r\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  const HttpRequest& q = r.value();
  EXPECT_EQ(q.method, "GET");
  EXPECT_EQ(q.path, "/api/latest");
  EXPECT_EQ(q.Param("estimator"), "depth");
  EXPECT_EQ(q.Param("x"), "a b c");
  EXPECT_EQ(q.Param("flag"), "");
  EXPECT_EQ(q.Param(""), "v");
  EXPECT_EQ(q.Param("missing"), "");
  ASSERT_EQ(q.headers.size(), 3u);
  EXPECT_EQ(q.Header("host"), "127.0.0.1:8080");
  EXPECT_EQ(q.Header("accept"), "text/html");  // names lower case, values trimmed.
  EXPECT_EQ(q.Header("x-empty"), "");
}

TEST(HttpRequestParserTest, BareLineFeedsAndHttp10AreAccepted) {
  const Result<HttpRequest> r = ParseHttpRequestHead("HEAD /healthz HTTP/1.0\nA: b\n\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r.value().method, "HEAD");
  EXPECT_EQ(r.value().Header("a"), "b");
}

TEST(HttpRequestParserTest, MalformedHeadsNameTheirFault) {
  const struct {
    const char* head;
    const char* fault;
  } cases[] = {
      {"GET /\r\n\r\n", "METHOD TARGET VERSION"},
      {"GET  / HTTP/1.1\r\n\r\n", "METHOD TARGET VERSION"},
      {"GET / HTTP/1.1 extra\r\n\r\n", "METHOD TARGET VERSION"},
      {"GET healthz HTTP/1.1\r\n\r\n", "does not start with '/'"},
      {"GET / HTTP/2.0\r\n\r\n", "HTTP/1.0 or HTTP/1.1"},
      {"G(T / HTTP/1.1\r\n\r\n", "the method is not a token"},
      {"AVERYLONGMETHODNAMEX / HTTP/1.1\r\n\r\n", "at most 16"},
      {"GET /a\x01 HTTP/1.1\r\n\r\n", "control character"},
      {"GET /?a=%4 HTTP/1.1\r\n\r\n", "percent escape"},
      {"GET /?a=%zz HTTP/1.1\r\n\r\n", "percent escape"},
      {"GET / HTTP/1.1\r\nno colon\r\n\r\n", "header line 1 is not 'Name: value'"},
      {"GET / HTTP/1.1\r\nA: b\r\nBad Name: c\r\n\r\n", "header line 2"},
      {"GET / HTTP/1.1\r\n folded: c\r\n\r\n", "header line 1"},
      {"GET / HTTP/1.1\r\nA: b\x7f\r\n\r\n", "control character"},
  };
  for (const auto& c : cases) {
    const Result<HttpRequest> r = ParseHttpRequestHead(c.head);
    ASSERT_FALSE(r.ok()) << c.head;
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument) << c.head;
    EXPECT_NE(r.error().message.find(c.fault), std::string::npos)
        << c.head << " -> " << r.error().message;
  }
}

TEST(HttpRequestParserTest, HeadsOverTheLimitsAreOutOfRange) {
  std::string many = "GET / HTTP/1.1\r\n";
  for (std::size_t i = 0; i < kMaxHttpHeaderLines; ++i) many += "A: b\r\n";
  ASSERT_TRUE(ParseHttpRequestHead(many + "\r\n").ok());
  const Result<HttpRequest> too_many = ParseHttpRequestHead(many + "A: b\r\n\r\n");
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.error().code, ErrorCode::kOutOfRange);
  EXPECT_NE(too_many.error().message.find("more than 64 header lines"), std::string::npos);

  const std::string large =
      "GET / HTTP/1.1\r\nA: " + std::string(kMaxHttpHeadBytes, 'v') + "\r\n\r\n";
  const Result<HttpRequest> too_large = ParseHttpRequestHead(large);
  ASSERT_FALSE(too_large.ok());
  EXPECT_EQ(too_large.error().code, ErrorCode::kOutOfRange);
}

}  // namespace
}  // namespace hpose::server
