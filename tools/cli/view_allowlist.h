// SPDX-License-Identifier: MIT
// What `cbrdf view` serves, decided once at start-up: the viewer folder's regular files (none
// whose real path leaves the folder), cbrdf.wasm, cbrdf.mjs and glsl.mjs from the wasm folder
// (the npm package's staging folder), /files.json and the given files as /files/N. Nothing else
// is ever looked up on disk from a request.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf::cli {

// The npm package's files the page imports from the wasm folder (glsl.mjs: the shader's
// evaluation), not the rest of the package the wasm build stages beside them. `cbrdf view` looks
// for a folder that has them all; the allowlist serves exactly these.
inline constexpr std::array<const char*, 3> kViewWasmFiles = {"cbrdf.wasm", "cbrdf.mjs",
                                                              "glsl.mjs"};

struct ServedFile {
  std::filesystem::path path;
  std::string mime;
  // The folder the file must still resolve into when it is opened (empty for the given files,
  // which the user named and may be symlinks).
  std::filesystem::path confined_to;
};

class ViewAllowlist {
 public:
  // Fails when a folder cannot be listed or a given file is not a regular file.
  static Expected<ViewAllowlist> build(const std::filesystem::path& viewer_dir,
                                       const std::filesystem::path& wasm_dir,
                                       const std::vector<std::string>& files);

  // The file for a request path ("/index.html", "/files/0"; "/" is "/index.html"), or null.
  const ServedFile* find(std::string_view path) const;
  // [{"name": NAME, "url": "/files/N"}, ...]: valid JSON and UTF-8 for any file name.
  const std::string& files_json() const { return files_json_; }
  std::size_t size() const { return by_path_.size(); }

 private:
  std::map<std::string, ServedFile, std::less<>> by_path_;
  std::string files_json_;
};

// Whether a request target as sent may name a served file at all: absolute ("/..."), made of
// letters, digits and "._-/" only, without "..", "//", backslashes, percent escapes or control
// bytes. The query ("?..."), which nothing served reads, is only checked for control bytes and
// backslashes. Anything else is a malformed request (400), before any lookup.
bool target_is_acceptable(std::string_view target);

// The MIME type served for a file name's extension.
std::string mime_of(const std::filesystem::path& p);

}  // namespace cbrdf::cli
