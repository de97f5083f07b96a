// SPDX-License-Identifier: MIT
#include "cbrdf/image_io.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cbrdf/file_io.h"
#include "exr_channels.h"

namespace cbrdf {
namespace {

std::string size_text(std::uint64_t w, std::uint64_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

bool valid_image(const Image& image) {
  return image.width > 0 && image.height > 0 && image.data.size() == image.pixel_count() * 3;
}

// A PNG file is far smaller than its pixels; this bounds what read_png loads before decoding.
constexpr std::uint64_t kMaxPngFileBytes = std::uint64_t{kMaxImagePixels} * 4 + (1u << 20);

std::uint8_t to_byte(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return std::uint8_t(std::lround(double(v) * 255.0));
}

Status check_writable(const std::filesystem::path& path, const Image& image) {
  if (valid_image(image)) return Status();
  return error(ErrorCode::kInvalidArgument,
               path.string() + ": cannot write an empty or inconsistent " +
                   size_text(std::uint64_t(std::max(image.width, 0)),
                             std::uint64_t(std::max(image.height, 0))) +
                   " image");
}

}  // namespace

Status write_exr(const std::filesystem::path& path, const Image& image) {
  CBRDF_RETURN_IF_ERROR(check_writable(path, image));
  return internal::write_exr_channels(path, image.width, image.height,
                                      {{"R", image.data.data(), 3},
                                       {"G", image.data.data() + 1, 3},
                                       {"B", image.data.data() + 2, 3}},
                                      {});
}

Expected<Image> read_exr(const std::filesystem::path& path) {
  CBRDF_ASSIGN_OR_RETURN(internal::ExrChannels exr,
                         internal::read_exr_channels(path, {"R", "G", "B", "Y"}, kMaxImagePixels));
  const auto& planes = exr.planes;
  Image image(exr.width, exr.height);
  const bool grey = !planes.contains("R") && !planes.contains("G") && !planes.contains("B") &&
                    planes.contains("Y");
  const char* names[3] = {"R", "G", "B"};
  for (std::size_t c = 0; c < 3; ++c) {
    const auto it = planes.find(grey ? "Y" : names[c]);
    if (it == planes.end()) continue;
    for (std::size_t i = 0; i < image.pixel_count(); ++i) image.data[i * 3 + c] = it->second[i];
  }
  return image;
}

Status write_png(const std::filesystem::path& path, const Image& image) {
  CBRDF_RETURN_IF_ERROR(check_writable(path, image));
  std::vector<std::uint8_t> pixels(image.data.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = to_byte(image.data[i]);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(image.width);
  png.height = png_uint_32(image.height);
  png.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  if (!png_image_write_get_memory_size(png, size, 0, pixels.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    return error(ErrorCode::kInternal,
                 path.string() + ": libpng could not encode the image: " + why);
  }
  std::vector<std::uint8_t> bytes(size);
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, pixels.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    return error(ErrorCode::kInternal,
                 path.string() + ": libpng could not encode the image: " + why);
  }
  bytes.resize(size);
  return write_file_atomic(path, std::span<const std::uint8_t>(bytes));
}

Expected<Image> read_png(const std::filesystem::path& path) {
  CBRDF_ASSIGN_OR_RETURN(std::vector<std::uint8_t> bytes, read_file(path, kMaxPngFileBytes));
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || !std::equal(kSignature, kSignature + 8, bytes.begin())) {
    return error(ErrorCode::kBadSignature,
                 path.string() + ": not a PNG file (bad signature at offset 0)");
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
    const std::string why = png.message;
    png_image_free(&png);
    return error(ErrorCode::kCorrupt, path.string() + ": unreadable PNG header: " + why);
  }
  if (std::uint64_t(png.width) * png.height > kMaxImagePixels || png.width > 0x7fffffffu ||
      png.height > 0x7fffffffu) {
    const std::string dims = size_text(png.width, png.height);
    png_image_free(&png);
    return error(ErrorCode::kLimit, path.string() + ": PNG image of " + dims +
                                        " pixels exceeds the limit of " +
                                        std::to_string(kMaxImagePixels) + " pixels");
  }
  png.format = PNG_FORMAT_RGB;
  Image image(int(png.width), int(png.height));
  std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(png), 0);  // zero: alpha composites onto black
  if (!png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    return error(ErrorCode::kCorrupt, path.string() + ": corrupt PNG data: " + why);
  }
  for (std::size_t i = 0; i < pixels.size(); ++i) image.data[i] = float(pixels[i]) / 255.0f;
  return image;
}

}  // namespace cbrdf
