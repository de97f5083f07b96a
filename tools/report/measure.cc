// SPDX-License-Identifier: MIT
#include "report/measure.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>
#include <random>

#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/file_io.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/parallel.h"
#include "cbrdf/samples.h"
#include "render/table_lookup.h"
#include "report/float16_baseline.h"
#include "report/lossless.h"
#include "report/progress.h"
#include "report/render_times.h"

namespace cbrdf::report {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct AnalyticModelDef {
  const char* name;
  std::vector<LobeKind> lobes;
};
// Ngan et al.'s competitors, each Lambertian + specular. "cook-torrance" is the Cook-Torrance
// microfacet form with a GGX distribution (height-correlated Smith G, Schlick F), as analytic.h
// defines the GGX lobe; the two-lobe GGX is where a second lobe helps most (Ngan et al.).
const std::vector<AnalyticModelDef>& analytic_models() {
  static const std::vector<AnalyticModelDef> defs = {
      {"ward", {LobeKind::kLambertian, LobeKind::kWard}},
      {"cook-torrance", {LobeKind::kLambertian, LobeKind::kGgx}},
      {"ashikhmin-shirley", {LobeKind::kLambertian, LobeKind::kAshikhminShirley}},
      {"ggx-2lobe", {LobeKind::kLambertian, LobeKind::kGgx, LobeKind::kGgx}},
  };
  return defs;
}

// Mean cost of one RGB evaluation over fixed random upper-hemisphere direction pairs.
template <typename Eval>
double eval_ns(const Eval& eval) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  constexpr int kPairs = 4096, kRounds = 8;
  std::vector<Vec3> dirs(2 * kPairs);
  for (Vec3& d : dirs) {
    const double z = u(rng), phi = 2 * std::numbers::pi * u(rng), r = std::sqrt(1 - z * z);
    d = {r * std::cos(phi), r * std::sin(phi), z};
  }
  volatile double sink = 0;
  double rgb[3];
  const auto t0 = Clock::now();
  for (int round = 0; round < kRounds; ++round) {
    for (int n = 0; n < kPairs; ++n) {
      eval(dirs[2 * std::size_t(n)], dirs[2 * std::size_t(n) + 1], rgb);
      sink = sink + rgb[0];  // keeps the loop from being optimized away
    }
  }
  return 1e9 * since(t0) / (double(kPairs) * kRounds);
}

std::vector<PolarCurve> polar_curves(const std::string& model, const BrdfFn& f) {
  std::vector<PolarCurve> out;
  for (double ti : kPolarThetaI) {
    PolarCurve c;
    c.model = model;
    c.theta_i_deg = ti;
    const double a = ti * std::numbers::pi / 180;
    const Vec3 wi{std::sin(a), 0.0, std::cos(a)};
    for (int to = -89; to <= 89; ++to) {
      const double b = to * std::numbers::pi / 180;
      double rgb[3];
      f(wi, Vec3{std::sin(b), 0.0, std::cos(b)}, rgb);
      c.theta_o_deg.push_back(to);
      c.value.push_back((rgb[0] + rgb[1] + rgb[2]) / 3);
    }
    out.push_back(std::move(c));
  }
  return out;
}

// The sweep's settings (flag true), then the paper's setting and the baselines' copula settings
// that the sweep does not hold.
std::vector<std::pair<CodecSetting, bool>> copula_settings(const Settings& st) {
  std::vector<std::pair<CodecSetting, bool>> out;
  for (const CodecSetting& s : st.sweep.settings()) out.emplace_back(s, true);
  auto add = [&](const CodecSetting& s) {
    const bool present =
        std::any_of(out.begin(), out.end(), [&](const auto& e) { return e.first == s; });
    if (!present) out.emplace_back(s, false);
  };
  add(paper_setting());
  const CodecSetting p = st.sweep.primary();
  std::vector<std::string> extra;
  if (st.baselines.separable) extra.push_back("independence");
  if (st.baselines.families) {
    for (CopulaFamily f : listed_families()) {
      if (family_has_parameter(f)) extra.emplace_back(family_name(f));
    }
    extra.push_back("auto");
  }
  for (const std::string& f : extra) add(CodecSetting{f, p.slices, p.bits, p.components});
  return out;
}

// The encoder's settings at a sweep setting, as `cbrdf encode` would build them from the same
// options (so that the sizes match what it writes).
Expected<EncoderSettings> encoder_settings_at(const CodecSetting& s, int threads,
                                              const std::string& source_name,
                                              const std::string& coding) {
  EncoderOptions o;
  o.format_version = coding;
  // Every encoder before 1.3 wrote full metadata: the 1.2 coding as it was.
  if (coding == "1.2") o.metadata = "full";
  o.slices = std::to_string(s.slices);
  o.components = components_name(s.components);
  o.family = s.family;
  o.bits = bits_name(s.bits);
  if (s.max_error > 0) {
    o.max_error = s.max_error;
    o.residual_steps = "visibility";
  }
  o.threads = threads;
  o.source_name = source_name;
  return encoder_settings(o);
}

// The file at the setting's bits, or at the bits `--bits auto` chooses (named in the row's
// detail), plus the setting's residual layer, as `cbrdf encode` writes it.
Expected<std::vector<std::uint8_t>> encode_at(const BrdfTable& table, const Model& model,
                                              const EncoderSettings& es, Row* r) {
  EncodeResult file;
  file.model = model;
  file.bits = es.container.bits;
  if (!es.auto_bits.enabled) {
    CBRDF_ASSIGN_OR_RETURN(auto bytes, encode_model(model, es.container));
    file.bytes = std::move(bytes);
  } else {
    CBRDF_ASSIGN_OR_RETURN(auto choice, choose_bits(table, model, es.container, es.auto_bits));
    r->detail = "chose " + std::to_string(choice.bits) + " bits";
    file.bits = choice.bits;
    file.bytes = std::move(choice.bytes);
  }
  if (es.residual.max_error > 0) CBRDF_RETURN_IF_ERROR(add_residual_layer(table, es, &file));
  return std::move(file.bytes);
}

class MaterialRun {
 public:
  MaterialRun(const Material& m, const Settings& st, int threads, Progress* progress,
              std::size_t slot)
      : m_(m), st_(st), threads_(threads), progress_(progress), slot_(slot) {
    sphere_.size = st.sphere_size;
    sphere_.threads = threads;
  }

  Expected<MaterialResult> run() {
    CBRDF_RETURN_IF_ERROR(load());
    result_.name = m_.name;
    result_.polar = polar_curves("measured", nearest_lookup_fn(table_));
    if (st_.render_times) table_renders();
    CBRDF_RETURN_IF_ERROR(copula_rows());
    if (st_.baselines.analytic) CBRDF_RETURN_IF_ERROR(analytic_rows());
    if (st_.baselines.float16) CBRDF_RETURN_IF_ERROR(float16_row());
    if (st_.baselines.lossless) CBRDF_RETURN_IF_ERROR(lossless_rows());
    if (st_.ladder.enabled) CBRDF_RETURN_IF_ERROR(ladder());
    return std::move(result_);
  }

 private:
  Status load() {
    if (m_.builtin) {
      CBRDF_ASSIGN_OR_RETURN(table_, make_sample(m_.name));
      if (st_.baselines.lossless) raw_ = serialize_merl(table_);
      input_bytes_ = double(kMerlFileBytes);
      return ok_status();
    }
    CBRDF_ASSIGN_OR_RETURN(table_, read_merl(m_.path));
    std::error_code ec;
    input_bytes_ = double(std::filesystem::file_size(m_.path, ec));
    if (ec) return error(ErrorCode::kIo, m_.path + ": cannot read its size: " + ec.message());
    if (st_.baselines.lossless) {
      CBRDF_ASSIGN_OR_RETURN(raw_, read_file(m_.path, kMerlFileBytes * 2));
    }
    return ok_status();
  }

  // Best of two one-thread renders: the time a single render thread spends, less disturbed by the
  // other materials measured at once.
  static constexpr int kRenderRepeats = 2;
  double render_scale() const { return st_.sphere_size / 256.0; }

  void table_renders() {
    const TableRenderTimes t = time_table_renders(table_, render_scale(), kRenderRepeats);
    result_.render_nearest_s = t.nearest_s;
    result_.render_trilinear_s = t.trilinear_s;
    // As the other rows' eval ns (the lossless rows' is the nearest-bin lookup's).
    result_.nearest_eval_ns = eval_ns(
        [&](const Vec3& wi, const Vec3& wo, double* rgb) { lookup_nearest(table_, wi, wo, rgb); });
    result_.trilinear_eval_ns = eval_ns([&](const Vec3& wi, const Vec3& wo, double* rgb) {
      render::lookup_trilinear_measured(table_, wi, wo, rgb);
    });
    result_.render_width = t.width;
    result_.render_height = t.height;
  }

  Row base_row(const std::string& model, const char* kind) const {
    Row r;
    r.material = m_.name;
    r.model = model;
    r.kind = kind;
    r.input_bytes = input_bytes_;
    return r;
  }

  void set_metrics(Row* r, const BrdfTable& test) const {
    const BrdfMetrics bm = brdf_metrics(table_, test);
    r->rel_rmse = bm.rel_rmse_mean;
    r->log_rmse = bm.log_rmse_mean;
    r->cos_rmse = bm.cos_rmse_mean;
    const ImageMetrics im = sphere_psnr(table_, test, sphere_);
    r->psnr_linear = im.psnr_linear;
    r->psnr_tonemapped = im.psnr_tonemapped;
  }

  Status copula_rows() {
    const auto settings = copula_settings(st_);
    const CodecSetting primary = st_.sweep.primary();
    // Settings that differ only in bits or the residual bound share one fit.
    struct Fit {
      CodecSetting key;  // bits 0, no residual
      Model model;
      double fit_s = 0;
    };
    std::vector<Fit> fits;
    // As `cbrdf encode` records it.
    const std::string source_name =
        m_.builtin ? m_.name : std::filesystem::path(m_.path).filename().string();
    for (const auto& [s, in_sweep] : settings) {
      auto es = encoder_settings_at(s, threads_, source_name, st_.codings.front());
      if (!es.ok()) return es.status().with_context(m_.name + " (" + s.label() + ")");
      const CodecSetting key{s.family, s.slices, 0, s.components};
      auto fit = std::find_if(fits.begin(), fits.end(), [&](const Fit& f) { return f.key == key; });
      if (fit == fits.end()) {
        // Through encode_table (at fixed bits, no residual: the model is fit_model's) so that the
        // fit reports progress and stops on a cancel.
        EncoderSettings fit_es = *es;
        fit_es.auto_bits.enabled = false;
        fit_es.residual = {};
        fit_es.progress = callback(0, 0.5);
        const auto t0 = Clock::now();
        auto m = encode_table(table_, fit_es);
        const double seconds = since(t0);
        if (!m.ok()) return m.status().with_context(m_.name + " (" + s.label() + ")");
        fits.push_back(Fit{key, std::move(m->model), seconds});
        fit = fits.end() - 1;
      }
      es->progress = callback(0.5, 0.9);
      const Model& model = fit->model;
      const double fit_s = fit->fit_s;
      Row r = base_row(s.model_name(), kKindCopula);
      r.slices = s.slices;
      r.bits = s.bits;
      r.components = s.components;
      r.max_error = s.max_error;
      r.in_sweep = in_sweep;
      r.primary = s == primary;
      r.paper = s == paper_setting();
      auto t0 = Clock::now();
      auto bytes = encode_at(table_, model, *es, &r);
      r.encode_s = fit_s + since(t0);
      if (!bytes.ok()) return bytes.status().with_context(m_.name + " (" + s.label() + ")");
      r.bytes = double(bytes->size());
      t0 = Clock::now();
      auto decoded_model = decode_model(*bytes);
      if (!decoded_model.ok()) {
        return decoded_model.status().with_context(m_.name + " (" + s.label() + ")");
      }
      const BrdfTable decoded = decoded_model->table();
      r.decode_s = since(t0);
      set_metrics(&r, decoded);
      if (st_.codings.size() > 1) {
        r.codings.push_back(
            {st_.codings.front(), r.bytes, r.psnr_linear, r.psnr_tonemapped, r.encode_s});
        for (std::size_t c = 1; c < st_.codings.size(); ++c) {
          auto other = other_coding(s, model, fit_s, source_name, st_.codings[c]);
          if (!other.ok()) return other.status().with_context(m_.name + " (" + s.label() + ")");
          r.codings.push_back(*other);
        }
      }
      const ModelEvaluator ev(*decoded_model);
      r.eval_ns =
          eval_ns([&](const Vec3& wi, const Vec3& wo, double* rgb) { ev.eval(wi, wo, rgb); });
      if (st_.render_times && (r.primary || r.paper)) {
        r.render_s = time_model_render(*decoded_model, render_scale(), kRenderRepeats);
      }
      if (r.primary) {
        images(decoded, r.label());
        const auto curves = polar_curves(r.label(), [&](const Vec3& wi, const Vec3& wo,
                                                        double rgb[3]) { ev.eval(wi, wo, rgb); });
        result_.polar.insert(result_.polar.end(), curves.begin(), curves.end());
      }
      result_.rows.push_back(std::move(r));
      CBRDF_RETURN_IF_ERROR(step(m_.name + ": " + s.label()));
    }
    return ok_status();
  }

  // The same fitted model written in another coding: its bytes, sphere PSNRs and encode time.
  Expected<CodingResult> other_coding(const CodecSetting& s, const Model& model, double fit_s,
                                      const std::string& source_name, const std::string& coding) {
    CBRDF_ASSIGN_OR_RETURN(auto es, encoder_settings_at(s, threads_, source_name, coding));
    Row scratch;
    const auto t0 = Clock::now();
    auto bytes = encode_at(table_, model, es, &scratch);
    CodingResult c;
    c.coding = coding;
    c.encode_s = fit_s + since(t0);
    if (!bytes.ok()) return bytes.status();
    c.bytes = double(bytes->size());
    CBRDF_ASSIGN_OR_RETURN(auto decoded, decode_model(*bytes));
    const ImageMetrics im = sphere_psnr(table_, decoded.table(), sphere_);
    c.psnr_linear = im.psnr_linear;
    c.psnr_tonemapped = im.psnr_tonemapped;
    return c;
  }

  void images(const BrdfTable& decoded, const std::string& label) {
    const std::vector<std::uint8_t> mask = sphere_mask(st_.sphere_size);
    const Image ref = render_sphere(table_, kImageLightDeg, st_.sphere_size, threads_);
    const Image dec = render_sphere(decoded, kImageLightDeg, st_.sphere_size, threads_);
    const double exposure = tonemap_exposure(ref, &mask);
    result_.reference = tonemap(ref, exposure);
    result_.decoded = tonemap(dec, exposure);
    result_.difference =
        difference_image(result_.reference, result_.decoded, kDifferenceScale, &mask);
    result_.decoded_label = label;
  }

  Status analytic_rows() {
    for (const AnalyticModelDef& def : analytic_models()) {
      Row r = base_row(def.name, kKindAnalytic);
      AnalyticFitSettings fs;
      fs.lobes = def.lobes;
      fs.sample_bins = st_.analytic_bins;
      fs.loss = st_.analytic_loss;
      fs.threads = threads_;
      auto t0 = Clock::now();
      auto brdf = fit_analytic(table_, fs);
      r.encode_s = since(t0);
      if (!brdf.ok()) return brdf.status().with_context(m_.name + " (" + def.name + ")");
      r.bytes = 8.0 * brdf->num_params();
      t0 = Clock::now();
      auto fitted = tabulate_like(*brdf, table_);
      r.decode_s = since(t0);
      if (!fitted.ok()) return fitted.status().with_context(m_.name + " (" + def.name + ")");
      set_metrics(&r, *fitted);
      const AnalyticBrdf& b = *brdf;
      r.eval_ns =
          eval_ns([&](const Vec3& wi, const Vec3& wo, double* rgb) { b.eval(wi, wo, rgb); });
      for (const Lobe& l : b.lobes) {
        char text[160];
        std::snprintf(text, sizeof text, "%s%s rgb (%.4g %.4g %.4g)", r.detail.empty() ? "" : "; ",
                      std::string(lobe_kind_name(l.kind)).c_str(), l.rgb[0], l.rgb[1], l.rgb[2]);
        r.detail += text;
        if (l.kind != LobeKind::kLambertian) {
          std::snprintf(text, sizeof text, " shape %.4g", l.shape);
          r.detail += text;
        }
      }
      if (def.lobes.size() == 2) {  // the paper's Figure 3 shows the one-lobe models
        const auto curves = polar_curves(
            def.name, [&](const Vec3& wi, const Vec3& wo, double rgb[3]) { b.eval(wi, wo, rgb); });
        result_.polar.insert(result_.polar.end(), curves.begin(), curves.end());
      }
      result_.rows.push_back(std::move(r));
      CBRDF_RETURN_IF_ERROR(step(m_.name + ": " + def.name));
    }
    return ok_status();
  }

  Status float16_row() {
    Row r = base_row("float16+zstd", kKindNearLossless);
    auto f = float16_round_trip(table_, st_.float16_zstd_level);
    if (!f.ok()) return f.status().with_context(m_.name + " (float16)");
    r.bytes = double(f->compressed.bytes.size());
    r.encode_s = f->compressed.encode_s;
    r.decode_s = f->compressed.decode_s;
    set_metrics(&r, f->decoded);
    const BrdfTable& t = f->decoded;
    r.eval_ns = eval_ns(
        [&](const Vec3& wi, const Vec3& wo, double* rgb) { lookup_nearest(t, wi, wo, rgb); });
    r.detail = "zstd level " + std::to_string(st_.float16_zstd_level);
    result_.rows.push_back(std::move(r));
    return step(m_.name + ": float16");
  }

  // The truth of this material in --truth DIR: NAME.binary for NAME.binary or NAME-noisy.binary.
  std::filesystem::path truth_path() const {
    std::string stem = m_.builtin ? m_.name : std::filesystem::path(m_.path).stem().string();
    const std::string suffix = "-noisy";
    if (stem.size() > suffix.size() && stem.ends_with(suffix)) {
      stem.resize(stem.size() - suffix.size());
    }
    return std::filesystem::path(st_.truth_dir) / (stem + ".binary");
  }

  Status ladder() {
    LadderSettings ls = st_.ladder;
    ls.threads = threads_;
    ls.sphere_size = st_.sphere_size;
    ls.progress = callback(0, 1);
    std::optional<BrdfTable> truth;
    if (!st_.truth_dir.empty()) {
      auto t = read_merl(truth_path());
      if (!t.ok()) return t.status().with_context("--truth");
      truth = std::move(t).value();
    }
    CBRDF_ASSIGN_OR_RETURN(result_.ladder,
                           measure_ladder(m_.name, table_, ls, truth ? &*truth : nullptr));
    return step(m_.name + ": ladder");
  }

  Status lossless_rows() {
    const double lookup_ns = eval_ns(
        [&](const Vec3& wi, const Vec3& wo, double* rgb) { lookup_nearest(table_, wi, wo, rgb); });
    auto add = [&](const std::string& model, const Expected<Compressed>& c) -> Status {
      if (!c.ok()) return c.status().with_context(m_.name + " (" + model + ")");
      Row r = base_row(model, kKindLossless);
      r.bytes = double(c->bytes.size());
      r.encode_s = c->encode_s;
      r.decode_s = c->decode_s;
      // Bit-exact (verified by the round trip): no error, the PSNR cap.
      r.psnr_linear = r.psnr_tonemapped = kPsnrCapDb;
      r.eval_ns = lookup_ns;
      r.render_s = result_.render_nearest_s;
      r.detail = "of the .binary bytes; eval = nearest-bin table lookup";
      result_.rows.push_back(std::move(r));
      return step(m_.name + ": " + model);
    };
    CBRDF_RETURN_IF_ERROR(add("zstd-" + std::to_string(st_.lossless_zstd_level),
                              zstd_round_trip(raw_, st_.lossless_zstd_level)));
    return add("xz-" + std::to_string(st_.xz_preset), xz_round_trip(raw_, st_.xz_preset));
  }

  // The encoder's callback for the part [from, to] of this material's running step; it cancels
  // once st_.cancel is set.
  ProgressCallback callback(double from, double to) const {
    return progress_->callback(slot_, from, to, st_.cancel);
  }
  // Marks a step done; between steps, a cancel stops the material.
  Status step(const std::string& what) {
    progress_->step(slot_, what);
    if (st_.cancel != nullptr && st_.cancel->load())
      return error(ErrorCode::kCancelled, "cancelled");
    return ok_status();
  }

  const Material& m_;
  const Settings& st_;
  int threads_;
  Progress* progress_;
  std::size_t slot_;  // the material's slot in the bar
  SphereSetup sphere_;
  BrdfTable table_;
  std::vector<std::uint8_t> raw_;
  double input_bytes_ = 0;
  MaterialResult result_;
};

std::size_t steps_per_material(const Settings& st) {
  std::size_t n = copula_settings(st).size();
  if (st.baselines.analytic) n += analytic_models().size();
  if (st.baselines.float16) ++n;
  if (st.baselines.lossless) n += 2;
  if (st.ladder.enabled) ++n;
  return n;
}

}  // namespace

std::string Row::label() const {
  if (kind == std::string(kKindCopula)) {
    return copula_label(model, slices, bits, components, max_error);
  }
  return model;
}

Expected<std::vector<MaterialResult>> measure_all(const std::vector<Material>& materials,
                                                  const Settings& st) {
  std::vector<MaterialResult> results(materials.size());
  std::vector<Status> errors(materials.size());
  const int jobs = std::max(1, std::min<int>(st.jobs, int(materials.size())));
  // With one job the fits and renders use every core; with several, each material gets one.
  const int threads = jobs == 1 ? thread_limit() : 1;
  Progress progress(materials.size() * steps_per_material(st), st.progress, materials.size());
  std::atomic<bool> failed{false};
  parallel_for(int(materials.size()), jobs, [&](int i) {
    if (failed) return;
    MaterialRun run(materials[std::size_t(i)], st, threads, &progress, std::size_t(i));
    auto r = run.run();
    if (r.ok()) {
      results[std::size_t(i)] = std::move(r).value();
    } else {
      errors[std::size_t(i)] = r.status();
      failed = true;
    }
  });
  progress.finish();
  for (const Status& e : errors) {
    if (!e.ok()) return e;
  }
  return results;
}

}  // namespace cbrdf::report
