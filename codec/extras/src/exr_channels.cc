// SPDX-License-Identifier: MIT
#include "exr_channels.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <span>

#include "cbrdf/file_io.h"

namespace cbrdf::internal {
namespace {

// OpenEXR writes through this into memory so that the file itself is written atomically.
class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    const std::size_t end = pos_ + std::size_t(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(bytes_.data() + pos_, c, std::size_t(n));
    pos_ = end;
  }
  std::uint64_t tellp() override { return pos_; }
  void seekp(std::uint64_t pos) override { pos_ = std::size_t(pos); }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

Status write_exr_channels(const std::filesystem::path& path, int width, int height,
                          const std::vector<ExrPlaneIn>& planes,
                          const std::vector<std::pair<std::string, std::string>>& strings) {
  if (width <= 0 || height <= 0) {
    return error(ErrorCode::kInvalidArgument, path.string() + ": cannot write an empty " +
                                                  std::to_string(width) + "x" +
                                                  std::to_string(height) + " image as OpenEXR");
  }
  MemoryOStream stream;
  try {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [name, value] : strings) header.insert(name, Imf::StringAttribute(value));
    Imf::FrameBuffer frame;
    for (const ExrPlaneIn& p : planes) {
      header.channels().insert(p.name, Imf::Channel(Imf::FLOAT));
      const std::size_t x_stride = sizeof(float) * p.stride;
      // OpenEXR only reads through the slice pointer when writing.
      frame.insert(p.name,
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(p.data)),
                              x_stride, x_stride * std::size_t(width)));
    }
    Imf::OutputFile file(stream, header);
    file.setFrameBuffer(frame);
    file.writePixels(height);
  } catch (const std::exception& e) {
    return error(ErrorCode::kInternal,
                 path.string() + ": OpenEXR could not encode the image: " + e.what());
  }
  return write_file_atomic(path, std::span<const std::uint8_t>(stream.bytes()));
}

Expected<ExrChannels> read_exr_channels(const std::filesystem::path& path,
                                        const std::vector<std::string>& wanted,
                                        std::size_t max_pixels) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return error(ErrorCode::kNotFound, path.string() + ": no such file");
  }
  try {
    Imf::InputFile file(path.string().c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1;
    const std::int64_t h = std::int64_t(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0) {
      return error(ErrorCode::kCorrupt, path.string() + ": empty OpenEXR data window");
    }
    if (std::uint64_t(w) * std::uint64_t(h) > max_pixels) {
      return error(ErrorCode::kLimit, path.string() + ": OpenEXR image of " + std::to_string(w) +
                                          "x" + std::to_string(h) +
                                          " pixels exceeds the limit of " +
                                          std::to_string(max_pixels) + " pixels");
    }
    ExrChannels out;
    out.width = int(w);
    out.height = int(h);
    for (auto it = header.begin(); it != header.end(); ++it) {
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
        out.strings[it.name()] = s->value();
      }
    }
    Imf::FrameBuffer frame;
    for (const std::string& name : wanted) {
      if (header.channels().findChannel(name) == nullptr) continue;
      std::vector<float>& plane = out.planes[name];
      plane.assign(std::size_t(w) * std::size_t(h), 0.0f);
      frame.insert(name, Imf::Slice::Make(Imf::FLOAT, plane.data(), dw));
    }
    file.setFrameBuffer(frame);
    file.readPixels(dw.min.y, dw.max.y);
    return out;
  } catch (const std::exception& e) {
    return error(ErrorCode::kCorrupt, path.string() + ": not a readable OpenEXR file: " + e.what());
  }
}

}  // namespace cbrdf::internal
