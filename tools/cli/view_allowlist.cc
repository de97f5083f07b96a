// SPDX-License-Identifier: MIT
#include "view_allowlist.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <system_error>

#include "info_json.h"

namespace cbrdf::cli {
namespace {

namespace fs = std::filesystem;

bool is_within(const fs::path& canonical_file, const fs::path& canonical_dir) {
  const auto [d, f] = std::mismatch(canonical_dir.begin(), canonical_dir.end(),
                                    canonical_file.begin(), canonical_file.end());
  return d == canonical_dir.end() && f != canonical_file.end();
}

bool is_url_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
         c == '_' || c == '-' || c == '/';
}

}  // namespace

std::string mime_of(const fs::path& p) {
  const std::string e = p.extension().string();
  if (e == ".html") return "text/html; charset=utf-8";
  if (e == ".mjs" || e == ".js") return "text/javascript; charset=utf-8";
  if (e == ".css") return "text/css; charset=utf-8";
  if (e == ".json") return "application/json";
  if (e == ".wasm") return "application/wasm";
  if (e == ".png") return "image/png";
  if (e == ".svg") return "image/svg+xml";
  if (e == ".md" || e == ".txt") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

bool target_is_acceptable(std::string_view target) {
  const std::size_t q = target.find('?');
  const std::string_view path = target.substr(0, q);
  if (path.empty() || path[0] != '/') return false;
  if (path.find("..") != std::string_view::npos || path.find("//") != std::string_view::npos) {
    return false;
  }
  for (const char c : path) {
    if (!is_url_char(c)) return false;  // '%', '\\', NUL, spaces and control bytes among them
  }
  if (q != std::string_view::npos) {
    for (const char c : target.substr(q)) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '\\') return false;
    }
  }
  return true;
}

Expected<ViewAllowlist> ViewAllowlist::build(const fs::path& viewer_dir, const fs::path& wasm_dir,
                                             const std::vector<std::string>& files) {
  ViewAllowlist a;
  std::error_code ec;
  const fs::path viewer = fs::canonical(viewer_dir, ec);
  if (ec) {
    return error(ErrorCode::kNotFound,
                 "view: the viewer folder " + viewer_dir.string() + ": " + ec.message());
  }
  // The folder's files, its subfolders' too (symlinked folders are not entered). A file is
  // served only when its real path, symlinks resolved, is inside the folder; dot files
  // (editors' temporaries, .git) are left out.
  fs::recursive_directory_iterator it(viewer, fs::directory_options::skip_permission_denied, ec),
      end;
  for (; !ec && it != end; it.increment(ec)) {
    const fs::path rel = it->path().lexically_relative(viewer);
    const std::string name = rel.filename().string();
    if (!name.empty() && name[0] == '.') {
      if (it->is_directory(ec)) it.disable_recursion_pending();
      continue;
    }
    std::error_code fec;
    const fs::path real = fs::canonical(it->path(), fec);
    if (fec || !fs::is_regular_file(real, fec) || !is_within(real, viewer)) continue;
    const std::string url = "/" + rel.generic_string();
    if (!target_is_acceptable(url)) continue;  // a name no request could spell
    a.by_path_[url] = ServedFile{real, mime_of(real), viewer};
  }
  if (ec) {
    return error(ErrorCode::kIo,
                 "view: cannot list the viewer folder " + viewer.string() + ": " + ec.message());
  }
  if (a.by_path_.find(std::string_view("/index.html")) == a.by_path_.end()) {
    return error(ErrorCode::kNotFound,
                 "view: the viewer folder " + viewer.string() + " has no regular index.html");
  }
  const fs::path wasm = fs::canonical(wasm_dir, ec);
  for (const char* name : kViewWasmFiles) {
    std::error_code fec;
    const fs::path real = ec ? fs::path() : fs::canonical(wasm / name, fec);
    if (ec || fec || !fs::is_regular_file(real, fec) || !is_within(real, wasm)) {
      return error(ErrorCode::kNotFound,
                   "view: " + (wasm_dir / name).string() +
                       " is not a regular file in its folder (a wasm build older than the npm "
                       "package's files? build it again: tools/wasm/README.md)");
    }
    a.by_path_[std::string("/") + name] = ServedFile{real, mime_of(real), wasm};
  }
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code fec;
    if (!fs::is_regular_file(files[i], fec)) {
      return error(ErrorCode::kNotFound,
                   "view: " + files[i] + ": no such file (give .cbrdf or MERL .binary files)");
    }
    const std::string url = "/files/" + std::to_string(i);
    a.by_path_[url] = ServedFile{fs::absolute(files[i], fec), "application/octet-stream", {}};
    list.push_back({{"name", fs::path(files[i]).filename().string()}, {"url", url}});
  }
  a.files_json_ = dump_json(list, -1);  // invalid UTF-8 becomes U+FFFD, controls \u00XX
  return a;
}

const ServedFile* ViewAllowlist::find(std::string_view path) const {
  if (path == "/") path = "/index.html";
  const auto it = by_path_.find(path);
  return it == by_path_.end() ? nullptr : &it->second;
}

}  // namespace cbrdf::cli
