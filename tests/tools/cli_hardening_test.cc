// SPDX-License-Identifier: MIT
// The `cbrdf` command against a hostile or careless user: device nodes and links as outputs,
// outputs that would destroy inputs, FIFOs as inputs, names that are not UTF-8, the longest file
// names, `-` for standard input and output, bad numbers, not-measured NaN and -Inf values.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "test_support.h"

namespace cbrdf {
namespace {
using testing::contains;

namespace fs = std::filesystem;
using testing::CommandResult;
using testing::run_cli;
using testing::TempDir;

int lines(const std::string& s) {
  return int(std::count(s.begin(), s.end(), '\n'));
}

std::string q(const fs::path& p) {
  return "'" + p.string() + "'";
}

std::string bytes_of_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs a shell command line in which CBRDF stands for the command, with stderr captured; for
// pipes and redirections that run_cli's fixed redirections do not allow.
CommandResult shell(const TempDir& tmp, std::string line) {
  for (std::size_t at; (at = line.find("CBRDF")) != std::string::npos;) {
    line.replace(at, 5, std::string("'") + CBRDF_CLI_PATH + "'");
  }
  const fs::path err = tmp / "shell.stderr";
  const std::string cmd = "( " + line + " ) 2> " + q(err);
  const int rc = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.err = bytes_of_file(err);
  return r;
}

// One plastic sample and its encoding, shared by the tests of this file.
class CliHardening : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    ASSERT_EQ(run_cli("sample plastic -o " + q(bin())).exit_code, 0);
    ASSERT_EQ(run_cli("encode " + q(bin()) + " -o " + q(enc()) + " --no-metrics").exit_code, 0);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path bin() { return *dir_ / "plastic.binary"; }
  static fs::path enc() { return *dir_ / "plastic.cbrdf"; }
  static TempDir* dir_;
};
TempDir* CliHardening::dir_ = nullptr;

// Item 1: an existing output that is a character device is written through; a symbolic link is
// followed and its target replaced, the link kept.
TEST_F(CliHardening, DeviceNodeAndSymlinkOutputs) {
  TempDir tmp;
  const fs::path null_node = tmp / "null";
  if (::mknod(null_node.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    auto r = run_cli("decode " + q(enc()) + " -o " + q(null_node));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    struct stat st {};
    ASSERT_EQ(::lstat(null_node.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced by a file";
  }
  fs::create_symlink("real.binary", tmp / "link.binary");
  auto r = run_cli("decode " + q(enc()) + " -o " + q(tmp / "link.binary"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(tmp / "link.binary"));
  EXPECT_EQ(fs::file_size(tmp / "real.binary"), kMerlFileBytes);
  r = run_cli("sample plastic -o " + q(tmp / "link.binary"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(tmp / "link.binary"));
  EXPECT_EQ(bytes_of_file(tmp / "real.binary"), bytes_of_file(bin()));
}

// Item 4: no output may name an input or another output, links and hard links included.
TEST_F(CliHardening, NoOutputOverwritesAnInputOrAnotherOutput) {
  TempDir tmp;
  const fs::path y = tmp / "y.cbrdf";
  fs::copy_file(enc(), y);
  const std::string original = bytes_of_file(y);
  fs::create_symlink(y, tmp / "sym.cbrdf");
  fs::create_hard_link(y, tmp / "hard.cbrdf");
  const std::vector<std::string> bad = {
      "decode " + q(y) + " -o " + q(y),
      "decode " + q(y) + " --exr " + q(y),
      "decode " + q(y) + " -o " + q(tmp / "sym.cbrdf"),
      "decode " + q(tmp / "sym.cbrdf") + " -o " + q(tmp / "hard.cbrdf"),
      "decode " + q(y) + " -o " + q(tmp / "Z") + " --exr " + q(tmp / "Z"),
      "decode " + q(y) + " -o " + q(tmp / "Z") + " --exr " + q(tmp / "." / "Z"),
      "encode " + q(bin()) + " -o " + q(bin()),
      "report " + q(bin()) + " -o " + q(bin()),
  };
  for (const std::string& args : bad) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "would overwrite") || contains(r.err, "name the same file"))
        << args << ": " << r.err;
  }
  EXPECT_EQ(bytes_of_file(y), original);
  EXPECT_FALSE(fs::exists(tmp / "Z"));
  EXPECT_EQ(fs::file_size(bin()), kMerlFileBytes);

  // render: the scene and the files it reads are inputs too.
  auto r = run_cli("render --builtin figure4 --export " + q(tmp / "scene"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path scene = tmp / "scene" / "figure4.json";
  const std::string scene_bytes = bytes_of_file(scene);
  r = run_cli("render " + q(scene) + " -o " + q(scene));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "would overwrite the scene")) << r.err;
  r = run_cli("render " + q(scene) + " --png " + q(tmp / "scene" / "plastic.cbrdf"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "would overwrite the material 'plastic'")) << r.err;
  EXPECT_EQ(bytes_of_file(scene), scene_bytes);
  // report: an input inside the output directory with a name the report writes.
  fs::copy_file(bin(), tmp / "report.csv");
  r = run_cli("report " + q(tmp / "report.csv") + " -o " + q(tmp.path()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "where the report would overwrite it")) << r.err;
}

// Item 5: a FIFO as input is refused at once (it used to block in open forever); `timeout` turns a
// hang into exit code 124.
TEST_F(CliHardening, FifoInputIsRefusedAtOnce) {
  TempDir tmp;
  const fs::path fifo = tmp / "f";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string sub : {"info", "decode", "encode"}) {
    const std::string out = sub == "info" ? "" : " -o " + q(tmp / "out");
    const auto r = shell(tmp, "timeout 60 CBRDF " + sub + " " + q(fifo) + out + " > /dev/null");
    EXPECT_EQ(r.exit_code, 1) << sub << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << sub << ": " << r.err;
    EXPECT_TRUE(contains(r.err, "is a FIFO (named pipe), not a regular file")) << r.err;
  }
}

// Item 3: names and metadata that are not UTF-8 never abort `info --json`; the encoder stores valid
// UTF-8.
TEST_F(CliHardening, NonUtf8NamesAndMetadataInJson) {
  TempDir tmp;
  const fs::path bad_bin = tmp / "bad\xff.binary", bad_enc = tmp / "bad\xff.cbrdf";
  fs::copy_file(bin(), bad_bin);
  auto r = run_cli("encode " + q(bad_bin) + " -o " + q(bad_enc) + " --no-metrics");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_cli("info --json " + q(bad_enc));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "\"source\": \"bad\xEF\xBF\xBD.binary\"")) << r.out;
  EXPECT_TRUE(contains(r.out, "\"file\": ")) << r.out;
  r = run_cli("info --json " + q(bad_bin));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "\"format\": \"merl\"")) << r.out;

  // A file an older encoder wrote, with the raw byte in its metadata, reads too.
  // Its chunks as the command wrote them, with the mETA payload (spec 4.5: "key=value" lines)
  // replaced.
  auto bytes = read_file(enc(), kMaxContainerBytes);
  ASSERT_TRUE(bytes.ok());
  auto parsed = parse_container(*bytes);
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  std::vector<ChunkToWrite> chunks;
  for (std::size_t i = 0; i < parsed->layout.chunks.size(); ++i) {
    const ChunkInfo& c = parsed->layout.chunks[i];
    if (c.tag == kTagEnd || c.tag == kTagMetadata) continue;
    chunks.push_back({c.tag, parsed->payloads[i], c.compressed});
  }
  const std::string meta = "source=old\xfe\xff.binary\n";
  chunks.push_back(
      {std::string(kTagMetadata), std::vector<std::uint8_t>(meta.begin(), meta.end())});
  auto legacy = write_container(chunks, 3, parsed->layout.minor);
  ASSERT_TRUE(legacy.ok()) << legacy.status().message();
  ASSERT_TRUE(write_file_atomic(tmp / "legacy.cbrdf", *legacy).ok());
  r = run_cli("info --json " + q(tmp / "legacy.cbrdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "old\xEF\xBF\xBD\xEF\xBF\xBD.binary")) << r.out;
}

// Item 7: NaN and -Inf are not-measured values in a MERL table; every table cbrdf decodes, it
// reads back and encodes again, with those values bit for bit.
TEST_F(CliHardening, NanAndMinusInfNotMeasuredValuesRoundTrip) {
  TempDir tmp;
  auto table = read_merl(bin());
  ASSERT_TRUE(table.ok());
  const double payload_nan = std::bit_cast<double>(std::uint64_t{0x7FF8000000000123});
  std::size_t set = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (table->measured(c, i)) continue;
      table->set_stored(c, i, ++set % 2 ? payload_nan : -std::numeric_limits<double>::infinity());
    }
  }
  ASSERT_GT(set, 1000u);
  ASSERT_TRUE(write_merl(tmp / "nan.binary", *table).ok());
  auto r = run_cli("encode " + q(tmp / "nan.binary") + " -o " + q(tmp / "nan.cbrdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_cli("decode " + q(tmp / "nan.cbrdf") + " -o " + q(tmp / "back.binary"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto back = read_merl(tmp / "back.binary");
  ASSERT_TRUE(back.ok()) << back.status().message();
  std::size_t differ = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (table->measured(c, i)) continue;
      differ += std::bit_cast<std::uint64_t>(table->stored(c, i)) !=
                std::bit_cast<std::uint64_t>(back->stored(c, i));
    }
  }
  EXPECT_EQ(differ, 0u);
  r = run_cli("encode " + q(tmp / "back.binary") + " -o " + q(tmp / "again.cbrdf"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run_cli("info " + q(tmp / "back.binary"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// Item 9: targets that are not positive finite numbers are usage errors with a short line.
TEST_F(CliHardening, BadTargetsAreShortUsageErrors) {
  TempDir tmp;
  for (const std::string opt : {"--target-bytes", "--target-psnr"}) {
    for (const std::string v : {"nan", "NaN", "inf", "-inf", "0", "-5", "1e400", "abc", "5x"}) {
      const auto r = run_cli("encode " + q(bin()) + " -o " + q(tmp / "x.cbrdf") + " " + opt + " " +
                             v + " --no-metrics");
      EXPECT_EQ(r.exit_code, 2) << opt << " " << v;
      EXPECT_EQ(lines(r.err), 1) << opt << " " << v << ": " << r.err;
      EXPECT_LT(r.err.size(), 200u) << r.err;
      // Not a number, or a number outside the target's range (validate()'s words).
      EXPECT_TRUE(contains(r.err, opt + " must be a number, not") ||
                  contains(r.err, opt + " must be above 0"))
          << r.err;
    }
  }
  EXPECT_FALSE(fs::exists(tmp / "x.cbrdf"));
  // A data-chosen slice count and rate control's search both choose it: refused, not ignored.
  const auto r = run_cli("encode " + q(bin()) + " -o " + q(tmp / "x.cbrdf") +
                         " --slices auto --target-bytes 5000");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--slices auto and a target")) << r.err;
}

// Item 11: the longest name the filesystem takes works (the temporary's name used to be longer).
TEST_F(CliHardening, LongestOutputName) {
  TempDir tmp;
  const fs::path out = tmp / (std::string(255 - 7, 'n') + ".binary");
  const auto r = run_cli("decode " + q(enc()) + " -o " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(fs::file_size(out), kMerlFileBytes);
  int files = 0;
  for (const auto& e : fs::directory_iterator(tmp.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

// Item 12: `-` is standard input and output where a stream makes sense, a usage error elsewhere;
// binary data is not written to a terminal; an unknown subcommand is named.
TEST_F(CliHardening, DashIsStandardInputAndOutput) {
  TempDir tmp;
  auto r = shell(tmp, "CBRDF decode " + q(enc()) + " -o - | cat > " + q(tmp / "piped.binary"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(run_cli("decode " + q(enc()) + " -o " + q(tmp / "file.binary")).exit_code, 0);
  EXPECT_EQ(bytes_of_file(tmp / "piped.binary"), bytes_of_file(tmp / "file.binary"));
  EXPECT_TRUE(contains(r.err, "wrote standard output")) << "info lines go to stderr: " << r.err;

  r = shell(tmp, "cat " + q(bin()) + " | CBRDF encode - -o - --no-metrics > " + q(tmp / "s.cbrdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = shell(tmp, "CBRDF decode - -o " + q(tmp / "s.binary") + " < " + q(tmp / "s.cbrdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_cli("info " + q(tmp / "s.binary"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = shell(tmp, "CBRDF info - < " + q(enc()) + " > " + q(tmp / "info.txt"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(bytes_of_file(tmp / "info.txt"), "standard input: cbrdf container"));

  r = run_cli("info -");  // run_cli gives /dev/null as standard input: empty
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "standard input")) << r.err;
  for (const std::string& args : std::vector<std::string>{
           "decode " + q(enc()) + " -o - --exr -", "report - -o " + q(tmp / "r"),
           "render --builtin figure4 -o -", "imgdiff - - "}) {
    r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
  }
  EXPECT_TRUE(contains(run_cli("render --builtin figure4 -o -").err,
                       "'-' (standard output) is not supported for -o"));

  // A terminal as standard output: a pseudo-terminal made here.
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master >= 0 && ::grantpt(master) == 0 && ::unlockpt(master) == 0) {
    const std::string slave = ::ptsname(master);
    r = shell(tmp, "CBRDF decode " + q(enc()) + " -o - > " + slave);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "refusing to write binary data to a terminal")) << r.err;
  }
  if (master >= 0) ::close(master);

  r = run_cli("frobnicate");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_TRUE(contains(r.err, "unknown subcommand 'frobnicate'")) << r.err;
  r = run_cli("-q frobnicate");
  EXPECT_TRUE(contains(r.err, "unknown subcommand 'frobnicate'")) << r.err;
}

}  // namespace
}  // namespace cbrdf
