// SPDX-License-Identifier: MIT
#include "info.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "arguments.h"
#include "bindings.h"
#include "cbrdf/container.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/model.h"
#include "errors.h"

namespace cbrdf::python {
namespace {

// Bytes from a file (a chunk tag, metadata) as a str: invalid UTF-8 becomes U+FFFD, as the
// command's JSON writer prints it.
py::str file_text(const std::string& s) {
  return py::reinterpret_steal<py::str>(
      PyUnicode_DecodeUTF8(s.data(), py::ssize_t(s.size()), "replace"));
}

// A number as JSON holds it: NaN and infinities are null there.
py::object number(double v) {
  return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
}

py::list pair_list(long long a, long long b) {
  py::list l;
  l.append(a);
  l.append(b);
  return l;
}

// `d` in the command's key order, then "file" (the caller's path, or None for bytes).
py::dict with_file(const py::dict& d, const py::object& file) {
  py::dict out = py::reinterpret_steal<py::dict>(json_ordered(d).release());
  out["file"] = file;
  return out;
}

py::dict residual_dict(const ContainerInfo& info) {
  // spec 4.6: modes 2-4 bound rows apart, min_error the finest row's bound.
  py::dict r;
  r["mode"] = info.residual_mode;
  r["max_error"] = number(info.residual_max_error);
  r["min_error"] =
      number(info.residual_mode >= 2 ? info.residual_min_error : info.residual_max_error);
  r["knee"] = number(info.residual_knee);
  r["escapes"] = info.residual_escapes;
  std::uint32_t stored = 0;
  for (const ChunkInfo& c : info.layout.chunks) {
    if (c.tag == kTagResidual) stored = c.stored_bytes;
  }
  r["stored_bytes"] = stored;
  if (info.residual_coding >= 0) r["coding"] = info.residual_coding;  // spec 4.6's predictor
  return r;
}

py::list slices_list(const ContainerInfo& info) {
  py::list slices;
  for (const SliceParams& s : info.slices) {
    py::list channels;
    for (std::size_t c = 0; c < std::size_t(kChannels); ++c) {
      py::dict ch;
      ch["family"] = std::string(family_name(s.family[c]));
      ch["theta"] = number(s.theta[c]);
      ch["scale"] = number(s.scale[c]);
      ch["components"] = s.components[c];
      channels.append(ch);
    }
    py::dict d;
    d["theta_d_bins"] = pair_list(s.theta_d_begin, s.theta_d_end);
    d["channels"] = channels;
    slices.append(d);
  }
  return slices;
}

py::dict merl_info_dict(const BrdfTable& table, const MerlInfo& mi, const py::object& file) {
  static const char* kNames[] = {"R", "G", "B"};
  const MerlStats st = merl_stats(table);
  py::dict d;
  d["format"] = "merl";
  d["dims"] = py::list(py::make_tuple(mi.dims[0], mi.dims[1], mi.dims[2]));
  d["folded_from_360"] = mi.folded_from_360;
  d["mask_matches_horizon"] = check_horizon_mask(table).matches();
  py::dict channels;
  for (int c = 0; c < kChannels; ++c) {
    const MerlChannelStats& s = st.channel[std::size_t(c)];
    py::dict ch;
    ch["measured"] = s.measured;
    ch["not_measured"] = s.not_measured;
    ch["zeros"] = s.zeros;
    ch["min"] = number(s.min);
    ch["max"] = number(s.max);
    ch["mean"] = number(s.mean);
    channels[kNames[c]] = ch;
  }
  d["channels"] = channels;
  d["noise"] = noise_dict(estimate_noise(table));
  return with_file(d, file);
}

// cbrdf.info of a .cbrdf's or a .binary's bytes; `name` prefixes error messages.
py::dict info_of_bytes(const std::vector<std::uint8_t>& bytes, const std::string& name,
                       const py::object& file) {
  const bool container =
      bytes.size() >= kContainerSignature.size() &&
      std::equal(kContainerSignature.begin(), kContainerSignature.end(), bytes.begin());
  if (container) {
    ContainerInfo info;
    auto model = take(decode_model(bytes, &info), name);
    const std::size_t evaluator_bytes = ModelEvaluator(std::move(model)).footprint_bytes();
    return container_info_dict(info, evaluator_bytes, file);
  }
  MerlInfo mi;
  auto table = take(parse_merl(bytes, name, {}, &mi));
  return merl_info_dict(table, mi, file);
}

}  // namespace

py::object json_ordered(const py::handle& value) {
  if (py::isinstance<py::dict>(value)) {
    std::vector<std::pair<std::string, py::object>> items;
    for (auto [k, v] : py::reinterpret_borrow<py::dict>(value)) {
      items.emplace_back(k.cast<std::string>(), py::reinterpret_borrow<py::object>(k));
    }
    std::sort(items.begin(), items.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    py::dict in = py::reinterpret_borrow<py::dict>(value), out;
    for (const auto& [text_key, key] : items) out[key] = json_ordered(in[key]);
    return out;
  }
  if (py::isinstance<py::list>(value)) {
    py::list out;
    for (const py::handle& v : py::reinterpret_borrow<py::list>(value)) out.append(json_ordered(v));
    return out;
  }
  return py::reinterpret_borrow<py::object>(value);
}

py::dict container_info_dict(const ContainerInfo& info, std::size_t evaluator_bytes,
                             const py::object& file) {
  py::dict d;
  d["format"] = "cbrdf";
  d["version"] = pair_list(info.layout.major, info.layout.minor);
  d["bytes"] = info.layout.file_bytes;
  py::list chunks;
  for (const ChunkInfo& c : info.layout.chunks) {
    py::dict ch;
    ch["tag"] = file_text(c.tag);
    ch["offset"] = c.offset;
    ch["stored_bytes"] = c.stored_bytes;
    ch["payload_bytes"] = c.payload_bytes;
    ch["compressed"] = c.compressed;
    ch["critical"] = c.critical;
    ch["known"] = c.known;
    chunks.append(ch);
  }
  if (!chunks.empty()) d["chunks"] = chunks;
  d["bits"] = info.bits;
  d["colour_scale"] = py::list(py::make_tuple(
      number(info.colour_scale[0]), number(info.colour_scale[1]), number(info.colour_scale[2])));
  d["not_measured_bins"] = info.not_measured_bins;
  if (info.residual_mode >= 0) d["residual"] = residual_dict(info);
  d["evaluator_bytes"] = evaluator_bytes;
  py::list slices = slices_list(info);
  if (!slices.empty()) d["slices"] = slices;
  if (!info.metadata.empty()) {
    py::dict meta;
    for (const auto& [k, v] : info.metadata) meta[file_text(k)] = file_text(v);
    d["metadata"] = meta;
  }
  return with_file(d, file);
}

py::dict noise_dict(const NoiseEstimate& e) {
  static const char* kNames[] = {"R", "G", "B"};
  py::dict d, sigma;
  for (int c = 0; c < kChannels; ++c) sigma[kNames[c]] = number(e.sigma[std::size_t(c)]);
  d["sigma"] = sigma;
  py::list bands;
  for (int b = 0; b < kNoiseBands; ++b) {
    const auto& s = e.band_sigma[std::size_t(b)];
    py::dict band, band_sigma;
    band["theta_d_begin"] = b * kNoiseBandDegrees;
    band["theta_d_end"] = (b + 1) * kNoiseBandDegrees;
    for (int c = 0; c < kChannels; ++c) band_sigma[kNames[c]] = number(s[std::size_t(c)]);
    band["sigma"] = band_sigma;
    bands.append(band);
  }
  d["bands"] = bands;
  d["grazing_growth"] = number(e.grazing_growth);
  d["noisy"] = e.noisy();
  // NaN (noise too large to render, noise.h) is said in words, as the command prints it.
  const auto ceiling = [](double db) -> py::object {
    return std::isfinite(db) ? py::object(py::float_(db)) : py::object(py::str("not measurable"));
  };
  d["psnr_ceiling_tonemapped"] = ceiling(e.psnr_ceiling_tonemapped);
  d["psnr_ceiling_linear"] = ceiling(e.psnr_ceiling_linear);
  return py::reinterpret_steal<py::dict>(json_ordered(d).release());
}

void bind_info(py::module_& m) {
  m.def(
      "_info_path",
      [](const py::object& file) {
        const std::string path = path_arg(file);
        auto bytes =
            take(read_file(path, std::max<std::uint64_t>(kMaxContainerBytes, 2 * kMerlFileBytes)));
        return info_of_bytes(bytes, path, file);
      },
      py::arg("path"));
  m.def(
      "_info_bytes",
      [](const py::buffer& b) { return info_of_bytes(bytes_of(b), "<bytes>", py::none()); },
      py::arg("data"));
}

}  // namespace cbrdf::python
