// SPDX-License-Identifier: MIT
#include "report/plots.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "report/frontier.h"
#include "report/svg.h"
#include "report/tables.h"

namespace cbrdf::report {
namespace {

bool is_lossless(const std::string& label) {
  return label.rfind("zstd-", 0) == 0 || label.rfind("xz-", 0) == 0;
}

// The labels plotted as lone points: every compared model that is not a copula sweep setting
// (lossless rows sit at the PSNR cap and are left out).
std::vector<std::string> point_labels(const std::vector<MaterialResult>& results,
                                      const Settings& st) {
  const std::vector<std::string> sweep = sweep_labels(st);
  std::vector<std::string> out;
  for (const std::string& l : compared_labels(results, st)) {
    if (is_lossless(l) || std::find(sweep.begin(), sweep.end(), l) != sweep.end()) continue;
    out.push_back(l);
  }
  return out;
}

using Getter = std::function<double(const std::string& label, double Row::*field)>;

// One chart of PSNR against a cost: per swept family all its settings as points and their
// Pareto front as a line, then each baseline as a point.
Chart cost_chart(const Settings& st, const std::vector<std::string>& baselines, const Getter& get,
                 double Row::*x_field, const std::string& title, const std::string& x_label) {
  Chart c;
  c.title = title;
  c.x_label = x_label;
  c.y_label = "sphere PSNR, tone-mapped (dB)";
  c.log_x = true;
  std::size_t colour = 0;
  for (const std::string& family : st.sweep.families) {
    std::vector<std::pair<double, double>> pts;
    for (const CodecSetting& s : st.sweep.settings()) {
      if (s.family != family) continue;
      pts.emplace_back(get(s.label(), x_field), get(s.label(), &Row::psnr_tonemapped));
    }
    std::sort(pts.begin(), pts.end());
    Series all{CodecSetting{family, 0, 0}.model_name() + " settings",
               {},
               {},
               palette(colour),
               false,
               true};
    Series front{CodecSetting{family, 0, 0}.model_name() + ", Pareto front",
                 {},
                 {},
                 palette(colour),
                 true,
                 false};
    double best = -INFINITY;
    for (const auto& [x, y] : pts) {
      all.x.push_back(x), all.y.push_back(y);
      if (y > best) {
        best = y;
        front.x.push_back(x), front.y.push_back(y);
      }
    }
    c.series.push_back(all);
    if (pts.size() > 1) c.series.push_back(front);
    ++colour;
  }
  for (const std::string& l : baselines) {
    c.series.push_back(Series{
        l, {get(l, x_field)}, {get(l, &Row::psnr_tonemapped)}, palette(colour++), false, true});
  }
  return c;
}

// The rate-distortion frontier: every sweep setting as a point (one colour per family and
// component count), the Pareto frontier as a kFrontierColour line with its settings named, the
// paper's setting as a ring and the baselines as diamonds.
Chart frontier_chart(const std::vector<RdPoint>& sweep, const RdPoint& paper,
                     const std::vector<std::string>& baselines, const Getter& get,
                     const std::string& title) {
  Chart c;
  c.title = title;
  c.x_label = "bytes (log)";
  c.y_label = "sphere PSNR, tone-mapped (dB)";
  c.log_x = true;
  c.width = 900;
  c.height = 520;
  // Groups: the family and component count, whatever the slices and bits ("frank s6 bauto k2"
  // belongs to "frank, 2 components").
  auto group_of = [](const std::string& label) {
    std::string g, components = "1 component";
    std::istringstream words(label);
    for (std::string w; words >> w;) {
      const bool digits = w.size() > 1 && std::all_of(w.begin() + 1, w.end(), [](char ch) {
                            return ch >= '0' && ch <= '9';
                          });
      if (w[0] == 'k' && digits) {
        components = w.substr(1) + (w == "k1" ? " component" : " components");
      } else if (!((w[0] == 's' || w[0] == 'b') && digits) && w != "bauto") {
        g += (g.empty() ? "" : " ") + w;
      }
    }
    return g + ", " + components;
  };
  std::vector<Series> groups;
  for (const RdPoint& p : sweep) {
    const std::string g = group_of(p.label);
    auto it =
        std::find_if(groups.begin(), groups.end(), [&](const Series& s) { return s.name == g; });
    if (it == groups.end()) {
      groups.push_back(Series{g, {}, {}, palette(groups.size()), false, true});
      it = groups.end() - 1;
    }
    it->x.push_back(p.bytes);
    it->y.push_back(p.psnr);
  }
  Series front{"Pareto frontier", {}, {}, kFrontierColour, true, false};
  front.width = 2.5;
  for (std::size_t i : pareto_frontier(sweep)) {
    front.x.push_back(sweep[i].bytes);
    front.y.push_back(sweep[i].psnr);
    front.notes.push_back(sweep[i].label);
  }
  // The budgets of the gain table: 1x, 2x and 4x the paper setting's bytes.
  double lo = paper.psnr, hi = paper.psnr;
  for (const RdPoint& p : sweep) {
    if (std::isfinite(p.psnr)) lo = std::min(lo, p.psnr), hi = std::max(hi, p.psnr);
  }
  std::vector<Series> budgets;
  for (double f : kBudgetFactors) {
    if (!std::isfinite(paper.bytes) || !std::isfinite(lo)) break;
    char name[64];
    std::snprintf(name, sizeof name, "%gx paper bytes", f);
    Series b{name, {f * paper.bytes, f * paper.bytes}, {lo, hi}, "#999", true, false, true, 1.0};
    if (f != kBudgetFactors[0]) b.name.clear();  // one legend entry for the three lines
    budgets.push_back(std::move(b));
  }
  if (!budgets.empty()) budgets.front().name = "1x, 2x, 4x paper bytes";
  c.series = std::move(groups);
  c.series.insert(c.series.end(), budgets.begin(), budgets.end());
  c.series.push_back(std::move(front));
  Series ref{"paper: " + paper.label, {paper.bytes}, {paper.psnr}, "#000", false, true};
  ref.marker = Marker::kRing;
  ref.marker_size = 8;
  c.series.push_back(std::move(ref));
  std::size_t colour = c.series.size();
  for (const std::string& l : baselines) {
    if (l == paper.label) continue;
    Series b{l,   {get(l, &Row::bytes)}, {get(l, &Row::psnr_tonemapped)}, palette(colour++), false,
             true};
    b.marker = Marker::kDiamond;
    b.marker_size = 5;
    c.series.push_back(std::move(b));
  }
  return c;
}

Figure polar_figure(const MaterialResult& m) {
  // Columns: each fitted model with polar curves (the primary copula setting first).
  std::vector<std::string> models;
  for (const PolarCurve& c : m.polar) {
    if (c.model != "measured" && std::find(models.begin(), models.end(), c.model) == models.end()) {
      models.push_back(c.model);
    }
  }
  auto curve = [&](const std::string& model, double ti) -> const PolarCurve* {
    for (const PolarCurve& c : m.polar) {
      if (c.model == model && c.theta_i_deg == ti) return &c;
    }
    return nullptr;
  };
  auto cube_root = [](const PolarCurve& c, const std::string& colour, bool dashed) {
    Series s{c.model, c.theta_o_deg, {}, colour, true, false, dashed, dashed ? 1.5 : 1.8};
    for (double v : c.value) s.y.push_back(std::cbrt(std::max(v, 0.0)));
    return s;
  };
  std::vector<PolarPanel> panels;
  for (double ti : kPolarThetaI) {
    for (std::size_t k = 0; k < models.size(); ++k) {
      PolarPanel p;
      char title[96];
      std::snprintf(title, sizeof title, "%s, theta_i %.0f", models[k].c_str(), ti);
      p.title = title;
      if (const PolarCurve* c = curve("measured", ti))
        p.series.push_back(cube_root(*c, "#000", true));
      if (const PolarCurve* c = curve(models[k], ti)) {
        p.series.push_back(cube_root(*c, palette(k), false));
      }
      panels.push_back(std::move(p));
    }
  }
  Figure f;
  f.material = m.name;
  f.file = "polar_" + file_stem(m.name) + ".svg";
  f.caption = m.name +
              ": BRDF in the plane of incidence (mean of R, G, B, cube root) at "
              "theta_i = 0, 45, 75 degrees; measured black dashed, fitted in colour, the mirror "
              "direction on the left: look for where a fitted curve leaves the measured one.";
  f.svg = render_polar_grid(m.name + " (cube root; measured dashed)", panels,
                            int(std::max<std::size_t>(models.size(), 1)));
  return f;
}

// The side-by-side codings: per coding, the mean over the materials of each one's best setting
// within a byte budget (frontier.h's compare_at_budget), as a line over the budgets.
Chart coding_chart(const std::vector<MaterialResult>& results, const Settings& st) {
  Chart c;
  c.title = "Frontier by coding, mean over materials";
  c.x_label = "byte budget (log)";
  c.y_label = "sphere PSNR, tone-mapped (dB)";
  c.log_x = true;
  c.width = 900;
  c.height = 520;
  const std::vector<std::vector<RdPoint>> fresh = coding_points(results, 0);
  for (std::size_t k = 0; k < st.codings.size(); ++k) {
    const std::vector<std::vector<RdPoint>> points = coding_points(results, k);
    Series line{
        "coding " + st.codings[k], {}, {}, k == 0 ? kFrontierColour : palette(k), true, true};
    line.width = k == 0 ? 2.5 : 1.5;
    line.dashed = k > 0;
    for (double budget : kCodingBudgets) {
      // Each coding's own mean at the budget (compare_at_budget's first argument's side).
      const CodingBudget b = compare_at_budget(points, fresh, budget);
      if (b.fresh_qualifying == 0) continue;
      line.x.push_back(budget);
      line.y.push_back(b.fresh_psnr);
      // Only where some materials have no setting within the budget.
      line.notes.push_back(b.fresh_qualifying < b.materials ? std::to_string(b.fresh_qualifying) +
                                                                  "/" + std::to_string(b.materials)
                                                            : std::string());
    }
    c.series.push_back(std::move(line));
  }
  return c;
}

}  // namespace

std::string file_stem(const std::string& name) {
  std::string out;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '-' || c == '_' || c == '.';
    out += ok ? c : '_';
  }
  return out.empty() ? "_" : out;
}

std::vector<Figure> report_figures(const std::vector<MaterialResult>& results, const Settings& st) {
  std::vector<Figure> figs;
  if (results.empty()) return figs;
  const std::vector<std::string> points = point_labels(results, st);
  const Getter mean = [&](const std::string& l, double Row::*f) { return mean_of(results, l, f); };

  const std::string frontier_caption =
      "up and left is better: look at how far the magenta frontier lies above the ring (the "
      "paper's setting) at or left of its bytes. A setting reads family, sN slices, bN bits per "
      "quantized value (bauto: chosen per file), kN copula components (none: one) and EN the "
      "residual layer's error bound.";
  figs.push_back(
      {kLeadFigure,
       "Sweep settings (dots) and baselines (diamonds), mean over the materials: " +
           frontier_caption,
       render_chart(frontier_chart(mean_sweep_points(results, st), mean_paper_point(results),
                                   points, mean, "Rate-distortion frontier, mean over materials")),
       ""});
  if (st.codings.size() > 1) {
    figs.push_back({"frontier_codings.svg",
                    "The same fits written in each coding (" + st.codings.front() +
                        ", solid; the others dashed): per byte budget, the mean over the "
                        "materials of each one's best setting within it (n/N: the materials that "
                        "have one). Up is better: the gap is what the coding gains.",
                    render_chart(coding_chart(results, st)), ""});
  }
  figs.push_back(
      {"time_psnr.svg",
       "What accuracy costs: mean encode time against mean tone-mapped PSNR; look for the "
       "settings that buy the most dB per second of encoding (the front of each family).",
       render_chart(cost_chart(st, points, mean, &Row::encode_s,
                               "Encode time vs PSNR, mean over materials", "encode seconds (log)")),
       ""});
  figs.push_back({"eval_psnr.svg",
                  "Mean evaluation time per RGB sample against mean tone-mapped PSNR: what a "
                  "renderer pays per shading call; look for points high up at the left.",
                  render_chart(cost_chart(st, points, mean, &Row::eval_ns,
                                          "Evaluation time vs PSNR, mean over materials",
                                          "ns per evaluation (log)")),
                  ""});

  // Figure 5: PSNR per material, sorted by the Ashikhmin-Shirley PSNR when it was fitted.
  std::vector<const MaterialResult*> order;
  for (const MaterialResult& m : results) order.push_back(&m);
  const std::string primary = st.sweep.primary().label();
  const std::string sort_by =
      find_row(results.front(), "ashikhmin-shirley") ? "ashikhmin-shirley" : primary;
  auto key = [&](const MaterialResult* m) {
    const Row* r = find_row(*m, sort_by);
    return r ? r->psnr_tonemapped : 0.0;
  };
  std::stable_sort(
      order.begin(), order.end(),
      [&](const MaterialResult* a, const MaterialResult* b) { return key(a) < key(b); });
  Chart fig5;
  fig5.title = "PSNR per material, sorted by " + sort_by;
  fig5.y_label = "sphere PSNR, tone-mapped (dB)";
  for (const MaterialResult* m : order) fig5.categories.push_back(m->name);
  std::vector<std::string> fig5_models = {"ashikhmin-shirley", "cook-torrance", "ward", "ggx-2lobe",
                                          primary};
  for (const std::string& l : compared_labels(results, st)) {
    if (!is_lossless(l) &&
        std::find(fig5_models.begin(), fig5_models.end(), l) == fig5_models.end()) {
      fig5_models.push_back(l);
    }
  }
  for (std::size_t k = 0; k < fig5_models.size(); ++k) {
    Series s{fig5_models[k], {}, {}, palette(k), true, true};
    for (std::size_t i = 0; i < order.size(); ++i) {
      if (const Row* r = find_row(*order[i], fig5_models[k])) {
        s.x.push_back(double(i));
        s.y.push_back(r->psnr_tonemapped);
      }
    }
    if (!s.x.empty()) fig5.series.push_back(std::move(s));
  }
  fig5.height = 520;
  figs.push_back({"psnr_by_material.svg",
                  "Tone-mapped sphere PSNR per material and model, materials sorted by the " +
                      sort_by +
                      " PSNR (the paper's Figure 5): look for the materials where a model falls "
                      "below the others.",
                  render_chart(fig5), ""});

  for (const MaterialResult& m : results) {
    const Getter one = [&](const std::string& l, double Row::*f) {
      const Row* r = find_row(m, l);
      return r ? r->*f : NAN;
    };
    const MaterialPoints mp = material_points(m);
    const RdPoint paper = mp.has_paper ? mp.paper : RdPoint{paper_setting().label(), NAN, NAN, NAN};
    figs.push_back({"frontier_" + file_stem(m.name) + ".svg", m.name + ": " + frontier_caption,
                    render_chart(frontier_chart(mp.sweep, paper, points, one,
                                                m.name + ": rate-distortion frontier")),
                    m.name});
    figs.push_back(polar_figure(m));
  }
  return figs;
}

}  // namespace cbrdf::report
