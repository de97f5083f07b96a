// SPDX-License-Identifier: MIT
// `cbrdf encode`: MERL .binary -> .cbrdf.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "cbrdf/container.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/encoder_settings.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/progress.h"
#include "cbrdf/rate_control.h"
#include "cli.h"
#include "cli_io.h"
#include "files/file_io.h"

namespace cbrdf::cli {
namespace {

// The encode's progress on stderr, when it is a terminal: "encoding: 42% (fit)", redrawn at most
// ten times a second on one line, cleared when the encode ends.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  void draw(const EncodeProgress& p) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    drawn_ = true;
    if (p.fraction >= 0) {
      std::fprintf(stderr, "\rencoding: %3.0f%% (%-8.*s)", 100 * p.fraction, int(p.stage.size()),
                   p.stage.data());
    } else {
      std::fprintf(stderr, "\rencoding: (%-8.*s)    ", int(p.stage.size()), p.stage.data());
    }
    std::fflush(stderr);
  }
  void clear() {
    if (!drawn_) return;
    std::fprintf(stderr, "\r%*s\r", 32, "");
    std::fflush(stderr);
    drawn_ = false;
  }

 private:
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

struct EncodeOptions {
  std::string input, output;
  EncoderOptions encoder;  // --slices ... --naive-marginals: parse_options() checks them
  bool no_metrics = false;
  std::string target_bytes, target_psnr;  // read here (CLI11 lets nan through), checked by validate
  std::string max_error;                  // the residual layer's bound, read here
  bool lossless = false;
  // --mixture-copulas as given (empty: not given; a target then searches at independence).
  std::string mixture_copulas;
  // Whether each was given (an empty value is given, and refused, not taken as absent).
  const CLI::Option* target_bytes_option = nullptr;
  const CLI::Option* target_psnr_option = nullptr;
  const CLI::Option* max_error_option = nullptr;
  const CLI::Option* residual_steps_option = nullptr;
  bool given(const CLI::Option* option) const { return option && option->count() > 0; }
};

// The command's spelling of a neutral setting name (cbrdf/encoder_settings.h): its option.
std::string option_spelling(std::string_view setting) {
  if (setting == "placement") return "--slice-placement";
  if (setting == "zstd_level") return "--level";
  std::string option = "--" + std::string(setting);
  std::replace(option.begin(), option.end(), '_', '-');
  return option;
}

// `text` as a number into *out, else a problem naming `setting`.
void read_number(const char* setting, const std::string& text, double* out,
                 std::vector<SettingProblem>* problems) {
  if (auto v = parse_number(text)) {
    *out = *v;
  } else {
    problems->push_back({setting, "must be a number, not '" + text + "'"});
  }
}

// --target-bytes / --target-psnr as a RateTarget (both 0: no target), and the residual options
// beside them; every problem goes to *problems.
void read_rate_target(const EncodeOptions& o, RateTarget* target,
                      std::vector<SettingProblem>* problems) {
  // RateTarget takes 0 as no target; an option given as 0 asks for one and is refused.
  const auto given_target = [&](const char* setting, const std::string& text, double* out) {
    read_number(setting, text, out, problems);
    if (*out == 0 && parse_number(text)) {
      problems->push_back({setting, "must be above 0, not '" + text + "' (leave it out for none)"});
    }
  };
  if (o.given(o.target_bytes_option))
    given_target("target_bytes", o.target_bytes, &target->max_bytes);
  if (o.given(o.target_psnr_option)) given_target("target_psnr", o.target_psnr, &target->min_psnr);
  for (SettingProblem& p : validate(*target)) problems->push_back(std::move(p));
  // Rate control chooses the slice count itself.
  const bool targeted = o.given(o.target_bytes_option) || o.given(o.target_psnr_option);
  if (auto conflict = residual_option_conflict(
          {targeted, o.given(o.max_error_option), o.lossless, o.given(o.residual_steps_option)})) {
    problems->push_back(std::move(*conflict));
  }
  if (targeted && o.encoder.slices == "auto") {
    problems->push_back({"slices",
                         "auto and a target ({target_bytes}, {target_psnr}) both choose the slice "
                         "count; give one of them"});
  }
}

// Encodes at the settings, or searches for the target when there is one.
// *smoothed: the residual layer codes the input with its noise smoothed out (RateResult).
Expected<EncodeResult> encode(const BrdfTable& table, const EncoderSettings& st, RateTarget target,
                              const Context& ctx, std::FILE* info, bool* smoothed) {
  if (target.max_bytes <= 0 && target.min_psnr <= 0) return encode_table(table, st);
  // An explicit --components K > 1 caps the search; otherwise it searches up to 4.
  if (!st.fit.auto_components && st.fit.components > 1) target.max_components = st.fit.components;
  auto rc = encode_to_target_ladder(table, st, target);
  if (!rc.ok()) return rc.status();
  *smoothed = rc->residual_of_smoothed_input;
  if (!ctx.quiet) {
    char residual_text[96] = "";
    const Residual& r = rc->encoded.model.residual;
    if (rc->chosen.max_error > 0 && !r.row_shift.empty()) {
      // Steps per row: no option writes this file again, so name the bounds, not an option: the
      // finest row's and the file's (Residual::bound(), what `cbrdf info` shows).
      std::snprintf(residual_text, sizeof residual_text,
                    " and a residual layer bounded per row (%.3g to %.3g)", rc->chosen.max_error,
                    r.bound());
    } else if (rc->chosen.max_error > 0) {
      std::snprintf(residual_text, sizeof residual_text, " --max-error %.3g", rc->chosen.max_error);
    }
    // The options that make this file again (the residual's row bounds aside).
    const char* copulas = rc->chosen.components > 1 && !target.mixture_copulas
                              ? " --mixture-copulas independence"
                              : "";
    std::fprintf(info,
                 "searched %zu settings: chose --slices %d --components %d%s --bits %d%s: %.0f "
                 "bytes, %.2f dB tone-mapped%s\n",
                 rc->tried.size(), rc->chosen.slices, rc->chosen.components, copulas,
                 rc->chosen.bits, residual_text, rc->chosen.bytes, rc->chosen.psnr_tonemapped,
                 rc->met ? "" : " (the target could not be met: this is the closest)");
    if (!rc->note.empty()) std::fprintf(info, "note: %s\n", rc->note.c_str());
    // With -v, each setting measured, in search order: what the search weighed.
    if (ctx.verbose) {
      for (const RateCandidate& c : rc->tried) {
        std::fprintf(info, "  tried --slices %d --components %d --bits %d", c.slices, c.components,
                     c.bits);
        if (c.max_error > 0) std::fprintf(info, " residual E %.3g", c.max_error);
        std::fprintf(info, ": %.0f bytes, %.2f dB tone-mapped\n", c.bytes, c.psnr_tonemapped);
      }
    }
  }
  return std::move(rc->encoded);
}

// The sizes, the fit's objective against the separable model and, with -v, the parameters.
void print_summary(const EncodeOptions& o, const Context& ctx, const EncodeResult& result,
                   double seconds, std::FILE* info) {
  std::error_code ec;
  const double in_bytes = o.input == kStdStream ? double(kMerlFileBytes)
                                                : double(std::filesystem::file_size(o.input, ec));
  const double out_bytes = double(result.bytes.size());
  const bool auto_bits =
      o.encoder.bits == "auto" && !o.given(o.target_bytes_option) && !o.given(o.target_psnr_option);
  std::fprintf(info, "%s -> %s: %.0f -> %.0f bytes (%.0f:1, %d bits%s) in %.2f s\n",
               shown(o.input, false).c_str(), shown(o.output, true).c_str(), in_bytes, out_bytes,
               in_bytes / out_bytes, result.bits, auto_bits ? ", chosen by --bits auto" : "",
               seconds);
  // How much the copula adds over the separable model, in the fit's own objective.
  double obj = 0, obj_sep = 0;
  for (const auto& s : result.report.slices) {
    for (const auto& c : s) {
      obj += c.objective;
      obj_sep += c.objective_independence;
    }
  }
  std::fprintf(info,
               "fit: %zu slices x 3 channels, %s; objective %.4g vs separable %.4g (%+.2f%%)\n",
               result.model.slices.size(), o.encoder.family.c_str(), obj, obj_sep,
               obj_sep > 0 ? 100.0 * (obj - obj_sep) / obj_sep : 0.0);
  if (!ctx.verbose) return;
  std::fprintf(info, "%-9s %-12s %-12s %-12s %s\n", "theta_d", "theta R", "theta G", "theta B",
               "family");
  for (const Slice& s : result.model.slices) {
    std::fprintf(info, "%2d-%-2d deg ", s.theta_d_begin, s.theta_d_end - 1);
    for (const auto& c : s.channel) std::fprintf(info, " %-12.5g", c.theta);
    std::fprintf(info, " %s\n", std::string(family_name(s.channel[0].family)).c_str());
  }
}

// The residual layer's bound and size, when the file has one.
// `smoothed`: the bound holds against the smoothed input the residual coded, not the input.
void print_residual(const EncodeResult& result, bool smoothed, std::FILE* info) {
  const Residual& r = result.model.residual;
  if (!r.present()) return;
  auto parsed = parse_container(result.bytes);
  const int at = parsed.ok() ? parsed->find(kTagResidual) : -1;
  if (at < 0) return;
  const std::uint32_t bytes = parsed->layout.chunks[std::size_t(at)].stored_bytes;
  if (r.exact) {
    std::fprintf(info, "residual layer: exact table (lossless, checked), %u bytes\n", bytes);
    return;
  }
  // Steps per row (--target-psnr, --target-bytes): the bound over every bin is the coarsest row's
  // (times the largest level multiplier in modes 3 and 4), the number `cbrdf info` shows.
  const int top = r.max_row_shift();
  std::fprintf(info,
               "residual layer: |log1p(decoded / k) - log1p(%s / k)| <= %g on every measured "
               "bin (k = %g; checked), %u bytes, %zu bins stored exactly\n",
               smoothed ? "smoothed" : "source", r.bound(), r.knee, bytes, r.escapes.size());
  if (smoothed) {
    std::fprintf(
        info,
        "  smoothed: the input with its measurement noise (see cbrdf info) smoothed out over "
        "theta_d and phi_d; the input itself is not within this bound\n");
  }
  if (top > 0 || r.interpolated()) {
    if (r.interpolated()) {
      std::string levels;  // finest first
      for (int l = 0; l < r.levels; ++l) {
        char text[32];
        std::snprintf(text, sizeof text, "%s%g", l == 0 ? "" : ", ",
                      r.max_error * double(r.multiplier_of_level(l)));
        levels += text;
      }
      std::fprintf(info,
                   "  steps per row by visibility: the most visible rows within %g at the "
                   "coarsest nodes, %s on the finer levels (finest first)\n",
                   r.max_error, levels.c_str());
    } else {
      std::fprintf(info, "  steps per row by visibility: the most visible rows within %g\n",
                   r.max_error);
    }
  }
}

int run_encode(const EncodeOptions& o, const Context& ctx) {
  if (o.output.empty()) return usage_error("encode: give the output file with -o OUT.cbrdf");
  const std::vector<PathArg> outputs = {{"-o", o.output}};
  if (auto bad = check_paths("encode", {{"input", o.input}}, outputs)) return usage_error(*bad);
  std::FILE* info = info_stream(outputs);
  // Every problem of the options at once, each in the library's words with the option's name.
  std::vector<SettingProblem> problems;
  RateTarget target;
  read_rate_target(o, &target, &problems);
  EncoderOptions eo = o.encoder;
  eo.source_name = o.input == kStdStream ? "" : std::filesystem::path(o.input).filename().string();
  if (o.given(o.max_error_option)) read_number("max_error", o.max_error, &eo.max_error, &problems);
  eo.lossless = o.lossless;
  if (!o.mixture_copulas.empty()) eo.mixture_copulas = o.mixture_copulas;
  ParsedOptions st = parse_options(eo);
  problems.insert(problems.end(), st.problems.begin(), st.problems.end());
  if (Status s = settings_status(problems, option_spelling); !s.ok()) {
    return usage_error("encode: " + s.message());
  }
  // Given explicitly, --mixture-copulas applies to the search too.
  if (!o.mixture_copulas.empty()) target.mixture_copulas = st.settings.fit.mixture_copulas;

  const auto t0 = std::chrono::steady_clock::now();
  // Ctrl-C from here to the write stops the command through the encode's progress callback, and
  // nothing is written.
  std::atomic<bool> interrupted{false};
  InterruptScope interrupt_scope(&interrupted);
  const auto cancelled = [] {
    std::fprintf(stderr, "cbrdf: cancelled\n");
    return kExitInterrupted;
  };
  MerlInfo merl;
  auto table = read_merl_input(input_path(o.input), {}, &merl);
  if (interrupted) return cancelled();
  if (!table.ok()) return fail(table.status());
  // The 360 layout is read as 180 phi_d bins (each the mean of phi_d and phi_d + 180): what
  // --lossless would keep is that table, not the file.
  if (o.lossless && merl.folded_from_360) {
    return usage_error("encode: " + shown(o.input, false) +
                       " is a 90x90x360 file, which is read as 180 phi_d bins (each the mean of "
                       "phi_d and phi_d + 180); --lossless cannot keep it exactly: give a "
                       "90x90x180 .binary, or drop --lossless");
  }
  bool smoothed = false;
  ProgressLine line(!ctx.quiet && ::isatty(STDERR_FILENO));
  st.settings.progress = [&](const EncodeProgress& p) {
    line.draw(p);
    return !interrupted.load();
  };
  auto result = encode(*table, st.settings, target, ctx, info, &smoothed);
  interrupt_scope.end();
  line.clear();
  if (interrupted) return cancelled();
  if (!result.ok()) return fail(result.status().with_context(shown(o.input, false)));
  if (Status s = write_file_atomic(output_path(o.output), result->bytes); !s.ok()) return fail(s);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (ctx.quiet) return kExitOk;
  print_summary(o, ctx, *result, seconds, info);
  print_residual(*result, smoothed, info);
  if (!o.no_metrics) {
    auto decoded = decode_table(result->bytes);
    if (!decoded.ok()) return fail(decoded.status());
    const ImageMetrics im = sphere_psnr(nearest_lookup_fn(*table), nearest_lookup_fn(*decoded));
    std::fprintf(info,
                 "sphere PSNR of the decoded file against the input: %.2f dB linear, %.2f dB "
                 "tone-mapped\n",
                 im.psnr_linear, im.psnr_tonemapped);
  }
  return kExitOk;
}

}  // namespace

void add_encode_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<EncodeOptions>();
  CLI::App* cmd = app.add_subcommand("encode", "Compress a MERL .binary into a .cbrdf file");
  cmd->add_option("input", o->input, "Input MERL .binary (- for standard input)")
      ->required()
      ->check(existing_file_or_stdin());
  cmd->add_option("-o,--output", o->output, "Output .cbrdf file (- for standard output)")
      ->required();
  cmd->add_option("--slices", o->encoder.slices,
                  "Slices along theta_d: 1 to 90, or auto (count and boundaries from the data)")
      ->capture_default_str();
  cmd->add_option("--slice-placement", o->encoder.placement,
                  "Where slice boundaries go: uniform (the paper's) or adaptive (from the data)")
      ->capture_default_str();
  cmd->add_option("--components", o->encoder.components,
                  "Copula components per slice and channel: 1 (the paper's model) to 8, or auto "
                  "(up to 4, added while each halves the fit's error)")
      ->capture_default_str();
  cmd->add_option("--family", o->encoder.family, "Copula family: " + family_list(", ") + ", auto")
      ->capture_default_str();
  cmd->add_option("--mixture-copulas", o->mixture_copulas,
                  "With 2 or more components: fit each component's copula (fit, the default) or "
                  "leave them at independence (independence: about half the fit's time, and in the "
                  "1.2 coding 6% fewer bytes, for about the same tone-mapped PSNR per byte; what "
                  "--target-bytes and --target-psnr search unless given)");
  cmd->add_option("--bits", o->encoder.bits,
                  "Bits per quantized marginal value, 6 to 16 (quality), or auto: the fewest bits "
                  "that cost at most 0.05 dB tone-mapped and 0.5 dB linear sphere PSNR against "
                  "the unquantized model")
      ->capture_default_str();
  cmd->add_option("--level", o->encoder.zstd_level, "zstd level (1 to 22): effort")
      ->capture_default_str();
  cmd->add_option("--format-version", o->encoder.format_version,
                  "Container coding: auto (1.3, the compact coding, where smaller than 1.2), 1.2 "
                  "(readable by cbrdf 1.x readers of 1.0-1.2) or 1.3")
      ->capture_default_str();
  cmd->add_option("--metadata", o->encoder.metadata,
                  "The metadata chunk: none, short (source file name and encoder) or full (also "
                  "bits and zstd level)")
      ->capture_default_str();
  cmd->add_option("--threads", o->encoder.threads, "Fitting threads (0: one per core) to 256");
  cmd->add_option("--loss", o->encoder.loss,
                  "What the fit minimizes: linear (the paper's), cosine (weighted by cos theta_i "
                  "cos theta_o) or log")
      ->capture_default_str();
  cmd->add_flag("--naive-marginals", o->encoder.naive_marginals,
                "Estimate marginals as the paper does (missing bins as 0)");
  cmd->add_flag("--no-metrics", o->no_metrics, "Skip the PSNR check of the decoded file");
  auto* tb = cmd->add_option("--target-bytes", o->target_bytes,
                             "Search slices, components (up to --components, else 4) and bits for "
                             "the best tone-mapped PSNR within N bytes");
  auto* tp =
      cmd->add_option("--target-psnr", o->target_psnr,
                      "Search slices, components and bits for the fewest bytes reaching DB dB "
                      "(tone-mapped sphere PSNR)");
  tb->excludes(tp);
  o->target_bytes_option = tb;
  o->target_psnr_option = tp;
  char bound_range[64];
  std::snprintf(bound_range, sizeof bound_range, "%g to %g", kMinResidualBound, kMaxResidualBound);
  auto* me = cmd->add_option(
      "--max-error", o->max_error,
      "Add the residual layer: every measured bin decodes within E of the source, "
      "|log1p(decoded / k) - log1p(source / k)| <= E on the values the .binary stores, k = 1e-4 "
      "(scaled down with tables whose values are all below 1): a relative bound (" +
          std::string(bound_range) + "; docs/compressing.md)");
  // A bound beside --lossless is validate()'s to refuse, in the library's words.
  cmd->add_flag("--lossless", o->lossless,
                "Add the residual layer that decodes to the source bit for bit");
  o->max_error_option = me;
  o->residual_steps_option =
      cmd->add_option("--residual-steps", o->encoder.residual_steps,
                      "How --max-error E bounds the layer: one (every measured bin within E) or "
                      "visibility (E bounds the most visible rows, coarser steps where bins count "
                      "less in rendered images, as --target-psnr writes: fewer bytes for the "
                      "same picture)")
          ->capture_default_str();
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_encode(*o, ctx); }; });
}

}  // namespace cbrdf::cli
