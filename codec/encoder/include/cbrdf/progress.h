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

/// Called on the thread that called the encoder (never on a fitting thread) every 20 ms or so
/// (at most 50 ms apart on an idle machine) while the work runs on a thread of its own, so a front
/// end can draw progress and poll for Ctrl-C; the first call comes after the first interval, and
/// none after the encode's work has ended. Return true to go on, false to cancel: the work stops
/// at its next checkpoint (a solver iteration, a HALS sweep, a parallel task, a file written or
/// scored: usually tens of milliseconds; the setup of a first encode in a process, which builds
/// the sphere renders' geometry, and one zstd compression of a residual layer at level 19
/// cannot be interrupted and may take a few hundred) and the encode returns a Status with
/// ErrorCode::kCancelled and the message "cancelled". An exception thrown by the callback also
/// stops the work, and is rethrown once it has stopped. Must not call into the same encode.
using ProgressCallback = std::function<bool(const EncodeProgress&)>;

}  // namespace cbrdf
