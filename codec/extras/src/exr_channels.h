// SPDX-License-Identifier: MIT
// OpenEXR files as named float channels: the one place that talks to the OpenEXR library, shared by
// the image writer/reader and the BrdfTable mosaic export. OpenEXR throws; these return Status.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf::internal {

// One channel of an interleaved float buffer: pixel (x, y) is data[(y * width + x) * stride].
struct ExrPlaneIn {
  std::string name;
  const float* data = nullptr;
  std::size_t stride = 1;
};

// Writes a scanline file of 32-bit float channels, ZIP-compressed, with string attributes,
// atomically (write_file_atomic).
Status write_exr_channels(const std::filesystem::path& path, int width, int height,
                          const std::vector<ExrPlaneIn>& planes,
                          const std::vector<std::pair<std::string, std::string>>& strings);

struct ExrChannels {
  int width = 0;
  int height = 0;
  std::map<std::string, std::vector<float>> planes;  // the wanted channels the file has, row-major
  std::map<std::string, std::string> strings;        // every string attribute of the header
};

// Reads the wanted channels that exist (any pixel type, converted to float) over the data window.
// Errors: kNotFound, kLimit beyond max_pixels, kCorrupt with OpenEXR's message otherwise.
Expected<ExrChannels> read_exr_channels(const std::filesystem::path& path,
                                        const std::vector<std::string>& wanted,
                                        std::size_t max_pixels);

}  // namespace cbrdf::internal
