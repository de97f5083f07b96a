// SPDX-License-Identifier: MIT
// Included by name relative to this folder (not "report/..."): tests compile this file alone.
#include "report/frontier.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf::report {

std::vector<std::size_t> pareto_frontier(const std::vector<RdPoint>& points) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (std::isfinite(points[i].bytes) && std::isfinite(points[i].psnr)) order.push_back(i);
  }
  // Fewest bytes first and, at equal bytes, the highest PSNR; stable, so that of identical
  // points the first comes first.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (points[a].bytes != points[b].bytes) return points[a].bytes < points[b].bytes;
    return points[a].psnr > points[b].psnr;
  });
  std::vector<std::size_t> front;
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i : order) {
    // Everything after a kept point has at least its bytes: it stays only with a strictly higher
    // PSNR (equal PSNR at more bytes, or the same point again, is dominated).
    if (points[i].psnr > best) {
      front.push_back(i);
      best = points[i].psnr;
    }
  }
  return front;
}

const RdPoint* best_within(const std::vector<RdPoint>& points, double max_bytes) {
  const RdPoint* best = nullptr;
  for (const RdPoint& p : points) {
    if (!std::isfinite(p.psnr) || !(p.bytes <= max_bytes)) continue;
    if (!best || p.psnr > best->psnr || (p.psnr == best->psnr && p.bytes < best->bytes)) {
      best = &p;
    }
  }
  return best;
}

MaterialGain material_gain(const MaterialPoints& m, double factor) {
  MaterialGain g;
  g.material = m.material;
  if (!m.has_paper) return g;
  g.has_paper = true;
  g.paper_bytes = m.paper.bytes;
  g.paper_psnr = m.paper.psnr;
  const RdPoint* best = best_within(m.sweep, factor * m.paper.bytes);
  if (!best) return g;
  g.qualifying = true;
  g.best = best->label;
  g.gain_db = best->psnr - m.paper.psnr;
  g.bytes_ratio = best->bytes / m.paper.bytes;
  g.encode_ratio = m.paper.encode_s > 0 ? best->encode_s / m.paper.encode_s
                                        : std::numeric_limits<double>::quiet_NaN();
  return g;
}

BudgetGain budget_gain(const std::vector<MaterialPoints>& materials, double factor) {
  BudgetGain b;
  b.factor = factor;
  b.materials = int(materials.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  b.mean_gain_db = b.min_gain_db = b.max_gain_db = b.mean_bytes_ratio = b.mean_encode_ratio = nan;
  double gain = 0, bytes = 0, encode = 0;
  for (const MaterialPoints& m : materials) {
    MaterialGain g = material_gain(m, factor);
    if (g.qualifying) {
      gain += g.gain_db;
      bytes += g.bytes_ratio;
      encode += g.encode_ratio;
      b.min_gain_db = b.qualifying ? std::min(b.min_gain_db, g.gain_db) : g.gain_db;
      b.max_gain_db = b.qualifying ? std::max(b.max_gain_db, g.gain_db) : g.gain_db;
      ++b.qualifying;
    }
    b.per_material.push_back(std::move(g));
  }
  if (b.qualifying) {
    b.mean_gain_db = gain / b.qualifying;
    b.mean_bytes_ratio = bytes / b.qualifying;
    b.mean_encode_ratio = encode / b.qualifying;
  }
  return b;
}

CodingBudget compare_at_budget(const std::vector<std::vector<RdPoint>>& fresh,
                               const std::vector<std::vector<RdPoint>>& old, double budget) {
  CodingBudget c;
  c.budget = budget;
  c.materials = int(std::max(fresh.size(), old.size()));
  double fp = 0, fl = 0, op = 0, ol = 0, gain = 0, lin = 0;
  const double inf = std::numeric_limits<double>::infinity();
  double min_gain = inf, min_lin = inf;
  for (std::size_t m = 0; m < std::size_t(c.materials); ++m) {
    const RdPoint* f = m < fresh.size() ? best_within(fresh[m], budget) : nullptr;
    const RdPoint* o = m < old.size() ? best_within(old[m], budget) : nullptr;
    if (f) fp += f->psnr, fl += f->psnr_linear, ++c.fresh_qualifying;
    if (o) op += o->psnr, ol += o->psnr_linear, ++c.old_qualifying;
    if (f && o) {
      gain += f->psnr - o->psnr;
      lin += f->psnr_linear - o->psnr_linear;
      min_gain = std::min(min_gain, f->psnr - o->psnr);
      min_lin = std::min(min_lin, f->psnr_linear - o->psnr_linear);
      ++c.paired;
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto mean = [&](double sum, int n) { return n ? sum / n : nan; };
  c.fresh_psnr = mean(fp, c.fresh_qualifying);
  c.fresh_linear = mean(fl, c.fresh_qualifying);
  c.old_psnr = mean(op, c.old_qualifying);
  c.old_linear = mean(ol, c.old_qualifying);
  c.gain_db = mean(gain, c.paired);
  c.linear_gain_db = mean(lin, c.paired);
  c.min_gain_db = c.paired ? min_gain : nan;
  c.min_linear_gain_db = c.paired ? min_lin : nan;
  return c;
}

double target_gain_db(double factor) {
  if (factor == 1.0) return 2.0;
  if (factor == 4.0) return 6.0;
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace cbrdf::report
