// SPDX-License-Identifier: MIT
#include "cbrdf/status.h"

namespace cbrdf {

const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return "ok";
    case ErrorCode::kIo:
      return "io";
    case ErrorCode::kNotFound:
      return "not-found";
    case ErrorCode::kTruncated:
      return "truncated";
    case ErrorCode::kBadSignature:
      return "bad-signature";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kCorrupt:
      return "corrupt";
    case ErrorCode::kChecksum:
      return "checksum";
    case ErrorCode::kLimit:
      return "limit";
    case ErrorCode::kInvalidArgument:
      return "invalid-argument";
    case ErrorCode::kNumeric:
      return "numeric";
    case ErrorCode::kInternal:
      return "internal";
    case ErrorCode::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

}  // namespace cbrdf
