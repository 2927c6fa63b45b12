#ifndef HPOSE_SERVER_TOKEN_AUTH_H_
#define HPOSE_SERVER_TOKEN_AUTH_H_

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "core/common/status.h"

namespace hpose::server {

// What a bearer token may do. kRead: GetLatest, StreamPoses, ListTemplates, GetStatus.
// kEstimate: those and the Estimate / EstimateStereo calls (which cost the daemon CPU).
enum class TokenRole { kRead, kEstimate };

// Bearer tokens from a file, checked on every PoseService call (streams included): the client
// sends "authorization: Bearer TOKEN" metadata. Thread-safe after Load.
//
// File format: one token per line, "TOKEN ROLE" with ROLE "read" or "estimate"; blank lines and
// lines starting with '#' are ignored. Tokens are at least 16 characters, without spaces.
class TokenAuthorizer {
 public:
  // Fails (kInvalidArgument / kNotFound) naming the line that is wrong, or an empty file.
  static Result<std::unique_ptr<TokenAuthorizer>> Load(const std::string& path);
  // Same, from the file's text (`origin` names it in messages).
  static Result<std::unique_ptr<TokenAuthorizer>> Parse(const std::string& text,
                                                        const std::string& origin);

  // OK when the call carries a known token whose role allows `needed`; UNAUTHENTICATED when it
  // carries none or an unknown one, PERMISSION_DENIED when the role is too weak. Every token is
  // compared in full (constant time in the token's contents).
  grpc::Status Check(const grpc::ServerContext& context, TokenRole needed) const;
  // The same on the metadata value ("Bearer TOKEN"); `present` false when there was none.
  grpc::Status CheckValue(bool present, const std::string& value, TokenRole needed) const;

  size_t size() const { return tokens_.size(); }

 private:
  struct Entry {
    std::string token;
    TokenRole role;
  };
  std::vector<Entry> tokens_;
};

}  // namespace hpose::server

#endif  // HPOSE_SERVER_TOKEN_AUTH_H_
