// SPDX-License-Identifier: MIT
// file_io (reads with limits, atomic writes) and MERL .binary reading, validation, folding,
// writing.
#include "cbrdf/merl_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/file_io.h"
#include "test_support.h"

// Counts allocations of 1 MB or more, to show that reading a table allocates it once and nothing
// else of its size. Replaces the global operator new of this test binary only.
namespace {
std::atomic<int> g_big_allocations{0};
constexpr std::size_t kBigAllocation = std::size_t{1} << 20;
}  // namespace

// The deletes are replaced too, so that new and delete pair as malloc and free even under ASan.
// GCC cannot see that this operator new is malloc and warns about the pairing.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (n >= kBigAllocation) g_big_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  return operator new(n);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

namespace cbrdf {
namespace {
using testing::bytes_of;
using testing::contains;
namespace fs = std::filesystem;
using testing::dir_entries;
using testing::TempDir;

void write_raw(const fs::path& p, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << p;
}

std::vector<std::uint8_t> read_all(const fs::path& p) {
  auto r = read_file(p, std::uint64_t{1} << 32);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? std::move(r).value() : std::vector<std::uint8_t>{};
}

// ---------------------------------------------------------------------------------------------
// file_io

TEST(ReadFile, MissingFileIsNotFound) {
  TempDir tmp;
  auto r = read_file(tmp / "nope.bin", 100);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(r.status().message(), (tmp / "nope.bin").string() + ": no such file");
}

TEST(ReadFile, DirectoryIsRefused) {
  TempDir tmp;
  auto r = read_file(tmp.path(), 100);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(r.status().message(), tmp.path().string() + ": is a directory"))
      << r.status().message();
}

TEST(ReadFile, LimitNamesBothSizes) {
  TempDir tmp;
  const std::vector<std::uint8_t> content(100, 7);
  write_raw(tmp / "f", content);
  auto r = read_file(tmp / "f", 99);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kLimit);
  EXPECT_TRUE(
      contains(r.status().message(), "file is 100 bytes, larger than the limit of 99 bytes"))
      << r.status().message();
  auto ok = read_file(tmp / "f", 100);
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(*ok, content);
}

// Runs read_file in a child process that is not root (root reads anything), reporting the status
// through a pipe.
TEST(ReadFile, PermissionDeniedNamesTheReason) {
  TempDir tmp;
  const fs::path p = tmp / "secret";
  write_raw(p, bytes_of("x"));
  ASSERT_EQ(::chmod(p.c_str(), 0), 0);
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(fds[0]);
    if (::geteuid() == 0 && ::setuid(65534) != 0) ::_exit(3);  // 65534: "nobody"
    auto r = read_file(p, 100);
    const std::string report = std::to_string(int(r.status().code())) + "|" + r.status().message();
    (void)!::write(fds[1], report.data(), report.size());
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string report;
  char buf[512];
  for (::ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) report.append(buf, std::size_t(n));
  ::close(fds[0]);
  int wstatus = 0;
  ASSERT_EQ(::waitpid(pid, &wstatus, 0), pid);
  ASSERT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0) << "child could not drop root";
  EXPECT_EQ(report.substr(0, report.find('|')), std::to_string(int(ErrorCode::kIo))) << report;
  EXPECT_TRUE(contains(report, "Permission denied")) << report;
}

TEST(FileReader, ShortReadIsTruncatedWithOffset) {
  TempDir tmp;
  write_raw(tmp / "f", std::vector<std::uint8_t>(10, 1));
  auto r = FileReader::open(tmp / "f");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->size(), 10u);
  std::uint8_t buf[16];
  ASSERT_TRUE(r->read_exact(buf, 4).ok());
  const Status s = r->read_exact(buf, 8);
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_TRUE(contains(s.message(),
                       "file ends at byte offset 10, but 8 bytes were needed from "
                       "offset 4"))
      << s.message();
}

TEST(WriteFileAtomic, WritesAndReplacesLeavingNoTemporary) {
  TempDir tmp;
  const fs::path p = tmp / "out.bin";
  ASSERT_TRUE(write_file_atomic(p, bytes_of("first version")).ok());
  EXPECT_EQ(read_all(p), bytes_of("first version"));
  ASSERT_EQ(::chmod(p.c_str(), 0640), 0);
  const Status s = write_file_atomic(p, bytes_of("second"));
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(read_all(p), bytes_of("second"));
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"out.bin"});
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u) << "replacing a file keeps its permissions";
}

TEST(WriteFileAtomic, ChunksOfAnySizeAreConcatenated) {
  TempDir tmp;
  std::vector<std::uint8_t> expected;
  std::uint32_t state = 12345;
  auto next = [&state] { return state = state * 1664525u + 1013904223u; };
  std::vector<std::vector<std::uint8_t>> chunks;
  for (int i = 0; i < 3000; ++i) {
    // Mostly small chunks (buffered), some larger than the 64 KB buffer (written through).
    const std::size_t n = i % 500 == 7 ? 70000 + next() % 1000 : next() % 300;
    std::vector<std::uint8_t> c(n);
    for (auto& b : c) b = std::uint8_t(next() >> 24);
    expected.insert(expected.end(), c.begin(), c.end());
    chunks.push_back(std::move(c));
  }
  const Status s = write_file_atomic(tmp / "f", [&](const ChunkSink& sink) -> Status {
    for (const auto& c : chunks) CBRDF_RETURN_IF_ERROR(sink(c));
    return ok_status();
  });
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(read_all(tmp / "f"), expected);
}

TEST(WriteFileAtomic, MissingDirectoryFailsAndCreatesNothing) {
  TempDir tmp;
  const fs::path p = tmp / "no-such-dir" / "out.bin";
  const Status s = write_file_atomic(p, bytes_of("data"));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(s.message(), p.string())) << s.message();
  EXPECT_TRUE(contains(s.message(), (tmp / "no-such-dir").string() + " does not exist"))
      << s.message();
  EXPECT_TRUE(dir_entries(tmp.path()).empty());
}

TEST(WriteFileAtomic, DirectoryTargetIsRefused) {
  TempDir tmp;
  fs::create_directory(tmp / "d");
  const Status s = write_file_atomic(tmp / "d", bytes_of("data"));
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_TRUE(contains(s.message(), "is a directory")) << s.message();
  EXPECT_TRUE(fs::is_directory(tmp / "d"));
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"d"});
}

// The producer fails after enough bytes that some reached the temporary file on disk.
Status fail_midway(const ChunkSink& sink) {
  const std::vector<std::uint8_t> block(300000, 0xAB);
  CBRDF_RETURN_IF_ERROR(sink(block));
  CBRDF_RETURN_IF_ERROR(sink(std::span(block).first(100)));
  return error(ErrorCode::kCorrupt, "producer gave up");
}

TEST(WriteFileAtomic, FailureMidwayLeavesNoFileAndNoTemporary) {
  TempDir tmp;
  const Status s = write_file_atomic(tmp / "out.bin", fail_midway);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_EQ(s.message(), "producer gave up");
  EXPECT_TRUE(dir_entries(tmp.path()).empty());
}

TEST(WriteFileAtomic, FailureMidwayLeavesExistingTargetIntact) {
  TempDir tmp;
  const fs::path p = tmp / "out.bin";
  write_raw(p, bytes_of("precious old content"));
  const Status s = write_file_atomic(p, fail_midway);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_EQ(read_all(p), bytes_of("precious old content"));
  EXPECT_EQ(dir_entries(tmp.path()), std::vector<std::string>{"out.bin"});
}

// ---------------------------------------------------------------------------------------------
// MERL

// A table of arbitrary doubles: the horizon mask as -1, and among the measured bins values of every
// magnitude, zeros, -0.0, and other negative "not measured" markers.
BrdfTable synthetic_table() {
  BrdfTable t;
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const BinIndex b = merl_bin(i);
      double v;
      if (bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) {
        v = -1.0;
      } else {
        switch (state >> 61) {
          case 0:
            v = 0.0;
            break;
          case 1:
            v = -0.0;
            break;
          case 2:
            v = -2.5 - double(state >> 40 & 0xff);
            break;
          case 3:
            v = std::ldexp(double(state >> 11), -1100);
            break;  // subnormal-ish
          default:
            v = double(state >> 11) * 1e-12;
            break;
        }
      }
      t.set_stored(c, i, v);
    }
  }
  return t;
}

bool same_bits(const BrdfTable& a, const BrdfTable& b) {
  return std::memcmp(a.stored_values().data(), b.stored_values().data(),
                     kChannels * kBinsPerChannel * sizeof(double)) == 0;
}

std::vector<std::uint8_t> header(std::int32_t a, std::int32_t b, std::int32_t c) {
  std::vector<std::uint8_t> h(12);
  const std::int32_t d[3] = {a, b, c};
  std::memcpy(h.data(), d, 12);
  return h;
}

// A file of the given dims and exactly the size they need, values from f(channel, file index).
template <typename F>
std::vector<std::uint8_t> merl_bytes(std::int32_t a, std::int32_t b, std::int32_t c, F f) {
  std::vector<std::uint8_t> bytes = header(a, b, c);
  const std::size_t n = std::size_t(a) * std::size_t(b) * std::size_t(c);
  bytes.resize(12 + 3 * n * 8);
  for (int ch = 0; ch < 3; ++ch) {
    for (std::size_t i = 0; i < n; ++i) {
      const double v = f(ch, i);
      std::memcpy(bytes.data() + 12 + (ch * n + i) * 8, &v, 8);
    }
  }
  return bytes;
}

Status read_error(const std::vector<std::uint8_t>& bytes, const MerlReadOptions& options = {}) {
  TempDir tmp;
  write_raw(tmp / "bad.binary", bytes);
  g_big_allocations = 0;
  auto r = read_merl(tmp / "bad.binary", options);
  EXPECT_FALSE(r.ok());
  if (r.ok()) return ok_status();
  // Prefixed by the file's path: the user sees which file is wrong.
  EXPECT_EQ(r.status().message().rfind((tmp / "bad.binary").string() + ": ", 0), 0u)
      << r.status().message();
  // The same bytes from memory fail the same way.
  auto m = parse_merl(bytes, "mem", options);
  EXPECT_FALSE(m.ok());
  if (!m.ok()) {
    EXPECT_EQ(m.status().code(), r.status().code());
  }
  return r.status();
}

TEST(Merl, WriteReadWriteIsByteExact) {
  TempDir tmp;
  const BrdfTable table = synthetic_table();
  const fs::path p = tmp / "t.binary";
  ASSERT_TRUE(write_merl(p, table).ok());
  const std::vector<std::uint8_t> file = read_all(p);
  ASSERT_EQ(file.size(), kMerlFileBytes);
  EXPECT_TRUE(file == serialize_merl(table));
  // The layout, pinned independently of the writer: little-endian int32 90, 90, 180, then channel
  // blocks in MERL index order.
  const std::uint8_t expected_header[12] = {90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0};
  EXPECT_EQ(std::memcmp(file.data(), expected_header, 12), 0);
  const std::size_t idx = std::size_t(5) + 180 * (4 + 90 * std::size_t(3));
  double g;
  std::memcpy(&g, file.data() + 12 + (kBinsPerChannel + idx) * 8, 8);
  EXPECT_EQ(std::memcmp(&g, &table.stored_values()[kBinsPerChannel + idx], 8), 0);

  MerlInfo info;
  auto back = read_merl(p, {}, &info);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(same_bits(*back, table));
  EXPECT_FALSE(info.folded_from_360);
  EXPECT_EQ(info.dims, (std::array<std::int32_t, 3>{90, 90, 180}));
  EXPECT_EQ(info.file_bytes, kMerlFileBytes);

  const fs::path p2 = tmp / "t2.binary";
  ASSERT_TRUE(write_merl(p2, *back).ok());
  EXPECT_TRUE(read_all(p2) == file);

  auto parsed = parse_merl(file, "in-memory");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_TRUE(same_bits(*parsed, table));
}

TEST(Merl, ReadAllocatesTheTableOnce) {
  TempDir tmp;
  const BrdfTable table = synthetic_table();
  ASSERT_TRUE(write_merl(tmp / "t.binary", table).ok());
  g_big_allocations = 0;
  auto r = read_merl(tmp / "t.binary");
  const int allocations = g_big_allocations;
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(allocations, 1);
  EXPECT_EQ(r->stored_values().capacity(), 3 * kBinsPerChannel);

  const std::vector<std::uint8_t> bytes = serialize_merl(table);
  g_big_allocations = 0;
  auto m = parse_merl(bytes, "mem");
  EXPECT_EQ(g_big_allocations, 1);
  ASSERT_TRUE(m.ok());
}

TEST(Merl, MissingFile) {
  TempDir tmp;
  auto r = read_merl(tmp / "absent.binary");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(r.status().message(), (tmp / "absent.binary").string() + ": no such file");
}

TEST(Merl, ShorterThanHeader) {
  const Status s = read_error({90, 0, 0, 0, 90});
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_TRUE(contains(s.message(), ": 5 bytes, shorter than the 12-byte MERL header"))
      << s.message();
}

TEST(Merl, TooShortForDims) {
  std::vector<std::uint8_t> bytes = header(90, 90, 180);
  bytes.resize(12 + 1000);
  const Status s = read_error(bytes);
  EXPECT_EQ(s.code(), ErrorCode::kTruncated);
  EXPECT_TRUE(contains(s.message(),
                       "too short for its dims (90, 90, 180): expected 34992012 bytes, found 1012"))
      << s.message();
  EXPECT_EQ(g_big_allocations, 0) << "refused before allocating the table";
}

TEST(Merl, TooLongForDims) {
  std::vector<std::uint8_t> bytes = serialize_merl(BrdfTable());
  bytes.resize(bytes.size() + 8);
  const Status s = read_error(bytes);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_TRUE(contains(s.message(),
                       "too long for its dims (90, 90, 180): expected 34992012 bytes, found "
                       "34992020"))
      << s.message();
}

TEST(Merl, OtherDimsAreRefusedNamingFoundAndAccepted) {
  const Status s = read_error(merl_bytes(90, 90, 100, [](int, std::size_t) { return 1.0; }));
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_TRUE(contains(s.message(), "MERL dims (90, 90, 100) are not supported")) << s.message();
  EXPECT_TRUE(contains(s.message(), "(90, 90, 180)")) << s.message();
  EXPECT_TRUE(contains(s.message(), "(90, 90, 360)")) << s.message();

  const Status small = read_error(merl_bytes(2, 3, 4, [](int, std::size_t) { return 1.0; }));
  EXPECT_EQ(small.code(), ErrorCode::kUnsupported);
  EXPECT_TRUE(contains(small.message(), "(2, 3, 4)")) << small.message();
}

TEST(Merl, ImplausibleDimsRefusedBeforeAllocating) {
  for (const auto& dims :
       std::vector<std::array<std::int32_t, 3>>{{-90, 90, 180},
                                                {90, 0, 180},
                                                {90, 90, 10001},
                                                {std::numeric_limits<std::int32_t>::min(), 1, 1}}) {
    std::vector<std::uint8_t> bytes = header(dims[0], dims[1], dims[2]);
    bytes.resize(4096);
    const Status s = read_error(bytes);
    EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
    EXPECT_TRUE(contains(s.message(), "are not plausible: each must be in 1..10000"))
        << s.message();
    EXPECT_EQ(g_big_allocations, 0);
  }
  std::vector<std::uint8_t> huge = header(10000, 10000, 10000);
  huge.resize(64);
  const Status s = read_error(huge);
  EXPECT_EQ(s.code(), ErrorCode::kLimit);
  EXPECT_TRUE(contains(s.message(), "give 1000000000000 bins per channel, more than the 100000000"))
      << s.message();
  EXPECT_EQ(g_big_allocations, 0);
}

TEST(Merl, BigEndianHeaderIsRecognised) {
  std::vector<std::uint8_t> bytes = {0, 0, 0, 90, 0, 0, 0, 90, 0, 0, 0, 180};
  bytes.resize(kMerlFileBytes);
  const Status s = read_error(bytes);
  EXPECT_EQ(s.code(), ErrorCode::kCorrupt);
  EXPECT_TRUE(contains(s.message(), "byte-swapped they read (90, 90, 180)")) << s.message();
  EXPECT_TRUE(contains(s.message(), "big-endian")) << s.message();
}

// One rule for every table cbrdf writes and reads: NaN and -Inf are "not measured" values (a
// decoded container may hold them) and round-trip bit for bit; only +Inf is refused, by count and
// first bin.
TEST(Merl, PlusInfIsRefusedWithCountAndFirstBin) {
  BrdfTable t;
  const double inf = std::numeric_limits<double>::infinity();
  t.set_stored(1, merl_index(7, 8, 9), inf);
  t.set_stored(1, merl_index(80, 1, 2), inf);
  t.set_stored(2, merl_index(0, 0, 0), inf);
  const Status s = read_error(serialize_merl(t));
  EXPECT_EQ(s.code(), ErrorCode::kNumeric);
  const std::size_t offset = 12 + (kBinsPerChannel + merl_index(7, 8, 9)) * 8;
  EXPECT_TRUE(contains(s.message(),
                       ": 3 +Inf values (a measurement must be finite); the first at channel G, "
                       "bin (theta_h 7, theta_d 8, phi_d 9), byte offset " +
                           std::to_string(offset)))
      << s.message();

  BrdfTable one;
  one.set_stored(0, merl_index(89, 89, 179), inf);
  const Status s1 = read_error(serialize_merl(one));
  EXPECT_EQ(s1.code(), ErrorCode::kNumeric);
  EXPECT_TRUE(contains(s1.message(),
                       ": 1 +Inf value (a measurement must be finite); the first at channel R, bin "
                       "(theta_h 89, theta_d 89, phi_d 179)"))
      << s1.message();
}

TEST(Merl, NanAndMinusInfAreNotMeasuredAndRoundTripExactly) {
  BrdfTable t;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double payload_nan = std::bit_cast<double>(std::uint64_t{0xFFF8000000001234});
  t.set_stored(1, merl_index(7, 8, 9), nan);
  t.set_stored(0, merl_index(80, 1, 2), -std::numeric_limits<double>::infinity());
  t.set_stored(2, merl_index(3, 4, 5), payload_nan);
  const std::vector<std::uint8_t> bytes = serialize_merl(t);
  auto back = parse_merl(bytes, "nan.binary");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(serialize_merl(*back), bytes);
  EXPECT_FALSE(back->measured(1, merl_index(7, 8, 9)));
  EXPECT_FALSE(back->measured(0, merl_index(80, 1, 2)));
  EXPECT_FALSE(back->measured(2, merl_index(3, 4, 5)));
  EXPECT_EQ(back->count_not_measured(), 3u);
  const MerlStats st = merl_stats(*back);
  EXPECT_EQ(st.channel[1].not_measured, 1u);
  EXPECT_TRUE(std::isfinite(st.channel[1].max));
}

TEST(Merl, NegativeValuesAreKeptExactly) {
  BrdfTable t;
  t.set_stored(0, 10, -1.0);
  t.set_stored(1, 11, -0.0);
  t.set_stored(2, 12, -1e300);
  t.set_stored(2, 13, -std::numeric_limits<double>::denorm_min());
  auto r = parse_merl(serialize_merl(t), "mem");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(same_bits(*r, t));
  EXPECT_FALSE(r->measured(0, 10));
  EXPECT_TRUE(std::signbit(r->stored(1, 11)));
  EXPECT_TRUE(r->measured(1, 11)) << "-0.0 is a measured zero";
  EXPECT_EQ(r->count_not_measured(), 3u);
}

// A 360-bin file where each (theta_h, theta_d, k) pair falls in one of four fold cases.
double value_360(int channel, std::size_t file_index) {
  const std::size_t phi = file_index % 360;
  const std::size_t td = (file_index / 360) % 90;
  const std::size_t th = file_index / (360 * 90);
  const std::size_t k = phi % 180;
  const bool upper = phi >= 180;
  const double base = double(k) + 100.0 * channel;
  switch ((th + td + k) % 4) {
    case 0:
      return upper ? base + 3.0 : base + 1.0;  // both measured: mean base + 2
    case 1:
      return upper ? -1.0 : base + 0.25;  // only k measured
    case 2:
      return upper ? base + 0.5 : -2.0;  // only k + 180 measured
    default:
      return upper ? -7.0 : -3.5;  // neither: k's -3.5 kept
  }
}

double expected_folded(int channel, int th, int td, int k) {
  const double base = double(k) + 100.0 * channel;
  switch ((th + td + k) % 4) {
    case 0:
      return base + 2.0;
    case 1:
      return base + 0.25;
    case 2:
      return base + 0.5;
    default:
      return -3.5;
  }
}

TEST(Merl, Phi360IsFoldedByReciprocity) {
  TempDir tmp;
  write_raw(tmp / "full.binary", merl_bytes(90, 90, 360, value_360));
  MerlInfo info;
  g_big_allocations = 0;
  auto r = read_merl(tmp / "full.binary", {}, &info);
  EXPECT_EQ(g_big_allocations, 1) << "folding streams slabs, it does not hold the 70 MB file";
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(info.folded_from_360);
  EXPECT_EQ(info.dims, (std::array<std::int32_t, 3>{90, 90, 360}));
  std::size_t cases[4] = {0, 0, 0, 0};
  std::size_t wrong = 0;
  for (int c = 0; c < 3; ++c) {
    for (int th = 0; th < 90; ++th) {
      for (int td = 0; td < 90; ++td) {
        for (int k = 0; k < 180; ++k) {
          ++cases[(th + td + k) % 4];
          wrong += r->stored(c, merl_index(th, td, k)) != expected_folded(c, th, td, k);
        }
      }
    }
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(info.fold_averaged, cases[0]);
  EXPECT_EQ(info.fold_one_side, cases[1] + cases[2]);
  EXPECT_EQ(info.fold_neither, cases[3]);
  EXPECT_DOUBLE_EQ(info.fold_max_rel_diff, 2.0 / 3.0);  // k = 0, channel R: 1 vs 3

  const auto bytes = merl_bytes(90, 90, 360, value_360);
  auto m = parse_merl(bytes, "mem");
  ASSERT_TRUE(m.ok());
  EXPECT_TRUE(same_bits(*m, *r));
}

TEST(Merl, Phi360FoldCanBeSwitchedOff) {
  MerlReadOptions no_fold;
  no_fold.fold_phi_360 = false;
  const Status s = read_error(merl_bytes(90, 90, 360, value_360), no_fold);
  EXPECT_EQ(s.code(), ErrorCode::kUnsupported);
  EXPECT_TRUE(contains(s.message(), "folding of (90, 90, 360) is switched off")) << s.message();
}

TEST(Merl, Phi360NonFiniteNamesTheFileBin) {
  const auto bytes = merl_bytes(90, 90, 360, [](int c, std::size_t i) {
    return c == 2 && i == 200 + 360 * (3 + 90 * 5) ? std::numeric_limits<double>::infinity() : 1.0;
  });
  const Status s = read_error(bytes);
  EXPECT_EQ(s.code(), ErrorCode::kNumeric);
  EXPECT_TRUE(contains(s.message(),
                       "1 +Inf value (a measurement must be finite); the first at channel B, bin "
                       "(theta_h 5, theta_d 3, phi_d 200)"))
      << s.message();
}

TEST(MerlStats, CountsAndRangesOfMeasuredValues) {
  BrdfTable t;                 // all measured zeros
  t.set_stored(0, 0, 1500.0);  // physical 1
  t.set_stored(0, 1, 3000.0);  // physical 2
  for (std::size_t i = 2; i < 10; ++i) t.set_stored(0, i, -1.0);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) t.set_stored(1, i, -1.0);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) t.set_stored(2, i, 0.5 * 1500.0 / 1.66);
  t.set_stored(2, 77, 0.25 * 1500.0 / 1.66);

  const MerlStats s = merl_stats(t);
  const MerlChannelStats& r = s.channel[0];
  EXPECT_EQ(r.measured, kBinsPerChannel - 8);
  EXPECT_EQ(r.not_measured, 8u);
  EXPECT_EQ(r.zeros, kBinsPerChannel - 10);
  EXPECT_EQ(r.min, 0.0);
  EXPECT_DOUBLE_EQ(r.max, 2.0);
  EXPECT_DOUBLE_EQ(r.mean, 3.0 / double(kBinsPerChannel - 8));

  const MerlChannelStats& g = s.channel[1];
  EXPECT_EQ(g.measured, 0u);
  EXPECT_EQ(g.not_measured, kBinsPerChannel);
  EXPECT_EQ(g.max, 0.0);
  EXPECT_EQ(g.mean, 0.0);

  const MerlChannelStats& b = s.channel[2];
  EXPECT_EQ(b.measured, kBinsPerChannel);
  EXPECT_EQ(b.zeros, 0u);
  EXPECT_NEAR(b.min, 0.25, 1e-15);
  EXPECT_NEAR(b.max, 0.5, 1e-15);
  EXPECT_NEAR(b.mean, 0.5 - 0.25 / double(kBinsPerChannel), 1e-12);
}

TEST(HorizonMask, MatchesOnlyTheGeometricMask) {
  BrdfTable t;
  std::size_t below = 0;
  std::size_t first_above = kBinsPerChannel, first_below = kBinsPerChannel;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    if (bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) {
      t.set_not_measured(i);
      ++below;
      if (first_below == kBinsPerChannel) first_below = i;
    } else if (first_above == kBinsPerChannel) {
      first_above = i;
    }
  }
  ASSERT_GT(below, 0u);
  ASSERT_LT(below, kBinsPerChannel);
  EXPECT_TRUE(check_horizon_mask(t).matches());

  t.set_stored(2, first_above, -1.0);  // not measured above the horizon
  HorizonMaskCheck c = check_horizon_mask(t);
  EXPECT_EQ(c.mismatches, 1u);
  EXPECT_EQ(c.first_channel, 2);
  EXPECT_EQ(c.first_index, first_above);

  t.set_stored(0, first_below, 0.5);  // measured below it
  c = check_horizon_mask(t);
  EXPECT_EQ(c.mismatches, 2u);
  EXPECT_EQ(c.first_channel, 0);
  EXPECT_EQ(c.first_index, first_below);
  EXPECT_FALSE(c.matches());
}

}  // namespace
}  // namespace cbrdf
