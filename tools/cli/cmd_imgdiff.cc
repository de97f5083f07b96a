// SPDX-License-Identifier: MIT
// `cbrdf imgdiff`: PSNR between two images and a false-colour difference image.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cbrdf/image_io.h"
#include "cbrdf/metrics.h"
#include "cli.h"
#include "cli_io.h"

namespace cbrdf::cli {
namespace {

struct ImgdiffOptions {
  std::string a, b, output;
  double scale = 0;
};

Expected<Image> read_image(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".png" || ext == ".PNG") return read_png(path);
  return read_exr(path);
}

int run_imgdiff(const ImgdiffOptions& o, const Context& ctx) {
  if (auto bad = check_paths("imgdiff", {{"a", o.a}, {"b", o.b}}, {{"-o", o.output}}, false)) {
    return usage_error(*bad);
  }
  auto a = read_image(o.a);
  if (!a.ok()) return fail(a.status());
  auto b = read_image(o.b);
  if (!b.ok()) return fail(b.status());
  if (a->width != b->width || a->height != b->height) {
    return fail(error(ErrorCode::kInvalidArgument,
                      "imgdiff: sizes differ: " + o.a + " is " + std::to_string(a->width) + "x" +
                          std::to_string(a->height) + ", " + o.b + " is " +
                          std::to_string(b->width) + "x" + std::to_string(b->height)));
  }
  for (const Image* img : {&*a, &*b}) {
    for (float v : img->data) {
      if (!std::isfinite(v)) {
        return fail(error(ErrorCode::kNumeric, "imgdiff: " + (img == &*a ? o.a : o.b) +
                                                   " holds NaN or infinite values"));
      }
    }
  }
  // Linear PSNR with the first image's per-channel maximum as the peak (metrics.h convention).
  double psnr_c[3], sum = 0, max_diff = 0;
  for (int c = 0; c < 3; ++c) {
    double peak = 0;
    for (std::size_t i = std::size_t(c); i < a->data.size(); i += 3)
      peak = std::max(peak, double(a->data[i]));
    psnr_c[c] = psnr(*a, *b, c, peak);
    sum += psnr_c[c];
  }
  for (std::size_t i = 0; i < a->data.size(); i += 3) {
    double d = 0;
    for (int c = 0; c < 3; ++c) d += std::abs(double(a->data[i + c]) - b->data[i + c]);
    max_diff = std::max(max_diff, d / 3);
  }
  std::printf("PSNR R %.2f dB, G %.2f dB, B %.2f dB, mean %.2f dB (peak: %s's channel maximum)\n",
              psnr_c[0], psnr_c[1], psnr_c[2], sum / 3, o.a.c_str());
  // Tone-mapped as the sphere metrics do: the first image's exposure for both, peak 1.
  const double exposure = tonemap_exposure(*a);
  const Image ta = tonemap(*a, exposure), tb = tonemap(*b, exposure);
  double tm[3], tm_sum = 0;
  for (int c = 0; c < 3; ++c) {
    tm[c] = psnr(ta, tb, c, 1.0);
    tm_sum += tm[c];
  }
  std::printf(
      "PSNR tone-mapped (exposure %.4g): R %.2f dB, G %.2f dB, B %.2f dB, tone-mapped mean %.2f "
      "dB\n",
      exposure, tm[0], tm[1], tm[2], tm_sum / 3);
  std::printf("max |difference| (channel mean) %.6g\n", max_diff);
  if (!o.output.empty()) {
    const double scale = o.scale > 0 ? o.scale : (max_diff > 0 ? max_diff : 1.0);
    const Image diff = difference_image(*a, *b, scale);
    if (Status s = write_png(o.output, diff); !s.ok()) return fail(s);
    if (!ctx.quiet) std::printf("wrote %s (viridis, yellow = %.6g)\n", o.output.c_str(), scale);
  }
  return kExitOk;
}

}  // namespace

void add_imgdiff_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<ImgdiffOptions>();
  CLI::App* cmd = app.add_subcommand("imgdiff", "PSNR and a false-colour difference of two images");
  cmd->add_option("a", o->a, "Reference image (.exr or .png)")->required();
  cmd->add_option("b", o->b, "Test image (.exr or .png)")->required();
  cmd->add_option("-o,--output", o->output, "Write the false-colour difference as PNG");
  cmd->add_option("--scale", o->scale,
                  "Difference shown as yellow (default: the largest difference); fix it to "
                  "compare several pairs on one scale")
      ->check(CLI::PositiveNumber);
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_imgdiff(*o, ctx); }; });
}

}  // namespace cbrdf::cli
