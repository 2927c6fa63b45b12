#include "server/http_request_parser.h"

#include <string>

namespace hpose::server {

namespace {

constexpr std::size_t kMaxMethodChars = 16;

// RFC 9110's token characters (method and header names).
bool IsTokenChar(char c) {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return true;
  return std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

bool IsToken(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!IsTokenChar(c)) return false;
  }
  return true;
}

// A target's characters: visible ASCII (RFC 3986 characters and the odd ones browsers send).
bool IsTargetChar(char c) { return c > 0x20 && c < 0x7f; }

// A header value's characters: visible, blank, or bytes of other encodings, never controls.
bool IsValueChar(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u == '\t' || (u >= 0x20 && u != 0x7f);
}

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decodes a query component ('+' is a space); false on a bad escape.
bool DecodeQueryPart(std::string_view in, std::string* out) {
  out->clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '+') {
      out->push_back(' ');
    } else if (in[i] == '%') {
      if (i + 2 >= in.size()) return false;
      const int hi = HexValue(in[i + 1]);
      const int lo = HexValue(in[i + 2]);
      if (hi < 0 || lo < 0) return false;
      out->push_back(static_cast<char>(hi * 16 + lo));
      i += 2;
    } else {
      out->push_back(in[i]);
    }
  }
  return true;
}

Result<HttpRequest> Malformed(const std::string& what) {
  return MakeError(ErrorCode::kInvalidArgument, "malformed request: " + what);
}

// Splits off the next line (without its CRLF or LF) from `rest`.
std::string_view NextLine(std::string_view* rest) {
  const std::size_t lf = rest->find('\n');
  std::string_view line = rest->substr(0, lf);
  rest->remove_prefix(lf == std::string_view::npos ? rest->size() : lf + 1);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

}  // namespace

std::size_t FindHttpHeadEnd(std::string_view buffer) {
  for (std::size_t lf = buffer.find('\n'); lf != std::string_view::npos;
       lf = buffer.find('\n', lf + 1)) {
    // The blank line: LF LF, or LF CR LF.
    if (lf + 1 < buffer.size() && buffer[lf + 1] == '\n') return lf + 2;
    if (lf + 2 < buffer.size() && buffer[lf + 1] == '\r' && buffer[lf + 2] == '\n') return lf + 3;
  }
  return std::string_view::npos;
}

Result<HttpRequest> ParseHttpRequestHead(std::string_view head) {
  if (head.size() > kMaxHttpHeadBytes) {
    return MakeError(ErrorCode::kOutOfRange, "request head of " + std::to_string(head.size()) +
                                                 " bytes; at most " +
                                                 std::to_string(kMaxHttpHeadBytes) + " are read");
  }
  HttpRequest request;
  std::string_view rest = head;
  const std::string_view line = NextLine(&rest);
  const std::size_t sp1 = line.find(' ');
  const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos) {
    return Malformed("the request line is not METHOD TARGET VERSION");
  }
  const std::string_view method = line.substr(0, sp1);
  const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (!IsToken(method) || method.size() > kMaxMethodChars) {
    return Malformed("the method is not a token of at most 16 characters");
  }
  if (version != "HTTP/1.1" && version != "HTTP/1.0") {
    return Malformed("the version is not HTTP/1.0 or HTTP/1.1");
  }
  if (target.empty() || target.front() != '/') {
    return Malformed("the target does not start with '/'");
  }
  for (char c : target) {
    if (!IsTargetChar(c)) return Malformed("the target holds a blank or control character");
  }
  request.method = std::string(method);
  const std::size_t question = target.find('?');
  request.path = std::string(target.substr(0, question));
  if (question != std::string_view::npos) {
    std::string_view query = target.substr(question + 1);
    while (!query.empty()) {
      const std::size_t amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      query.remove_prefix(amp == std::string_view::npos ? query.size() : amp + 1);
      if (pair.empty()) continue;
      const std::size_t eq = pair.find('=');
      std::string key;
      std::string value;
      if (!DecodeQueryPart(pair.substr(0, eq), &key) ||
          (eq != std::string_view::npos && !DecodeQueryPart(pair.substr(eq + 1), &value))) {
        return Malformed("a bad percent escape in the query");
      }
      request.params.emplace_back(std::move(key), std::move(value));
    }
  }
  while (!rest.empty()) {
    const std::string_view header = NextLine(&rest);
    if (header.empty()) break;  // the blank line.
    if (request.headers.size() == kMaxHttpHeaderLines) {
      return MakeError(ErrorCode::kOutOfRange,
                       "more than " + std::to_string(kMaxHttpHeaderLines) + " header lines");
    }
    const std::size_t colon = header.find(':');
    if (colon == std::string_view::npos || !IsToken(header.substr(0, colon))) {
      return Malformed("header line " + std::to_string(request.headers.size() + 1) +
                       " is not 'Name: value'");
    }
    const std::string_view value = TrimBlanks(header.substr(colon + 1));
    for (char c : value) {
      if (!IsValueChar(c)) {
        return Malformed("header line " + std::to_string(request.headers.size() + 1) +
                         " holds a control character");
      }
    }
    std::string name(header.substr(0, colon));
    for (char& c : name) {
      if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    request.headers.emplace_back(std::move(name), std::string(value));
  }
  return request;
}

}  // namespace hpose::server
