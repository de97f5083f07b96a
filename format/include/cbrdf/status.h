// SPDX-License-Identifier: MIT
/// @file
/// Errors as values: a stable code and a message a user can act on (naming file, chunk, offset).
/// Nothing in cbrdf throws across its API.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace cbrdf {

/// Stable numeric codes: never renumber, only append.
enum class ErrorCode : int {
  kOk = 0,
  kIo = 1,               ///< the operating system refused a read or write
  kNotFound = 2,         ///< a named file does not exist
  kTruncated = 3,        ///< the data ends before its declared content
  kBadSignature = 4,     ///< not a file of the expected kind
  kUnsupported = 5,      ///< a newer version or an unknown critical feature
  kCorrupt = 6,          ///< structurally invalid data
  kChecksum = 7,         ///< a checksum does not match
  kLimit = 8,            ///< a declared size exceeds a documented maximum
  kInvalidArgument = 9,  ///< a caller passed a value outside its domain
  kNumeric = 10,         ///< NaN, Inf or a value outside a parameter's domain in the data
  kInternal = 11,        ///< a bug in cbrdf
  kCancelled = 12,       ///< the caller cancelled the operation (a progress callback said stop)
};

/// The code's stable name ("kCorrupt" -> "corrupt"), for messages and JSON.
const char* error_code_name(ErrorCode code);

/// The result of an operation: ok, or an ErrorCode and a message naming what was wrong
/// (file, chunk, byte offset, argument) and what is allowed.
class [[nodiscard]] Status {
 public:
  Status() = default;  ///< An ok status.
  /// An error (code must not be kOk).
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  static Status ok_status() { return {}; }  ///< An ok status.

  bool ok() const { return code_ == ErrorCode::kOk; }      ///< Whether the operation succeeded.
  ErrorCode code() const { return code_; }                 ///< The stable code (kOk when ok).
  const std::string& message() const { return message_; }  ///< Empty when ok.
  /// Prefixes context, e.g. the file name: "foo.binary: too short".
  Status with_context(const std::string& context) const {
    if (ok()) return *this;
    return Status(code_, context + ": " + message_);
  }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

/// An ok status.
inline Status ok_status() {
  return Status();
}
/// An error status with the given code and message.
inline Status error(ErrorCode code, std::string message) {
  return Status(code, std::move(message));
}

/// A value or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] Expected {
 public:
  /// A value.
  Expected(T value) : v_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  /// The error explaining why there is no value (status must not be ok).
  Expected(Status status) : v_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    assert(!std::get<Status>(v_).ok() && "Expected built from an ok Status");
  }

  bool ok() const { return std::holds_alternative<T>(v_); }  ///< Whether a value is held.
  explicit operator bool() const { return ok(); }            ///< Same as ok().
  /// The error; an ok Status when a value is held.
  const Status& status() const {
    static const Status kOkStatus;
    return ok() ? kOkStatus : std::get<Status>(v_);
  }
  /** The value (only when ok()). */
  ///@{
  T& value() & { return std::get<T>(v_); }
  const T& value() const& { return std::get<T>(v_); }
  T&& value() && { return std::get<T>(std::move(v_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  ///@}

 private:
  std::variant<T, Status> v_;
};

}  // namespace cbrdf

/// Propagates a non-ok Status from an expression returning Status.
#define CBRDF_RETURN_IF_ERROR(expr)                \
  do {                                             \
    ::cbrdf::Status cbrdf_status_ = (expr);        \
    if (!cbrdf_status_.ok()) return cbrdf_status_; \
  } while (0)

/// Unwraps an expression returning `Expected<T>`: on an error, returns its Status unchanged from
/// the enclosing function (which returns `Status` or any `Expected<U>`); else moves the value into
/// `lhs`.
///
///     CBRDF_ASSIGN_OR_RETURN(auto bytes, read_file(path));
///     CBRDF_ASSIGN_OR_RETURN(model, decode_model(bytes));  // an existing variable
///
/// `lhs` declares a value (`auto x`, `Model m`) or names an assignable variable. A reference
/// (`const auto& x`) is not supported: it would name the macro's hidden temporary rather than own
/// its value. The macro is several statements (use braces around it under an `if`), and a type
/// with a comma in `lhs` needs an alias. Temporaries are unique per line, so one line holds one.
#define CBRDF_ASSIGN_OR_RETURN(lhs, expr) \
  CBRDF_ASSIGN_OR_RETURN_IMPL_(CBRDF_STATUS_CONCAT_(cbrdf_expected_, __LINE__), lhs, expr)

/// @cond internal
#define CBRDF_STATUS_CONCAT_INNER_(a, b) a##b
#define CBRDF_STATUS_CONCAT_(a, b) CBRDF_STATUS_CONCAT_INNER_(a, b)
#define CBRDF_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                 \
  if (!tmp.ok()) return tmp.status();                \
  lhs = std::move(tmp).value()
/// @endcond
