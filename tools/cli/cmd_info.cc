// SPDX-License-Identifier: MIT
// `cbrdf info`: describe a .cbrdf container or a MERL .binary.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/noise.h"
#include "cli.h"
#include "cli_io.h"
#include "files/file_io.h"
#include "info_json.h"

namespace cbrdf::cli {
namespace {

struct InfoOptions {
  std::string input;
  bool json = false;
};

void print_json(nlohmann::json j, const std::string& file) {
  j["file"] = file;
  std::printf("%s\n", dump_json(j, 2).c_str());
}

bool is_container(const std::vector<std::uint8_t>& bytes) {
  return bytes.size() >= kContainerSignature.size() &&
         std::equal(kContainerSignature.begin(), kContainerSignature.end(), bytes.begin());
}

int info_container(const InfoOptions& o, const std::vector<std::uint8_t>& bytes) {
  // One validating pass gives the description and the model; the model shows what a renderer
  // holds to evaluate the file (the evaluator's tables, against the 35 MB table).
  Expected<ContainerInfo> info = ContainerInfo{};
  auto model = decode_model(bytes, &*info);
  if (!model.ok()) return fail(model.status().with_context(shown(o.input, false)));
  const std::size_t evaluator_bytes = ModelEvaluator(std::move(model).value()).footprint_bytes();
  if (o.json) {
    print_json(container_info_json(*info, evaluator_bytes), o.input);
    return kExitOk;
  }
  std::printf("%s: cbrdf container version %u.%u, %llu bytes\n", shown(o.input, false).c_str(),
              info->layout.major, info->layout.minor,
              static_cast<unsigned long long>(info->layout.file_bytes));
  std::printf("chunks:\n");
  for (const ChunkInfo& c : info->layout.chunks) {
    std::printf("  %-4s at %6llu: %7u bytes stored, %8u payload%s%s%s\n", c.tag.c_str(),
                static_cast<unsigned long long>(c.offset), c.stored_bytes, c.payload_bytes,
                c.compressed ? ", zstd" : "", c.critical ? ", critical" : ", ancillary",
                c.known ? "" : " (unknown, skipped)");
  }
  std::printf("marginals: %d bits per value; not-measured bins: %zu%s\n", info->bits,
              info->not_measured_bins,
              info->mask_relative_to_horizon ? " (coded against the horizon mask)" : "");
  if (info->residual_mode >= 0) {
    if (info->residual_mode == 1) {
      std::printf("residual layer: exact table (lossless), %u bytes\n",
                  residual_chunk_bytes(*info));
    } else {
      std::printf(
          "residual layer: |log1p(decoded / k) - log1p(source / k)| <= %g on every "
          "measured bin (k = %g), %u bytes, %zu bins stored exactly\n",
          info->residual_max_error, info->residual_knee, residual_chunk_bytes(*info),
          info->residual_escapes);
      if (info->residual_mode >= 2) {
        std::printf(
            "  a bound per (theta_h, theta_d) row, by its weight in rendering: %g in the finest "
            "rows\n",
            info->residual_min_error);
      }
      if (info->residual_mode == 3) {
        std::printf(
            "  codes correct an interpolation of coarser bins; the finest level (odd theta_d or "
            "phi_d) has a multiple of its row's bound\n");
      } else if (info->residual_mode == 4) {
        std::printf(
            "  codes correct an interpolation of coarser bins; each level finer than the "
            "coarsest has a multiple of its row's bound\n");
      }
      static constexpr const char* kCodings[] = {
          "zigzag varints through zstd", "zigzag varints after the previous phi_d bin's code",
          "range coded with contexts",
          "range coded after a prediction from the previous theta_h slab and channel"};
      if (info->residual_coding >= 0 && info->residual_coding < 4) {
        std::printf("  codes: %s (predictor %d)\n", kCodings[info->residual_coding],
                    info->residual_coding);
      }
    }
  }
  std::printf("evaluator: %zu bytes in memory (the MERL table it replaces: %zu)\n", evaluator_bytes,
              std::size_t(kMerlFileBytes));
  for (const auto& [k, v] : info->metadata) std::printf("%s: %s\n", k.c_str(), v.c_str());
  // Parameters of each slice channel's first component; a mixture adds the component counts.
  bool mixture = false;
  for (const SliceParams& s : info->slices) {
    for (int n : s.components) mixture = mixture || n > 1;
  }
  std::printf("%-10s %-8s %-13s %-13s %-13s %-11s %-11s %-11s%s\n", "theta_d", "family", "theta R",
              "theta G", "theta B", "K R", "K G", "K B", mixture ? " components R G B" : "");
  for (const SliceParams& s : info->slices) {
    std::printf("%2d-%-2d deg  %-8s", s.theta_d_begin, s.theta_d_end - 1,
                std::string(family_name(s.family[0])).c_str());
    for (double t : s.theta) std::printf(" %-13.6g", t);
    for (double k : s.scale) std::printf(" %-11.5g", k);
    if (mixture) std::printf(" %d %d %d", s.components[0], s.components[1], s.components[2]);
    std::printf("\n");
  }
  return kExitOk;
}

// The noise estimate in three lines: size per channel, growth with theta_d, the PSNR ceiling.
void print_noise(const NoiseEstimate& e) {
  if (!e.noisy()) {
    std::printf(
        "noise: none measurable (relative deviation %.2g%% / %.2g%% / %.2g%% R/G/B, below "
        "%.2g%%): a smooth table\n",
        100 * e.sigma[0], 100 * e.sigma[1], 100 * e.sigma[2], 100 * kNoiseFreeSigma);
    return;
  }
  std::printf(
      "noise: %.2f%% / %.2f%% / %.2f%% R/G/B (relative deviation, estimated from the "
      "table)\n",
      100 * e.sigma[0], 100 * e.sigma[1], 100 * e.sigma[2]);
  std::printf("  by theta_d:");
  for (int b = 0; b < kNoiseBands; ++b) {
    const auto& s = e.band_sigma[std::size_t(b)];
    std::printf(" %d-%d: %.2f%%", b * kNoiseBandDegrees, (b + 1) * kNoiseBandDegrees - 1,
                100 * (s[0] + s[1] + s[2]) / 3);
  }
  std::printf(" (x%.2f towards grazing)\n", e.grazing_growth);
  // A ceiling is NaN when the noise is too large to render (noise.h): said, not printed as nan.
  const auto db = [](double ceiling, const char* what) {
    char text[64];
    if (std::isfinite(ceiling)) {
      std::snprintf(text, sizeof text, "%.1f dB %s", ceiling, what);
    } else {
      std::snprintf(text, sizeof text, "%s not measurable", what);
    }
    return std::string(text);
  };
  const bool unmeasured =
      !std::isfinite(e.psnr_ceiling_tonemapped) || !std::isfinite(e.psnr_ceiling_linear);
  std::printf(
      "  noise floor: sphere PSNR %s, %s%s; coding closer than this reproduces noise\n",
      db(e.psnr_ceiling_tonemapped, "tone-mapped").c_str(),
      db(e.psnr_ceiling_linear, "linear").c_str(),
      unmeasured ? " (the noise, many decades per bin, takes the renders past their range)" : "");
}

int info_merl(const InfoOptions& o, const std::vector<std::uint8_t>& bytes) {
  MerlInfo mi;
  auto table = parse_merl(bytes, shown(o.input, false), {}, &mi);
  if (!table.ok()) return fail(table.status());
  if (o.json) {
    print_json(merl_info_json(*table, mi), o.input);
    return kExitOk;
  }
  const MerlStats st = merl_stats(*table);
  const HorizonMaskCheck hm = check_horizon_mask(*table);
  static const char* kNames[] = {"R", "G", "B"};
  std::printf("%s: MERL table %dx%dx%d%s\n", shown(o.input, false).c_str(), mi.dims[0], mi.dims[1],
              mi.dims[2], mi.folded_from_360 ? " (phi_d folded from 360 bins to 180)" : "");
  std::printf("not-measured mask %s the below-horizon geometry",
              hm.matches() ? "equals" : "differs from");
  if (!hm.matches()) std::printf(" (%zu bins differ)", hm.mismatches);
  std::printf("\n%-2s %10s %10s %8s %12s %12s %12s\n", "", "measured", "missing", "zeros", "min",
              "max", "mean");
  for (int c = 0; c < kChannels; ++c) {
    const MerlChannelStats& s = st.channel[c];
    std::printf("%-2s %10zu %10zu %8zu %12.5g %12.5g %12.5g\n", kNames[c], s.measured,
                s.not_measured, s.zeros, s.min, s.max, s.mean);
  }
  print_noise(estimate_noise(*table));
  return kExitOk;
}

int run_info(const InfoOptions& o) {
  if (auto bad = check_paths("info", {{"input", o.input}}, {})) return usage_error(*bad);
  auto bytes = read_file(input_path(o.input),
                         std::max<std::uint64_t>(kMaxContainerBytes, 2 * kMerlFileBytes));
  if (!bytes.ok()) return fail(bytes.status());
  return is_container(*bytes) ? info_container(o, *bytes) : info_merl(o, *bytes);
}

}  // namespace

void add_info_command(CLI::App& app, const Context&, Action* action) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a .cbrdf file or a MERL .binary");
  cmd->add_option("input", o->input, "A .cbrdf or MERL .binary file (- for standard input)")
      ->required()
      ->check(existing_file_or_stdin());
  cmd->add_flag("--json", o->json, "Print JSON");
  cmd->callback([o, action] { *action = [o] { return run_info(*o); }; });
}

}  // namespace cbrdf::cli
