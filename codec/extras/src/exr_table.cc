// SPDX-License-Identifier: MIT
#include "cbrdf/exr_table.h"

#include <string>
#include <vector>

#include "exr_channels.h"

namespace cbrdf {
namespace {

constexpr std::size_t kMosaicPixels = std::size_t{kExrTableWidth} * kExrTableHeight;

std::size_t pixel_offset(int theta_h, int theta_d, int phi_d) {
  const MosaicPixel p = exr_table_pixel(theta_h, theta_d, phi_d);
  return std::size_t(p.y) * kExrTableWidth + std::size_t(p.x);
}

const char kComment[] =
    "cbrdf BRDF table: tile (theta_d % 10, theta_d / 10) of 180 x 90 per theta_d bin; "
    "x = 180 * (theta_d % 10) + phi_d, y = 90 * (theta_d / 10) + theta_h (MERL bins); "
    "RGB physical 1/sr, 0 where not measured; A = 1 where measured in all channels";

}  // namespace

Status write_exr_table(const std::filesystem::path& path, const BrdfTable& table) {
  // Planar float channels: the mosaic has no pixels outside the 90 x 90 x 180 bins.
  std::vector<float> rgb(kMosaicPixels * 3, 0.0f), alpha(kMosaicPixels, 0.0f);
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const std::size_t idx = merl_index(h, d, p), px = pixel_offset(h, d, p);
        bool all = true;
        for (int c = 0; c < kChannels; ++c) {
          const bool m = table.measured(c, idx);
          all = all && m;
          if (m) rgb[px * 3 + std::size_t(c)] = float(table.physical(c, idx));
        }
        alpha[px] = all ? 1.0f : 0.0f;
      }
    }
  }
  return internal::write_exr_channels(path, kExrTableWidth, kExrTableHeight,
                                      {{"R", rgb.data(), 3},
                                       {"G", rgb.data() + 1, 3},
                                       {"B", rgb.data() + 2, 3},
                                       {"A", alpha.data(), 1}},
                                      {{"cbrdf.layout", kExrTableLayout}, {"comments", kComment}});
}

Expected<BrdfTable> read_exr_table(const std::filesystem::path& path) {
  CBRDF_ASSIGN_OR_RETURN(internal::ExrChannels exr,
                         internal::read_exr_channels(path, {"R", "G", "B", "A"}, kMosaicPixels));
  const auto layout = exr.strings.find("cbrdf.layout");
  if (layout == exr.strings.end() || layout->second != kExrTableLayout) {
    return error(
        ErrorCode::kBadSignature,
        path.string() + ": not a cbrdf table mosaic (header attribute cbrdf.layout is " +
            (layout == exr.strings.end() ? std::string("missing") : "'" + layout->second + "'") +
            ", expected '" + kExrTableLayout + "')");
  }
  if (exr.width != kExrTableWidth || exr.height != kExrTableHeight) {
    return error(ErrorCode::kCorrupt, path.string() + ": table mosaic is " +
                                          std::to_string(exr.width) + "x" +
                                          std::to_string(exr.height) + ", expected 1800x810");
  }
  for (const char* name : {"R", "G", "B", "A"}) {
    if (!exr.planes.contains(name)) {
      return error(ErrorCode::kCorrupt, path.string() + ": table mosaic has no channel " + name);
    }
  }
  const std::vector<float>* planes[3] = {&exr.planes["R"], &exr.planes["G"], &exr.planes["B"]};
  const std::vector<float>& alpha = exr.planes["A"];
  BrdfTable table;
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const std::size_t idx = merl_index(h, d, p), px = pixel_offset(h, d, p);
        if (!(alpha[px] >= 0.5f)) {
          table.set_not_measured(idx);
          continue;
        }
        for (int c = 0; c < kChannels; ++c) table.set_physical(c, idx, double((*planes[c])[px]));
      }
    }
  }
  return table;
}

}  // namespace cbrdf
