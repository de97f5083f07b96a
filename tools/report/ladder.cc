// SPDX-License-Identifier: MIT
#include "report/ladder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/noise.h"
#include "cbrdf/parallel.h"
#include "report/float16_baseline.h"
#include "report/lossless.h"
#include "report/progress.h"
#include "report/zfp_baseline.h"

namespace cbrdf::report {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string format_g(const char* fmt, double v) {
  char text[64];
  std::snprintf(text, sizeof text, fmt, v);
  return text;
}

bool bit_identical(const BrdfTable& a, const BrdfTable& b) {
  return std::memcmp(a.stored_values().data(), b.stored_values().data(),
                     a.stored_values().size() * sizeof(double)) == 0;
}

class LadderRun {
 public:
  LadderRun(const std::string& name, const BrdfTable& table, const LadderSettings& st,
            const BrdfTable* truth)
      : table_(table), st_(st), truth_(truth) {
    out_.name = name;
    sphere_.size = st.sphere_size;
    sphere_.threads = st.threads;
  }

  Expected<LadderMaterial> run() {
    CBRDF_RETURN_IF_ERROR(reach(0));
    CBRDF_RETURN_IF_ERROR(base_points());
    CBRDF_RETURN_IF_ERROR(reach(kResidualsFrom));
    CBRDF_RETURN_IF_ERROR(residual_points());
    CBRDF_RETURN_IF_ERROR(noise_floor_point());
    if (st_.lossless) CBRDF_RETURN_IF_ERROR(cbrdf_lossless_point());
    CBRDF_RETURN_IF_ERROR(reach(kResidualsTo));
    CBRDF_RETURN_IF_ERROR(zfp_points());
    if (st_.float16) CBRDF_RETURN_IF_ERROR(float16_point());
    if (st_.compressors) CBRDF_RETURN_IF_ERROR(compressor_points());
    return std::move(out_);
  }

 private:
  // The ladder's share before its residual points (the base fits) and up to their end.
  static constexpr double kResidualsFrom = 0.2, kResidualsTo = 0.8;
  // Progress at `fraction` of the ladder, between points: a cancel stops it here.
  Status reach(double fraction) const {
    if (st_.progress && !st_.progress(EncodeProgress{fraction, "ladder"})) {
      return error(ErrorCode::kCancelled, "cancelled");
    }
    return ok_status();
  }

  Status context(const Status& s, const LadderPoint& p) const {
    return s.with_context(out_.name + " (ladder: " + p.method + " " + p.setting + ")");
  }

  // Metrics of `decoded` against the source, then the point is kept.
  void add(LadderPoint p, const BrdfTable& decoded) {
    const ImageMetrics im = sphere_psnr(table_, decoded, sphere_);
    p.psnr_tonemapped = im.psnr_tonemapped;
    p.psnr_linear = im.psnr_linear;
    if (truth_) p.psnr_truth_tonemapped = sphere_psnr(*truth_, decoded, sphere_).psnr_tonemapped;
    out_.points.push_back(std::move(p));
  }
  // A baseline's bytes and times on its point.
  static LadderPoint with_costs(LadderPoint p, const Compressed& c) {
    p.bytes = double(c.bytes.size());
    p.encode_s = c.encode_s;
    p.decode_s = c.decode_s;
    return p;
  }
  void add_exact(LadderPoint p) {
    p.exact = true;
    p.psnr_tonemapped = p.psnr_linear = kPsnrCapDb;
    if (truth_) {
      // The input itself, measured once.
      if (std::isnan(input_truth_)) {
        input_truth_ = sphere_psnr(*truth_, table_, sphere_).psnr_tonemapped;
      }
      p.psnr_truth_tonemapped = input_truth_;
    }
    out_.points.push_back(std::move(p));
  }

  EncoderOptions options(int components, int bits) const {
    EncoderOptions o;
    o.components = std::to_string(components);
    o.bits = bits == kAutoBits ? "auto" : std::to_string(bits);
    o.threads = st_.threads;
    o.source_name = out_.name;
    return o;
  }

  // One fit per component count, every bits from it (as `cbrdf encode` would write each).
  Status base_points() {
    for (std::size_t ki = 0; ki < st_.base_components.size(); ++ki) {
      CBRDF_RETURN_IF_ERROR(
          reach(kResidualsFrom * double(ki) / double(st_.base_components.size())));
      const int k = st_.base_components[ki];
      Model model;
      double fit_s = 0;
      for (std::size_t b = 0; b < st_.base_bits.size(); ++b) {
        LadderPoint p{kLadderBase,
                      "k" + std::to_string(k) + " b" + std::to_string(st_.base_bits[b])};
        auto es = encoder_settings(options(k, st_.base_bits[b]));
        if (!es.ok()) return context(es.status(), p);
        if (b == 0) {
          const auto t0 = Clock::now();
          auto m = fit_model(table_, es->fit);
          if (!m.ok()) return context(m.status(), p);
          model = std::move(m).value();
          fit_s = since(t0);
          if (k == st_.residual_base_components) {
            residual_base_ = model;
            residual_fit_s_ = fit_s;
          }
        }
        auto t0 = Clock::now();
        auto bytes = encode_model(model, es->container);
        if (!bytes.ok()) return context(bytes.status(), p);
        p.encode_s = fit_s + since(t0);
        p.bytes = double(bytes->size());
        t0 = Clock::now();
        auto decoded = decode_table(*bytes);
        p.decode_s = since(t0);
        if (!decoded.ok()) return context(decoded.status(), p);
        add(std::move(p), *decoded);
      }
    }
    return ok_status();
  }

  // The residual's base: the model fitted for the base points when they include its component
  // count (else fitted here once), written at residual_base_bits; every residual point reuses it.
  Status residual_base() {
    if (have_residual_base_) return ok_status();
    const int k = st_.residual_base_components;
    CBRDF_ASSIGN_OR_RETURN(auto es, encoder_settings(options(k, st_.residual_base_bits)));
    if (!residual_base_) {
      const auto t0 = Clock::now();
      CBRDF_ASSIGN_OR_RETURN(residual_base_, fit_model(table_, es.fit));
      residual_fit_s_ = since(t0);
    }
    const auto t0 = Clock::now();
    CBRDF_ASSIGN_OR_RETURN(auto bytes, encode_model(*residual_base_, es.container));
    base_file_.bytes = std::move(bytes);
    base_file_.bits = st_.residual_base_bits;
    base_file_.model = *residual_base_;
    residual_fit_s_ += since(t0);
    have_residual_base_ = true;
    return ok_status();
  }

  // The base file plus a residual layer; the encode time counts the fit, as `cbrdf encode` pays
  // it. Lossless points must decode bit for bit.
  Status residual_point(LadderPoint p, const ResidualSettings& rs,
                        const BrdfTable* source = nullptr) {
    if (Status s = residual_base(); !s.ok()) return context(s, p);
    auto es = encoder_settings(options(st_.residual_base_components, st_.residual_base_bits));
    if (!es.ok()) return context(es.status(), p);
    es->residual = rs;
    // Each residual encode gets an equal part of the ladder's residual share, in call order.
    const int calls = int(st_.max_errors.size()) + 2;
    const double part = (kResidualsTo - kResidualsFrom) / calls;
    const double from = kResidualsFrom + part * std::min(residual_calls_++, calls - 1);
    es->progress = part_of(st_.progress, from, from + part);
    EncodeResult r = base_file_;
    auto t0 = Clock::now();
    if (Status s = add_residual_layer(source ? *source : table_, *es, &r); !s.ok()) {
      return context(s, p);
    }
    p.encode_s = residual_fit_s_ + since(t0);
    p.bytes = double(r.bytes.size());
    t0 = Clock::now();
    auto decoded = decode_table(r.bytes);
    p.decode_s = since(t0);
    if (!decoded.ok()) return context(decoded.status(), p);
    if (!rs.lossless) {
      add(std::move(p), *decoded);
      return ok_status();
    }
    if (!bit_identical(table_, *decoded)) {
      return context(error(ErrorCode::kInternal, "the lossless file does not decode bit for bit"),
                     p);
    }
    add_exact(std::move(p));
    return ok_status();
  }

  Status residual_points() {
    for (double e : st_.max_errors) {
      ResidualSettings rs = target_residual_settings(e);
      rs.row_steps = st_.residual_row_steps;
      if (!st_.residual_interpolated) rs.levels = 0;
      CBRDF_RETURN_IF_ERROR(residual_point({kLadderResidual, format_g("E %g", e)}, rs));
    }
    return ok_status();
  }

  // The noise estimate, and on a noisy table the residual the rate control stops at: the base
  // times the smoothed ratio, at the floor's bound. Its PSNR against the input is the ladder's
  // noise floor: points above it reproduce noise.
  Status noise_floor_point() {
    NoiseOptions o;
    o.threads = st_.threads;
    const NoiseEstimate e = estimate_noise(table_, o);
    out_.noise_sigma = e.max_sigma();
    out_.noise_ceiling_tonemapped = e.psnr_ceiling_tonemapped;
    if (!e.noisy()) return ok_status();
    LadderPoint p{kLadderNoiseFloor, format_g("E %.3g", noise_floor_error(e))};
    if (Status s = residual_base(); !s.ok()) return context(s, p);
    auto base = decode_table(base_file_.bytes);
    if (!base.ok()) return context(base.status(), p);
    const BrdfTable source = noise_floor_source(table_, *base);
    return residual_point(std::move(p), target_residual_settings(noise_floor_error(e)), &source);
  }

  Status cbrdf_lossless_point() {
    ResidualSettings rs;
    rs.lossless = true;
    return residual_point({kLadderLossless, "k" + std::to_string(st_.residual_base_components) +
                                                " b" + std::to_string(st_.residual_base_bits)},
                          rs);
  }

  Status zfp_points() {
    for (double tol : st_.zfp_tolerances) {
      LadderPoint p{kLadderZfp, format_g("tol %g", tol)};
      auto z = zfp_log_round_trip(table_, tol);
      if (!z.ok()) return context(z.status(), p);
      add(with_costs(std::move(p), z->compressed), z->decoded);
    }
    return ok_status();
  }

  Status float16_point() {
    LadderPoint p{kLadderFloat16, "level " + std::to_string(st_.zstd_level)};
    auto f = float16_round_trip(table_, st_.zstd_level);
    if (!f.ok()) return context(f.status(), p);
    add(with_costs(std::move(p), f->compressed), f->decoded);
    return ok_status();
  }

  // zstd and xz of the .binary bytes (verified round trips, so exact).
  Status compressor_points() {
    const std::vector<std::uint8_t> raw = serialize_merl(table_);
    auto put = [&](LadderPoint p, const Expected<Compressed>& c) -> Status {
      if (!c.ok()) return context(c.status(), p);
      add_exact(with_costs(std::move(p), *c));
      return ok_status();
    };
    CBRDF_RETURN_IF_ERROR(put({kLadderZstd, "-" + std::to_string(st_.zstd_level)},
                              zstd_round_trip(raw, st_.zstd_level)));
    return put({kLadderXz, "-" + std::to_string(st_.xz_preset)}, xz_round_trip(raw, st_.xz_preset));
  }

  const BrdfTable& table_;
  const LadderSettings& st_;
  const BrdfTable* truth_;
  double input_truth_ = NAN;            // the input's PSNR against the truth, once measured
  std::optional<Model> residual_base_;  // the fit under the residual points
  double residual_fit_s_ = 0;           // its fit and write time
  EncodeResult base_file_;
  bool have_residual_base_ = false;
  int residual_calls_ = 0;
  SphereSetup sphere_;
  LadderMaterial out_;
};

}  // namespace

Expected<LadderMaterial> measure_ladder(const std::string& name, const BrdfTable& table,
                                        const LadderSettings& st, const BrdfTable* truth) {
  return LadderRun(name, table, st, truth).run();
}

}  // namespace cbrdf::report
