// SPDX-License-Identifier: MIT
// Image: a small linear float RGB image, the currency of the metrics, the renderer and image I/O.
//
// Pixels are interleaved R, G, B, row-major, row 0 at the top: pixel (x, y) channel c is
// data[(y * width + x) * 3 + c]. Values are whatever the producer says (radiance for renders,
// display-encoded [0, 1] for tone-mapped or false-colour images).
#pragma once

#include <cstddef>
#include <vector>

namespace cbrdf {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> data;  // 3 * width * height

  Image() = default;
  // A black image. Negative sizes give an empty image.
  Image(int w, int h)
      : width(w > 0 && h > 0 ? w : 0),
        height(w > 0 && h > 0 ? h : 0),
        data(std::size_t(width) * std::size_t(height) * 3, 0.0f) {}

  std::size_t pixel_count() const { return std::size_t(width) * std::size_t(height); }
  bool empty() const { return pixel_count() == 0; }
  std::size_t offset(int x, int y, int c) const {
    return (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3 + std::size_t(c);
  }
  float& at(int x, int y, int c) { return data[offset(x, y, c)]; }
  float at(int x, int y, int c) const { return data[offset(x, y, c)]; }

  bool operator==(const Image& other) const = default;
};

}  // namespace cbrdf
