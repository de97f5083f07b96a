// SPDX-License-Identifier: MIT
/// @file
/// RAII for the C API's handle, header-only, for C++ programs that link the shared library (whose
/// only interface is the C API of cbrdf/cbrdf_decode.h), as libjxl's decode_cxx.h:
///
///   cbrdf::abi::ModelPtr m = cbrdf::abi::open_model_file("paint.cbrdf");
///   if (!m) std::fprintf(stderr, "%s\n", cbrdf_last_error_message());
///   cbrdf_model_eval(m.get(), wi, wo, rgb);
///
/// Nothing here is compiled into the library: it is the C ABI, held by a std::unique_ptr.
#pragma once

#include <cstddef>
#include <memory>

#include "cbrdf/cbrdf_decode.h"

namespace cbrdf::abi {

/// Frees a cbrdf_model with cbrdf_model_free() (the deleter of ModelPtr).
struct ModelDeleter {
  /// Frees model (NULL allowed).
  void operator()(cbrdf_model* model) const noexcept { cbrdf_model_free(model); }
};

/// Owns a cbrdf_model*; null after a failed open (the reason in cbrdf_last_error_message()).
using ModelPtr = std::unique_ptr<cbrdf_model, ModelDeleter>;

/// cbrdf_model_open_file() into an owning pointer.
inline ModelPtr open_model_file(const char* path) {
  return ModelPtr(cbrdf_model_open_file(path));
}

/// cbrdf_model_open_memory() into an owning pointer.
inline ModelPtr open_model_memory(const void* data, std::size_t size) {
  return ModelPtr(cbrdf_model_open_memory(data, size));
}

}  // namespace cbrdf::abi
