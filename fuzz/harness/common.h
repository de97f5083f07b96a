// SPDX-License-Identifier: MIT
// What every fuzz target reports about one input: accepted or rejected (with the error), and the
// invariants it found broken. The libFuzzer entry points abort on a broken invariant, so the
// fuzzer records the input as a crash; tests/fuzz/fuzz_regression_test.cc replays the same
// functions and turns each broken invariant into a test failure.
//
// The harnesses are header-only so that the fuzz binaries and the ordinary test build compile
// exactly the same code (tests/CMakeLists.txt builds each test from one source file).
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf::fuzz {

using Bytes = std::span<const std::uint8_t>;

enum class Outcome { kRejected, kAccepted };

struct Result {
  Outcome outcome = Outcome::kRejected;
  ErrorCode code = ErrorCode::kOk;  // the error when rejected
  std::string message;
  std::vector<std::string> violations;  // each one is a bug in cbrdf (or in the harness)

  void check(bool condition, const std::string& what) {
    if (!condition) violations.push_back(what);
  }
  void accept() { outcome = Outcome::kAccepted; }
  // Records a refusal; an error must carry a real code and a message a user can act on.
  void reject(const Status& status, const char* api) {
    outcome = Outcome::kRejected;
    code = status.code();
    message = status.message();
    check(!status.ok(), std::string(api) + " failed with an ok status");
    check(status.code() != ErrorCode::kInternal,
          std::string(api) + " reported an internal error: " + status.message());
    check(!status.message().empty(), std::string(api) + " failed with an empty message");
  }
};

// "accepted" or "rejected <code>": the form recorded in the EXPECTED.txt manifests.
inline std::string outcome_text(const Result& r) {
  if (r.outcome == Outcome::kAccepted) return "accepted";
  return std::string("rejected ") + error_code_name(r.code);
}

// For the libFuzzer entry points: a broken invariant is a crash.
inline int finish(const Result& r, const char* target) {
  if (r.violations.empty()) return 0;
  for (const std::string& v : r.violations) std::fprintf(stderr, "%s: %s\n", target, v.c_str());
  std::fprintf(stderr, "%s: outcome %s: %s\n", target, outcome_text(r).c_str(), r.message.c_str());
  std::abort();
}

// FNV-1a: a cheap, stable hash of an input, for choosing expensive checks deterministically (so
// that replaying a file takes the same path as the run that found it).
inline std::uint64_t input_hash(Bytes bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::uint8_t b : bytes) h = (h ^ b) * 0x100000001b3ull;
  return h;
}

// Reads fuzzer bytes as small numbers; past the end every read is 0, so any input is usable.
class ByteSource {
 public:
  explicit ByteSource(Bytes bytes) : bytes_(bytes) {}
  std::uint8_t u8() { return pos_ < bytes_.size() ? bytes_[pos_++] : 0; }
  std::uint16_t u16() { return std::uint16_t(u8() | (unsigned(u8()) << 8)); }
  std::uint32_t u32() { return std::uint32_t(u16()) | (std::uint32_t(u16()) << 16); }
  std::uint64_t u64() { return std::uint64_t(u32()) | (std::uint64_t(u32()) << 32); }
  // Uniform-ish in [lo, hi] with 16 bits of resolution.
  double in_range(double lo, double hi) { return lo + (hi - lo) * (u16() / 65535.0); }
  bool empty() const { return pos_ >= bytes_.size(); }
  Bytes rest() const { return pos_ < bytes_.size() ? bytes_.subspan(pos_) : Bytes{}; }

 private:
  Bytes bytes_;
  std::size_t pos_ = 0;
};

}  // namespace cbrdf::fuzz
