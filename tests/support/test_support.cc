// SPDX-License-Identifier: MIT
#include "test_support.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <random>
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
    // CBRDF_REAL_MATERIALS_DIR lets a second build tree (the sanitizer suite) reuse the tables
    // the first one made instead of making 700 MB again.
    const char* env = std::getenv("CBRDF_REAL_MATERIALS_DIR");
    const fs::path out = env && *env ? fs::path(env) : fs::path(CBRDF_BUILD_DIR) / "real-materials";
    // Tests run as parallel processes: the lock keeps a second one from reading a table the
    // first is still writing (make-merl.sh skips the tables that exist).
    const std::string cmd = "flock '" + out.string() + ".lock' bash '" + script.string() + "' '" +
                            out.string() + "' > '" + out.string() + ".log' 2>&1";
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

CommandResult shared_run(const std::string& key,
                         const std::function<CommandResult(const fs::path& dir)>& make,
                         fs::path* dir) {
  const fs::path root = fs::path(CBRDF_BUILD_DIR) / "shared-runs";
  fs::create_directories(root);
  *dir = root / key;
  const int lock = ::open((root / (key + ".lock")).c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock < 0 || ::flock(lock, LOCK_EX) != 0) {
    std::fprintf(stderr, "shared_run: cannot lock %s\n", (root / (key + ".lock")).c_str());
    std::abort();
  }
  // The executable's size and time name the build that made the run.
  const fs::path cli(CBRDF_CLI_PATH);
  const std::string stamp = std::to_string(fs::file_size(cli)) + " " +
                            std::to_string(fs::last_write_time(cli).time_since_epoch().count()) +
                            "\n";
  CommandResult r;
  if (fs::exists(*dir / ".stamp") && read_text(*dir / ".stamp") == stamp) {
    r.exit_code = 0;
    r.out = read_text(*dir / ".stdout");
    r.err = read_text(*dir / ".stderr");
  } else {
    fs::remove_all(*dir);
    fs::create_directories(*dir);
    r = make(*dir);
    if (r.exit_code == 0) {  // a failed run is made again by the next process
      std::ofstream(*dir / ".stdout", std::ios::binary) << r.out;
      std::ofstream(*dir / ".stderr", std::ios::binary) << r.err;
      std::ofstream(*dir / ".stamp", std::ios::binary) << stamp;
    }
  }
  ::flock(lock, LOCK_UN);
  ::close(lock);
  return r;
}

BrdfTable with_noise(const BrdfTable& t, double sigma, unsigned seed, double grazing) {
  BrdfTable out = t;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int c = 0; c < kChannels; ++c) {
    double* v = out.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double z = normal(rng);
      if (v[i] < 0) continue;
      const double d = merl_bin(i).theta_d / 90.0;
      v[i] *= std::exp(sigma * (1 + grazing * d * d * d * d) * z);
    }
  }
  return out;
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
