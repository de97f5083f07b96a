// SPDX-License-Identifier: MIT
// The C API's encoding part (cbrdf/cbrdf_c.h): settings, and table or file -> .cbrdf. Kept apart
// from c_api_decoder.cc so that a decoder-only library need not link the fitter.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "capi/c_api_internal.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/cbrdf_encode.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/encoder_settings.h"
#include "cbrdf/file_io.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/noise.h"
#include "cbrdf/parallel.h"
#include "cbrdf/status.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

static_assert(CBRDF_NOISE_BANDS == kNoiseBands, "the C API's bands are the library's");

// The first version of the struct ends with `threads`.
constexpr std::size_t kFirstSettingsSize = offsetof(cbrdf_encode_settings, threads) + sizeof(int);

cbrdf_encode_settings default_settings() {
  const EncoderSettings d;
  cbrdf_encode_settings s{};
  s.struct_size = sizeof s;
  s.bits = CBRDF_BITS_AUTO;  // as `cbrdf encode`: the bit depth from the data
  s.zstd_level = d.container.zstd_level;
  s.slices = d.fit.slices;
  s.components = d.fit.components;
  s.family = int(d.fit.family);
  s.threads = d.fit.threads;
  s.mixture_copulas = d.fit.mixture_copulas ? 1 : 0;
  s.format_version = CBRDF_FORMAT_AUTO;  // as `cbrdf encode`
  s.metadata = CBRDF_METADATA_SHORT;
  s.residual_steps = CBRDF_RESIDUAL_STEPS_ONE;
  return s;
}

// A struct from before 2.2 ends before these fields; its callers keep the coding they had.
constexpr std::size_t kSettingsSize22 = offsetof(cbrdf_encode_settings, metadata) + sizeof(int);

// The C API's spelling of a neutral setting name: its field.
std::string c_spelling(std::string_view setting) {
  return "cbrdf_encode_settings." + std::string(setting);
}

// A C value that stands for one of a few named constants: a problem when it is none of them.
void check_choice(std::vector<SettingProblem>* problems, const char* setting, int value, bool known,
                  const char* values) {
  if (!known) {
    problems->push_back(
        {setting, std::string("must be ") + values + ", not " + std::to_string(value)});
  }
}

// The C settings (NULL: the defaults) as the C++ encoder's, checked by validate().
Expected<EncoderSettings> to_encoder_settings(const cbrdf_encode_settings* in) {
  cbrdf_encode_settings s = default_settings();
  if (in != nullptr) {
    if (in->struct_size < kFirstSettingsSize) {
      return invalid_argument("cbrdf_encode_settings.struct_size is " +
                              std::to_string(in->struct_size) + ", less than " +
                              std::to_string(kFirstSettingsSize) +
                              " (fill the struct with cbrdf_encode_settings_init)");
    }
    // A newer caller's struct may be longer: read what this version knows.
    std::memcpy(&s, in, std::min<std::size_t>(in->struct_size, sizeof s));
    if (in->struct_size < kSettingsSize22) {
      s.format_version = CBRDF_FORMAT_1_2;
      s.metadata = CBRDF_METADATA_FULL;
    }
  }
  // Only what C spells as integer constants is read here; every range is validate()'s.
  std::vector<SettingProblem> problems;
  const bool family_known =
      s.family == CBRDF_FAMILY_AUTO ||
      (s.family >= 0 && family_valid(std::uint8_t(s.family)) && s.family < int(kCopulaFamilyCount));
  const std::string families = "a cbrdf_family (0 to " + std::to_string(kCopulaFamilyCount - 1) +
                               ") or CBRDF_FAMILY_AUTO (-1)";
  check_choice(&problems, "family", s.family, family_known, families.c_str());
  check_choice(&problems, "lossless", s.lossless, s.lossless == 0 || s.lossless == 1, "0 or 1");
  check_choice(&problems, "mixture_copulas", s.mixture_copulas,
               s.mixture_copulas == 0 || s.mixture_copulas == 1, "0 or 1");
  check_choice(&problems, "format_version", s.format_version,
               s.format_version == CBRDF_FORMAT_AUTO || s.format_version == CBRDF_FORMAT_1_2 ||
                   s.format_version == CBRDF_FORMAT_1_3,
               "CBRDF_FORMAT_AUTO (0), CBRDF_FORMAT_1_2 (12) or CBRDF_FORMAT_1_3 (13)");
  check_choice(&problems, "metadata", s.metadata,
               s.metadata >= CBRDF_METADATA_NONE && s.metadata <= CBRDF_METADATA_FULL,
               "CBRDF_METADATA_NONE (0), CBRDF_METADATA_SHORT (1) or CBRDF_METADATA_FULL (2)");
  check_choice(&problems, "residual_steps", s.residual_steps,
               s.residual_steps == CBRDF_RESIDUAL_STEPS_ONE ||
                   s.residual_steps == CBRDF_RESIDUAL_STEPS_VISIBILITY,
               "CBRDF_RESIDUAL_STEPS_ONE (0) or CBRDF_RESIDUAL_STEPS_VISIBILITY (1)");
  if (!problems.empty()) return settings_status(problems, c_spelling);

  EncoderSettings out;
  out.auto_bits.enabled = s.bits == CBRDF_BITS_AUTO;
  if (!out.auto_bits.enabled) out.container.bits = s.bits;
  out.container.zstd_level = s.zstd_level;
  out.fit.slices = s.slices;
  out.fit.components = s.components;
  if (s.family == CBRDF_FAMILY_AUTO) {
    out.fit.auto_family = true;
  } else {
    out.fit.family = CopulaFamily(s.family);
  }
  out.fit.threads = s.threads;
  out.residual = residual_request(s.max_error, s.lossless != 0,
                                  s.residual_steps == CBRDF_RESIDUAL_STEPS_VISIBILITY);
  out.fit.mixture_copulas = s.mixture_copulas != 0;
  out.container.format = s.format_version == CBRDF_FORMAT_1_2   ? ContainerSettings::Format::kV12
                         : s.format_version == CBRDF_FORMAT_1_3 ? ContainerSettings::Format::kV13
                                                                : ContainerSettings::Format::kAuto;
  out.container.write_metadata = s.metadata != CBRDF_METADATA_NONE;
  out.container.metadata = s.metadata == CBRDF_METADATA_FULL ? ContainerSettings::Metadata::kFull
                                                             : ContainerSettings::Metadata::kShort;
  // (NULL for a struct from before 2.3: the bytes past its struct_size keep the defaults.)
  if (s.progress != nullptr) {
    out.progress = [fn = s.progress, user = s.progress_user](const EncodeProgress& p) {
      return fn(user, p.fraction) == 0;
    };
  }
  CBRDF_RETURN_IF_ERROR(settings_status(validate(out), c_spelling));
  // 0: one thread per core, as `cbrdf encode --threads 0`.
  if (out.fit.threads == 0) out.fit.threads = thread_limit();
  return out;
}

// read_merl refuses +Inf; a table from memory is held to the same rule.
Status check_no_positive_infinity(const BrdfTable& table) {
  for (int c = 0; c < kChannels; ++c) {
    const double* data = table.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (data[i] == std::numeric_limits<double>::infinity()) {
        return Status(ErrorCode::kNumeric,
                      "stored_values[" + std::to_string(std::size_t(c) * kBinsPerChannel + i) +
                          "] (channel " + std::to_string(c) + ", bin " + std::to_string(i) +
                          ") is +Inf, which is neither a measurement nor the "
                          "not-measured mark (a negative value or NaN)");
      }
    }
  }
  return ok_status();
}

}  // namespace
}  // namespace cbrdf::internal

extern "C" {

cbrdf_status cbrdf_encode_settings_init(cbrdf_encode_settings* settings) {
  return cbrdf::internal::guarded([&]() -> cbrdf::Status {
    if (settings == nullptr) {
      return cbrdf::internal::invalid_argument("cbrdf_encode_settings_init: settings is NULL");
    }
    *settings = cbrdf::internal::default_settings();
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_encode_table(const double* stored_values, size_t count,
                                const cbrdf_encode_settings* settings, void** out_bytes,
                                size_t* out_size) {
  if (out_bytes != nullptr) *out_bytes = nullptr;
  if (out_size != nullptr) *out_size = 0;
  return cbrdf::internal::guarded([&]() -> cbrdf::Status {
    using cbrdf::internal::invalid_argument;
    if (stored_values == nullptr || out_bytes == nullptr || out_size == nullptr) {
      return invalid_argument("cbrdf_encode_table: stored_values, out_bytes or out_size is NULL");
    }
    if (count != cbrdf_merl_table_size()) {
      return invalid_argument(
          "cbrdf_encode_table: count is " + std::to_string(count) +
          ", not cbrdf_merl_table_size() = " + std::to_string(cbrdf_merl_table_size()));
    }
    CBRDF_ASSIGN_OR_RETURN(auto st, cbrdf::internal::to_encoder_settings(settings));
    cbrdf::BrdfTable table;
    std::memcpy(table.stored_values().data(), stored_values, count * sizeof(double));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_no_positive_infinity(table));
    CBRDF_ASSIGN_OR_RETURN(auto encoded, cbrdf::encode_table(table, st));
    const std::vector<std::uint8_t>& bytes = encoded.bytes;
    void* buffer = std::malloc(bytes.size());
    if (buffer == nullptr) throw std::bad_alloc();
    std::memcpy(buffer, bytes.data(), bytes.size());
    *out_bytes = buffer;
    *out_size = bytes.size();
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_encode_merl_file(const char* in_path, const char* out_path,
                                    const cbrdf_encode_settings* settings) {
  return cbrdf::internal::guarded([&]() -> cbrdf::Status {
    if (in_path == nullptr || out_path == nullptr) {
      return cbrdf::internal::invalid_argument(
          "cbrdf_encode_merl_file: in_path or out_path is NULL");
    }
    CBRDF_ASSIGN_OR_RETURN(auto st, cbrdf::internal::to_encoder_settings(settings));
    st.container.source_name = std::filesystem::path(in_path).filename().string();
    CBRDF_ASSIGN_OR_RETURN(auto table, cbrdf::read_merl(in_path));
    auto encoded = cbrdf::encode_table(table, st);
    if (!encoded.ok()) return encoded.status().with_context(in_path);
    return cbrdf::write_file_atomic(out_path, encoded->bytes);
  });
}

cbrdf_status cbrdf_estimate_noise(const double* stored_values, size_t count,
                                  cbrdf_noise_estimate* out) {
  return cbrdf::internal::guarded([&]() -> cbrdf::Status {
    using cbrdf::internal::invalid_argument;
    if (stored_values == nullptr || out == nullptr) {
      return invalid_argument("cbrdf_estimate_noise: stored_values or out is NULL");
    }
    // The first version of the struct ends with `noisy`.
    constexpr std::size_t kFirstSize = offsetof(cbrdf_noise_estimate, noisy) + sizeof(int);
    if (out->struct_size < kFirstSize) {
      return invalid_argument("cbrdf_estimate_noise: out->struct_size is " +
                              std::to_string(out->struct_size) + ", less than " +
                              std::to_string(kFirstSize) + " (set it to sizeof(*out))");
    }
    if (count != cbrdf_merl_table_size()) {
      return invalid_argument(
          "cbrdf_estimate_noise: count is " + std::to_string(count) +
          ", not cbrdf_merl_table_size() = " + std::to_string(cbrdf_merl_table_size()));
    }
    cbrdf::BrdfTable table;
    std::memcpy(table.stored_values().data(), stored_values, count * sizeof(double));
    const cbrdf::NoiseEstimate e = cbrdf::estimate_noise(table);
    cbrdf_noise_estimate r{};
    r.struct_size = std::uint32_t(std::min<std::size_t>(out->struct_size, sizeof r));
    for (int c = 0; c < 3; ++c) {
      r.sigma[c] = e.sigma[std::size_t(c)];
      for (int b = 0; b < CBRDF_NOISE_BANDS; ++b) {
        r.band_sigma[b][c] = e.band_sigma[std::size_t(b)][std::size_t(c)];
      }
    }
    r.grazing_growth = e.grazing_growth;
    r.psnr_ceiling_tonemapped = e.psnr_ceiling_tonemapped;
    r.psnr_ceiling_linear = e.psnr_ceiling_linear;
    r.noisy = e.noisy() ? 1 : 0;
    std::memcpy(out, &r, r.struct_size);
    return cbrdf::ok_status();
  });
}

}  // extern "C"
