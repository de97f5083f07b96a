// SPDX-License-Identifier: MIT
// decode_model_file: a .cbrdf file read from a path and decoded (cbrdf/codec.h).
#include <span>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/file_io.h"

namespace cbrdf {

Expected<Model> decode_model_file(const std::string& path, ContainerInfo* info) {
  // An empty path would otherwise read as ": no such file".
  if (path.empty()) {
    return Status(ErrorCode::kInvalidArgument,
                  "decode_model_file: the path is empty (give the path of a .cbrdf file)");
  }
  CBRDF_ASSIGN_OR_RETURN(auto bytes, read_file(path, kMaxContainerBytes));
  auto model = decode_model(std::span<const std::uint8_t>(bytes), info);
  if (!model.ok()) return model.status().with_context(path);
  return model;
}

}  // namespace cbrdf
