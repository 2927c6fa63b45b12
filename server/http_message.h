#ifndef HPOSE_SERVER_HTTP_MESSAGE_H_
#define HPOSE_SERVER_HTTP_MESSAGE_H_

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hpose::server {

// One HTTP request as the web view's server read it (server/http_request_parser.h).
struct HttpRequest {
  std::string method;  // as sent, e.g. "GET".
  std::string path;    // the target before '?', as sent.
  // The query, split at '&' and '=' and percent-decoded, in order.
  std::vector<std::pair<std::string, std::string>> params;
  // Header names in lower case, values without surrounding blanks, in order.
  std::vector<std::pair<std::string, std::string>> headers;
  std::string remote_addr;  // the peer's address, for logs.

  // The first value of query parameter `name`; "" when there is none.
  std::string Param(std::string_view name) const {
    for (const auto& [key, value] : params) {
      if (key == name) return value;
    }
    return "";
  }
  // The first value of header `lower_name` (lower case); "" when there is none.
  std::string Header(std::string_view lower_name) const {
    for (const auto& [key, value] : headers) {
      if (key == lower_name) return value;
    }
    return "";
  }
};

// What a handler answers: a status and a body of known length, or a `stream`, which the server
// calls again and again, each time with a writer, until it returns false or a write fails
// (Server-Sent Events). The connection closes after every answer.
struct HttpResponse {
  using Writer = std::function<bool(std::string_view)>;

  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // added to the answer's head.
  std::function<bool(const Writer&)> stream;
  std::function<void()> stream_done;  // called once when a stream ends (or is never started).
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_HTTP_MESSAGE_H_
