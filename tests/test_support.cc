// SPDX-License-Identifier: MIT
#include "test_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>

namespace cbrdf::testing {
namespace fs = std::filesystem;

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  path_ = fs::path(CBRDF_BUILD_DIR) / "test-tmp" /
          ("t" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  fs::remove_all(path_);
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

fs::path real_materials_dir() {
  static std::once_flag once;
  static fs::path dir;
  std::call_once(once, [] {
    const fs::path shared(CBRDF_SHARED_DIR);
    const fs::path script = shared / "tools" / "make-merl.sh";
    if (!fs::exists(shared / "data" / "nbrdf-merl") || !fs::exists(script)) return;
    const fs::path out = fs::path(CBRDF_BUILD_DIR) / "real-materials";
    const std::string cmd =
        "bash '" + script.string() + "' '" + out.string() + "' > '" + out.string() + ".log' 2>&1";
    fs::create_directories(out);
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "make-merl.sh failed, see %s.log\n", out.string().c_str());
      return;
    }
    dir = out;
  });
  return dir;
}

std::vector<std::string> real_material_names() {
  std::vector<std::string> names;
  const fs::path dir = real_materials_dir();
  if (dir.empty()) return names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".binary") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

fs::path noisy_materials_dir(const std::string& sigma, const std::vector<std::string>& names) {
  const fs::path shared(CBRDF_SHARED_DIR);
  const fs::path script = shared / "tools" / "make-merl.sh";
  if (!fs::exists(shared / "data" / "nbrdf-merl") || !fs::exists(script)) return {};
  const fs::path out = fs::path(CBRDF_BUILD_DIR) / ("noisy-materials-" + sigma);
  fs::create_directories(out);
  // The script skips tables already made, so a second call costs nothing; the lock keeps tests
  // run in parallel from reading a table another one is still writing.
  std::string cmd = "flock '" + out.string() + ".lock' bash '" + script.string() + "' --noise " +
                    sigma + " '" + out.string() + "'";
  for (const std::string& n : names) cmd += " '" + n + "'";
  cmd += " > '" + out.string() + ".log' 2>&1";
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "make-merl.sh --noise failed, see %s.log\n", out.string().c_str());
    return {};
  }
  return out;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CommandResult run_cli(const std::string& args) {
  TempDir tmp;
  const fs::path out = tmp / "stdout", err = tmp / "stderr";
  const std::string cmd = std::string("'") + CBRDF_CLI_PATH + "' " + args + " > '" + out.string() +
                          "' 2> '" + err.string() + "' < /dev/null";
  const int rc = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

std::vector<std::string> dir_entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::vector<std::uint8_t> bytes_of(const std::string& s) {
  return {s.begin(), s.end()};
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace cbrdf::testing
