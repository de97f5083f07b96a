// SPDX-License-Identifier: MIT
// Helpers shared by the tests: temporary directories, the real-data folder, running the CLI.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "cbrdf/brdf_table.h"

namespace cbrdf::testing {

// A fresh empty directory under the build tree, removed by its destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// The folder of real MERL-layout materials made from ../shared/data with
// ../shared/tools/make-merl.sh, built once into the build tree. Empty when ../shared is absent
// (callers GTEST_SKIP with a message).
std::filesystem::path real_materials_dir();
// Names of the real materials available (empty without ../shared).
std::vector<std::string> real_material_names();

// A folder made by ../shared/tools/make-merl.sh --noise `sigma` (text as the script takes it,
// "0.03" for 3%) for the named materials: NAME.binary (the truth) and NAME-noisy.binary beside it,
// built once per sigma into the build tree. Empty without ../shared or when the script fails.
// make-merl.sh's noise: every measured value times exp(s n), n standard normal drawn from
// mt19937_64(seed) for every bin in storage order, s = sigma (1 + grazing (theta_d / 90)^4)
// (grazing 0: the same everywhere, as make-merl.sh).
BrdfTable with_noise(const BrdfTable& t, double sigma, unsigned seed, double grazing = 0);

std::filesystem::path noisy_materials_dir(const std::string& sigma,
                                          const std::vector<std::string>& names);

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};
// Runs the built `cbrdf` executable with the given argument string (shell-quoted by the caller).
CommandResult run_cli(const std::string& args);

// Runs make(dir) once for every test process of a build and returns its result: the directory
// and the result are kept under the build tree by `key`, and made again when the cbrdf
// executable changes or the last run failed. For test suites that share one expensive run (a
// `cbrdf report` sweep): gtest_discover_tests runs each test in a process of its own, so
// SetUpTestSuite alone would repeat the run for every test. `dir` is empty when make is called.
CommandResult shared_run(const std::string& key,
                         const std::function<CommandResult(const std::filesystem::path& dir)>& make,
                         std::filesystem::path* dir);

std::string read_text(const std::filesystem::path& p);

// The bytes of a string, and whether a message contains a phrase.
std::vector<std::uint8_t> bytes_of(const std::string& s);
bool contains(const std::string& haystack, const std::string& needle);

// The names in a directory, sorted.
std::vector<std::string> dir_entries(const std::filesystem::path& dir);

}  // namespace cbrdf::testing
