// SPDX-License-Identifier: MIT
// Writes the seed corpora fuzz/corpus/<target>/ and their manifest fuzz/corpus/EXPECTED.txt
// (the outcome each seed is made to have; tests/fuzz/fuzz_regression_test.cc checks it).
//   Usage: fuzz_make_seeds OUT_DIR      (normally fuzz/corpus; the output is deterministic)
// Seeds: the golden files and encoder outputs (container, decode; for decode also rewritten with
// uncompressed chunks so that mutations hit payload fields), a few damaged files, MERL headers and
// template patches (merl), and byte strings for the round trip.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "harness/roundtrip_target.h"
#include "synthetic_model.h"

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using cbrdf::Model;

struct Writer {
  fs::path root;
  std::vector<std::string> manifest;
  bool failed = false;

  void add(const std::string& target, const std::string& name, const Bytes& bytes,
           const std::string& expected) {
    fs::create_directories(root / target);
    std::ofstream out(root / target / name, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) {
      std::fprintf(stderr, "cannot write %s\n", (root / target / name).c_str());
      failed = true;
    }
    manifest.push_back(target + "/" + name + " " + expected);
  }
};

Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

Bytes encode(const Model& m, int bits, bool metadata = true, int zstd_level = 19,
             cbrdf::ContainerSettings::Format format = cbrdf::ContainerSettings::Format::kV12) {
  cbrdf::ContainerSettings s;
  s.format = format;
  s.metadata = cbrdf::ContainerSettings::Metadata::kFull;  // the seeds as they were written
  s.bits = bits;
  s.zstd_level = zstd_level;
  s.source_name = "seed.binary";
  s.write_metadata = metadata;
  cbrdf::Expected<Bytes> b = cbrdf::encode_model(m, s);
  if (!b.ok()) {
    std::fprintf(stderr, "encode failed: %s\n", b.status().message().c_str());
    std::exit(1);
  }
  return *b;
}

// Appends a chunk, and the end, in the framing of `minor` (1.3's compact one or the older).
void append_chunk(Bytes* out, std::uint16_t minor, std::string_view tag, std::uint32_t flags,
                  std::span<const std::uint8_t> stored, std::uint32_t payload_bytes) {
  if (cbrdf::uses_compact_framing(minor)) {
    cbrdf::append_compact_chunk(out, tag, flags, stored, payload_bytes);
  } else {
    cbrdf::append_raw_chunk(out, tag, flags, stored, payload_bytes);
  }
}
void append_end(Bytes* out, std::uint16_t minor) {
  if (cbrdf::uses_compact_framing(minor)) {
    cbrdf::append_compact_end(out);
  } else {
    cbrdf::append_raw_chunk(out, cbrdf::kTagEnd, 0, {}, 0);
  }
}

// The same file with every known chunk stored uncompressed (unknown chunks copied as they are),
// of its own version unless `minor` is given; `edit` may change a known chunk's payload.
Bytes uncompressed(const Bytes& file, int minor = -1,
                   const std::function<void(const std::string&, Bytes*)>& edit = {}) {
  cbrdf::Expected<cbrdf::ParsedContainer> pc = cbrdf::parse_container(file);
  if (!pc.ok()) std::exit(1);
  const auto m = std::uint16_t(minor >= 0 ? minor : int(pc->layout.minor));
  const bool compact_source = cbrdf::uses_compact_framing(pc->layout.minor);
  Bytes out = cbrdf::container_file_header(cbrdf::kContainerMajorVersion, m);
  for (std::size_t i = 0; i + 1 < pc->layout.chunks.size(); ++i) {
    const cbrdf::ChunkInfo& c = pc->layout.chunks[i];
    if (c.known) {
      Bytes p = pc->payloads[i];
      if (edit) edit(c.tag, &p);
      append_chunk(&out, m, c.tag, 0, p, std::uint32_t(p.size()));
    } else {
      const std::size_t at =
          std::size_t(c.offset) + (compact_source ? c.frame_bytes : cbrdf::kChunkHeaderBytes);
      append_chunk(&out, m, c.tag, c.flags,
                   std::span<const std::uint8_t>(file).subspan(at, c.stored_bytes),
                   c.payload_bytes);
    }
  }
  append_end(&out, m);
  return out;
}

// Inserts an ancillary chunk before the end chunk.
Bytes with_ancillary(const Bytes& file) {
  cbrdf::Expected<cbrdf::ParsedContainer> pc = cbrdf::parse_container(file);
  if (!pc.ok()) std::exit(1);
  std::vector<cbrdf::ChunkToWrite> chunks;
  for (std::size_t i = 0; i + 1 < pc->layout.chunks.size(); ++i) {
    chunks.push_back({pc->layout.chunks[i].tag, pc->payloads[i], pc->layout.chunks[i].compressed});
  }
  const std::string hi = "hello";
  chunks.push_back({"zTST", Bytes(hi.begin(), hi.end()), false});
  cbrdf::Expected<Bytes> out = cbrdf::write_container(chunks, 19, pc->layout.minor);
  if (!out.ok()) std::exit(1);
  return *out;
}

Model sparse_per_bin_mask_model() {
  Model m = cbrdf::testing::make_model({0, 30, 90}, false, 7);
  m.not_measured = cbrdf::NotMeasured{};
  for (std::size_t i = 7; i < cbrdf::kBinsPerChannel; i += 1000) m.not_measured.set(0, i);
  m.not_measured.values.clear();
  for (std::size_t k = 0; k < m.not_measured.count(); ++k) {
    m.not_measured.values.push_back(-1.0 - double(k % 3));
  }
  return m;
}

// Every bin masked with its own stored value: the largest Model a file holds (4.4 million values),
// 13 KB compressed. Decoding it must stay fast under the sanitizers.
Model all_masked_model() {
  Model m = cbrdf::testing::make_model({0, 90}, false, 11);
  m.not_measured = cbrdf::NotMeasured{};
  for (int c = 0; c < cbrdf::kChannels; ++c) {
    for (std::size_t i = 0; i < cbrdf::kBinsPerChannel; ++i) m.not_measured.set(c, i);
  }
  const std::size_t count = m.not_measured.count();
  m.not_measured.values.clear();
  for (std::size_t k = 0; k < count; ++k) m.not_measured.values.push_back(-1.0 - double(k % 1000));
  return m;
}

Model bitmap_mask_model() {
  Model m = cbrdf::testing::make_model({0, 45, 90}, false, 9);
  m.not_measured = cbrdf::NotMeasured{};
  for (int c = 0; c < cbrdf::kChannels; ++c) {
    for (std::size_t i = 0; i < cbrdf::kBinsPerChannel; i += 3) m.not_measured.set(c, i);
  }
  m.not_measured.values = {-2.0};
  return m;
}

Bytes merl_header(std::int32_t a, std::int32_t b, std::int32_t c) {
  Bytes out(12);
  const std::int32_t d[3] = {a, b, c};
  std::memcpy(out.data(), d, 12);
  return out;
}

void append_double(Bytes* out, double v) {
  std::uint8_t b[8];
  std::memcpy(b, &v, 8);
  out->insert(out->end(), b, b + 8);
}

// "TPL" flags [header] [size change] u32 offset, then the window of doubles.
Bytes merl_patch(std::uint8_t flags, const Bytes& header, int size_change, std::uint32_t offset,
                 const std::vector<double>& window) {
  Bytes out = {'T', 'P', 'L', flags};
  if (flags & 4) out.insert(out.end(), header.begin(), header.end());
  if (flags & 8) {
    out.push_back(std::uint8_t(size_change & 0xFF));
    out.push_back(std::uint8_t((size_change >> 8) & 0xFF));
  }
  for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(offset >> (8 * i)));
  for (double v : window) append_double(&out, v);
  return out;
}

void container_and_decode_seeds(Writer& w) {
  using cbrdf::testing::make_model;
  std::map<std::string, Bytes> valid;
  for (const auto& e : fs::directory_iterator(CBRDF_GOLDEN_DIR)) {
    valid["golden-" + e.path().filename().string()] = read_file(e.path());
  }
  valid["enc-tiny1-b6.cbrdf"] = encode(make_model({0, 90}, false, 1), 6);
  valid["enc-mixture-b8.cbrdf"] = encode(cbrdf::testing::make_mixture_model({0, 40, 90}, 4, 6), 8);
  valid["enc-six-peaked-b10.cbrdf"] = encode(make_model(cbrdf::testing::six_slices(), true, 2), 10);
  valid["enc-three-b16-nometa.cbrdf"] = encode(make_model({0, 10, 40, 90}, false, 3), 16, false);
  valid["enc-perbin-values.cbrdf"] = encode(sparse_per_bin_mask_model(), 8);
  valid["enc-bitmap-mask.cbrdf"] = encode(bitmap_mask_model(), 8);
  valid["enc-ancillary-chunk.cbrdf"] = with_ancillary(valid["enc-tiny1-b6.cbrdf"]);
  // Version 1.3 (BASE, the range-coded tables).
  constexpr auto kV13 = cbrdf::ContainerSettings::Format::kV13;
  valid["enc13-six-peaked-b10.cbrdf"] =
      encode(make_model(cbrdf::testing::six_slices(), true, 2), 10, true, 19, kV13);
  valid["enc13-mixture-b8.cbrdf"] =
      encode(cbrdf::testing::make_mixture_model({0, 40, 90}, 4, 6), 8, true, 19, kV13);
  valid["enc13-tiny1-b16.cbrdf"] = encode(make_model({0, 90}, false, 1), 16, false, 19, kV13);
  valid["enc13-ancillary-chunk.cbrdf"] = with_ancillary(valid["enc13-tiny1-b16.cbrdf"]);

  for (const auto& [name, bytes] : valid) {
    w.add("fuzz_container", name, bytes, "accepted");
    w.add("fuzz_decode", name, bytes, "accepted");
    w.add("fuzz_capi", name, bytes, "accepted");
    // A residual layer (RESD) is megabytes uncompressed: compressed seeds only.
    if (name.find("residual") == std::string::npos) {
      w.add("fuzz_decode", "raw-" + name, uncompressed(bytes), "accepted");
    }
  }
  // Compressed only: uncompressed it would be 35 MB.
  const Bytes all_masked = encode(all_masked_model(), 8, true, 3);
  w.add("fuzz_container", "enc-all-masked-perbin.cbrdf", all_masked, "accepted");
  w.add("fuzz_decode", "enc-all-masked-perbin.cbrdf", all_masked, "accepted");
  // A newer minor version may append fields: trailing payload bytes are then ignored.
  w.add("fuzz_decode", "raw-minor2-enc-mixture-b8.cbrdf",
        uncompressed(valid["enc-mixture-b8.cbrdf"], cbrdf::kContainerMinorVersion + 1), "accepted");

  // 1.3: BASE in a file labelled 1.2 (the chunk layer refuses it), and BASE with bytes after its
  // coded stream (the payload reader does).
  const Bytes& v13 = valid["enc13-six-peaked-b10.cbrdf"];
  w.add("fuzz_container", "bad13-base-in-minor2.cbrdf", uncompressed(v13, 2), "rejected corrupt");
  w.add("fuzz_decode", "bad13-base-trailing.cbrdf",
        uncompressed(v13, -1,
                     [](const std::string& tag, Bytes* p) {
                       if (tag == cbrdf::kTagBase) p->insert(p->end(), 5, 0x55);
                     }),
        "rejected corrupt");

  // The compact framing (spec 2.2): each way its fields can be wrong.
  const Bytes v13_header = cbrdf::container_file_header(cbrdf::kContainerMajorVersion, 3);
  auto framed13 = [&](std::initializer_list<std::uint8_t> body) {
    Bytes b = v13_header;
    b.insert(b.end(), body);
    return b;
  };
  w.add("fuzz_container", "bad13-truncated-varint.cbrdf", framed13({'H', 'E', 'A', 'D', 0x80}),
        "rejected truncated");
  w.add("fuzz_container", "bad13-overlong-varint.cbrdf",
        framed13({'H', 'E', 'A', 'D', 0x88, 0x00, 0, 0}), "rejected corrupt");
  w.add("fuzz_container", "bad13-long-varint.cbrdf",
        framed13({'H', 'E', 'A', 'D', 0x80, 0x80, 0x80, 0x80, 0x80, 0x01}), "rejected corrupt");
  w.add("fuzz_container", "bad13-length-past-end.cbrdf",
        framed13({'H', 'E', 'A', 'D', 0xA0, 0x1F, 1, 2, 3}), "rejected truncated");
  w.add("fuzz_container", "bad13-reserved-bit.cbrdf", framed13({'H', 'E', 'A', 'D', 0x0A, 0, 0}),
        "rejected corrupt");
  Bytes damaged13 = v13;
  damaged13[damaged13.size() / 2] ^= 0x40;
  w.add("fuzz_container", "bad13-checksum.cbrdf", damaged13, "rejected checksum");
  w.add("fuzz_container", "bad13-no-file-checksum.cbrdf", Bytes(v13.begin(), v13.end() - 4),
        "rejected truncated");
  {
    Bytes many = v13_header;
    cbrdf::append_compact_chunk(&many, cbrdf::kTagHeader, 0, Bytes(2, 0), 2);
    for (std::size_t i = 0; i < cbrdf::kMaxChunks; ++i) {
      cbrdf::append_compact_chunk(&many, "xPAD", 0, {}, 0);
    }
    cbrdf::append_compact_end(&many);
    w.add("fuzz_container", "bad13-too-many-chunks.cbrdf", many, "rejected limit");
  }
  {
    // A compressed chunk whose declared payload is above its limit: refused from the field.
    Bytes big = v13_header;
    cbrdf::append_compact_chunk(&big, cbrdf::kTagHeader, cbrdf::kChunkFlagZstd, Bytes(9, 0),
                                0xFFFFFFFFu);
    cbrdf::append_compact_end(&big);
    w.add("fuzz_container", "bad13-payload-limit.cbrdf", big, "rejected limit");
  }

  const Bytes& tiny = valid["enc-tiny1-b6.cbrdf"];
  w.add("fuzz_container", "bad-truncated.cbrdf", Bytes(tiny.begin(), tiny.begin() + 40),
        "rejected truncated");
  Bytes text_mode = tiny;
  text_mode.erase(text_mode.begin() + 4);  // CR LF -> LF
  w.add("fuzz_container", "bad-text-mode.cbrdf", text_mode, "rejected bad-signature");
  Bytes damaged = tiny;
  damaged[damaged.size() / 2] ^= 0x40;
  w.add("fuzz_container", "bad-checksum.cbrdf", damaged, "rejected checksum");
}

void merl_seeds(Writer& w) {
  Bytes h180 = merl_header(90, 90, 180);
  w.add("fuzz_merl", "raw-header-180.bin", h180, "rejected truncated");
  Bytes some = h180;
  for (int i = 0; i < 8; ++i) append_double(&some, i == 3 ? -1.0 : 0.5 * i);
  w.add("fuzz_merl", "raw-short-180.bin", some, "rejected truncated");
  w.add("fuzz_merl", "raw-header-360.bin", merl_header(90, 90, 360), "rejected truncated");
  w.add("fuzz_merl", "raw-big-endian.bin", merl_header(0x5A000000, 0x5A000000, -1275068416),
        "rejected corrupt");
  w.add("fuzz_merl", "raw-huge-dims.bin", merl_header(10000, 10000, 10000), "rejected limit");
  w.add("fuzz_merl", "raw-unsupported-dims.bin", merl_header(90, 90, 90), "rejected unsupported");
  w.add("fuzz_merl", "raw-short-header.bin", Bytes{90, 0, 0, 0, 90}, "rejected truncated");

  const std::vector<double> plain = {0.5, 1.0, -1.0, 0.0, -0.0, 2.5, 1e-300, 3.0};
  const std::vector<double> nan = {1.0, std::nan(""), 2.0};
  const std::vector<double> inf = {1.0, 2.0, HUGE_VAL};
  w.add("fuzz_merl", "tpl-180-values.bin", merl_patch(0, {}, 0, 8 * 1000, plain), "accepted");
  w.add("fuzz_merl", "tpl-360-values.bin", merl_patch(1, {}, 0, 8 * 777, plain), "accepted");
  w.add("fuzz_merl", "tpl-360-fold-off.bin", merl_patch(3, {}, 0, 0, {}), "rejected unsupported");
  w.add("fuzz_merl", "tpl-180-nan.bin", merl_patch(0, {}, 0, 8 * 4000000, nan),
        "accepted");  // NaN: not measured
  w.add("fuzz_merl", "tpl-360-inf.bin", merl_patch(1, {}, 0, 8 * 123456, inf), "rejected numeric");
  w.add("fuzz_merl", "tpl-180-short.bin", merl_patch(8, {}, -8, 0, {}), "rejected truncated");
  w.add("fuzz_merl", "tpl-180-long.bin", merl_patch(8, {}, 16, 0, {}), "rejected corrupt");
  w.add("fuzz_merl", "tpl-180-as-360.bin", merl_patch(4, merl_header(90, 90, 360), 0, 0, {}),
        "rejected truncated");
}

void roundtrip_seeds(Writer& w) {
  std::mt19937 rng(20240611);
  for (int i = 0; i < 24; ++i) {
    Bytes b(std::size_t(64) << (i % 6));
    for (std::uint8_t& v : b) v = std::uint8_t(rng());
    const bool broken = i % 4 == 3;
    b[3] = std::uint8_t((b[3] & 0xFE) | (broken ? 1 : 0));  // the byte that breaks a rule
    w.add("fuzz_roundtrip", "seed-" + std::to_string(i) + ".bin", b,
          broken ? "rejected invalid-argument" : "accepted");
  }
  // Inputs long enough to reach the residual layer (one in 32 of them): the first with one bound
  // (mode 0), with a shift per row (mode 2), with interpolated levels (mode 3) and with a step per
  // level (mode 4, written only where version 1.3 codes the model), from a fixed search.
  std::mt19937_64 search(2026);
  bool have[4] = {false, false, false, false};
  const char* names[4] = {"residual-one-bound.bin", "residual-row-bounds.bin",
                          "residual-interpolated.bin", "residual-level-steps.bin"};
  for (int t = 0; t < 100000 && !(have[0] && have[1] && have[2] && have[3]); ++t) {
    Bytes b(20000 + search() % 40000);
    for (std::uint8_t& v : b) v = std::uint8_t(search());
    b[3] &= 0xFE;  // valid: the residual is checked
    cbrdf::fuzz::ByteSource in({b.data(), b.size()});
    for (int k = 0; k < 4; ++k) in.u8();  // bits, level, metadata, breakage
    const Model m = cbrdf::fuzz::build_model(in, true);
    const int mode = m.residual.row_shift.empty() ? 0
                     : m.residual.middle_steps()  ? 3
                     : m.residual.interpolated()  ? 2
                                                  : 1;
    if (!m.residual.present() || have[mode]) continue;
    cbrdf::fuzz::RoundtripOptions with_residual;
    with_residual.always_residual = true;
    if (mode == 3 &&
        cbrdf::fuzz::run_roundtrip(b, with_residual).outcome != cbrdf::fuzz::Outcome::kAccepted) {
      continue;
    }
    have[mode] = true;
    w.add("fuzz_roundtrip", names[mode], b, "accepted");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR (normally fuzz/corpus)\n", argv[0]);
    return 2;
  }
  Writer w{fs::path(argv[1]), {}, false};
  container_and_decode_seeds(w);
  merl_seeds(w);
  roundtrip_seeds(w);
  std::ofstream manifest(w.root / "EXPECTED.txt");
  manifest << "# <target>/<seed> accepted | rejected <error code>: written by fuzz_make_seeds.\n";
  for (const std::string& line : w.manifest) manifest << line << "\n";
  if (!manifest || w.failed) return 1;
  std::printf("wrote %zu seeds to %s\n", w.manifest.size(), argv[1]);
  return 0;
}
