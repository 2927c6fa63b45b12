#ifndef HPOSE_SERVER_HTTP_REQUEST_PARSER_H_
#define HPOSE_SERVER_HTTP_REQUEST_PARSER_H_

#include <cstddef>
#include <string_view>

#include "core/common/status.h"
#include "server/http_message.h"

namespace hpose::server {

// A request head (request line and header lines, up to the blank line) may hold at most this
// many bytes and header lines; a browser sends well under 2 KB and 20.
constexpr std::size_t kMaxHttpHeadBytes = 16 * 1024;
constexpr std::size_t kMaxHttpHeaderLines = 64;

// The offset just past the blank line that ends a request head in `buffer` (CRLF CRLF, or bare
// LF LF), or std::string_view::npos while it has not come.
std::size_t FindHttpHeadEnd(std::string_view buffer);

// Parses a request head of HTTP/1.0 or 1.1: "METHOD /target HTTP/1.x", then "Name: value"
// lines, each ended by CRLF (or a bare LF). kInvalidArgument naming what is malformed (the
// answer is 400); kOutOfRange for a head over the limits above (431).
Result<HttpRequest> ParseHttpRequestHead(std::string_view head);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HTTP_REQUEST_PARSER_H_
