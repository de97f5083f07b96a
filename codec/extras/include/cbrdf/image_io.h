// SPDX-License-Identifier: MIT
/// @file
/// Image files: OpenEXR (linear float RGB) and PNG (8-bit RGB), for renders, difference images and
/// reports. Part of the extras library (libcbrdf_extras), which needs OpenEXR and libpng.
///
/// Writers are atomic (cbrdf/file_io.h). Readers refuse images over kMaxImagePixels before
/// allocating.
#pragma once

#include <cstddef>
#include <filesystem>

#include "cbrdf/image.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// The most pixels a reader accepts: 8192 x 8192.
inline constexpr std::size_t kMaxImagePixels = std::size_t{1} << 26;

/// Writes R, G, B as 32-bit float channels (ZIP compression), values exactly as given: a float32
/// round trip is exact. Errors: kInvalidArgument for an empty image, kIo from the write.
Status write_exr(const std::filesystem::path& path, const Image& image);
/// Reads R, G, B (any OpenEXR pixel type, converted to float) over the data window; a missing
/// channel reads as 0, a Y-only (luminance) file as grey. Other channels are ignored. Errors:
/// kNotFound, kLimit (over kMaxImagePixels), kCorrupt (OpenEXR's reason in the message).
Expected<Image> read_exr(const std::filesystem::path& path);

/// Writes 8-bit RGB: round(clamp(v, 0, 1) * 255) per channel, NaN as 0. No transfer function is
/// applied: pass display-encoded values (tonemap(), difference_image() of cbrdf/metrics.h).
Status write_png(const std::filesystem::path& path, const Image& image);
/// Reads any PNG as RGB with values v / 255 (8-bit files exactly; grey is expanded, alpha is
/// composited on black and 16-bit samples reduced by libpng's simplified API).
/// Errors: kNotFound, kLimit, kBadSignature / kCorrupt with libpng's reason.
Expected<Image> read_png(const std::filesystem::path& path);

}  // namespace cbrdf
