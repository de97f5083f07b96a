// SPDX-License-Identifier: MIT
#include "report/tables.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "cbrdf/analytic_fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "report/paper_tables.h"
#include "report/svg.h"

namespace cbrdf::report {
namespace {

std::string fmt(const char* format, double v) {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}
std::string db(double v) {
  return fmt("%.2f", v);
}
std::string signed_db(double v) {
  return fmt("%+.2f", v);
}
std::string bytes(double v) {
  return fmt("%.0f", v);
}
std::string secs(double v) {
  return fmt(v < 0.1 && v > -0.1 ? "%.4f" : "%.2f", v);
}
std::string nanos(double v) {
  return fmt("%.0f", v);
}

TextTable per_material_table(const std::vector<MaterialResult>& results,
                             const std::vector<std::string>& labels, double Row::*field,
                             std::string (*format)(double)) {
  TextTable t;
  t.header.push_back("material");
  for (const std::string& l : labels) t.header.push_back(l);
  for (const MaterialResult& m : results) {
    std::vector<std::string> row{m.name};
    for (const std::string& l : labels) {
      const Row* r = find_row(m, l);
      row.push_back(r ? format(r->*field) : "-");
    }
    t.rows.push_back(std::move(row));
  }
  std::vector<std::string> mean{"mean"};
  for (const std::string& l : labels) mean.push_back(format(mean_of(results, l, field)));
  t.rows.push_back(std::move(mean));
  return t;
}

std::vector<std::string> summary_row(const std::vector<MaterialResult>& results,
                                     const std::string& label) {
  return {label,
          bytes(mean_of(results, label, &Row::bytes)),
          fmt("%.0f:1",
              mean_of(results, label, &Row::input_bytes) / mean_of(results, label, &Row::bytes)),
          db(mean_of(results, label, &Row::psnr_linear)),
          db(mean_of(results, label, &Row::psnr_tonemapped)),
          fmt("%.4f", mean_of(results, label, &Row::rel_rmse)),
          fmt("%.4f", mean_of(results, label, &Row::log_rmse)),
          fmt("%.4g", mean_of(results, label, &Row::cos_rmse)),
          secs(mean_of(results, label, &Row::encode_s)),
          secs(mean_of(results, label, &Row::decode_s)),
          nanos(mean_of(results, label, &Row::eval_ns))};
}

const std::vector<std::string> kSummaryHeader = {"model",      "bytes",    "ratio",    "PSNR dB",
                                                 "PSNR tm dB", "rel RMSE", "log RMSE", "cos RMSE",
                                                 "encode s",   "decode s", "eval ns"};

std::vector<std::string> step_row(const std::vector<MaterialResult>& results,
                                  const std::string& from, const std::string& to) {
  auto d = [&](double Row::*f) { return mean_of(results, to, f) - mean_of(results, from, f); };
  const double gain = d(&Row::psnr_tonemapped);
  const double enc = d(&Row::encode_s);
  return {from + " -> " + to,
          signed_db(gain),
          signed_db(d(&Row::psnr_linear)),
          fmt("%+.0f", d(&Row::bytes)),
          fmt("%+.3f", enc),
          fmt("%+.4f", d(&Row::decode_s)),
          fmt("%+.0f", d(&Row::eval_ns)),
          gain > 0.01 ? fmt("%.3f", enc / gain) : "-"};
}

const std::vector<std::string> kStepHeader = {"step",          "dB tm",          "dB linear",
                                              "extra bytes",   "extra encode s", "extra decode s",
                                              "extra eval ns", "encode s per dB"};

std::string loss_name(AnalyticLoss loss) {
  return loss == AnalyticLoss::kLog ? "log(1 + f) L2 (as the log RMSE column)"
                                    : "cosine-weighted L2 (as the cos RMSE column)";
}

std::string times(double v) {
  return fmt("%.2fx", v);
}

// The setting chosen most often at a budget (ties: the first met in report order).
std::string most_chosen(const BudgetGain& b) {
  std::vector<std::pair<std::string, int>> counts;
  for (const MaterialGain& g : b.per_material) {
    if (!g.qualifying) continue;
    auto it = std::find_if(counts.begin(), counts.end(),
                           [&](const auto& c) { return c.first == g.best; });
    if (it == counts.end()) {
      counts.emplace_back(g.best, 1);
    } else {
      ++it->second;
    }
  }
  std::string best = "-";
  int n = 0;
  for (const auto& [label, c] : counts) {
    if (c > n) best = label, n = c;
  }
  return n ? best + " (" + std::to_string(n) + ")" : best;
}

// Per budget factor, the mean, min and max gain over the paper's setting and whether the target
// is met.
TextTable gain_table(const std::vector<BudgetGain>& gains, const std::string& paper) {
  TextTable g;
  g.id = "gain";
  g.title = "Gain over the paper's setting (" + paper + ") at 1x, 2x and 4x its bytes";
  g.nav = "Gain by budget";
  g.note =
      "Per material, the sweep setting with the highest tone-mapped sphere PSNR among those "
      "with at most 1x, 2x or 4x that material's bytes at the paper's setting (Frank, 6 uniform "
      "slices, one component, " +
      std::to_string(paper_setting().bits) +
      " bits); its PSNR minus the paper setting's, then the mean, min and max over the "
      "materials that have such a setting. The target is the mean gain cbrdf aims for: +2 dB at "
      "1x, "
      "+6 dB at 4x. "
      "Ratios are per material, then averaged; encode time includes the fit.";
  g.header = {
      "budget",    "materials", "mean gain dB",  "min gain dB",         "max gain dB",
      "target dB", "met",       "bytes / paper", "encode time / paper", "most chosen setting"};
  for (const BudgetGain& b : gains) {
    const double target = target_gain_db(b.factor);
    std::string met = "-";
    if (!std::isnan(target)) {
      met = b.qualifying == 0 ? "no (no setting)" : (b.mean_gain_db >= target ? "yes" : "no");
    }
    g.rows.push_back({fmt("%gx", b.factor),
                      std::to_string(b.qualifying) + "/" + std::to_string(b.materials),
                      signed_db(b.mean_gain_db), signed_db(b.min_gain_db), signed_db(b.max_gain_db),
                      signed_db(target), met, times(b.mean_bytes_ratio), times(b.mean_encode_ratio),
                      most_chosen(b)});
  }
  return g;
}

// Per material, the paper's setting and the gain and chosen setting at each budget factor.
TextTable gain_material_table(const std::vector<MaterialResult>& results,
                              const std::vector<BudgetGain>& gains) {
  TextTable pm;
  pm.id = "gain-material";
  pm.title = "Gain over the paper's setting per material";
  pm.nav = "Gain per material";
  pm.note =
      "The paper's setting's bytes and PSNR, then per budget the gain (dB) and the setting "
      "that gives it ('-': no sweep setting within the budget).";
  pm.header = {"material", "paper bytes", "paper PSNR tm dB"};
  for (const BudgetGain& b : gains) {
    pm.header.push_back(fmt("%gx gain dB", b.factor));
    pm.header.push_back(fmt("%gx setting", b.factor));
  }
  for (std::size_t i = 0; i < results.size(); ++i) {
    const MaterialGain& first = gains.front().per_material[i];
    std::vector<std::string> row{results[i].name, first.has_paper ? bytes(first.paper_bytes) : "-",
                                 first.has_paper ? db(first.paper_psnr) : "-"};
    for (const BudgetGain& b : gains) {
      const MaterialGain& m = b.per_material[i];
      row.push_back(m.qualifying ? signed_db(m.gain_db) : "-");
      row.push_back(m.qualifying ? m.best : "-");
    }
    pm.rows.push_back(std::move(row));
  }
  return pm;
}

// The sweep's Pareto frontier of mean bytes against mean PSNR, then the paper's setting.
TextTable frontier_settings_table(const std::vector<MaterialResult>& results, const Settings& st,
                                  const std::string& paper) {
  TextTable mf;
  mf.id = "frontier";
  mf.title = "Frontier settings: the sweep's settings no other beats, means over the materials";
  mf.nav = "Frontier settings";
  mf.note =
      "Each sweep setting's bytes and tone-mapped PSNR averaged over the materials; the "
      "settings no other has both fewer bytes and a higher PSNR than (the Pareto frontier: "
      "frontier_mean.svg; per material in frontier.csv and frontier_MATERIAL.svg). Gains and "
      "ratios against the paper's setting's means.";
  mf.header = {"setting", "bytes", "PSNR tm dB", "gain dB", "bytes / paper", "encode time / paper"};
  const std::vector<RdPoint> mean = mean_sweep_points(results, st);
  const RdPoint p = mean_paper_point(results);
  for (std::size_t i : pareto_frontier(mean)) {
    const RdPoint& q = mean[i];
    mf.rows.push_back({q.label, bytes(q.bytes), db(q.psnr), signed_db(q.psnr - p.psnr),
                       times(q.bytes / p.bytes), times(q.encode_s / p.encode_s)});
  }
  mf.rows.push_back(
      {paper + " (paper)", bytes(p.bytes), db(p.psnr), signed_db(0.0), times(1.0), times(1.0)});
  return mf;
}

// Whether any material's gain at any budget prints as other than +0.00.
bool any_printed_gain(const std::vector<BudgetGain>& gains) {
  bool any_gain = false;
  for (const BudgetGain& b : gains) {
    for (const MaterialGain& m : b.per_material)
      any_gain |= m.qualifying && signed_db(m.gain_db) != "+0.00";
  }
  return any_gain;
}

std::vector<TextTable> frontier_tables(const std::vector<MaterialResult>& results,
                                       const Settings& st) {
  const std::vector<MaterialPoints> points = material_points(results);
  std::vector<BudgetGain> gains;
  for (double f : kBudgetFactors) gains.push_back(budget_gain(points, f));
  const std::string paper = paper_setting().label();
  // With only the paper's setting in the sweep there is nothing to compare: no frontier tables.
  if (st.sweep.only_paper_setting()) return {};
  TextTable mf = frontier_settings_table(results, st, paper);
  // Gain tables whose every entry would print as +0.00 say nothing: leave them out.
  if (!any_printed_gain(gains)) return {mf};
  return {gain_table(gains, paper), mf, gain_material_table(results, gains)};
}

}  // namespace

std::string format_value(const char* format, double v, const char* non_finite) {
  if (!std::isfinite(v)) return non_finite;
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

const Row* find_row(const MaterialResult& m, const std::string& label) {
  for (const Row& r : m.rows) {
    if (r.label() == label) return &r;
  }
  return nullptr;
}

double mean_of(const std::vector<MaterialResult>& results, const std::string& label,
               double Row::*field) {
  double sum = 0;
  int n = 0;
  for (const MaterialResult& m : results) {
    if (const Row* r = find_row(m, label)) {
      sum += r->*field;
      ++n;
    }
  }
  return n ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

MaterialPoints material_points(const MaterialResult& m) {
  MaterialPoints p;
  p.material = m.name;
  for (const Row& r : m.rows) {
    if (r.kind != std::string(kKindCopula)) continue;
    const RdPoint point{r.label(), r.bytes, r.psnr_tonemapped, r.encode_s};
    if (r.in_sweep) p.sweep.push_back(point);
    if (r.paper) {
      p.has_paper = true;
      p.paper = point;
    }
  }
  return p;
}

std::vector<std::vector<RdPoint>> coding_points(const std::vector<MaterialResult>& results,
                                                std::size_t coding) {
  std::vector<std::vector<RdPoint>> out;
  for (const MaterialResult& m : results) {
    std::vector<RdPoint> points;
    for (const Row& r : m.rows) {
      if (r.kind != std::string(kKindCopula) || !(r.in_sweep || r.paper)) continue;
      if (r.codings.size() <= coding) continue;
      const CodingResult& c = r.codings[coding];
      RdPoint p{r.label(), c.bytes, c.psnr_tonemapped, c.encode_s};
      p.psnr_linear = c.psnr_linear;
      points.push_back(std::move(p));
    }
    out.push_back(std::move(points));
  }
  return out;
}

std::vector<MaterialPoints> material_points(const std::vector<MaterialResult>& results) {
  std::vector<MaterialPoints> out;
  for (const MaterialResult& m : results) out.push_back(material_points(m));
  return out;
}

std::vector<RdPoint> mean_sweep_points(const std::vector<MaterialResult>& results,
                                       const Settings& st) {
  std::vector<RdPoint> out;
  for (const std::string& l : sweep_labels(st)) {
    out.push_back({l, mean_of(results, l, &Row::bytes), mean_of(results, l, &Row::psnr_tonemapped),
                   mean_of(results, l, &Row::encode_s)});
  }
  return out;
}

RdPoint mean_paper_point(const std::vector<MaterialResult>& results) {
  const std::string l = paper_setting().label();
  return {l, mean_of(results, l, &Row::bytes), mean_of(results, l, &Row::psnr_tonemapped),
          mean_of(results, l, &Row::encode_s)};
}

std::vector<std::string> sweep_labels(const Settings& st) {
  std::vector<std::string> out;
  for (const CodecSetting& s : st.sweep.settings()) out.push_back(s.label());
  return out;
}

std::vector<std::string> compared_labels(const std::vector<MaterialResult>& results,
                                         const Settings& st) {
  std::vector<std::string> out;
  if (results.empty()) return out;
  const CodecSetting p = st.sweep.primary();
  out.push_back(p.label());
  if (paper_setting().label() != p.label()) out.push_back(paper_setting().label());
  for (const Row& r : results.front().rows) {
    const bool copula_at_primary = r.kind == std::string(kKindCopula) && r.slices == p.slices &&
                                   r.bits == p.bits && r.components == p.components;
    if (r.kind != std::string(kKindCopula) || copula_at_primary) {
      if (std::find(out.begin(), out.end(), r.label()) == out.end()) out.push_back(r.label());
    }
  }
  return out;
}

namespace {

// Tables 1, 1b and 2: tone-mapped and linear PSNR of the lossy models, and the bytes of every
// compared model, per material.
void add_per_material_tables(const std::vector<MaterialResult>& results,
                             const std::vector<std::string>& lossy,
                             const std::vector<std::string>& compared, const Settings& st,
                             std::vector<TextTable>* tables) {
  TextTable t1 = per_material_table(results, lossy, &Row::psnr_tonemapped, db);
  t1.id = "psnr";
  t1.title = "Table 1: sphere PSNR per material and model (tone-mapped, dB)";
  t1.nav = "PSNR";
  t1.note =
      "As the paper's Table 1 and Figure 5: each model decoded to a full table and rendered on "
      "256x256 spheres lit at 10, 45 and 75 degrees, against the input; PSNR over sphere pixels "
      "after tone mapping with the input's exposure, mean over lights and channels (capped at " +
      db(kPsnrCapDb) +
      " dB). Copula columns are 'family sSLICES bBITS'. Lossless baselines are "
      "bit-exact and not listed.";
  tables->push_back(std::move(t1));

  TextTable t1b = per_material_table(results, lossy, &Row::psnr_linear, db);
  t1b.id = "psnr-linear";
  t1b.title = "Table 1b: sphere PSNR per material and model (linear radiance, dB)";
  t1b.nav = "Linear PSNR";
  t1b.note =
      "The same renders without tone mapping; the peak is the input image's maximum per "
      "channel, so highlights dominate.";
  tables->push_back(std::move(t1b));

  TextTable t2 = per_material_table(results, compared, &Row::bytes, bytes);
  t2.id = "storage";
  t2.title = "Table 2: storage per material and model (bytes)";
  t2.nav = "Storage";
  t2.note =
      "Copula: the .cbrdf container (marginals quantized to BITS bits, zstd level 19). "
      "Analytic models: 8 bytes per double parameter. float16: IEEE half physical values, "
      "zstd level " +
      std::to_string(st.float16_zstd_level) + ". Lossless: zstd level " +
      std::to_string(st.lossless_zstd_level) + " and xz preset " + std::to_string(st.xz_preset) +
      " of the .binary file (34,992,012 bytes).";
  tables->push_back(std::move(t2));
}

// Mean and largest over the materials of a per-material value (NaN where it is not finite).
struct MeanMax {
  double mean = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};
template <typename F>
MeanMax mean_max(const std::vector<MaterialResult>& results, F value) {
  double sum = 0;
  int n = 0;
  MeanMax out;
  for (const MaterialResult& m : results) {
    const double v = value(m);
    if (!std::isfinite(v)) continue;
    sum += v;
    ++n;
    out.max = n == 1 ? v : std::max(out.max, v);
  }
  if (n) out.mean = sum / n;
  return out;
}

std::string ratio_cell(const MeanMax& r) {
  if (!std::isfinite(r.mean)) return "-";
  return fmt("%.2fx", r.mean) + " (max " + fmt("%.2fx", r.max) + ")";
}

// The render columns of Table 3 for a row label: its render time, and its time over the measured
// table's (nearest-bin, trilinear) per material.
std::vector<std::string> render_cells(const std::vector<MaterialResult>& results,
                                      const std::string& label) {
  const auto ratio_to = [&](double MaterialResult::*table_s) {
    return ratio_cell(mean_max(results, [&](const MaterialResult& m) {
      const Row* r = find_row(m, label);
      return r ? r->render_s / (m.*table_s) : std::numeric_limits<double>::quiet_NaN();
    }));
  };
  return {secs(mean_of(results, label, &Row::render_s)),
          ratio_to(&MaterialResult::render_nearest_s),
          ratio_to(&MaterialResult::render_trilinear_s)};
}

// Table 3's rows for the measured table itself, looked up at the nearest bin and trilinearly.
std::vector<std::string> table_row(const std::vector<MaterialResult>& results, bool trilinear) {
  const auto field =
      trilinear ? &MaterialResult::render_trilinear_s : &MaterialResult::render_nearest_s;
  const auto eval =
      trilinear ? &MaterialResult::trilinear_eval_ns : &MaterialResult::nearest_eval_ns;
  const auto of = [](double MaterialResult::*f) {
    return [f](const MaterialResult& m) { return m.*f; };
  };
  const MeanMax own =
      mean_max(results, [&](const MaterialResult& m) { return (m.*field) / m.render_nearest_s; });
  const MeanMax tri =
      mean_max(results, [&](const MaterialResult& m) { return (m.*field) / m.render_trilinear_s; });
  std::vector<std::string> row = {
      trilinear ? "measured table, trilinear lookup" : "measured table, nearest-bin lookup",
      bytes(double(kMerlFileBytes)),
      "1:1",
      "-",
      "-",
      "0",
      "0",
      "0",
      "-",
      "-",
      nanos(mean_max(results, of(eval)).mean),
      secs(mean_max(results, of(field)).mean),
      ratio_cell(own),
      ratio_cell(tri)};
  return row;
}

// Table 3: means over the materials per compared model, with rendering times.
TextTable time_table(const std::vector<MaterialResult>& results,
                     const std::vector<std::string>& compared, const Settings& st) {
  TextTable t3;
  t3.id = "time";
  t3.title = "Table 3: means over the materials per model: size, error and time";
  t3.nav = "Size, error, time";
  t3.note =
      "encode: fit + quantization + container (copula), compression (lossless, float16) "
      "or the Ceres fit (analytic: " +
      loss_name(st.analytic_loss) + " on " + std::to_string(st.analytic_bins) +
      " bins, theta_i and theta_o up to 80 degrees). "
      "decode: bytes or parameters to a full 90x90x180 table. eval: one RGB value at a "
      "random direction pair (copula: the library's evaluator; analytic: closed form; "
      "tables: nearest-bin lookup). Run with --jobs " +
      std::to_string(st.jobs) + ".";
  t3.header = kSummaryHeader;
  const bool rendered = !results.empty() && std::isfinite(results.front().render_nearest_s);
  if (rendered) {
    const MaterialResult& r0 = results.front();
    t3.note += " render: the paper's Figure 4 layout (six spheres under one directional light, " +
               std::to_string(r0.render_width) + "x" + std::to_string(r0.render_height) +
               " pixels, one sample per pixel) with every sphere in the material, rendered on "
               "one thread from the model (the primary and the paper's settings) or from the "
               "measured table (lossless rows: nearest-bin); best of two renders. The ratios "
               "are the model's time over the table's, per material, then the mean (and the "
               "largest); cbrdf aims for at most 1.00x, the paper's Table 3 reports 1.06x. "
               "Trilinear lookup: the 8 surrounding bins, not-measured ones skipped.";
    for (const char* h : {"render s", "render / nearest table", "render / trilinear table"}) {
      t3.header.push_back(h);
    }
  }
  for (const std::string& l : compared) {
    std::vector<std::string> row = summary_row(results, l);
    if (rendered) {
      for (std::string& c : render_cells(results, l)) row.push_back(std::move(c));
    }
    t3.rows.push_back(std::move(row));
  }
  if (rendered) {
    t3.rows.push_back(table_row(results, false));
    t3.rows.push_back(table_row(results, true));
  }
  return t3;
}

// Table 4: every setting of the sweep, means over the materials.
TextTable sweep_table(const std::vector<MaterialResult>& results,
                      const std::vector<std::string>& sweep) {
  TextTable t4;
  t4.id = "sweep";
  t4.title = "Table 4: the sweep, means over the materials";
  t4.nav = "Sweep";
  t4.note = "Every combination of the --sweep axes.";
  t4.header = kSummaryHeader;
  t4.header[0] = "setting";
  for (const std::string& l : sweep) t4.rows.push_back(summary_row(results, l));
  return t4;
}

// Table 5: what accuracy costs in time, along each swept axis (the other axes at the primary
// setting), then along the lossy models ordered by tone-mapped PSNR.
TextTable cost_table(const std::vector<MaterialResult>& results,
                     const std::vector<std::string>& lossy, const Settings& st) {
  TextTable t5;
  t5.id = "cost";
  t5.title = "Table 5: what accuracy costs in time";
  t5.nav = "Cost of accuracy";
  t5.note = "Each step up in one setting (the others at the primary setting " +
            st.sweep.primary().label() +
            "), then every compared model ordered by tone-mapped PSNR: the mean dB gained "
            "against the extra bytes and the extra encode, decode and evaluation time.";
  t5.header = kStepHeader;
  const CodecSetting p = st.sweep.primary();
  auto axis_steps = [&](std::vector<CodecSetting> chain) {
    for (std::size_t i = 1; i < chain.size(); ++i) {
      t5.rows.push_back(step_row(results, chain[i - 1].label(), chain[i].label()));
    }
  };
  {
    std::vector<int> v = st.sweep.slices;
    std::sort(v.begin(), v.end());
    std::vector<CodecSetting> chain;
    for (int s : v) chain.push_back({p.family, s, p.bits, p.components});
    axis_steps(chain);
  }
  {
    std::vector<int> v = st.sweep.bits;
    std::sort(v.begin(), v.end());
    std::vector<CodecSetting> chain;
    for (int b : v) chain.push_back({p.family, p.slices, b, p.components});
    axis_steps(chain);
  }
  {
    std::vector<CodecSetting> chain;
    for (const std::string& f : st.sweep.families) {
      chain.push_back({f, p.slices, p.bits, p.components});
    }
    axis_steps(chain);
  }
  {
    std::vector<CodecSetting> chain;
    for (int k : st.sweep.components) chain.push_back({p.family, p.slices, p.bits, k});
    axis_steps(chain);
  }
  std::vector<std::string> ladder = lossy;
  std::sort(ladder.begin(), ladder.end(), [&](const std::string& a, const std::string& b) {
    return mean_of(results, a, &Row::psnr_tonemapped) < mean_of(results, b, &Row::psnr_tonemapped);
  });
  for (std::size_t i = 1; i < ladder.size(); ++i) {
    t5.rows.push_back(step_row(results, ladder[i - 1], ladder[i]));
  }
  return t5;
}

// The fitted analytic models' parameters, per material.
TextTable analytic_table(const std::vector<MaterialResult>& results) {
  TextTable t6;
  t6.id = "analytic";
  t6.title = "Fitted analytic parameters";
  t6.nav = "Analytic fits";
  t6.note =
      "Lobe colours are per channel (Lambertian albedo, GGX F0, Ward rho_s, "
      "Ashikhmin-Shirley Rs); shape is the roughness alpha or the exponent n.";
  t6.header = {"material", "model", "parameters"};
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) {
      if (r.kind == std::string(kKindAnalytic)) t6.rows.push_back({m.name, r.model, r.detail});
    }
  }
  return t6;
}

// The "met" cell of a coding budget row: "yes", or "no:" and the targets missed.
std::string coding_met(const CodingBudget& b, double budget, const std::string& old) {
  std::vector<std::string> misses;
  if (b.fresh_qualifying == 0) misses.push_back("no setting");
  if (b.paired > 0 && b.gain_db < kCodingTargetGainDb) misses.push_back("gain");
  if (b.paired > 0 && b.linear_gain_db < -kCodingMaxLinearLossDb) misses.push_back("linear");
  if (budget == kCodingBudgets[0] && !(b.fresh_psnr >= kCodingOneKbTargetDb)) {
    misses.push_back(format_value("%.0f dB at 1 KB", kCodingOneKbTargetDb));
  }
  std::string met = b.paired == 0 ? "yes (" + old + ": no setting)" : "yes";
  if (!misses.empty()) {
    met = "no:";
    for (const std::string& m : misses) met += " " + m;
  }
  return met;
}

// The further coding `c` (named `old`) against the first (`fresh`) at each byte budget.
TextTable coding_frontier_table(const std::vector<std::vector<RdPoint>>& fresh_points,
                                const std::vector<std::vector<RdPoint>>& old_points,
                                const std::string& fresh, const std::string& old, std::size_t c) {
  TextTable t;
  t.id = "coding-frontier";
  if (c > 1) t.id += "-" + std::to_string(c);
  t.title = "Codings compared: " + fresh + " against " + old + " at byte budgets";
  t.nav = "Codings by budget" + (c > 1 ? " (" + old + ")" : std::string());
  char note[1024];
  std::snprintf(
      note, sizeof note,
      "The same fits written in both codings. Per material, the sweep or paper setting with "
      "the highest tone-mapped sphere PSNR within the budget in each coding, then means over "
      "the materials that have one ('n'). Gains are %s minus %s over the materials where both "
      "have one (mean, and the smallest). What the %s coding aims for: a gain of at least %+.1f "
      "dB "
      "tone-mapped at every budget, linear PSNR at most %.1f dB lower, and at least %.0f dB at "
      "1 KB; a budget where %s has no setting counts as met when %s has one.",
      fresh.c_str(), old.c_str(), fresh.c_str(), kCodingTargetGainDb, kCodingMaxLinearLossDb,
      kCodingOneKbTargetDb, old.c_str(), fresh.c_str());
  t.note = note;
  t.header = {"budget",         fresh + " n",        fresh + " PSNR tm dB", fresh + " PSNR dB",
              old + " n",       old + " PSNR tm dB", old + " PSNR dB",      "gain tm dB",
              "min gain tm dB", "gain linear dB",    "min gain linear dB",  "met"};
  for (double budget : kCodingBudgets) {
    const CodingBudget b = compare_at_budget(fresh_points, old_points, budget);
    t.rows.push_back(
        {fmt("%.1f KB", budget / 1000),
         std::to_string(b.fresh_qualifying) + "/" + std::to_string(b.materials), db(b.fresh_psnr),
         db(b.fresh_linear), std::to_string(b.old_qualifying) + "/" + std::to_string(b.materials),
         db(b.old_psnr), db(b.old_linear), signed_db(b.gain_db), signed_db(b.min_gain_db),
         signed_db(b.linear_gain_db), signed_db(b.min_linear_gain_db), coding_met(b, budget, old)});
  }
  return t;
}

// Every setting written in coding `c`, in the order first met, its means in both codings.
TextTable coding_settings_table(const std::vector<MaterialResult>& results,
                                const std::string& fresh, const std::string& old, std::size_t c) {
  TextTable s;
  s.id = "coding-settings";
  if (c > 1) s.id += "-" + std::to_string(c);
  s.title = "Settings by coding: " + fresh + " and " + old + ", means over the materials";
  s.nav = "Codings per setting" + (c > 1 ? " (" + old + ")" : std::string());
  s.note =
      "Each setting's mean bytes, sphere PSNRs and encode time (fit included) written in both "
      "codings from the same fit; ratios are of the means. The bauto setting is `cbrdf "
      "encode`'s default.";
  s.header = {"setting",           fresh + " bytes",  old + " bytes",  "bytes ratio",
              fresh + " PSNR tm",  old + " PSNR tm",  fresh + " PSNR", old + " PSNR",
              fresh + " encode s", old + " encode s", "encode ratio"};
  std::vector<std::string> labels;
  for (const MaterialResult& m : results) {
    for (const Row& r : m.rows) {
      if (r.codings.size() > c &&
          std::find(labels.begin(), labels.end(), r.label()) == labels.end()) {
        labels.push_back(r.label());
      }
    }
  }
  for (const std::string& l : labels) {
    double sum[4][2] = {};  // bytes, tm, linear, encode; [fresh, old]
    int n = 0;
    for (const MaterialResult& m : results) {
      const Row* r = find_row(m, l);
      if (!r || r->codings.size() <= c) continue;
      const CodingResult* pair[2] = {&r->codings.front(), &r->codings[c]};
      for (int k = 0; k < 2; ++k) {
        sum[0][k] += pair[k]->bytes;
        sum[1][k] += pair[k]->psnr_tonemapped;
        sum[2][k] += pair[k]->psnr_linear;
        sum[3][k] += pair[k]->encode_s;
      }
      ++n;
    }
    if (n == 0) continue;
    s.rows.push_back({l, bytes(sum[0][0] / n), bytes(sum[0][1] / n),
                      fmt("%.3f", sum[0][0] / sum[0][1]), fmt("%.3f", sum[1][0] / n),
                      fmt("%.3f", sum[1][1] / n), fmt("%.3f", sum[2][0] / n),
                      fmt("%.3f", sum[2][1] / n), secs(sum[3][0] / n), secs(sum[3][1] / n),
                      fmt("%.2fx", sum[3][0] / sum[3][1])});
  }
  return s;
}

// The side-by-side codings (Settings::codings): per further coding, the frontier at byte budgets
// against the rows' coding, and every sweep setting's means in both.
std::vector<TextTable> coding_tables(const std::vector<MaterialResult>& results,
                                     const Settings& st) {
  std::vector<TextTable> out;
  if (st.codings.size() < 2) return out;
  const std::string fresh = st.codings.front();
  const std::vector<std::vector<RdPoint>> fresh_points = coding_points(results, 0);
  for (std::size_t c = 1; c < st.codings.size(); ++c) {
    const std::string old = st.codings[c];
    out.push_back(coding_frontier_table(fresh_points, coding_points(results, c), fresh, old, c));
    out.push_back(coding_settings_table(results, fresh, old, c));
  }
  return out;
}

}  // namespace

std::vector<TextTable> report_tables(const std::vector<MaterialResult>& results,
                                     const Settings& st) {
  std::vector<TextTable> tables = frontier_tables(results, st);
  for (TextTable& t : coding_tables(results, st)) tables.push_back(std::move(t));
  for (TextTable& t : paper_tables(results)) tables.push_back(std::move(t));
  const std::vector<std::string> compared = compared_labels(results, st);
  std::vector<std::string> lossy;
  for (const std::string& l : compared) {
    if (l.rfind("zstd-", 0) != 0 && l.rfind("xz-", 0) != 0) lossy.push_back(l);
  }
  add_per_material_tables(results, lossy, compared, st, &tables);
  tables.push_back(time_table(results, compared, st));
  const std::vector<std::string> sweep = sweep_labels(st);
  if (sweep.size() > 1) tables.push_back(sweep_table(results, sweep));
  tables.push_back(cost_table(results, lossy, st));
  if (st.baselines.analytic) tables.push_back(analytic_table(results));
  return tables;
}

std::string to_markdown(const TextTable& t) {
  std::ostringstream out;
  out << "## " << t.title << "\n\n";
  if (!t.note.empty()) out << t.note << "\n\n";
  out << "|";
  for (const std::string& h : t.header) out << " " << h << " |";
  out << "\n|";
  for (std::size_t i = 0; i < t.header.size(); ++i) out << (i == 0 ? "---|" : "---:|");
  out << "\n";
  for (const auto& row : t.rows) {
    out << "|";
    for (const std::string& c : row) out << " " << c << " |";
    out << "\n";
  }
  out << "\n";
  return out.str();
}

std::string to_html(const TextTable& t) {
  std::ostringstream out;
  out << "<h2 id=\"" << t.id << "\">" << xml_escape(t.title) << "</h2>\n";
  if (!t.note.empty()) out << "<p class=\"note\">" << xml_escape(t.note) << "</p>\n";
  out << "<div class=\"scroll\"><table>\n<tr>";
  for (const std::string& h : t.header) out << "<th>" << xml_escape(h) << "</th>";
  out << "</tr>\n";
  for (const auto& row : t.rows) {
    out << "<tr>";
    for (std::size_t i = 0; i < row.size(); ++i) {
      // Names (the first column, setting labels) read from the left, numbers from the right.
      const bool text =
          i == 0 || (!row[i].empty() && std::isalpha(static_cast<unsigned char>(row[i][0])));
      out << (text ? "<td class=\"l\">" : "<td>") << xml_escape(row[i]) << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</table></div>\n";
  return out.str();
}

std::string to_text(const TextTable& t) {
  std::vector<std::size_t> width(t.header.size(), 0);
  auto widen = [&](const std::vector<std::string>& row) {
    for (std::size_t i = 0; i < row.size() && i < width.size(); ++i) {
      width[i] = std::max(width[i], row[i].size());
    }
  };
  widen(t.header);
  for (const auto& row : t.rows) widen(row);
  std::ostringstream out;
  out << t.title << "\n";
  auto line = [&](const std::vector<std::string>& row) {
    for (std::size_t i = 0; i < row.size() && i < width.size(); ++i) {
      const std::string pad(width[i] - row[i].size(), ' ');
      out << (i == 0 ? row[i] + pad : "  " + pad + row[i]);
    }
    out << "\n";
  };
  line(t.header);
  for (const auto& row : t.rows) line(row);
  return out.str();
}

}  // namespace cbrdf::report
