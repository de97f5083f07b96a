// SPDX-License-Identifier: MIT
// What the C API's encoder part (c_api_encoder.cc) uses from its decoder part (c_api_decoder.cc):
// the thread's last error and the boundary that turns Status values and exceptions into it. Not
// installed. Both parts are compiled into the encoder library (libcbrdf_encoder.so holds the
// format, decoder and encoder objects itself; it does not link libcbrdf_decoder.so), so one copy of
// the last error serves both.
#pragma once

#include <string>
#include <string_view>
#include <utility>

#include "cbrdf/cbrdf_decode.h"
#include "cbrdf/status.h"

// Shared by the C API's decoder and encoder halves, which always sit in one library
// (ARCHITECTURE.md: the shared libraries export the C API only). Not part of the public API: not
// installed.

namespace cbrdf::internal {

cbrdf_status to_c_status(ErrorCode code) noexcept;

// Records a failure as the calling thread's last error (when memory runs out, the message may be
// cut short or empty; the code is always kept).
void set_last_error(cbrdf_status code, std::string_view message) noexcept;
void clear_last_error() noexcept;
// Records a non-ok status, clears the last error for an ok one; returns the status's code.
cbrdf_status report(const Status& status) noexcept;
// Call only inside a catch block: records the exception in flight (std::bad_alloc as "out of
// memory", anything else as an internal error) and returns the code recorded.
cbrdf_status report_current_exception() noexcept;

// The boundary of every status-returning function: runs body (returning Status) and reports its
// result; no exception leaves it.
template <typename Body>
cbrdf_status guarded(Body&& body) noexcept {
  try {
    return report(body());
  } catch (...) {
    return report_current_exception();
  }
}

inline Status invalid_argument(std::string message) {
  return Status(ErrorCode::kInvalidArgument, std::move(message));
}

}  // namespace cbrdf::internal
