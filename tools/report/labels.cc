// SPDX-License-Identifier: MIT
#include "report/labels.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf::report {
namespace {

// Gap kept between a label and anything else, so that neighbours do not touch.
constexpr double kGap = 1.5;
// A label further than this from its point gets a leader line.
constexpr double kLeaderFrom = 9;

struct Segment {
  double x0, y0, x1, y1;
};

Box padded(const Box& b, double pad) {
  return {b.x0 - pad, b.y0 - pad, b.x1 + pad, b.y1 + pad};
}

bool inside(const Box& b, const Box& area) {
  return b.x0 >= area.x0 && b.y0 >= area.y0 && b.x1 <= area.x1 && b.y1 <= area.y1;
}

// Whether two segments cross (touching at an end point, as two lines from one point do, is not
// crossing).
bool crosses(const Segment& a, const Segment& b) {
  auto side = [](double ax, double ay, double bx, double by, double cx, double cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
  };
  const double d1 = side(a.x0, a.y0, a.x1, a.y1, b.x0, b.y0);
  const double d2 = side(a.x0, a.y0, a.x1, a.y1, b.x1, b.y1);
  const double d3 = side(b.x0, b.y0, b.x1, b.y1, a.x0, a.y0);
  const double d4 = side(b.x0, b.y0, b.x1, b.y1, a.x1, a.y1);
  return d1 * d2 < 0 && d3 * d4 < 0;
}

bool crosses(const Segment& s, const Box& b) {
  auto in = [&](double x, double y) { return x > b.x0 && x < b.x1 && y > b.y0 && y < b.y1; };
  if (in(s.x0, s.y0) || in(s.x1, s.y1)) return true;
  const Segment edges[] = {{b.x0, b.y0, b.x1, b.y0},
                           {b.x1, b.y0, b.x1, b.y1},
                           {b.x1, b.y1, b.x0, b.y1},
                           {b.x0, b.y1, b.x0, b.y0}};
  for (const Segment& e : edges) {
    if (crosses(s, e)) return true;
  }
  return false;
}

// The point of `b` nearest to (x, y).
void nearest_on(const Box& b, double x, double y, double* nx, double* ny) {
  *nx = std::clamp(x, b.x0, b.x1);
  *ny = std::clamp(y, b.y0, b.y1);
}

struct Layout {
  const std::vector<Box>& obstacles;
  const Box& area;
  std::vector<Box> placed;
  std::vector<Segment> leaders;

  // The label at `box` for the point (px, py), or nothing when it collides.
  // With `cross` set, a label may lie across other labels' leader lines and its own line across
  // other labels: the last resort before an overlap.
  bool fits(const Box& box, double px, double py, PlacedLabel* out, bool cross = false) const {
    if (!inside(box, area)) return false;
    const Box halo = padded(box, kGap);
    for (const Box& o : obstacles) {
      if (overlaps(halo, o)) return false;
    }
    for (const Box& p : placed) {
      if (overlaps(halo, p)) return false;
    }
    for (const Segment& s : leaders) {
      if (!cross && crosses(s, halo)) return false;
    }
    double lx = 0, ly = 0;
    nearest_on(box, px, py, &lx, &ly);
    const bool leader = std::hypot(lx - px, ly - py) > kLeaderFrom;
    if (leader && !cross) {
      const Segment s{px, py, lx, ly};
      for (const Box& p : placed) {
        if (crosses(s, p)) return false;
      }
      for (const Segment& other : leaders) {
        if (crosses(s, other)) return false;
      }
    }
    out->box = box;
    out->leader = leader;
    out->leader_x = lx;
    out->leader_y = ly;
    return true;
  }

  void keep(const PlacedLabel& l, double px, double py) {
    placed.push_back(l.box);
    if (l.leader) leaders.push_back({px, py, l.leader_x, l.leader_y});
  }
};

// The box of a label whose nearest side or corner is `r` pixels from (px, py) in direction
// (dx, dy): right of the point for dx > 0, left for dx < 0, centred on it for dx = 0; likewise
// above, below or centred.
Box box_towards(double px, double py, double dx, double dy, double r, double w, double h) {
  const double n = std::hypot(dx, dy);
  const double ax = px + r * dx / n, ay = py + r * dy / n;
  const double x0 = dx > 0 ? ax : dx < 0 ? ax - w : ax - w / 2;
  const double y0 = dy < 0 ? ay - h : dy > 0 ? ay : ay - h / 2;
  return {x0, y0, x0 + w, y0 + h};
}

}  // namespace

bool overlaps(const Box& a, const Box& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

Box text_box(double x, double baseline, const std::string& text, double font_size) {
  std::size_t chars = 0;
  for (unsigned char c : text) chars += (c & 0xC0) != 0x80;  // code points, not UTF-8 bytes
  return {x, baseline - 0.82 * font_size, x + 0.62 * font_size * double(chars),
          baseline + 0.25 * font_size};
}

std::vector<PlacedLabel> place_labels(const std::vector<LabelRequest>& requests,
                                      const std::vector<Box>& obstacles, const Box& area) {
  // Up and right first (where a rising frontier leaves room), then the other sides; further out,
  // the directions between them too.
  static constexpr double kNear[][2] = {{1, -1}, {1, 0},   {1, 1},  {0, -1},
                                        {0, 1},  {-1, -1}, {-1, 0}, {-1, 1}};
  static constexpr double kFar[][2] = {{2, -1},  {2, 1},  {1, -2},  {1, 2},
                                       {-2, -1}, {-2, 1}, {-1, -2}, {-1, 2}};
  static constexpr double kRadii[] = {3, 8, 14, 22, 32, 45, 60, 80, 105, 135, 170, 210};
  Layout layout{obstacles, area, {}, {}};
  std::vector<PlacedLabel> out;
  for (const LabelRequest& q : requests) {
    const Box unit = text_box(0, 0, q.text, q.font_size);
    const double w = unit.x1 - unit.x0, h = unit.y1 - unit.y0;
    PlacedLabel best;
    bool found = false;
    for (double r : kRadii) {
      for (const auto& d : kNear) {
        if (!found)
          found = layout.fits(box_towards(q.x, q.y, d[0], d[1], r, w, h), q.x, q.y, &best);
      }
      for (const auto& d : kFar) {
        if (!found && r >= 20) {
          found = layout.fits(box_towards(q.x, q.y, d[0], d[1], r, w, h), q.x, q.y, &best);
        }
      }
      if (found) break;
    }
    // Crowded: the free spot nearest the point anywhere in the area, first clear of every
    // leader line, then allowed across them.
    for (bool cross : {false, true}) {
      double nearest = std::numeric_limits<double>::infinity();
      for (double y0 = area.y0; !found && y0 + h <= area.y1; y0 += 3) {
        for (double x0 = area.x0; x0 + w <= area.x1; x0 += 3) {
          const Box box{x0, y0, x0 + w, y0 + h};
          double nx = 0, ny = 0;
          nearest_on(box, q.x, q.y, &nx, &ny);
          const double dist = std::hypot(nx - q.x, ny - q.y);
          PlacedLabel candidate;
          if (dist < nearest && layout.fits(box, q.x, q.y, &candidate, cross)) {
            nearest = dist;
            best = candidate;
          }
        }
      }
      if (std::isfinite(nearest)) found = true;
      if (found) break;
    }
    if (!found) {
      best.box = box_towards(q.x, q.y, 1, -1, kRadii[0], w, h);
      best.leader = false;
    }
    best.x = best.box.x0;
    best.baseline = best.box.y0 - unit.y0;
    layout.keep(best, q.x, q.y);
    out.push_back(best);
  }
  return out;
}

}  // namespace cbrdf::report
