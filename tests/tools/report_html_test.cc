// SPDX-License-Identifier: MIT
// report.html in headless Chromium: the page loads, every image resolves, and the first screen
// shows the rate-distortion frontier.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>

#include "cbrdf/image_io.h"
#include "report/plots.h"
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

// Two small materials and two settings (so that the report has a frontier), written once.
class ReportHtml : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!have_chromium()) return;
    tmp_ = new TempDir();
    out_ = *tmp_ / "report";
    for (const char* m : {"lambertian", "ggx-rough"}) {
      ASSERT_EQ(run_cli(std::string("-q sample ") + m + " -o '" + (*tmp_ / m).string() + ".binary'")
                    .exit_code,
                0);
    }
    const auto r = run_cli("-q report '" + (*tmp_ / "lambertian.binary").string() + "' '" +
                           (*tmp_ / "ggx-rough.binary").string() +
                           "' --jobs 2 --sweep bits=8,12 --baselines analytic --analytic-bins "
                           "3000 -o '" +
                           out_.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete tmp_;
    tmp_ = nullptr;
  }
  void SetUp() override {
    if (!have_chromium()) {
      GTEST_SKIP() << "chromium is not installed (Debian package 'chromium'); the HTML checks "
                      "need a headless browser";
    }
    ASSERT_TRUE(fs::exists(out_ / "report.html"));
  }
  static TempDir* tmp_;
  static fs::path out_;
};
TempDir* ReportHtml::tmp_ = nullptr;
fs::path ReportHtml::out_;

TEST_F(ReportHtml, LoadsInChromiumWithEveryImage) {
  const std::string html = testing::read_text(out_ / "report.html");
  const std::vector<std::string> sources = image_sources(html);
  // 4 figures over all materials; per material 3 renders, a rate-distortion and a polar plot.
  EXPECT_EQ(sources.size(), 4u + 2u * 5u);
  for (const std::string& src : sources) {
    EXPECT_TRUE(fs::is_regular_file(out_ / src)) << src;
    EXPECT_GT(fs::file_size(out_ / src), 100u) << src;
  }

  const std::string dom = dump_dom(out_ / "report.html", *tmp_);
  ASSERT_FALSE(dom.empty()) << "chromium did not produce a DOM";
  EXPECT_NE(dom.find("Table 1: sphere PSNR"), std::string::npos);
  EXPECT_NE(dom.find("Summary: the paper's setting"), std::string::npos);
  EXPECT_NE(dom.find("Frontier settings: the sweep's settings"), std::string::npos);
  EXPECT_NE(dom.find("src=\"frontier_mean.svg\""), std::string::npos);
  EXPECT_EQ(body_attribute(dom, "data-loaded"), "ok");
  EXPECT_EQ(body_attribute(dom, "data-images"), std::to_string(sources.size()));
  EXPECT_EQ(body_attribute(dom, "data-images-broken"), "0");

  // The check itself notices a missing image.
  const fs::path png = out_ / "sphere_ggx-rough_difference.png", aside = *tmp_ / "aside.png";
  fs::rename(png, aside);
  const std::string broken = dump_dom(out_ / "report.html", *tmp_);
  fs::rename(aside, png);
  EXPECT_EQ(body_attribute(broken, "data-loaded"), "broken");
  EXPECT_EQ(body_attribute(broken, "data-images-broken"), "1");
}

// The first screen as headless Chromium shows it at 1280 x 800.
Expected<Image> screenshot(const fs::path& html, const TempDir& tmp) {
  const fs::path profile = tmp / "profile-shot", out = tmp / "shot.png";
  fs::remove_all(profile);
  fs::remove(out);
  const std::string cmd =
      "timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic "
      "--no-first-run --disable-background-networking --disable-component-update --disable-sync "
      "--user-data-dir='" +
      profile.string() + "' --window-size=1280,800 --screenshot='" + out.string() + "' 'file://" +
      html.string() + "' > /dev/null 2>&1";
  if (std::system(cmd.c_str()) != 0) return error(ErrorCode::kIo, "chromium failed: " + cmd);
  return read_png(out);
}

// Pixels within `tolerance` (of 255) of an "#rrggbb" colour in every channel.
int pixels_of(const Image& image, const std::string& hex, int tolerance) {
  const int want[3] = {std::stoi(hex.substr(1, 2), nullptr, 16),
                       std::stoi(hex.substr(3, 2), nullptr, 16),
                       std::stoi(hex.substr(5, 2), nullptr, 16)};
  int n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      bool near = true;
      for (int c = 0; c < 3; ++c) {
        const int v = int(std::lround(image.data[image.offset(x, y, c)] * 255.0f));
        near = near && std::abs(v - want[c]) <= tolerance;
      }
      n += near;
    }
  }
  return n;
}

TEST_F(ReportHtml, FirstScreenShowsTheFrontier) {
  if (!fs::exists("/usr/bin/chromium")) GTEST_SKIP() << "no /usr/bin/chromium for the screenshot";
  // The frontier's line and its named settings are drawn in a colour nothing else on the page
  // uses, so its pixels on the first screen mean the figure is there.
  auto shot = screenshot(out_ / "report.html", *tmp_);
  ASSERT_TRUE(shot.ok()) << shot.status().message();
  EXPECT_EQ(shot->width, 1280);
  EXPECT_EQ(shot->height, 800);
  const int on_screen = pixels_of(*shot, report::kFrontierColour, 40);
  EXPECT_GT(on_screen, 150) << "the first screen does not show the frontier figure";

  // The check notices a figure pushed below the fold: the same page with 800 pixels of space
  // before it.
  std::string html = testing::read_text(out_ / "report.html");
  const std::string body = "<body>\n";
  const std::size_t at = html.find(body);
  ASSERT_NE(at, std::string::npos);
  html.insert(at + body.size(), "<div style=\"height: 800px\"></div>\n");
  const fs::path pushed = out_ / "pushed.html";
  {
    std::ofstream f(pushed);
    f << html;
  }
  auto below = screenshot(pushed, *tmp_);
  fs::remove(pushed);
  ASSERT_TRUE(below.ok()) << below.status().message();
  EXPECT_LT(pixels_of(*below, report::kFrontierColour, 40), 10);
}

}  // namespace
}  // namespace cbrdf
