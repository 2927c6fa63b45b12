// Bytes as a client could send them to hposed's web view, read as the server reads a request
// head: every input is a request or an Error, never a crash; a request it accepts keeps the
// parser's promises, and any message quoting the input serialises as JSON.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "server/http_request_parser.h"
#include "server/http_server.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace hpose::server;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t end = FindHttpHeadEnd(bytes);
  if (end != std::string_view::npos && (end > size || end < 2 || bytes[end - 1] != '\n')) {
    std::abort();
  }
  const std::string_view head = end == std::string_view::npos ? bytes : bytes.substr(0, end);
  const hpose::Result<HttpRequest> request = ParseHttpRequestHead(head);
  if (!request.ok()) {
    HttpErrorJson("INVALID_ARGUMENT", request.error().message);
    return 0;
  }
  const HttpRequest& r = request.value();
  if (r.method.empty() || r.path.empty() || r.path.front() != '/' ||
      r.headers.size() > kMaxHttpHeaderLines) {
    std::abort();
  }
  for (const auto& [key, value] : r.params) {
    HttpErrorJson("INVALID_ARGUMENT", "parameter '" + key + "' = '" + value + "'");
  }
  HttpErrorJson("NOT_FOUND", "no page " + r.path);
  return 0;
}
