#include "server/token_auth.h"

#include <algorithm>
#include <sstream>

#include "core/io/atomic_file.h"

namespace hpose::server {
namespace {

constexpr size_t kMinTokenLength = 16;
constexpr char kBearer[] = "Bearer ";

// Equal contents, in time that depends on the lengths only.
bool ConstantTimeEquals(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  const size_t n = std::max(a.size(), b.size());
  for (size_t i = 0; i < n; ++i) {
    const unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    const unsigned char y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    diff |= x ^ y;
  }
  return diff == 0;
}

}  // namespace

Result<std::unique_ptr<TokenAuthorizer>> TokenAuthorizer::Load(const std::string& path) {
  Result<std::string> text = ReadFile(path);
  if (!text.ok()) return text.error();
  return Parse(*text, path);
}

Result<std::unique_ptr<TokenAuthorizer>> TokenAuthorizer::Parse(const std::string& text,
                                                                const std::string& origin) {
  auto auth = std::unique_ptr<TokenAuthorizer>(new TokenAuthorizer());
  std::istringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream fields(line);
    std::string token, role, extra;
    if (!(fields >> token) || token[0] == '#') continue;
    const std::string where = origin + ":" + std::to_string(number) + ": ";
    if (!(fields >> role) || (fields >> extra)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       where + "expected 'TOKEN ROLE' (ROLE: read or estimate)");
    }
    if (token.size() < kMinTokenLength) {
      return MakeError(
          ErrorCode::kInvalidArgument,
          where + "the token is shorter than " + std::to_string(kMinTokenLength) + " characters");
    }
    if (role != "read" && role != "estimate") {
      return MakeError(ErrorCode::kInvalidArgument,
                       where + "unknown role '" + role + "' (expected read or estimate)");
    }
    auth->tokens_.push_back({token, role == "read" ? TokenRole::kRead : TokenRole::kEstimate});
  }
  if (auth->tokens_.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, origin + ": no tokens in the file");
  }
  return auth;
}

grpc::Status TokenAuthorizer::Check(const grpc::ServerContext& context, TokenRole needed) const {
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return CheckValue(false, "", needed);
  return CheckValue(true, std::string(it->second.data(), it->second.size()), needed);
}

grpc::Status TokenAuthorizer::CheckValue(bool present, const std::string& value,
                                         TokenRole needed) const {
  if (!present) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "this daemon needs a bearer token (metadata 'authorization: Bearer "
                        "TOKEN'; hpose query --token-file FILE)");
  }
  if (value.compare(0, sizeof(kBearer) - 1, kBearer) != 0) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "the authorization metadata must be 'Bearer TOKEN'");
  }
  const std::string token = value.substr(sizeof(kBearer) - 1);
  const Entry* match = nullptr;
  for (const Entry& e : tokens_) {  // every entry compared: no early exit.
    if (ConstantTimeEquals(e.token, token) && match == nullptr) match = &e;
  }
  if (match == nullptr) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "unknown bearer token");
  }
  if (needed == TokenRole::kEstimate && match->role != TokenRole::kEstimate) {
    return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                        "this token is read-only; Estimate calls need a token with the "
                        "'estimate' role");
  }
  return grpc::Status::OK;
}

}  // namespace hpose::server
