// SPDX-License-Identifier: MIT
/// @file
/// Watching and cancelling an encode: EncoderSettings::progress.
#pragma once

#include <functional>
#include <string_view>

namespace cbrdf {

/// How far an encode has come.
///
/// Stages, in the order an encode passes through them (a stage may be skipped):
/// - "fit": the model fit (marginals, copulas, mixtures; Ceres solves);
/// - "bits": `--bits auto` writing and decoding trial depths;
/// - "residual": the residual layer (quantizing, coding, checking the bound);
/// - "target": rate control (--target-psnr, --target-bytes) trying settings and bounds.
struct EncodeProgress {
  /// The share of the whole encode done, 0 to 1, never decreasing from one call to the next;
  /// negative when it cannot be estimated (the callback is still called, to allow a cancel).
  double fraction;
  std::string_view stage;  ///< the stage above; valid only during the call
};

/// Called on the thread that called the encoder (never on a fitting thread) at least every 50 ms
/// of encoder work, so a front end can draw progress and poll for Ctrl-C. Return true to go on,
/// false to cancel: the encode then stops within about 50 ms and returns a Status with
/// ErrorCode::kCancelled and the message "cancelled". Must not call back into the same encode.
using ProgressCallback = std::function<bool(const EncodeProgress&)>;

}  // namespace cbrdf
