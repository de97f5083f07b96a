// `cbrdf report`: size against quality and time, per material and setting.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "cli.h"
#include "report/measure.h"

namespace cbrdf::cli {
namespace {

struct ReportOptions {
  std::vector<std::string> inputs;
  bool builtin = false;
  std::string output_dir;
  int jobs = 0;
  int slices = 6;
  int bits = EncodeSettings{}.bits;
};

int run_report(const ReportOptions& o, const Context& ctx) {
  if (o.inputs.empty() && !o.builtin) {
    return usage_error("report: give MERL .binary files, --builtin, or both");
  }
  std::vector<report::Material> materials;
  if (o.builtin) {
    for (const SampleInfo& s : sample_materials()) {
      materials.push_back({std::string(s.name), "", true});
    }
  }
  for (const std::string& f : o.inputs) {
    materials.push_back({std::filesystem::path(f).stem().string(), f, false});
  }
  report::Settings st;
  st.slices = o.slices;
  st.bits = o.bits;
  st.jobs = o.jobs > 0 ? o.jobs : int(std::max(1u, std::thread::hardware_concurrency()));
  st.progress = !ctx.quiet;
  auto rows = report::measure_all(materials, st);
  if (!rows.ok()) return fail(rows.status());
  std::printf("%s", report::format_table(*rows).c_str());
  if (!o.output_dir.empty()) {
    if (Status s = report::write_files(*rows, o.output_dir); !s.ok()) return fail(s);
    if (!ctx.quiet) std::printf("wrote %s/report.md, report.csv, report.json\n", o.output_dir.c_str());
  }
  return kExitOk;
}

}  // namespace

void add_report_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd =
      app.add_subcommand("report", "Measure storage against PSNR and time, per material");
  cmd->add_option("inputs", o->inputs, "MERL .binary files")->check(CLI::ExistingFile);
  cmd->add_flag("--builtin", o->builtin, "Include the built-in sample materials");
  cmd->add_option("-o,--output", o->output_dir, "Write report.md, report.csv and report.json here");
  cmd->add_option("--jobs", o->jobs, "Materials measured in parallel (0: one per core)")
      ->check(CLI::Range(0, 256));
  cmd->add_option("--slices", o->slices, "Slices along theta_d (1 to 90)")
      ->capture_default_str()
      ->check(CLI::Range(1, 90));
  cmd->add_option("--bits", o->bits, "Bits per quantized marginal value (6 to 16)")
      ->capture_default_str()
      ->check(CLI::Range(6, 16));
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_report(*o, ctx); }; });
}

}  // namespace cbrdf::cli
