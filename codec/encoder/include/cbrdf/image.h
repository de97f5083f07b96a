// SPDX-License-Identifier: MIT
/// @file
/// Image: a small linear float RGB image, the currency of the metrics (cbrdf/metrics.h), the
/// extras' image files (cbrdf/image_io.h) and a renderer's output.
///
/// Pixels are interleaved R, G, B, row-major, row 0 at the top: pixel (x, y) channel c is
/// data[(y * width + x) * 3 + c]. Values are whatever the producer says (radiance for renders,
/// display-encoded [0, 1] for tone-mapped or false-colour images).
#pragma once

#include <cstddef>
#include <vector>

namespace cbrdf {

/// A linear float RGB image (see the file's description for the layout).
struct Image {
  int width = 0;            ///< pixels per row
  int height = 0;           ///< rows
  std::vector<float> data;  ///< 3 * width * height values, R, G, B interleaved

  /// An empty image (0 x 0).
  Image() = default;
  /// A black w x h image. Sizes that are not both positive give an empty image.
  Image(int w, int h)
      : width(w > 0 && h > 0 ? w : 0),
        height(w > 0 && h > 0 ? h : 0),
        data(std::size_t(width) * std::size_t(height) * 3, 0.0f) {}

  /// width * height.
  std::size_t pixel_count() const { return std::size_t(width) * std::size_t(height); }
  /// Whether the image has no pixel.
  bool empty() const { return pixel_count() == 0; }
  /// The index in data of pixel (x, y), channel c (0 R, 1 G, 2 B). Not range-checked.
  std::size_t offset(int x, int y, int c) const {
    return (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3 + std::size_t(c);
  }
  /// Pixel (x, y), channel c. Not range-checked.
  float& at(int x, int y, int c) { return data[offset(x, y, c)]; }
  /// Pixel (x, y), channel c. Not range-checked.
  float at(int x, int y, int c) const { return data[offset(x, y, c)]; }

  /// Same size and equal values (compared as floats: NaN never equals NaN, -0 equals 0).
  bool operator==(const Image& other) const = default;
};

}  // namespace cbrdf
