// The one error rule of hpose: programming errors are assertions; expected
// failures (bad file, empty cloud, no floor, unknown template, ...) are returned as an Error with
// a reason. server/ turns an Error into a grpc::Status, tools/ into a message and an exit code.
#ifndef HPOSE_CORE_COMMON_STATUS_H_
#define HPOSE_CORE_COMMON_STATUS_H_

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace hpose {

// Mirrors the subset of canonical gRPC codes that core failures fall into.
enum class ErrorCode {
  kInvalidArgument,     // the caller's input is malformed (wrong sizes, NaN, bad option).
  kNotFound,            // a named file or template does not exist.
  kDataLoss,            // a file exists but is corrupt or truncated.
  kFailedPrecondition,  // the input is well formed but cannot be processed (no floor found).
  kOutOfRange,          // a value outside the supported range (too large a request).
  kUnavailable,         // a source (device, recording) cannot deliver now.
  kInternal,            // an unexpected failure inside a library we call.
};

// Stable lowercase name of a code, e.g. "invalid_argument".
const char* ErrorCodeName(ErrorCode code);

struct Error {
  ErrorCode code = ErrorCode::kInternal;
  std::string message;  // names what is wrong, e.g. "depth.png: not a 16-bit PNG".

  std::string ToString() const;
};

inline Error MakeError(ErrorCode code, std::string message) {
  return Error{code, std::move(message)};
}

// A value or an Error. Accessing the wrong alternative is a programming error (asserts).
template <typename T>
class Result {
 public:
  Result(T value) : data_(std::move(value)) {}      // NOLINT: implicit by design.
  Result(Error error) : data_(std::move(error)) {}  // NOLINT: implicit by design.

  bool ok() const { return std::holds_alternative<T>(data_); }
  explicit operator bool() const { return ok(); }

  const T& value() const& {
    assert(ok());
    return std::get<T>(data_);
  }
  T& value() & {
    assert(ok());
    return std::get<T>(data_);
  }
  T&& value() && {
    assert(ok());
    return std::get<T>(std::move(data_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  const Error& error() const {
    assert(!ok());
    return std::get<Error>(data_);
  }

 private:
  std::variant<T, Error> data_;
};

// Result of an operation that yields nothing but may fail.
class Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT: implicit by design.

  static Status Ok() { return Status(); }
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const {
    assert(!ok_);
    return error_;
  }

 private:
  Error error_;
  bool ok_ = true;
};

}  // namespace hpose

#endif  // HPOSE_CORE_COMMON_STATUS_H_
