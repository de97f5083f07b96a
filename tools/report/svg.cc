// SPDX-License-Identifier: MIT
#include "report/svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "report/labels.h"

namespace cbrdf::report {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string tick_text(double v) {
  char buf[32];
  if (v != 0 && (std::abs(v) >= 1e5 || std::abs(v) < 1e-3)) {
    std::snprintf(buf, sizeof buf, "%.0e", v);
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

// 1, 2, 5 times a power of ten, about `target` ticks over [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int target) {
  const double raw = (hi - lo) / std::max(target, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  double step = p;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * p;
    if (step >= raw) break;
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) {
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  }
  return ticks;
}

struct Frame {
  double left, top, right, bottom;  // plot area in pixels
  double x0, x1, y0, y1;            // data range (x in log10 when log)
  bool log_x;
  double px(double x) const {
    const double v = log_x ? std::log10(x) : x;
    return left + (v - x0) / (x1 - x0) * (right - left);
  }
  double py(double y) const { return bottom - (y - y0) / (y1 - y0) * (bottom - top); }
};

void draw_marker(std::ostringstream& out, Marker m, double x, double y, double r,
                 const std::string& colour) {
  switch (m) {
    case Marker::kCircle:
      out << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"" << num(r)
          << "\" fill=\"" << colour << "\"/>\n";
      break;
    case Marker::kRing:
      out << "<circle cx=\"" << num(x) << "\" cy=\"" << num(y) << "\" r=\"" << num(r)
          << "\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\"/>\n";
      break;
    case Marker::kDiamond:
      out << "<polygon points=\"" << num(x) << "," << num(y - r) << " " << num(x + r) << ","
          << num(y) << " " << num(x) << "," << num(y + r) << " " << num(x - r) << "," << num(y)
          << "\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\"/>\n";
      break;
  }
}

void draw_series(std::ostringstream& out, const Series& s, const std::string& colour,
                 const Frame& f) {
  std::string points;
  for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (f.log_x && s.x[i] <= 0)) continue;
    points += num(f.px(s.x[i])) + "," + num(f.py(s.y[i])) + " ";
    if (s.markers) draw_marker(out, s.marker, f.px(s.x[i]), f.py(s.y[i]), s.marker_size, colour);
  }
  if (s.line && !points.empty()) {
    out << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"" << num(s.width)
        << "\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << " points=\"" << points
        << "\"/>\n";
  }
}

}  // namespace

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

const std::string& palette(std::size_t i) {
  // Twenty distinct colours (matplotlib's tab10, then darker and lighter companions) so that a
  // full comparison (sweep, families, analytic models, baselines) never repeats one.
  static const std::vector<std::string> colours = {
      "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2",
      "#7f7f7f", "#bcbd22", "#17becf", "#393b79", "#843c39", "#637939", "#e6550d",
      "#7b4173", "#3182bd", "#636363", "#8c6d31", "#31a354", "#de9ed6"};
  return colours[i % colours.size()];
}

namespace {

// The data range of the chart's axes (x in log10 when log_x), padded so no point sits on the frame.
struct Range {
  double xmin, xmax, ymin, ymax;
};

Range data_range(const Chart& c) {
  const bool categorical = !c.categories.empty();
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const Series& s : c.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (c.log_x && s.x[i] <= 0)) continue;
      const double x = c.log_x ? std::log10(s.x[i]) : s.x[i];
      xmin = std::min(xmin, x), xmax = std::max(xmax, x);
      ymin = std::min(ymin, s.y[i]), ymax = std::max(ymax, s.y[i]);
    }
  }
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  if (categorical) xmin = -0.5, xmax = double(c.categories.size()) - 0.5;
  // Log axes span whole decades, with points kept off the frame.
  if (c.log_x) xmin = std::floor(xmin - 0.1), xmax = std::max(std::ceil(xmax + 0.1), xmin + 1);
  if (xmax - xmin < 1e-12) xmin -= 0.5, xmax += 0.5;
  if (ymax - ymin < 1e-12) ymin -= 1, ymax += 1;
  const double ypad = 0.05 * (ymax - ymin);
  ymin -= ypad, ymax += ypad;
  return {xmin, xmax, ymin, ymax};
}

// Grid lines, ticks, the frame and the axis labels.
void draw_axes(std::ostringstream& out, const Chart& c, const Frame& f) {
  const bool categorical = !c.categories.empty();
  // Grid and ticks.
  for (double t : nice_ticks(f.y0, f.y1, 6)) {
    out << "<line x1=\"" << num(f.left) << "\" x2=\"" << num(f.right) << "\" y1=\"" << num(f.py(t))
        << "\" y2=\"" << num(f.py(t)) << "\" stroke=\"#ddd\"/>\n";
    out << "<text x=\"" << num(f.left - 6) << "\" y=\"" << num(f.py(t) + 4)
        << "\" text-anchor=\"end\">" << tick_text(t) << "</text>\n";
  }
  if (categorical) {
    for (std::size_t i = 0; i < c.categories.size(); ++i) {
      const double x = f.px(double(i));
      out << "<line x1=\"" << num(x) << "\" x2=\"" << num(x) << "\" y1=\"" << num(f.top)
          << "\" y2=\"" << num(f.bottom) << "\" stroke=\"#eee\"/>\n";
      out << "<text transform=\"translate(" << num(x + 4) << "," << num(f.bottom + 8)
          << ") rotate(60)\" font-size=\"11\">" << xml_escape(c.categories[i]) << "</text>\n";
    }
  } else {
    std::vector<double> ticks;
    if (c.log_x) {
      for (double e = f.x0; e <= f.x1 + 1e-9; e += 1) ticks.push_back(std::pow(10.0, e));
    } else {
      ticks = nice_ticks(f.x0, f.x1, 8);
    }
    for (double t : ticks) {
      const double x = f.px(t);
      out << "<line x1=\"" << num(x) << "\" x2=\"" << num(x) << "\" y1=\"" << num(f.top)
          << "\" y2=\"" << num(f.bottom) << "\" stroke=\"#ddd\"/>\n";
      out << "<text x=\"" << num(x) << "\" y=\"" << num(f.bottom + 16)
          << "\" text-anchor=\"middle\">" << tick_text(t) << "</text>\n";
    }
  }
  out << "<rect x=\"" << num(f.left) << "\" y=\"" << num(f.top) << "\" width=\""
      << num(f.right - f.left) << "\" height=\"" << num(f.bottom - f.top)
      << "\" fill=\"none\" stroke=\"#333\"/>\n";
  if (!categorical) {
    out << "<text x=\"" << num((f.left + f.right) / 2) << "\" y=\"" << num(f.bottom + 38)
        << "\" text-anchor=\"middle\">" << xml_escape(c.x_label) << "</text>\n";
  }
  out << "<text transform=\"translate(18," << num((f.top + f.bottom) / 2)
      << ") rotate(-90)\" text-anchor=\"middle\">" << xml_escape(c.y_label) << "</text>\n";
}

// Series and legend (series without a name have no legend entry).
void draw_series_and_legend(std::ostringstream& out, const Chart& c, const Frame& f) {
  std::size_t entries = 0;
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    const Series& s = c.series[i];
    const std::string colour = s.colour.empty() ? palette(i) : s.colour;
    draw_series(out, s, colour, f);
    if (s.name.empty()) continue;
    const double ly = f.top + 6 + 18.0 * double(entries++);
    const double lx = f.right + 14;
    if (s.line) {
      out << "<line x1=\"" << num(lx) << "\" x2=\"" << num(lx + 22) << "\" y1=\"" << num(ly)
          << "\" y2=\"" << num(ly) << "\" stroke=\"" << colour << "\" stroke-width=\"2\""
          << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    }
    if (s.markers) draw_marker(out, s.marker, lx + 11, ly, std::min(s.marker_size, 6.0), colour);
    out << "<text x=\"" << num(lx + 28) << "\" y=\"" << num(ly + 4) << "\">" << xml_escape(s.name)
        << "</text>\n";
  }
}

// The series' notes, placed clear of every marker and of each other (labels.h), drawn last so that
// they sit on top; a white halo keeps them legible over grid and series lines.
void draw_notes(std::ostringstream& out, const Chart& c, const Frame& f) {
  std::vector<LabelRequest> requests;
  std::vector<std::string> colours;
  std::vector<Box> obstacles;
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    const Series& s = c.series[i];
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k]) || (f.log_x && s.x[k] <= 0)) continue;
      const double x = f.px(s.x[k]), y = f.py(s.y[k]);
      const bool note = k < s.notes.size() && !s.notes[k].empty();
      const double r = s.markers ? s.marker_size + 1 : note ? 2 : 0;
      if (r > 0) obstacles.push_back({x - r, y - r, x + r, y + r});
      if (note) {
        requests.push_back({x, y, s.notes[k], 10});
        colours.push_back(s.colour.empty() ? palette(i) : s.colour);
      }
    }
  }
  if (requests.empty()) return;
  const std::vector<PlacedLabel> placed =
      place_labels(requests, obstacles, {f.left + 2, f.top + 2, f.right - 2, f.bottom - 2});
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (!placed[i].leader) continue;
    out << "<line x1=\"" << num(requests[i].x) << "\" y1=\"" << num(requests[i].y) << "\" x2=\""
        << num(placed[i].leader_x) << "\" y2=\"" << num(placed[i].leader_y) << "\" stroke=\""
        << colours[i] << "\" stroke-width=\"0.8\" opacity=\"0.6\"/>\n";
  }
  for (std::size_t i = 0; i < placed.size(); ++i) {
    out << "<text class=\"note\" x=\"" << num(placed[i].x) << "\" y=\"" << num(placed[i].baseline)
        << "\" font-size=\"" << num(requests[i].font_size) << "\" fill=\"" << colours[i]
        << "\" stroke=\"white\" stroke-width=\"3\" stroke-linejoin=\"round\" "
           "paint-order=\"stroke\">"
        << xml_escape(requests[i].text) << "</text>\n";
  }
}

}  // namespace

std::string render_chart(const Chart& c) {
  const bool categorical = !c.categories.empty();
  const Range r = data_range(c);
  const double legend_w = 190;
  const double bottom_margin = categorical ? 150 : 56;
  Frame f{70,     40,     c.width - legend_w - 10, c.height - bottom_margin, r.xmin, r.xmax, r.ymin,
          r.ymax, c.log_x};
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << c.width << "\" height=\""
      << c.height << "\" viewBox=\"0 0 " << c.width << " " << c.height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  out << "<text x=\"" << c.width / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
      << xml_escape(c.title) << "</text>\n";
  draw_axes(out, c, f);
  draw_series_and_legend(out, c, f);
  draw_notes(out, c, f);
  out << "</svg>\n";
  return out.str();
}

std::string render_polar_grid(const std::string& title, const std::vector<PolarPanel>& panels,
                              int columns) {
  constexpr int kPanel = 220, kTitle = 36;
  const int cols = std::max(1, std::min<int>(columns, int(panels.size())));
  const int rows = (int(panels.size()) + cols - 1) / cols;
  const int width = cols * kPanel, height = kTitle + rows * (kPanel / 2 + 50);
  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" viewBox=\"0 0 " << width << " " << height
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  out << "<text x=\"" << width / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">"
      << xml_escape(title) << "</text>\n";
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const PolarPanel& panel = panels[p];
    const double ox = double(int(p) % cols) * kPanel + kPanel / 2.0;
    const double oy = kTitle + double(int(p) / cols) * (kPanel / 2 + 50) + kPanel / 2.0 + 10;
    const double radius = kPanel / 2.0 - 16;
    double rmax = 0;
    for (const Series& s : panel.series) {
      for (double v : s.y) {
        if (std::isfinite(v)) rmax = std::max(rmax, v);
      }
    }
    if (rmax <= 0) rmax = 1;
    // The upper half disc: the surface along the bottom, the normal straight up.
    for (double fr : {0.5, 1.0}) {
      out << "<path d=\"M " << num(ox - radius * fr) << " " << num(oy) << " A " << num(radius * fr)
          << " " << num(radius * fr) << " 0 0 1 " << num(ox + radius * fr) << " " << num(oy)
          << "\" fill=\"none\" stroke=\"#ddd\"/>\n";
    }
    out << "<line x1=\"" << num(ox - radius) << "\" x2=\"" << num(ox + radius) << "\" y1=\""
        << num(oy) << "\" y2=\"" << num(oy) << "\" stroke=\"#999\"/>\n";
    out << "<line x1=\"" << num(ox) << "\" x2=\"" << num(ox) << "\" y1=\"" << num(oy) << "\" y2=\""
        << num(oy - radius) << "\" stroke=\"#ddd\"/>\n";
    out << "<text x=\"" << num(ox) << "\" y=\"" << num(oy + 16) << "\" text-anchor=\"middle\">"
        << xml_escape(panel.title) << "</text>\n";
    for (std::size_t i = 0; i < panel.series.size(); ++i) {
      const Series& s = panel.series[i];
      const std::string colour = s.colour.empty() ? palette(i) : s.colour;
      std::string points;
      for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
        if (!std::isfinite(s.y[k])) continue;
        const double a = s.x[k] * std::numbers::pi / 180, r = s.y[k] / rmax * radius;
        points += num(ox + r * std::sin(a)) + "," + num(oy - r * std::cos(a)) + " ";
      }
      out << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"" << num(s.width)
          << "\"" << (s.dashed ? " stroke-dasharray=\"4,3\"" : "") << " points=\"" << points
          << "\"/>\n";
    }
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace cbrdf::report
