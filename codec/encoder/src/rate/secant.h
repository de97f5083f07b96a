// SPDX-License-Identifier: MIT
// The residual rate control's search for a bound (residual_rate.cc): a value that falls smoothly
// as x = log E grows (the file's PSNR, or the log of the residual's bytes), tried at a few x, and
// the x where it crosses an aim. Each try costs a whole residual encode, so the next x comes from
// the secant through the last two tries (one try: a slope given by the caller), kept inside the
// bracket of the tries that met the target and missed it.
#pragma once

#include <optional>
#include <vector>

namespace cbrdf::internal {

class Secant {
 public:
  // x is searched in [x_min, x_max]; `slope` (< 0) is d value / dx until two tries are known.
  Secant(double x_min, double x_max, double slope);
  // A try at x gave `value`; `met`: whether that try met the target.
  void add(double x, double value, bool met);
  // The next x to try for `aim`, or none: the bracket is narrower than kClose, or the aim lies past
  // the end of the range already tried there, or the next x was already tried.
  std::optional<double> next(double aim) const;

  // Tries closer than this in x (log E: 2%) are the same.
  static constexpr double kClose = 0.02;

 private:
  struct Point {
    double x, value;
    bool met;
  };
  // The bracket's ends: the nearest tries on each side of the crossing, when known.
  std::optional<Point> nearest(bool met) const;

  double x_min_, x_max_, slope_;
  std::vector<Point> points_;
};

}  // namespace cbrdf::internal
