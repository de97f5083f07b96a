// SPDX-License-Identifier: MIT
// The browser viewer's (viewer/) entry points in cbrdf.wasm, beside the C API: a model's GPU
// tables (cbrdf/gpu_tables.h, which glsl.mjs's packGpuTables repacks), the file's facts as
// JSON, and a slice's marginals and copula density for the page's slice plot.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/gpu_tables.h"
#include "cbrdf/model.h"

namespace {

using namespace cbrdf;

void append_json_string(std::string* out, const std::string& s) {
  *out += '"';
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      *out += '\\';
      *out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(ch));
      *out += buf;
    } else {
      *out += ch;
    }
  }
  *out += '"';
}

}  // namespace

// What cbrdf_viewer_open builds; the arrays are read in place by the page.
struct cbrdf_viewer {
  GpuTables tables;
  std::string facts;  // JSON
  Model model;        // for cbrdf_viewer_slice
};

#define CBRDF_WASM_EXPORT extern "C" __attribute__((visibility("default"), used))

namespace {

cbrdf_viewer* open_viewer(const void* data, std::size_t size) {
  if (data == nullptr) return nullptr;
  ContainerInfo info;
  auto decoded = decode_model(
      std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(data), size), &info);
  if (!decoded.ok()) return nullptr;
  const Model& model = decoded.value();
  auto v = std::unique_ptr<cbrdf_viewer>(new (std::nothrow) cbrdf_viewer);
  if (!v) return nullptr;

  v->tables = gpu_tables(model);

  // Facts: chunks, settings, evaluator footprint.
  v->model = std::move(decoded.value());
  const ModelEvaluator evaluator(
      std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &v->model));
  std::string& j = v->facts;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "{\"version\":\"%u.%u\",\"fileBytes\":%llu,\"bits\":%d,\"footprintBytes\":%zu,"
                "\"gpuTableBytes\":%zu,\"residualMode\":%d,\"residualMaxError\":%.17g,"
                "\"residualMinError\":%.17g,\"residualKnee\":%.17g,\"residualEscapes\":%zu,"
                "\"notMeasuredBins\":%zu,\"chunks\":[",
                unsigned(info.layout.major), unsigned(info.layout.minor),
                static_cast<unsigned long long>(info.layout.file_bytes), info.bits,
                evaluator.footprint_bytes(), v->tables.bytes(), info.residual_mode,
                info.residual_max_error, info.residual_min_error, info.residual_knee,
                info.residual_escapes, info.not_measured_bins);
  j += buf;
  for (std::size_t i = 0; i < info.layout.chunks.size(); ++i) {
    const ChunkInfo& c = info.layout.chunks[i];
    j += i ? ",{\"tag\":" : "{\"tag\":";
    append_json_string(&j, c.tag);
    std::snprintf(buf, sizeof buf,
                  ",\"offset\":%llu,\"storedBytes\":%u,\"payloadBytes\":%u,\"compressed\":%s}",
                  static_cast<unsigned long long>(c.offset), unsigned(c.stored_bytes),
                  unsigned(c.payload_bytes), c.compressed ? "true" : "false");
    j += buf;
  }
  // The slices and metadata as the C API reports them (cbrdf.mjs's info(): sliceList, metadata),
  // so that the page needs no second decode through cbrdf_model_open_memory.
  j += "],\"sliceList\":[";
  for (std::size_t s = 0; s < v->model.slices.size(); ++s) {
    const Slice& sl = v->model.slices[s];
    std::snprintf(buf, sizeof buf, "%s{\"thetaDBegin\":%d,\"thetaDEnd\":%d,\"channels\":[",
                  s ? "," : "", sl.theta_d_begin, sl.theta_d_end);
    j += buf;
    for (int ch = 0; ch < kChannels; ++ch) {
      const ChannelSlice& cs = sl.channel[std::size_t(ch)];
      j += ch ? ",[" : "[";
      for (int r = 0; r < cs.components(); ++r) {
        const Component& c = cs.component(r);
        j += r ? ",{\"family\":" : "{\"family\":";
        append_json_string(&j, std::string(family_name(c.family)));
        std::snprintf(buf, sizeof buf, ",\"theta\":%.17g,\"scale\":%.17g}", c.theta, c.scale);
        j += buf;
      }
      j += "]";
    }
    j += "]}";
  }
  j += "],\"metadata\":[";
  for (std::size_t i = 0; i < info.metadata.size(); ++i) {
    j += i ? ",[" : "[";
    append_json_string(&j, info.metadata[i].first);
    j += ",";
    append_json_string(&j, info.metadata[i].second);
    j += "]";
  }
  j += "]}";
  return v.release();
}

}  // namespace

// Builds the viewer's arrays from a .cbrdf file in memory, its one decode on the page; NULL when
// the file does not decode (the page then asks cbrdf_model_open_memory why) or memory runs out:
// nothing may unwind into JavaScript, where an escaped exception stops the whole instance.
CBRDF_WASM_EXPORT cbrdf_viewer* cbrdf_viewer_open(const void* data, std::size_t size) {
  try {
    return open_viewer(data, size);
  } catch (...) {
    return nullptr;
  }
}

// Array `which` (0 tables, 1 generic, 2 residual): its first float, and its length in *count
// (0 and NULL when absent).
CBRDF_WASM_EXPORT const float* cbrdf_viewer_array(const cbrdf_viewer* v, int which,
                                                  std::size_t* count) {
  if (v == nullptr || which < 0 || which > 2) {
    if (count) *count = 0;
    return nullptr;
  }
  const std::vector<float>& a =
      which == 0 ? v->tables.tables : (which == 1 ? v->tables.generic : v->tables.residual);
  if (count) *count = a.size();
  return a.empty() ? nullptr : a.data();
}

// The marginals and copula of one slice and channel (its first component), for the page's slice
// plot: out[0..89] the theta_h masses, out[90..269] the phi_d masses, out[270..359] the theta_d
// masses (the slice's width of them, then 0), out[360 + 180 i + k] the copula density at theta_h
// bin i, phi_d bin k and the slice's middle theta_d bin (the family's grid, as bin values use it).
// 16,560 floats. Returns the slice's width, -1 for a slice or channel out of range, or -2 when
// memory runs out (the copula plane is computed here).
CBRDF_WASM_EXPORT int cbrdf_viewer_slice(const cbrdf_viewer* v, int slice, int channel,
                                         float* out) try {
  if (v == nullptr || out == nullptr || slice < 0 || slice >= int(v->model.slices.size()) ||
      channel < 0 || channel >= kChannels) {
    return -1;
  }
  const Slice& sl = v->model.slices[std::size_t(slice)];
  const Component& c = sl.channel[std::size_t(channel)];
  std::fill(out, out + 16560, 0.0f);
  for (int i = 0; i < kThetaHBins; ++i) out[i] = float(c.pdf_h[std::size_t(i)]);
  for (int k = 0; k < kPhiDBins; ++k) out[90 + k] = float(c.pdf_p[std::size_t(k)]);
  for (int j = 0; j < sl.width(); ++j) out[270 + j] = float(c.pdf_d[std::size_t(j)]);
  const std::vector<double> density = copula_density_plane(c, sl.width() / 2);
  for (std::size_t i = 0; i < density.size(); ++i) out[360 + i] = float(density[i]);
  return sl.width();
} catch (...) {
  return -2;
}

CBRDF_WASM_EXPORT const char* cbrdf_viewer_facts(const cbrdf_viewer* v) {
  return v ? v->facts.c_str() : "";
}

CBRDF_WASM_EXPORT void cbrdf_viewer_free(cbrdf_viewer* v) {
  delete v;
}
