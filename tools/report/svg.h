// SPDX-License-Identifier: MIT
// Minimal SVG charts for the report, written as text: x-y charts (linear or log x, or categories)
// and grids of polar plots. No dependency; every chart has a fixed width and height so that an
// <img> shows it at its natural size.
#pragma once

#include <string>
#include <vector>

namespace cbrdf::report {

enum class Marker { kCircle, kDiamond, kRing };

struct Series {
  std::string name;
  std::vector<double> x, y;  // same length; non-finite points are skipped
  std::string colour;        // empty: the palette's next colour
  bool line = true;
  bool markers = true;
  bool dashed = false;
  double width = 1.5;
  Marker marker = Marker::kCircle;
  double marker_size = 3;               // radius in pixels
  std::vector<std::string> notes = {};  // optional text beside each point (same length as x)
};

struct Chart {
  std::string title, x_label, y_label;
  bool log_x = false;
  // When set, x values are indices into these labels (drawn rotated under the axis).
  std::vector<std::string> categories;
  std::vector<Series> series;
  int width = 760, height = 440;
};

std::string render_chart(const Chart& chart);

// One polar panel: each series' x is the signed angle from the normal in degrees (-90..90), y the
// radius (already scaled, e.g. cube-rooted). Radii are normalized by the panel's largest.
struct PolarPanel {
  std::string title;
  std::vector<Series> series;
};
std::string render_polar_grid(const std::string& title, const std::vector<PolarPanel>& panels,
                              int columns);

std::string xml_escape(const std::string& s);
const std::string& palette(std::size_t i);

}  // namespace cbrdf::report
