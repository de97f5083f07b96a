// SPDX-License-Identifier: MIT
/// @file
/// A BrdfTable as an OpenEXR image, for looking at a material in any EXR viewer (`cbrdf decode
/// --exr`). Part of the extras library (libcbrdf_extras).
///
/// Layout: one 180 x 90 tile per theta_d bin (x = phi_d bin, y = theta_h bin, row 0 at the top),
/// the 90 tiles in a 10 x 9 mosaic, row-major by theta_d: 1800 x 810 pixels. Bin (theta_h, theta_d,
/// phi_d) is pixel x = 180 * (theta_d % 10) + phi_d, y = 90 * (theta_d / 10) + theta_h.
/// Channels (32-bit float): R, G, B hold physical values (1/sr, the stored value times kMerlScale),
/// 0 where that channel is not measured; A is 1 where all three channels are measured and 0 where
/// any is not, so viewers show unmeasured bins transparent and tools can mask them without NaN. The
/// header's string attribute "cbrdf.layout" is kExrTableLayout; "comments" repeats this layout in
/// words.
#pragma once

#include <filesystem>

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// Tiles per mosaic row.
inline constexpr int kExrTableTilesX = 10;
/// Tile rows.
inline constexpr int kExrTableTilesY = 9;
/// The mosaic's width, pixels (1800).
inline constexpr int kExrTableWidth = kExrTableTilesX * kPhiDBins;
/// The mosaic's height, pixels (810).
inline constexpr int kExrTableHeight = kExrTableTilesY * kThetaHBins;
/// The value of the "cbrdf.layout" header attribute.
inline constexpr const char* kExrTableLayout = "merl-mosaic-10x9-v1";

/// A pixel of the mosaic.
struct MosaicPixel {
  int x = 0;  ///< column, from the left
  int y = 0;  ///< row, from the top
};

/// The pixel that holds bin (theta_h, theta_d, phi_d).
constexpr MosaicPixel exr_table_pixel(int theta_h, int theta_d, int phi_d) {
  return {kPhiDBins * (theta_d % kExrTableTilesX) + phi_d,
          kThetaHBins * (theta_d / kExrTableTilesX) + theta_h};
}

/// Writes the table as the mosaic above, atomically (cbrdf/file_io.h). Errors: kIo from the
/// write, kInternal when OpenEXR cannot encode the image (its reason in the message).
Status write_exr_table(const std::filesystem::path& path, const BrdfTable& table);

/// Reads a mosaic written by write_exr_table back into a table: values to float32 precision, bins
/// with A < 0.5 marked not measured with stored value -1 in every channel. Errors: those of OpenEXR
/// reading, kBadSignature when the layout attribute is missing or different, kCorrupt on a wrong
/// size or missing channel.
Expected<BrdfTable> read_exr_table(const std::filesystem::path& path);

}  // namespace cbrdf
