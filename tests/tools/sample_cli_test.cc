// SPDX-License-Identifier: MIT
// `cbrdf sample`: the list shows every built-in material with its kind, and a measured one is
// written as a full MERL table, the same bytes the library makes.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "test_support.h"

namespace cbrdf {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::TempDir;

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// One line per material, in the library's order: name, kind, description.
TEST(SampleCli, ListShowsNameKindAndDescription) {
  const auto r = run_cli("sample --list");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), sample_materials().size()) << r.out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const SampleInfo& s = sample_materials()[i];
    std::istringstream fields(lines[i]);
    std::string name, kind;
    fields >> name >> kind;
    EXPECT_EQ(name, s.name) << lines[i];
    EXPECT_EQ(kind, sample_kind_name(s.kind)) << lines[i];
    EXPECT_NE(lines[i].find(s.description), std::string::npos) << lines[i];
  }
  EXPECT_EQ(lines_of(r.out).front().rfind("blue-metallic-paint", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("nickel                measured"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("plastic               analytic"), std::string::npos) << r.out;

  const auto help = run_cli("sample --help");
  EXPECT_NE(help.out.find("built-in material (measured or analytic)"), std::string::npos)
      << help.out;
}

TEST(SampleCli, MeasuredSampleIsWrittenAsAFullMerlTable) {
  TempDir tmp;
  const fs::path out = tmp / "nickel.binary";
  const auto r = run_cli("sample nickel -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote"), std::string::npos) << r.out;
  ASSERT_EQ(fs::file_size(out), kMerlFileBytes);
  const std::vector<std::uint8_t> bytes = read_file(out, 2 * kMerlFileBytes).value();
  std::int32_t dims[3];
  std::memcpy(dims, bytes.data(), sizeof dims);
  EXPECT_EQ(dims[0], 90);
  EXPECT_EQ(dims[1], 90);
  EXPECT_EQ(dims[2], 180);
  EXPECT_TRUE(bytes == serialize_merl(make_sample("nickel").value()));

  const auto bad = run_cli("sample gold-leaf -o '" + (tmp / "x.binary").string() + "'");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;  // a usage error: one line, the choices
  EXPECT_EQ(lines_of(bad.err).size(), 1u) << bad.err;
  EXPECT_NE(bad.err.find("valid names: blue-metallic-paint, nickel,"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(fs::exists(tmp / "x.binary"));
}

}  // namespace
}  // namespace cbrdf
