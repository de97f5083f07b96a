// SPDX-License-Identifier: MIT
// The report's SVG charts: point labels (the frontier's setting names) never overlap one another
// or cover a marker, however dense the points.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "report/svg.h"

namespace cbrdf::report {
namespace {

// A text element's box as a browser draws it at most: sans-serif digits and lowercase letters
// are at most 0.6 em wide on average, and the glyphs span 0.8 em above the baseline to 0.2 em
// below it. Read from the SVG itself, independently of how the chart placed it.
struct TextBox {
  std::string text;
  double x0, y0, x1, y1;
};

std::vector<TextBox> text_boxes(const std::string& svg, const std::set<std::string>& wanted) {
  std::vector<TextBox> out;
  const std::regex element("<text([^>]*)>([^<]*)</text>");
  auto attribute = [](const std::string& attrs, const std::string& name) {
    std::smatch m;
    const std::regex re("\\s" + name + "=\"([^\"]*)\"");
    return std::regex_search(attrs, m, re) ? std::stod(m[1].str()) : NAN;
  };
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), element);
       it != std::sregex_iterator(); ++it) {
    const std::string attrs = (*it)[1].str(), text = (*it)[2].str();
    if (!wanted.count(text)) continue;
    const double x = attribute(attrs, "x"), y = attribute(attrs, "y");
    double size = attribute(attrs, "font-size");
    if (std::isnan(size)) size = 12;  // the chart's default
    EXPECT_TRUE(std::isfinite(x) && std::isfinite(y)) << attrs;
    out.push_back({text, x, y - 0.8 * size, x + 0.6 * size * double(text.size()), y + 0.2 * size});
  }
  return out;
}

bool overlap(const TextBox& a, const TextBox& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

// A frontier shaped like the quickstart's: a steep rise, then a crowd of settings within a
// dB and a factor of two in bytes, each named.
Chart dense_chart(std::vector<std::string>* names) {
  Chart c;
  c.log_x = true;
  c.width = 900;
  c.height = 520;
  Series dots{"settings", {}, {}, "#1f77b4", false, true};
  Series front{"frontier", {}, {}, "#e6007e", true, false};
  const char* families[] = {"frank", "clayton", "gumbel"};
  const char* bits[] = {"b6", "b8", "b12", "bauto"};
  int n = 0;
  for (const char* f : families) {
    for (int s : {3, 6}) {
      for (const char* b : bits) {
        const double bytes = 600 * std::pow(1.13, n), psnr = n < 6 ? 35 + 2 * n : 47 + 0.06 * n;
        const std::string name = std::string(f) + " s" + std::to_string(s) + " " + b + " k4";
        dots.x.push_back(bytes);
        dots.y.push_back(psnr);
        front.x.push_back(bytes);
        front.y.push_back(psnr);
        front.notes.push_back(name);
        names->push_back(name);
        ++n;
      }
    }
  }
  c.series = {dots, front};
  return c;
}

TEST(ChartLabels, NoTwoLabelsOverlapOnADenseFrontier) {
  std::vector<std::string> names;
  const Chart c = dense_chart(&names);
  const std::string svg = render_chart(c);
  const std::vector<TextBox> boxes = text_boxes(svg, {names.begin(), names.end()});
  ASSERT_EQ(boxes.size(), names.size()) << "every point keeps its label";
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      EXPECT_FALSE(overlap(boxes[i], boxes[j]))
          << "'" << boxes[i].text << "' at (" << boxes[i].x0 << ", " << boxes[i].y1 << ") and '"
          << boxes[j].text << "' at (" << boxes[j].x0 << ", " << boxes[j].y1 << ")";
    }
  }
}

TEST(ChartLabels, LabelsCoverNoMarkerAndStayInTheChart) {
  std::vector<std::string> names;
  const Chart c = dense_chart(&names);
  const std::string svg = render_chart(c);
  const std::vector<TextBox> boxes = text_boxes(svg, {names.begin(), names.end()});
  ASSERT_EQ(boxes.size(), names.size());
  const std::regex circle("<circle cx=\"([^\"]+)\" cy=\"([^\"]+)\" r=\"([^\"]+)\"");
  int markers = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator();
       ++it) {
    const double cx = std::stod((*it)[1].str()), cy = std::stod((*it)[2].str());
    const double r = std::stod((*it)[3].str());
    ++markers;
    for (const TextBox& b : boxes) {
      EXPECT_FALSE(cx + r > b.x0 && cx - r < b.x1 && cy + r > b.y0 && cy - r < b.y1)
          << "'" << b.text << "' covers the marker at (" << cx << ", " << cy << ")";
    }
  }
  EXPECT_GE(markers, int(names.size()));
  for (const TextBox& b : boxes) {
    EXPECT_GE(b.x0, 0) << b.text;
    EXPECT_LE(b.x1, c.width) << b.text;
    EXPECT_GE(b.y0, 0) << b.text;
    EXPECT_LE(b.y1, c.height) << b.text;
  }
}

// A label pushed away from its point is joined to it by a line that starts at the point.
TEST(ChartLabels, MovedLabelsHaveLeaderLines) {
  std::vector<std::string> names;
  const std::string svg = render_chart(dense_chart(&names));
  const std::vector<TextBox> boxes = text_boxes(svg, {names.begin(), names.end()});
  ASSERT_EQ(boxes.size(), names.size());
  // Point positions as the chart drew them: the frontier's markers are the dots' circles, in order.
  const std::regex circle("<circle cx=\"([^\"]+)\" cy=\"([^\"]+)\"");
  std::vector<std::pair<double, double>> points;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator();
       ++it) {
    points.emplace_back(std::stod((*it)[1].str()), std::stod((*it)[2].str()));
  }
  ASSERT_GE(points.size(), boxes.size());
  const std::regex line("<line x1=\"([^\"]+)\" y1=\"([^\"]+)\" x2=\"([^\"]+)\" y2=\"([^\"]+)\"");
  std::vector<std::array<double, 4>> lines;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), line); it != std::sregex_iterator();
       ++it) {
    lines.push_back({std::stod((*it)[1].str()), std::stod((*it)[2].str()),
                     std::stod((*it)[3].str()), std::stod((*it)[4].str())});
  }
  int moved = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto [px, py] = points[i];
    const double dx = std::max({boxes[i].x0 - px, 0.0, px - boxes[i].x1});
    const double dy = std::max({boxes[i].y0 - py, 0.0, py - boxes[i].y1});
    if (std::hypot(dx, dy) <= 16) continue;  // beside its point (box estimates differ a little)
    ++moved;
    bool joined = false;
    for (const auto& l : lines) {
      joined |= std::abs(l[0] - px) < 0.2 && std::abs(l[1] - py) < 0.2 && l[2] >= boxes[i].x0 - 6 &&
                l[2] <= boxes[i].x1 + 6 && l[3] >= boxes[i].y0 - 6 && l[3] <= boxes[i].y1 + 6;
    }
    EXPECT_TRUE(joined) << "'" << boxes[i].text << "' is far from its point with no line to it";
  }
  // The crowd cannot all sit beside their points: the test exercises moved labels.
  EXPECT_GT(moved, 0);
}

}  // namespace
}  // namespace cbrdf::report
