// SPDX-License-Identifier: MIT
// The C API's decoder part (cbrdf/cbrdf_decode.h), its experimental section included: errors, model
// handles, description, evaluation, sampling and tables. Everything here is a thin boundary over
// the C++ API: arguments are checked, results copied out, and every exception is caught and
// reported as the thread's last error. The experimental calls are defined here too.
#define CBRDF_EXPERIMENTAL_API 1

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iterator>
#include <memory>
#include <mutex>
#include <new>
#include <numbers>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "capi/batch_checks.h"
#include "capi/c_api_internal.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/cbrdf_decode.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/model.h"
#include "cbrdf/parallel.h"
#include "cbrdf/sampling.h"
#include "cbrdf/status.h"
#include "cbrdf/version.h"

// The C enums are the C++ ones, value for value.
#define CBRDF_SAME_CODE(c, cpp) \
  static_assert(int(c) == int(cbrdf::ErrorCode::cpp), #c " differs from ErrorCode::" #cpp)
CBRDF_SAME_CODE(CBRDF_OK, kOk);
CBRDF_SAME_CODE(CBRDF_ERROR_IO, kIo);
CBRDF_SAME_CODE(CBRDF_ERROR_NOT_FOUND, kNotFound);
CBRDF_SAME_CODE(CBRDF_ERROR_TRUNCATED, kTruncated);
CBRDF_SAME_CODE(CBRDF_ERROR_BAD_SIGNATURE, kBadSignature);
CBRDF_SAME_CODE(CBRDF_ERROR_UNSUPPORTED, kUnsupported);
CBRDF_SAME_CODE(CBRDF_ERROR_CORRUPT, kCorrupt);
CBRDF_SAME_CODE(CBRDF_ERROR_CHECKSUM, kChecksum);
CBRDF_SAME_CODE(CBRDF_ERROR_LIMIT, kLimit);
CBRDF_SAME_CODE(CBRDF_ERROR_INVALID_ARGUMENT, kInvalidArgument);
CBRDF_SAME_CODE(CBRDF_ERROR_NUMERIC, kNumeric);
CBRDF_SAME_CODE(CBRDF_ERROR_INTERNAL, kInternal);
CBRDF_SAME_CODE(CBRDF_ERROR_CANCELLED, kCancelled);
#undef CBRDF_SAME_CODE
static_assert(int(CBRDF_FAMILY_INDEPENDENCE) == int(cbrdf::CopulaFamily::kIndependence));
static_assert(int(CBRDF_FAMILY_FRANK) == int(cbrdf::CopulaFamily::kFrank));
static_assert(int(CBRDF_FAMILY_CLAYTON) == int(cbrdf::CopulaFamily::kClayton));
static_assert(int(CBRDF_FAMILY_GUMBEL) == int(cbrdf::CopulaFamily::kGumbel));
static_assert(int(CBRDF_FAMILY_JOE) == int(cbrdf::CopulaFamily::kJoe));
static_assert(sizeof(double) == 8);

// The handle. It is created once, on the heap, and never copied or moved: the evaluator keeps a
// pointer to `model` (and its Term objects pointers into model's components), and the sampler a
// pointer to the evaluator. Members are destroyed in reverse order, so the sampler goes first.
struct cbrdf_model {
  cbrdf::ContainerInfo info;
  cbrdf::Model model;
  std::unique_ptr<const cbrdf::ModelEvaluator> evaluator;  // built from `model` where it lives
  mutable std::once_flag sampler_once;
  mutable std::unique_ptr<const cbrdf::BrdfSampler> sampler;
  // Set once the sampler is built: checked first, as std::call_once costs more than a load, and
  // renderers draw one sample per call.
  mutable std::atomic<const cbrdf::BrdfSampler*> sampler_ready{nullptr};

  cbrdf_model() = default;
  cbrdf_model(const cbrdf_model&) = delete;
  cbrdf_model& operator=(const cbrdf_model&) = delete;
};

namespace cbrdf::internal {
namespace {

struct LastError {
  cbrdf_status code = CBRDF_OK;
  std::string message;
};

LastError& last_error() noexcept {
  thread_local LastError e;
  return e;
}

// Largest element count for which n triples of doubles can exist in memory.
constexpr std::size_t kMaxTriples = SIZE_MAX / (3 * sizeof(double));
template <class T>
std::string format_vector(const T* w) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", double(w[0]), double(w[1]), double(w[2]));
  return buf;
}

// A finite unit vector (within kDirectionTolerance: the evaluator rescales it, model.h). Checked
// per element of a batch, so it allocates nothing unless it fails.
template <class T>
bool is_direction(const T* w) {
  T x = w[0], y = w[1], z = w[2];
  return unit_direction(x, y, z);
}

// `name`, or `name[index]` for an element of a batch.
template <class T>
Status direction_error(const T* w, const char* name, std::size_t index = SIZE_MAX) {
  std::string what = name;
  if (index != SIZE_MAX) what += "[" + std::to_string(index) + "]";
  return invalid_argument(what +
                          " must be a finite unit vector (squared length within 1e-3 of 1)"
                          ", not " +
                          format_vector(w));
}

template <class T>
Status check_direction(const T* w, const char* name, std::size_t index = SIZE_MAX) {
  return is_direction(w) ? ok_status() : direction_error(w, name, index);
}

// A direction to evaluate (eval, sample_pdf): a finite unit vector as above, or exactly (0, 0, 0),
// a rejected draw's wi, which evaluates to 0 (model.h), so that drawn directions pass unchecked.
template <class T>
Status check_eval_direction(const T* w, const char* name, std::size_t index = SIZE_MAX) {
  if (internal::zero_direction(w[0], w[1], w[2]) || is_direction(w)) return ok_status();
  return invalid_argument(std::string(name) +
                          (index != SIZE_MAX ? "[" + std::to_string(index) + "]" : "") +
                          " must be a finite unit vector (squared length within 1e-3 of 1) or "
                          "(0, 0, 0) (a rejected draw), not " +
                          format_vector(w));
}

// check_eval_direction over a batch's n interleaved pairs: one pass that builds no Status
// (eval_pairs_usable), and the first bad direction's error, in the order wi[0], wo[0], wi[1], ...,
// only when it fails.
template <class T>
Status check_eval_pairs(const T* wi, const T* wo, std::size_t n) {
  if (eval_pairs_usable(wi, wo, n)) return ok_status();
  for (std::size_t k = 0; k < n; ++k) {
    CBRDF_RETURN_IF_ERROR(check_eval_direction(wi + 3 * k, "wi", k));
    CBRDF_RETURN_IF_ERROR(check_eval_direction(wo + 3 * k, "wo", k));
  }
  return ok_status();
}

Status check_unit_numbers(double u1, double u2, const std::string& what) {
  if (std::isfinite(u1) && std::isfinite(u2)) return ok_status();
  char buf[96];
  std::snprintf(buf, sizeof buf, " (%.9g, %.9g) must be finite numbers in [0, 1)", u1, u2);
  return invalid_argument(what + buf);
}

Vec3 to_vec3(const double* w) {
  return Vec3{w[0], w[1], w[2]};
}

// Arguments of the per-slice getters.
Status check_slice(const cbrdf_model* model, int slice) {
  if (model == nullptr) return invalid_argument("model is NULL");
  const int n = int(model->model.slices.size());
  if (slice < 0 || slice >= n) {
    return invalid_argument("slice " + std::to_string(slice) + " is out of range (the model has " +
                            std::to_string(n) + ", 0 to " + std::to_string(n - 1) + ")");
  }
  return ok_status();
}

Status check_slice_channel(const cbrdf_model* model, int slice, int channel) {
  CBRDF_RETURN_IF_ERROR(check_slice(model, slice));
  if (channel < 0 || channel >= kChannels) {
    return invalid_argument("channel " + std::to_string(channel) + " is out of range (0 to 2)");
  }
  return ok_status();
}

// Builds the handle from a file's bytes: one validating pass gives the model and the description
// (chunk layout, header fields, metadata) that Model does not hold.
Expected<std::unique_ptr<cbrdf_model>> build_model(std::span<const std::uint8_t> bytes) {
  auto handle = std::make_unique<cbrdf_model>();
  CBRDF_ASSIGN_OR_RETURN(handle->model, decode_model(bytes, &handle->info));
  // The handle owns the model and never moves, so the evaluator shares it without owning it.
  handle->evaluator = std::make_unique<const ModelEvaluator>(
      std::shared_ptr<const Model>(std::shared_ptr<const Model>(), &handle->model));
  return handle;
}

template <typename Open>
cbrdf_model* open_reported(Open&& open) noexcept {
  try {
    Expected<std::unique_ptr<cbrdf_model>> handle = open();
    if (!handle.ok()) {
      report(handle.status());
      return nullptr;
    }
    clear_last_error();
    return handle.value().release();
  } catch (...) {
    report_current_exception();
    return nullptr;
  }
}

const BrdfSampler& sampler_of(const cbrdf_model* model) {
  if (const BrdfSampler* s = model->sampler_ready.load(std::memory_order_acquire)) return *s;
  // A throw inside leaves the flag unset, so the next call tries again.
  std::call_once(model->sampler_once, [model] {
    model->sampler = std::make_unique<const BrdfSampler>(make_model_sampler(*model->evaluator));
    model->sampler_ready.store(model->sampler.get(), std::memory_order_release);
  });
  return *model->sampler;
}

}  // namespace

cbrdf_status to_c_status(ErrorCode code) noexcept {
  return cbrdf_status(int(code));
}

void set_last_error(cbrdf_status code, std::string_view message) noexcept {
  LastError& e = last_error();
  e.code = code == CBRDF_OK ? CBRDF_ERROR_INTERNAL : code;
  try {
    e.message.assign(message);
  } catch (...) {
    // Keep what fits in the capacity already there rather than nothing.
    e.message.clear();
    try {
      e.message.assign(message.substr(0, e.message.capacity()));
    } catch (...) {
    }
  }
}

void clear_last_error() noexcept {
  LastError& e = last_error();
  e.code = CBRDF_OK;
  e.message.clear();
}

cbrdf_status report(const Status& status) noexcept {
  if (status.ok()) {
    clear_last_error();
    return CBRDF_OK;
  }
  set_last_error(to_c_status(status.code()), status.message());
  return last_error().code;
}

cbrdf_status report_current_exception() noexcept {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    set_last_error(CBRDF_ERROR_INTERNAL, "out of memory");
  } catch (const std::exception& ex) {
    try {
      set_last_error(CBRDF_ERROR_INTERNAL, std::string("internal error: ") + ex.what());
    } catch (...) {
      set_last_error(CBRDF_ERROR_INTERNAL, "internal error");
    }
  } catch (...) {
    set_last_error(CBRDF_ERROR_INTERNAL, "internal error: unknown exception");
  }
  return CBRDF_ERROR_INTERNAL;
}

}  // namespace cbrdf::internal

using cbrdf::internal::guarded;
using cbrdf::internal::invalid_argument;

extern "C" {

const char* cbrdf_version_string(void) {
  return CBRDF_VERSION_STRING;
}

int cbrdf_version_number(void) {
  static constexpr int kVersion = CBRDF_VERSION;
  return kVersion;
}

cbrdf_status cbrdf_last_error_code(void) {
  return cbrdf::internal::last_error().code;
}

const char* cbrdf_last_error_message(void) {
  return cbrdf::internal::last_error().message.c_str();
}

void cbrdf_set_thread_limit(int n) {
  cbrdf::set_thread_limit(n);
}

int cbrdf_thread_limit(void) {
  return cbrdf::thread_limit();
}

const char* cbrdf_status_name(cbrdf_status status) {
  // A C caller may pass any int as the enum; reading one outside its values as the enum is
  // undefined in C++ (clang's UBSan reports it), so its bytes are read as the underlying integer.
  std::underlying_type_t<cbrdf_status> raw;
  std::memcpy(&raw, &status, sizeof raw);
  const long long code = static_cast<long long>(raw);
  if (code < CBRDF_OK || code > CBRDF_ERROR_CANCELLED) return "unknown";
  return cbrdf::error_code_name(cbrdf::ErrorCode(code));
}

cbrdf_model* cbrdf_model_open_memory(const void* data, size_t size) {
  return cbrdf::internal::open_reported([&]() -> cbrdf::Expected<std::unique_ptr<cbrdf_model>> {
    if (data == nullptr) return invalid_argument("cbrdf_model_open_memory: data is NULL");
    return cbrdf::internal::build_model(
        std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(data), size));
  });
}

cbrdf_model* cbrdf_model_open_file(const char* path) {
  return cbrdf::internal::open_reported([&]() -> cbrdf::Expected<std::unique_ptr<cbrdf_model>> {
    if (path == nullptr) return invalid_argument("cbrdf_model_open_file: path is NULL");
    if (*path == '\0') {
      return invalid_argument(
          "cbrdf_model_open_file: path is empty (give the path of a .cbrdf file)");
    }
    CBRDF_ASSIGN_OR_RETURN(auto bytes, cbrdf::read_file(path, cbrdf::kMaxContainerBytes));
    auto handle = cbrdf::internal::build_model(bytes);
    if (!handle.ok()) return handle.status().with_context(path);
    return handle;
  });
}

void cbrdf_model_free(cbrdf_model* model) {
  delete model;
}

cbrdf_status cbrdf_model_get_info(const cbrdf_model* model, cbrdf_model_info* info) {
  return guarded([&] {
    // The first version of the struct ends with not_measured_bins.
    constexpr std::size_t kFirstSize =
        offsetof(cbrdf_model_info, not_measured_bins) + sizeof(uint64_t);
    if (model == nullptr || info == nullptr) {
      return invalid_argument("cbrdf_model_get_info: model or info is NULL");
    }
    if (info->struct_size < kFirstSize) {
      return invalid_argument("cbrdf_model_get_info: info->struct_size is " +
                              std::to_string(info->struct_size) + ", less than " +
                              std::to_string(kFirstSize) + " (set it to sizeof(cbrdf_model_info))");
    }
    cbrdf_model_info out{};
    out.struct_size = uint32_t(std::min<std::size_t>(info->struct_size, sizeof out));
    out.version_major = model->info.layout.major;
    out.version_minor = model->info.layout.minor;
    out.slices = int(model->model.slices.size());
    out.max_components = 0;
    for (const cbrdf::Slice& s : model->model.slices) {
      for (const cbrdf::ChannelSlice& c : s.channel) {
        out.max_components = std::max(out.max_components, c.components());
      }
    }
    out.bits = model->info.bits;
    out.file_bytes = model->info.layout.file_bytes;
    out.not_measured_bins = model->info.not_measured_bins;
    const cbrdf::ContainerInfo& ci = model->info;
    out.residual_mode = ci.residual_mode < 0 ? CBRDF_RESIDUAL_NONE : ci.residual_mode;
    const bool rows = ci.residual_mode == CBRDF_RESIDUAL_ROW_BOUNDED ||
                      ci.residual_mode == CBRDF_RESIDUAL_INTERPOLATED ||
                      ci.residual_mode == CBRDF_RESIDUAL_LEVEL_STEPS;
    const bool bounded = rows || ci.residual_mode == CBRDF_RESIDUAL_BOUNDED;
    out.residual_max_error = model->model.residual.bound();  // 0 in mode 1 and without RESD
    out.residual_min_error = rows ? ci.residual_min_error : bounded ? ci.residual_max_error : 0;
    out.residual_knee = bounded ? ci.residual_knee : 0;
    for (const cbrdf::ChunkInfo& c : ci.layout.chunks) {
      if (c.tag == cbrdf::kTagResidual) out.residual_bytes = c.stored_bytes;
    }
    std::memcpy(info, &out, out.struct_size);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_get_slice(const cbrdf_model* model, int slice, int* theta_d_begin,
                                   int* theta_d_end) {
  return guarded([&] {
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_slice(model, slice));
    if (theta_d_begin == nullptr || theta_d_end == nullptr) {
      return invalid_argument("cbrdf_model_get_slice: an output pointer is NULL");
    }
    const cbrdf::Slice& s = model->model.slices[std::size_t(slice)];
    *theta_d_begin = s.theta_d_begin;
    *theta_d_end = s.theta_d_end;
    return cbrdf::ok_status();
  });
}

const char* cbrdf_family_name(int family) {
  if (family == CBRDF_FAMILY_AUTO) return "auto";
  if (family < 0 || family > 255 || !cbrdf::family_valid(std::uint8_t(family))) return "unknown";
  // family_name returns views of string literals, so data() is NUL-terminated.
  return cbrdf::family_name(cbrdf::CopulaFamily(family)).data();
}

cbrdf_status cbrdf_model_get_component_count(const cbrdf_model* model, int slice, int channel,
                                             int* count) {
  return guarded([&] {
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_slice_channel(model, slice, channel));
    if (count == nullptr) return invalid_argument("cbrdf_model_get_component_count: count is NULL");
    *count = model->model.slices[std::size_t(slice)].channel[std::size_t(channel)].components();
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_get_component(const cbrdf_model* model, int slice, int channel,
                                       int component, int* family, double* theta, double* scale) {
  return guarded([&] {
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_slice_channel(model, slice, channel));
    const cbrdf::ChannelSlice& cs =
        model->model.slices[std::size_t(slice)].channel[std::size_t(channel)];
    if (component < 0 || component >= cs.components()) {
      return invalid_argument("component " + std::to_string(component) +
                              " is out of range (slice " + std::to_string(slice) + " channel " +
                              std::to_string(channel) + " has " + std::to_string(cs.components()) +
                              ")");
    }
    if (family == nullptr || theta == nullptr || scale == nullptr) {
      return invalid_argument("cbrdf_model_get_component: an output pointer is NULL");
    }
    const cbrdf::Component& c = cs.component(component);
    *family = int(c.family);
    *theta = c.theta;
    *scale = c.scale;
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_metadata_count(const cbrdf_model* model, size_t* count) {
  return guarded([&] {
    if (model == nullptr || count == nullptr) {
      return invalid_argument("cbrdf_model_metadata_count: model or count is NULL");
    }
    *count = model->info.metadata.size();
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_metadata_at(const cbrdf_model* model, size_t i, const char** key,
                                     const char** value) {
  return guarded([&] {
    if (model == nullptr || key == nullptr || value == nullptr) {
      return invalid_argument("cbrdf_model_metadata_at: model, key or value is NULL");
    }
    const auto& meta = model->info.metadata;
    if (i >= meta.size()) {
      return invalid_argument("metadata index " + std::to_string(i) +
                              " is out of range (the model has " + std::to_string(meta.size()) +
                              " entries)");
    }
    *key = meta[i].first.c_str();
    *value = meta[i].second.c_str();
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval(const cbrdf_model* model, const double wi[3], const double wo[3],
                              double rgb[3]) {
  return guarded([&] {
    if (model == nullptr || wi == nullptr || wo == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_eval: model, wi, wo or rgb is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wi, "wi"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wo, "wo"));
    model->evaluator->eval(cbrdf::internal::to_vec3(wi), cbrdf::internal::to_vec3(wo), rgb);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval_batch(const cbrdf_model* model, size_t n, const double* wi,
                                    const double* wo, double* rgb, int threads) {
  return guarded([&] {
    if (model == nullptr) return invalid_argument("cbrdf_model_eval_batch: model is NULL");
    if (n == 0) return cbrdf::ok_status();
    if (wi == nullptr || wo == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_eval_batch: wi, wo or rgb is NULL");
    }
    if (n > cbrdf::internal::kMaxTriples) {
      return invalid_argument("cbrdf_model_eval_batch: n = " + std::to_string(n) + " is too large");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_pairs(wi, wo, n));
    // Bit for bit eval's, vectorized and threaded.
    model->evaluator->eval_batch(n, wi, wo, rgb, threads);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval_batch_soa(const cbrdf_model* model, size_t n, const double* wi_x,
                                        const double* wi_y, const double* wi_z, const double* wo_x,
                                        const double* wo_y, const double* wo_z, double* r,
                                        double* g, double* b, int threads) {
  return guarded([&] {
    if (model == nullptr) return invalid_argument("cbrdf_model_eval_batch_soa: model is NULL");
    if (n == 0) return cbrdf::ok_status();
    const double* in[6] = {wi_x, wi_y, wi_z, wo_x, wo_y, wo_z};
    if (std::find(std::begin(in), std::end(in), nullptr) != std::end(in) || r == nullptr ||
        g == nullptr || b == nullptr) {
      return invalid_argument("cbrdf_model_eval_batch_soa: an input or output array is NULL");
    }
    if (n > cbrdf::internal::kMaxTriples * 3) {
      return invalid_argument("cbrdf_model_eval_batch_soa: n = " + std::to_string(n) +
                              " is too large");
    }
    for (std::size_t k = 0; k < n; ++k) {
      const double i[3] = {wi_x[k], wi_y[k], wi_z[k]}, o[3] = {wo_x[k], wo_y[k], wo_z[k]};
      CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(i, "wi", k));
      CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(o, "wo", k));
    }
    model->evaluator->eval_batch(n, wi_x, wi_y, wi_z, wo_x, wo_y, wo_z, r, g, b, threads);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval_f32(const cbrdf_model* model, const float wi[3], const float wo[3],
                                  float rgb[3]) {
  return guarded([&] {
    if (model == nullptr || wi == nullptr || wo == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_eval_f32: model, wi, wo or rgb is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wi, "wi"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wo, "wo"));
    model->evaluator->eval_f32(wi, wo, rgb);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval_batch_f32(const cbrdf_model* model, size_t n, const float* wi,
                                        const float* wo, float* rgb, int threads) {
  return guarded([&] {
    if (model == nullptr) return invalid_argument("cbrdf_model_eval_batch_f32: model is NULL");
    if (n == 0) return cbrdf::ok_status();
    if (wi == nullptr || wo == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_eval_batch_f32: wi, wo or rgb is NULL");
    }
    if (n > SIZE_MAX / (3 * sizeof(float))) {
      return invalid_argument("cbrdf_model_eval_batch_f32: n = " + std::to_string(n) +
                              " is too large");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_pairs(wi, wo, n));
    model->evaluator->eval_batch_f32(n, wi, wo, rgb, threads);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_sample(const cbrdf_model* model, const double wo[3], double u1, double u2,
                                double wi[3], double* pdf, double weight[3]) {
  return guarded([&] {
    if (model == nullptr || wo == nullptr || wi == nullptr || pdf == nullptr || weight == nullptr) {
      return invalid_argument("cbrdf_model_sample: model, wo, wi, pdf or weight is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_direction(wo, "wo"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_unit_numbers(u1, u2, "u1, u2"));
    double w[3];
    const cbrdf::BrdfSample s =
        cbrdf::internal::sampler_of(model).sample(cbrdf::internal::to_vec3(wo), u1, u2, w);
    wi[0] = s.wi.x;
    wi[1] = s.wi.y;
    wi[2] = s.wi.z;
    *pdf = s.pdf;
    std::copy(w, w + 3, weight);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_sample_batch(const cbrdf_model* model, size_t n, const double* wo,
                                      const double* u, double* wi, double* pdf, double* weight,
                                      int threads) {
  return guarded([&] {
    if (model == nullptr) return invalid_argument("cbrdf_model_sample_batch: model is NULL");
    if (n == 0) return cbrdf::ok_status();
    if (wo == nullptr || u == nullptr || wi == nullptr || pdf == nullptr || weight == nullptr) {
      return invalid_argument("cbrdf_model_sample_batch: wo, u, wi, pdf or weight is NULL");
    }
    if (n > cbrdf::internal::kMaxTriples) {
      return invalid_argument("cbrdf_model_sample_batch: n = " + std::to_string(n) +
                              " is too large");
    }
    for (std::size_t k = 0; k < n; ++k) {
      CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_direction(wo + 3 * k, "wo", k));
      if (!std::isfinite(u[2 * k]) || !std::isfinite(u[2 * k + 1])) {
        return cbrdf::internal::check_unit_numbers(u[2 * k], u[2 * k + 1],
                                                   "u pair " + std::to_string(k) + " (u[" +
                                                       std::to_string(2 * k) + "], u[" +
                                                       std::to_string(2 * k + 1) + "])");
      }
    }
    // The batch path: the same draws, pdfs and weights as sample() and eval per draw, bit for bit.
    cbrdf::internal::sampler_of(model).sample_batch(n, wo, u, wi, pdf, weight, threads);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_sample_pdf(const cbrdf_model* model, const double wi[3],
                                    const double wo[3], double* pdf) {
  return guarded([&] {
    if (model == nullptr || wi == nullptr || wo == nullptr || pdf == nullptr) {
      return invalid_argument("cbrdf_model_sample_pdf: model, wi, wo or pdf is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wi, "wi"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wo, "wo"));
    *pdf = cbrdf::internal::sampler_of(model).sample_pdf(cbrdf::internal::to_vec3(wi),
                                                         cbrdf::internal::to_vec3(wo));
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_eval_pdf(const cbrdf_model* model, const double wi[3], const double wo[3],
                                  double rgb[3], double* pdf) {
  return guarded([&] {
    if (model == nullptr || wi == nullptr || wo == nullptr || rgb == nullptr || pdf == nullptr) {
      return invalid_argument("cbrdf_model_eval_pdf: model, wi, wo, rgb or pdf is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wi, "wi"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wo, "wo"));
    const cbrdf::Vec3 i = cbrdf::internal::to_vec3(wi), o = cbrdf::internal::to_vec3(wo);
    const double p =
        cbrdf::internal::sampler_of(model).sample_pdf(i, o);  // may throw: before any output
    model->evaluator->eval(i, o, rgb);
    *pdf = p;
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_pdf(const cbrdf_model* model, const double wo[3], const double wi[3],
                             double* pdf) {
  return guarded([&] {
    if (model == nullptr || wo == nullptr || wi == nullptr || pdf == nullptr) {
      return invalid_argument("cbrdf_model_pdf: model, wo, wi or pdf is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wo, "wo"));
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_eval_direction(wi, "wi"));
    *pdf = cbrdf::internal::sampler_of(model).sample_pdf(cbrdf::internal::to_vec3(wi),
                                                         cbrdf::internal::to_vec3(wo));
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_albedo(const cbrdf_model* model, const double wo[3], double rgb[3],
                                int threads) {
  return guarded([&] {
    if (model == nullptr || wo == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_albedo: model, wo or rgb is NULL");
    }
    CBRDF_RETURN_IF_ERROR(cbrdf::internal::check_direction(wo, "wo"));
    cbrdf::Vec3 o = cbrdf::internal::to_vec3(wo);
    cbrdf::unit_direction(o);
    model->evaluator->albedo(o.z, rgb, threads);
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_albedo_table(const cbrdf_model* model, size_t n, double* rgb,
                                      int threads) {
  return guarded([&] {
    if (model == nullptr || rgb == nullptr) {
      return invalid_argument("cbrdf_model_albedo_table: model or rgb is NULL");
    }
    // Each entry is a whole albedo (129,600 evaluations): the bound keeps one call to seconds.
    constexpr std::size_t kMaxAlbedoEntries = 256;
    if (n < 1 || n > kMaxAlbedoEntries) {
      return invalid_argument("cbrdf_model_albedo_table: n = " + std::to_string(n) +
                              " is out of range (1 to " + std::to_string(kMaxAlbedoEntries) +
                              "; each entry costs a whole cbrdf_model_albedo)");
    }
    std::vector<double> out(3 * n);  // rgb is written only on success
    for (std::size_t k = 0; k < n; ++k) {
      const double theta = (double(k) + 0.5) / double(n) * (std::numbers::pi / 2);
      model->evaluator->albedo(std::cos(theta), &out[3 * k], threads);
    }
    std::copy(out.begin(), out.end(), rgb);
    return cbrdf::ok_status();
  });
}

size_t cbrdf_merl_table_size(void) {
  return cbrdf::kChannels * cbrdf::kBinsPerChannel;
}

cbrdf_status cbrdf_model_table(const cbrdf_model* model, double* stored_values, size_t count) {
  return guarded([&] {
    if (model == nullptr || stored_values == nullptr) {
      return invalid_argument("cbrdf_model_table: model or stored_values is NULL");
    }
    if (count != cbrdf_merl_table_size()) {
      return invalid_argument(
          "cbrdf_model_table: count is " + std::to_string(count) +
          ", not cbrdf_merl_table_size() = " + std::to_string(cbrdf_merl_table_size()));
    }
    const cbrdf::BrdfTable table = model->evaluator->table();
    std::memcpy(stored_values, table.stored_values().data(), count * sizeof(double));
    return cbrdf::ok_status();
  });
}

cbrdf_status cbrdf_model_write_merl(const cbrdf_model* model, const char* path) {
  return guarded([&] {
    if (model == nullptr || path == nullptr) {
      return invalid_argument("cbrdf_model_write_merl: model or path is NULL");
    }
    return cbrdf::write_merl(path, model->evaluator->table());
  });
}

void cbrdf_free(void* p) {
  std::free(p);
}

}  // extern "C"
