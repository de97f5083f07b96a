// SPDX-License-Identifier: MIT
// BASE (spec 4.8, container version 1.3): MODL and MARG in one chunk, the parameters as binary32
// (K as binary64 where binary32 would lose it) and the marginal tables predicted and range coded
// (range_coder.h). The reader (the writer is the encoder's, base_writer.cc).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "base_marginals.h"
#include "byte_reader.h"
#include "chunks.h"
#include "range_coder.h"

namespace cbrdf {

using base_marginals::clamp_code;
using base_marginals::first_prediction;
using base_marginals::for_each_component;
using base_marginals::kAxisNames;
using base_marginals::kPredictRefStep;
using base_marginals::MarginalContexts;
using base_marginals::predict;
using base_marginals::Reference;
using base_marginals::residual_class;

Status decode_base_chunk(std::span<const std::uint8_t> payload, int slice_count,
                         std::vector<Slice>* slices, int* bits_out) {
  ByteReader r = payload_reader(payload);
  std::uint8_t bits = 0, flags = 0;
  CBRDF_RETURN_IF_ERROR(r.u8(&bits, "bits per code"));
  CBRDF_RETURN_IF_ERROR(r.u8(&flags, "flags"));
  if (bits < kMinMarginalBits || bits > kMaxMarginalBits) {
    return error(ErrorCode::kCorrupt, "bits per code " + std::to_string(bits) + " is outside " +
                                          std::to_string(kMinMarginalBits) + ".." +
                                          std::to_string(kMaxMarginalBits));
  }
  if ((flags & ~(kBaseFlagComponents | kBaseFlagWideScales)) != 0) {
    return error(ErrorCode::kCorrupt,
                 "flags byte at payload offset 1 is " + std::to_string(flags) +
                     "; only bits 0 (further components) and 1 (K as binary64) are defined");
  }
  const bool wide = (flags & kBaseFlagWideScales) != 0;
  CBRDF_RETURN_IF_ERROR(read_slice_bounds(r, slice_count, slices));
  if (flags & kBaseFlagComponents) CBRDF_RETURN_IF_ERROR(read_component_counts(r, slices));
  Status st;
  auto name = [](std::size_t s, int c, int k) {
    return "slice " + std::to_string(s) + " channel " + kChannelNames[c] +
           (k > 0 ? " component " + std::to_string(k) : std::string());
  };
  for_each_component(*slices, [&](std::size_t s, int c, int k) {
    if (!st.ok()) return;
    std::uint8_t family = 0;
    float theta = 0.0f, scale32 = 0.0f;
    double scale = 0.0;
    st = r.u8(&family, "copula family");
    if (st.ok()) st = r.f32(&theta, "copula parameter");
    if (st.ok() && wide) st = r.f64(&scale, "scale K");
    if (st.ok() && !wide) {
      st = r.f32(&scale32, "scale K");
      scale = double(scale32);
    }
    if (st.ok()) st = check_channel_params(family, double(theta), scale);
    if (!st.ok()) {
      st = st.with_context(name(s, c, k));
      return;
    }
    Component& comp = (*slices)[s].channel[std::size_t(c)].component(k);
    comp.family = CopulaFamily(family);
    comp.theta = double(theta);
    comp.scale = scale;
  });
  CBRDF_RETURN_IF_ERROR(st);

  std::span<const std::uint8_t> rest;
  CBRDF_RETURN_IF_ERROR(r.bytes(r.remaining(), &rest, "coded marginal tables"));
  internal::Decoder dec(rest);
  MarginalContexts ctx;
  const std::int64_t top = max_code(bits);
  std::array<std::vector<std::uint32_t>, 3> last_codes;
  std::array<GridRange, 3> last_range{};
  std::array<bool, 3> have_last{};
  for_each_component(*slices, [&](std::size_t s, int c, int k) {
    Component& comp = (*slices)[s].channel[std::size_t(c)].component(k);
    std::vector<double>* axes[3] = {&comp.pdf_h, &comp.pdf_d, &comp.pdf_p};
    const std::size_t sizes[3] = {std::size_t(kThetaHBins), std::size_t((*slices)[s].width()),
                                  std::size_t(kPhiDBins)};
    for (std::size_t a = 0; a < 3 && st.ok(); ++a) {
      // Built only for a message: the decoder's loop does not pay for it.
      auto where = [&] { return name(s, c, k) + " " + kAxisNames[a] + " table"; };
      std::int32_t dh = 0, dspan = 0, mode_hi = 0;
      st = internal::get_sint(dec, ctx.hi[a], &dh);
      if (st.ok()) st = internal::get_sint(dec, ctx.span[a], &dspan);
      if (!st.ok()) {
        st = st.with_context(where());
        return;
      }
      const std::int64_t h = std::int64_t(last_range[a].hi_units) + dh;
      const std::int64_t d = std::int64_t(last_range[a].span_units) + dspan;
      if (h < 0 || d < 0 || h + d > std::int64_t(kMaxGridUnits)) {
        st = error(ErrorCode::kCorrupt,
                   where() + ": log-mass range units H " + std::to_string(h) + " and D " +
                       std::to_string(d) +
                       " must be >= 0 with H + D <= " + std::to_string(kMaxGridUnits));
        return;
      }
      GridRange range{std::uint32_t(h), std::uint32_t(d)};
      mode_hi = dec.bit(ctx.predictor[a][0]);
      const int mode = 2 * mode_hi + dec.bit(ctx.predictor[a][std::size_t(1 + mode_hi)]);
      Reference ref;
      if (have_last[a] && last_codes[a].size() == sizes[a]) {
        ref = {&last_codes[a], last_range[a].span_units};
      }
      if (mode >= kPredictRefStep && ref.codes == nullptr) {
        st = error(ErrorCode::kCorrupt, where() + ": predictor " + std::to_string(mode) +
                                            " needs a previous " + kAxisNames[a] +
                                            " table of the same size, and there is none");
        return;
      }
      const std::int64_t first = first_prediction(have_last[a] ? &last_codes[a] : nullptr, top);
      QuantizedTable t = grid_table(range);
      t.codes.assign(sizes[a], 0);
      int cls = 2;
      for (std::size_t i = 0; i < sizes[a]; ++i) {
        std::int32_t e = 0;
        st = internal::get_sint(dec, ctx.residual[a][std::size_t(cls)], &e);
        if (!st.ok()) {
          st = st.with_context(where());
          return;
        }
        const std::int64_t q =
            clamp_code(predict(mode, t.codes, i, ref, range.span_units, first), top) + e;
        if (q < 0 || q > top) {
          st = error(ErrorCode::kCorrupt, where() + ": code " + std::to_string(i) + " is " +
                                              std::to_string(q) + ", outside 0.." +
                                              std::to_string(top));
          return;
        }
        t.codes[i] = std::uint32_t(q);
        cls = residual_class(e);
      }
      Expected<std::vector<double>> m = dequantize_masses(t, bits);
      if (!m.ok()) {
        st = m.status().with_context(where());
        return;
      }
      *axes[a] = std::move(m.value());
      last_codes[a] = std::move(t.codes);
      last_range[a] = range;
      have_last[a] = true;
    }
  });
  CBRDF_RETURN_IF_ERROR(st);
  CBRDF_RETURN_IF_ERROR(dec.finish());
  *bits_out = bits;
  return ok_status();
}

}  // namespace cbrdf
