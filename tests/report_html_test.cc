// SPDX-License-Identifier: MIT
// report.html in headless Chromium: the page loads and every image resolves.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>

#include "test_support.h"

namespace cbrdf {
namespace {

using testing::run_cli;
using testing::TempDir;
namespace fs = std::filesystem;

bool have_chromium() {
  return std::system("command -v chromium > /dev/null 2>&1") == 0;
}

// The DOM after the page's load event, as headless Chromium serializes it.
std::string dump_dom(const fs::path& html, const TempDir& tmp) {
  const fs::path profile = tmp / "profile", out = tmp / "dom.html";
  fs::remove_all(profile);
  const std::string cmd =
      "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync "
      "--user-data-dir='" +
      profile.string() + "' --dump-dom 'file://" + html.string() + "' > '" + out.string() +
      "' 2> /dev/null";
  if (std::system(cmd.c_str()) != 0) return "";
  return testing::read_text(out);
}

std::string body_attribute(const std::string& dom, const std::string& name) {
  const std::regex re("<body[^>]*\\s" + name + "=\"([^\"]*)\"");
  std::smatch m;
  return std::regex_search(dom, m, re) ? m[1].str() : "(absent)";
}

std::vector<std::string> image_sources(const std::string& html) {
  std::vector<std::string> out;
  const std::regex re("<img src=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator();
       ++it) {
    out.push_back((*it)[1].str());
  }
  return out;
}

TEST(ReportHtml, LoadsInChromiumWithEveryImage) {
  if (!have_chromium()) {
    GTEST_SKIP() << "chromium is not installed (Debian package 'chromium'); the HTML check "
                    "needs a headless browser";
  }
  TempDir tmp;
  const fs::path out = tmp / "report";
  for (const char* m : {"lambertian", "ggx-rough"}) {
    ASSERT_EQ(run_cli(std::string("-q sample ") + m + " -o '" + (tmp / m).string() + ".binary'")
                  .exit_code,
              0);
  }
  const auto r =
      run_cli("-q report '" + (tmp / "lambertian.binary").string() + "' '" +
              (tmp / "ggx-rough.binary").string() +
              "' --jobs 2 --baselines analytic --analytic-bins 3000 -o '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const std::string html = testing::read_text(out / "report.html");
  const std::vector<std::string> sources = image_sources(html);
  // 4 figures over all materials; per material 3 renders, a rate-distortion and a polar plot.
  EXPECT_EQ(sources.size(), 4u + 2u * 5u);
  for (const std::string& src : sources) {
    EXPECT_TRUE(fs::is_regular_file(out / src)) << src;
    EXPECT_GT(fs::file_size(out / src), 100u) << src;
  }

  const std::string dom = dump_dom(out / "report.html", tmp);
  ASSERT_FALSE(dom.empty()) << "chromium did not produce a DOM";
  EXPECT_NE(dom.find("Table 1: sphere PSNR"), std::string::npos);
  EXPECT_NE(dom.find("Frontier: gain over the paper"), std::string::npos);
  EXPECT_NE(dom.find("src=\"frontier_mean.svg\""), std::string::npos);
  EXPECT_EQ(body_attribute(dom, "data-loaded"), "ok");
  EXPECT_EQ(body_attribute(dom, "data-images"), std::to_string(sources.size()));
  EXPECT_EQ(body_attribute(dom, "data-images-broken"), "0");

  // The check itself notices a missing image.
  fs::remove(out / "sphere_ggx-rough_difference.png");
  const std::string broken = dump_dom(out / "report.html", tmp);
  EXPECT_EQ(body_attribute(broken, "data-loaded"), "broken");
  EXPECT_EQ(body_attribute(broken, "data-images-broken"), "1");
}

}  // namespace
}  // namespace cbrdf
