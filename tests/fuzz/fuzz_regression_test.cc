// SPDX-License-Identifier: MIT
// Replays every seed in fuzz/corpus/<target>/ and every crash input kept in
// fuzz/regressions/<target>/ through the fuzz targets' own entry points (fuzz/harness/, and
// tests/encoder/fuzz_roundtrip_target.h for fuzz_roundtrip), as one test per file: no broken
// invariant, and the outcome recorded for the file in the directory's EXPECTED.txt ("accepted" or
// "rejected <error code>"). A file without a record fails, so a new regression input is never kept
// without saying what it must do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../../fuzz/harness/capi_target.h"
#include "../../fuzz/harness/container_target.h"
#include "../../fuzz/harness/decode_target.h"
#include "../../fuzz/harness/merl_target.h"
#include "../encoder/fuzz_roundtrip_target.h"

namespace cbrdf {
namespace {

namespace fs = std::filesystem;

const fs::path& fuzz_dir() {
  static const fs::path p = fs::path(CBRDF_TEST_DATA_DIR) / ".." / ".." / "fuzz";
  return p;
}

struct Input {
  std::string set;     // "corpus" or "regressions"
  std::string target;  // fuzz_container, ...
  fs::path path;
  std::string key() const { return target + "/" + path.filename().string(); }
};

// Names the file in gtest's messages instead of dumping the struct's bytes.
void PrintTo(const Input& input, std::ostream* os) {
  *os << input.set << "/" << input.key();
}

std::vector<Input> list_inputs() {
  std::vector<Input> out;
  for (const char* set : {"corpus", "regressions"}) {
    const fs::path root = fuzz_dir() / set;
    if (!fs::is_directory(root)) continue;
    for (const auto& target : fs::directory_iterator(root)) {
      if (!target.is_directory()) continue;
      for (const auto& f : fs::directory_iterator(target.path())) {
        if (f.is_regular_file()) out.push_back({set, target.path().filename().string(), f.path()});
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const Input& a, const Input& b) { return a.path < b.path; });
  return out;
}

// <target>/<file> -> "accepted" | "rejected <code>"
std::map<std::string, std::string> read_manifest(const std::string& set) {
  std::map<std::string, std::string> m;
  std::ifstream in(fuzz_dir() / set / "EXPECTED.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t space = line.find(' ');
    if (space != std::string::npos) m[line.substr(0, space)] = line.substr(space + 1);
  }
  return m;
}

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FuzzReplay : public ::testing::TestWithParam<Input> {};

TEST_P(FuzzReplay, NoBrokenInvariantAndRecordedOutcome) {
  const Input& input = GetParam();
  const std::vector<std::uint8_t> bytes = read_bytes(input.path);
  const fuzz::Bytes span(bytes);
  fuzz::Result r;
  if (input.target == "fuzz_container") {
    r = fuzz::run_container(span);
  } else if (input.target == "fuzz_decode") {
    fuzz::DecodeOptions options;
    options.always_table = true;  // the full reconstruction for every replayed file
    r = fuzz::run_decode(span, options);
  } else if (input.target == "fuzz_merl") {
    fuzz::MerlOptions options;
    options.always_full_read = true;  // every valid-size template patch read in full
    r = fuzz::run_merl(span, options);
  } else if (input.target == "fuzz_roundtrip") {
    fuzz::RoundtripOptions options;
    options.always_residual = true;  // every seed's residual layer, however rare when fuzzing
    r = fuzz::run_roundtrip(span, options);
  } else if (input.target == "fuzz_capi") {
    fuzz::CapiOptions options;
    options.always_full = true;  // the whole file, sampled at 48 distinct directions
    r = fuzz::run_capi(span, options);
  } else {
    FAIL() << "no fuzz target named " << input.target << " (directory of " << input.path << ")";
  }
  for (const std::string& v : r.violations) ADD_FAILURE() << input.key() << ": " << v;

  const std::map<std::string, std::string> manifest = read_manifest(input.set);
  const auto it = manifest.find(input.key());
  ASSERT_NE(it, manifest.end()) << input.key() << " has no line in fuzz/" << input.set
                                << "/EXPECTED.txt; its outcome is: " << fuzz::outcome_text(r);
  EXPECT_EQ(fuzz::outcome_text(r), it->second) << input.key() << ": " << r.message;
}

std::string test_name(const ::testing::TestParamInfo<Input>& info) {
  std::string s = info.param.set + "_" + info.param.key();
  for (char& c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return s;
}

INSTANTIATE_TEST_SUITE_P(Files, FuzzReplay, ::testing::ValuesIn(list_inputs()), test_name);

TEST(FuzzCorpus, EveryTargetHasSeedsAndEveryRecordHasAFile) {
  std::map<std::string, int> per_target;
  for (const Input& i : list_inputs()) {
    if (i.set == "corpus") ++per_target[i.target];
  }
  for (const char* t :
       {"fuzz_container", "fuzz_decode", "fuzz_merl", "fuzz_roundtrip", "fuzz_capi"}) {
    EXPECT_GE(per_target[t], 5) << "fuzz/corpus/" << t << " has too few seeds";
  }
  for (const char* set : {"corpus", "regressions"}) {
    for (const auto& [key, outcome] : read_manifest(set)) {
      EXPECT_TRUE(fs::is_regular_file(fuzz_dir() / set / key))
          << "fuzz/" << set << "/EXPECTED.txt records " << key << " (" << outcome
          << ") but the file is missing";
    }
  }
}

}  // namespace
}  // namespace cbrdf
