// SPDX-License-Identifier: MIT
// `cbrdf report`: storage against PSNR and time, per material and setting, with baselines.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "cbrdf/fit.h"
#include "cbrdf/parallel.h"
#include "cbrdf/samples.h"
#include "cbrdf/sampling.h"
#include "cli.h"
#include "cli_io.h"
#include "files/file_io.h"
#include "report/ladder_check.h"
#include "report/ladder_output.h"
#include "report/measure.h"
#include "report/sampling_study.h"
#include "report/summary.h"
#include "report/sweep.h"
#include "report/tables.h"
#include "report/write.h"

namespace cbrdf::cli {
namespace {

struct ReportOptions {
  std::vector<std::string> inputs;
  // --builtin KIND: measured (bare --builtin), analytic or all; empty when not given.
  std::string builtin;
  std::string output_dir;
  int jobs = 0;
  std::vector<std::string> sweep;
  std::string baselines = "separable,float16,analytic";
  std::string analytic_loss = "cos";
  int analytic_bins = 20000;
  bool quiet = false;  // also accepted after the subcommand, where users type it
  std::string progress = "auto";
  bool ladder = false;    // issue 18's ladder: base, residual, lossless and baselines
  std::string truth_dir;  // noise-free tables of noisy inputs (issue 30)
  std::string format_version = "auto";
  bool sampling = false;  // the importance-sampling study instead of storage against PSNR
  int draws = 200000;
  double min_table_gain = SamplerSettings{}.min_table_gain;
};

// Whether a built-in sample belongs to `--builtin kind`.
bool builtin_wanted(const SampleInfo& s, const std::string& kind) {
  return kind == "all" || (kind == "measured") == (s.kind == SampleKind::kMeasured);
}

// Why the inputs and the output directory cannot be used together, if they cannot.
std::optional<std::string> path_problem(const ReportOptions& o) {
  std::vector<PathArg> inputs;
  for (const std::string& f : o.inputs) inputs.push_back({"input", f});
  if (auto bad = check_paths("report", inputs, {{"-o", o.output_dir}}, false)) return bad;
  // The report writes only these kinds of file into its directory: an input there with such a
  // name would be overwritten.
  std::error_code ec;
  for (const std::string& f : o.inputs) {
    const std::filesystem::path p(f);
    const std::string ext = p.extension().string();
    const bool report_kind = ext == ".html" || ext == ".md" || ext == ".csv" || ext == ".json" ||
                             ext == ".svg" || ext == ".png";
    const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : ".";
    if (report_kind && !o.output_dir.empty() &&
        std::filesystem::equivalent(dir, o.output_dir, ec)) {
      return "report: the input " + f + " is in the output directory " + o.output_dir +
             ", where the report would overwrite it";
    }
  }
  return std::nullopt;
}

// --format-version: a comma-separated list of distinct codings, the rows' own first, then those
// measured beside.
Expected<std::vector<std::string>> parse_codings(const std::string& list) {
  std::vector<std::string> codings;
  std::string item;
  for (std::size_t i = 0; i <= list.size(); ++i) {
    if (i < list.size() && list[i] != ',') {
      item += list[i];
      continue;
    }
    if (item != "auto" && item != "1.2" && item != "1.3") {
      return error(ErrorCode::kInvalidArgument,
                   "--format-version takes auto, 1.2 or 1.3, or a list of them such as "
                   "auto,1.2; not '" +
                       item + "' in '" + list + "'");
    }
    if (std::find(codings.begin(), codings.end(), item) != codings.end()) {
      return error(ErrorCode::kInvalidArgument,
                   "--format-version names " + item + " twice in '" + list + "'");
    }
    codings.push_back(item);
    item.clear();
  }
  return codings;
}

// The built-in samples asked for, then the input files.
std::vector<report::Material> report_materials(const ReportOptions& o) {
  std::vector<report::Material> materials;
  std::set<std::string> names;
  auto add = [&](std::string name, const std::string& path, bool builtin) {
    // Output files are named after materials: keep the names distinct.
    const std::string stem = name;
    for (int k = 2; names.count(name); ++k) name = stem + "-" + std::to_string(k);
    names.insert(name);
    materials.push_back({name, path, builtin});
  };
  if (!o.builtin.empty()) {
    for (const SampleInfo& s : sample_materials()) {
      if (builtin_wanted(s, o.builtin)) add(std::string(s.name), "", true);
    }
  }
  for (const std::string& f : o.inputs) add(std::filesystem::path(f).stem().string(), f, false);
  return materials;
}

// The terminal's share of the report: the main tables, the summary and the answer.
void print_report(const std::vector<report::MaterialResult>& results, const ReportOptions& o,
                  const report::Settings& st, double elapsed) {
  for (const report::TextTable& t : report::report_tables(results, st)) {
    if (t.id == "time" || t.id == "psnr" || t.id == "sweep" || t.id == "gain" ||
        t.id == "paper-psnr" || t.id == "paper-storage" || t.id.starts_with("coding-")) {
      std::printf("%s\n", report::to_text(t).c_str());
    }
  }
  std::printf("%s\n", report::run_summary(results, st, elapsed).c_str());
  if (o.ladder) std::printf("%s", report::ladder_check_text(report::ladders_of(results)).c_str());
  if (!o.output_dir.empty()) {
    std::printf(
        "Wrote report.md, report.csv, report.json, frontier.csv, SVG figures and sphere PNGs "
        "beside report.html.\n");
  }
  // Last, so that it is what a terminal shows: the answer and where the full report is.
  const std::string html =
      o.output_dir.empty() ? "" : (std::filesystem::path(o.output_dir) / "report.html").string();
  std::printf("\n%s", report::closing_summary(results, st, html).c_str());
}

// `--sampling`: the importance-sampling study of each material, printed and, with -o, written as
// sampling.md and sampling.csv.
int run_sampling(const ReportOptions& o, const Context& ctx) {
  report::SamplingStudySettings st;
  st.draws = o.draws;
  st.sampler.min_table_gain = o.min_table_gain;
  std::vector<report::SamplingRow> rows;
  for (const report::Material& m : report_materials(o)) {
    if (!ctx.quiet) std::fprintf(stderr, "sampling %s\n", m.name.c_str());
    auto study = report::study_material(m, st);
    if (!study.ok()) return fail(study.status());
    rows.insert(rows.end(), study->begin(), study->end());
  }
  const report::TextTable table = report::sampling_table(rows);
  const std::string summary = report::sampling_summary(rows);
  if (!o.output_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.output_dir, ec);
    const std::filesystem::path dir(o.output_dir);
    const std::string md = report::to_markdown(table) + "\n" + summary;
    const std::string csv = report::sampling_csv(rows);
    for (const auto& [name, text] :
         {std::pair{"sampling.md", &md}, std::pair{"sampling.csv", &csv}}) {
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(text->data());
      if (Status s = write_file_atomic(dir / name, {bytes, text->size()}); !s.ok()) return fail(s);
    }
  }
  if (!ctx.quiet) std::printf("%s\n%s", report::to_text(table).c_str(), summary.c_str());
  return kExitOk;
}

int run_report(ReportOptions o, const Context& global) {
  Context ctx = global;
  ctx.quiet = ctx.quiet || o.quiet;
  if (!o.builtin.empty() && o.builtin != "measured" && o.builtin != "analytic" &&
      o.builtin != "all") {
    // `--builtin FILE`, as before --builtin took a value: the file is an input.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(o.builtin, ec)) {
      return usage_error("report: --builtin takes measured (the default), analytic or all, not '" +
                         o.builtin + "'");
    }
    o.inputs.insert(o.inputs.begin(), o.builtin);
    o.builtin = "measured";
  }
  if (o.inputs.empty() && o.builtin.empty()) {
    return usage_error("report: give MERL .binary files, --builtin, or both");
  }
  if (auto bad = path_problem(o)) return usage_error(*bad);
  if (o.sampling) return run_sampling(o, ctx);
  auto sweep = report::parse_sweep(o.sweep);
  if (!sweep.ok()) return usage_error("report: " + sweep.status().message());
  auto baselines = report::parse_baselines(o.baselines);
  if (!baselines.ok()) return usage_error("report: " + baselines.status().message());
  report::Settings st;
  st.sweep = *sweep;
  st.baselines = *baselines;
  if (o.analytic_loss == "log") {
    st.analytic_loss = AnalyticLoss::kLog;
  } else if (o.analytic_loss != "cos") {
    return usage_error("report: --analytic-loss must be cos or log, not '" + o.analytic_loss + "'");
  }
  st.analytic_bins = o.analytic_bins;
  st.ladder.enabled = o.ladder;
  if (!o.truth_dir.empty() && !o.ladder) {
    return usage_error("report: --truth measures the ladder against the truth: add --ladder");
  }
  st.truth_dir = o.truth_dir;
  auto codings = parse_codings(o.format_version);
  if (!codings.ok()) return usage_error("report: " + codings.status().message());
  st.codings = std::move(*codings);
  st.jobs = o.jobs > 0 ? o.jobs : thread_limit();
  // The bar redraws one line with carriage returns: by default only for a terminal, so that logs
  // stay readable.
  st.progress = !ctx.quiet &&
                (o.progress == "always" || (o.progress == "auto" && isatty(fileno(stderr)) == 1));

  const std::vector<report::Material> materials = report_materials(o);
  const auto t0 = std::chrono::steady_clock::now();
  // Ctrl-C stops the measuring through the encodes' progress callbacks, and nothing is written.
  std::atomic<bool> interrupted{false};
  st.cancel = &interrupted;
  InterruptScope interrupt_scope(&interrupted);
  auto results = report::measure_all(materials, st);
  interrupt_scope.end();
  if (interrupted) {
    std::fprintf(stderr, "cbrdf: cancelled\n");
    return kExitInterrupted;
  }
  if (!results.ok()) return fail(results.status());
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!o.output_dir.empty()) {
    if (Status s = report::write_report(*results, st, o.output_dir, elapsed); !s.ok()) {
      return fail(s);
    }
  }
  if (!ctx.quiet) print_report(*results, o, st, elapsed);
  return kExitOk;
}

}  // namespace

void add_report_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Measure storage against PSNR and time per material and setting, with baselines");
  cmd->add_option("inputs", o->inputs, "MERL .binary files")->check(CLI::ExistingFile);
  cmd->add_option("--builtin", o->builtin,
                  "Include the built-in sample materials: measured (the default when given bare: "
                  "neural fits of real MERL measurements), analytic, or all")
      ->expected(0, 1)
      ->default_str("measured");
  cmd->add_option("-o,--output", o->output_dir,
                  "Write report.md, .csv, .json, .html, SVG figures and PNG renders here");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bar and no tables on stdout");
  cmd->add_option("--progress", o->progress,
                  "Progress bar on stderr: auto (when stderr is a terminal), always or never")
      ->check(CLI::IsMember({"auto", "always", "never"}))
      ->capture_default_str();
  cmd->add_option("--jobs", o->jobs, "Materials measured in parallel (0: one per core)")
      ->check(CLI::Range(0, 256));
  cmd->add_option(
         "--sweep", o->sweep,
         std::string("Settings to measure, the cartesian product of KEY=V1,V2,... items: ") +
             "slices=1..90, bits=6..16, family=frank,clayton,gumbel,joe,independence,auto, "
             "components=1.." +
             std::to_string(kMaxComponents) +
             ",auto, residual=E,... (the primary setting, at each of the components, plus the "
             "residual layer at bound E, as --max-error E --residual-steps visibility writes) "
             "(default: family=" +
             report::default_setting().family +
             " slices=" + std::to_string(report::default_setting().slices) +
             " bits=" + std::to_string(report::default_setting().bits) +
             " components=" + report::components_name(report::default_setting().components) +
             "). The paper's setting (" + report::paper_setting().label() +
             ") is always measured as the reference.")
      ->expected(1, -1);
  cmd->add_option("--baselines", o->baselines,
                  std::string("Baselines beside the sweep: all, none, or a list of ") +
                      report::kBaselineNames + " (lossless costs about 25 s per material)")
      ->capture_default_str();
  cmd->add_flag("--ladder", o->ladder,
                "Also measure the ladder per material: bytes against PSNR from the base model to "
                "lossless for cbrdf (base, base + residual, lossless), ZFP on log1p values, "
                "float16+zstd, zstd -19 and xz -9 (several minutes per material)");
  cmd->add_option("--truth", o->truth_dir,
                  "With --ladder: a folder of noise-free tables (NAME.binary for an input "
                  "NAME.binary or NAME-noisy.binary); the ladder is measured against them too")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--format-version", o->format_version,
                  "Container coding of the copula rows: auto (1.3 where smaller, as `cbrdf "
                  "encode`), 1.2 or 1.3. A list such as auto,1.2 also writes every setting's fit "
                  "in the further codings and shows the frontiers side by side (1.2 with full "
                  "metadata, as it was written)")
      ->capture_default_str();
  cmd->add_option("--analytic-loss", o->analytic_loss,
                  "Loss of the analytic fits: cos (cosine-weighted L2, after Ngan et al.) or log")
      ->capture_default_str();
  cmd->add_option("--analytic-bins", o->analytic_bins, "Measured bins per analytic fit (0: all)")
      ->capture_default_str()
      ->check(CLI::Range(0, 2000000));
  cmd->add_flag("--sampling", o->sampling,
                "Measure importance sampling instead: per material and view elevation (0, 30, 60, "
                "75 degrees), the variance of the measured table's albedo estimator under "
                "cosine-weighted sampling, cbrdf's sampler of the default file and a tabulated "
                "sampler of the measurement, with draws per second; -o writes sampling.md and "
                "sampling.csv");
  cmd->add_option("--draws", o->draws, "With --sampling: draws per sampler, material and elevation")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000000));
  cmd->add_option("--min-table-gain", o->min_table_gain,
                  "With --sampling: the sampler's SamplerSettings::min_table_gain (0: every table "
                  "is used with the least cosine share, as the sampler of cbrdf 2.2)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_report(*o, ctx); }; });
}

}  // namespace cbrdf::cli
