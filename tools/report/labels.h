// SPDX-License-Identifier: MIT
// Places text labels beside chart points so that no two overlap: each label goes to the nearest
// free spot around its point (greedily, in the order given), with a leader line when it had to
// move away from the point.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace cbrdf::report {

// An axis-aligned box in SVG pixels (y grows downwards).
struct Box {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
bool overlaps(const Box& a, const Box& b);

// The box a line of `text` covers when its baseline starts at (x, baseline), estimated without
// font metrics: wide enough for sans-serif digits and lowercase letters, which set the width of
// setting labels such as "frank s6 bauto k4".
Box text_box(double x, double baseline, const std::string& text, double font_size);

struct LabelRequest {
  double x = 0, y = 0;  // the point the label names
  std::string text;
  double font_size = 10;
};

struct PlacedLabel {
  double x = 0, baseline = 0;         // where the text starts
  Box box;                            // text_box of the text there
  bool leader = false;                // far enough from its point to need a line to it
  double leader_x = 0, leader_y = 0;  // the line's end on the box, nearest the point
};

// One placement per request, in order. Labels stay inside `area` and off the `obstacles`
// (markers), off each other and off each other's leader lines. A label with no free spot left in
// the whole area keeps the spot beside its point.
std::vector<PlacedLabel> place_labels(const std::vector<LabelRequest>& requests,
                                      const std::vector<Box>& obstacles, const Box& area);

}  // namespace cbrdf::report
