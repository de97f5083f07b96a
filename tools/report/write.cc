// SPDX-License-Identifier: MIT
#include "report/write.h"

#include <cstdio>
#include <filesystem>
#include <span>
#include <sstream>
#include <thread>

#include "cbrdf/file_io.h"
#include "cbrdf/image_io.h"
#include "report/export.h"
#include "report/html.h"
#include "report/ladder_output.h"
#include "report/plots.h"
#include "report/summary.h"
#include "report/tables.h"

namespace cbrdf::report {
namespace {

Status write_text(const std::filesystem::path& path, const std::string& text) {
  return write_file_atomic(
      path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()),
                                          text.size()));
}

}  // namespace

std::string run_summary(const std::vector<MaterialResult>& results, const Settings& st,
                        double elapsed_s) {
  std::ostringstream out;
  char secs[32];
  std::snprintf(secs, sizeof secs, "%.1f", elapsed_s);
  out << results.size() << " materials, " << st.sweep.settings().size()
      << " codec settings (families";
  for (const std::string& f : st.sweep.families) out << " " << f;
  out << "; slices";
  for (int s : st.sweep.slices) out << " " << s;
  out << "; bits";
  for (int b : st.sweep.bits) out << " " << bits_name(b);
  out << "; components";
  for (int k : st.sweep.components) out << " " << components_name(k);
  out << "), primary setting " << st.sweep.primary().label() << ", paper's setting "
      << paper_setting().label() << ". Baselines:" << (st.baselines.separable ? " separable" : "")
      << (st.baselines.families ? " families" : "") << (st.baselines.analytic ? " analytic" : "")
      << (st.baselines.float16 ? " float16" : "") << (st.baselines.lossless ? " lossless" : "")
      << (!st.baselines.separable && !st.baselines.families && !st.baselines.analytic &&
                  !st.baselines.float16 && !st.baselines.lossless
              ? " none"
              : "")
      << ". Measured in " << secs << " s with --jobs " << st.jobs << " on "
      << std::thread::hardware_concurrency() << " hardware threads.";
  return out.str();
}

Status write_report(const std::vector<MaterialResult>& results, const Settings& st,
                    const std::string& dir, double elapsed_s) {
  const std::filesystem::path root(dir);
  std::error_code ec;
  std::filesystem::create_directories(root, ec);
  if (ec) return error(ErrorCode::kIo, dir + ": cannot create the directory: " + ec.message());
  const std::string summary = run_summary(results, st, elapsed_s);
  const std::string answer = answer_paragraph(results, st);
  // The answer's table first, then the measurements.
  std::vector<TextTable> tables = report_tables(results, st);
  tables.insert(tables.begin(), answer_table(results));
  std::vector<Figure> figures = report_figures(results, st);
  // The ladder (--ladder): its tables after the others, its figures with them.
  const std::vector<LadderMaterial> ladders = ladders_of(results);
  for (TextTable& t : ladder_tables(ladders)) tables.push_back(std::move(t));
  for (Figure& f : ladder_figures(ladders)) figures.push_back(std::move(f));

  std::ostringstream md;
  md << "# cbrdf report\n\n"
     << answer << "\n\n![" << kLeadFigure << "](" << kLeadFigure << ")\n\n"
     << summary << "\n\n";
  for (const TextTable& t : tables) md << to_markdown(t);
  md << "## Figures\n\n";
  md << "- [frontier.csv](frontier.csv): the Pareto frontier of the sweep per material and of "
        "the means.\n";
  for (const Figure& f : figures)
    md << "- [" << f.file << "](" << f.file << "): " << f.caption << "\n";
  md << "\nSphere renders per material (input, decoded, difference) and every figure are "
        "gathered in [report.html](report.html).\n";
  CBRDF_RETURN_IF_ERROR(write_text(root / "report.md", md.str()));
  CBRDF_RETURN_IF_ERROR(write_text(root / "report.csv", to_csv(results)));
  CBRDF_RETURN_IF_ERROR(write_text(root / "report.json", to_json(results, st, elapsed_s)));
  CBRDF_RETURN_IF_ERROR(write_text(root / "frontier.csv", frontier_csv(results, st)));
  if (!ladders.empty()) {
    CBRDF_RETURN_IF_ERROR(write_text(root / "ladder.csv", ladder_csv(ladders)));
    CBRDF_RETURN_IF_ERROR(write_text(root / "ladder.json", ladder_json(ladders)));
  }
  for (const Figure& f : figures) CBRDF_RETURN_IF_ERROR(write_text(root / f.file, f.svg));
  for (const MaterialResult& m : results) {
    CBRDF_RETURN_IF_ERROR(write_png(root / sphere_file(m.name, "reference"), m.reference));
    CBRDF_RETURN_IF_ERROR(write_png(root / sphere_file(m.name, "decoded"), m.decoded));
    CBRDF_RETURN_IF_ERROR(write_png(root / sphere_file(m.name, "difference"), m.difference));
  }
  return write_text(root / "report.html",
                    report_html(results, st, tables, figures, summary, answer));
}

}  // namespace cbrdf::report
