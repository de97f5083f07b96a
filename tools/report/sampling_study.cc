// SPDX-License-Identifier: MIT
#include "sampling_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <sstream>

#include "cbrdf/codec.h"
#include "cbrdf/coords.h"
#include "cbrdf/encoder.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "cbrdf/sampling.h"

namespace cbrdf::report {
namespace {

// A draw of one sampler: wi and its pdf (0: rejected).
struct Drawn {
  Vec3 wi;
  double pdf;
};

// The measured table's reflectance as the integrand: mean RGB, not-measured bins as 0.
double measured_mean(const BrdfTable& table, const Vec3& wi, const Vec3& wo) {
  double rgb[3];
  lookup_nearest(table, wi, wo, rgb);
  double m = 0.0;
  for (double v : rgb) m += v > 0 ? v : 0.0;
  return m / 3;
}

// Draws first (timed, the renderer's cost), then the estimator's moments (not timed: the
// integrand's lookups are the same for every sampler).
template <class Sampler>
SamplerFigures measure(const BrdfTable& table, const Vec3& wo, const std::vector<double>& u,
                       Sampler&& draw) {
  const std::size_t n = u.size() / 2;
  std::vector<Drawn> drawn(n);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < n; ++k) drawn[k] = draw(wo, u[2 * k], u[2 * k + 1]);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  long double s1 = 0, s2 = 0;
  for (const Drawn& d : drawn) {
    const double x = d.pdf > 0 ? measured_mean(table, d.wi, wo) * d.wi.z / d.pdf : 0.0;
    s1 += x;
    s2 += static_cast<long double>(x) * x;
  }
  const double count = double(n);
  const long double mean = s1 / count;
  return {double(mean), double(s2 / count - mean * mean), seconds > 0 ? count / seconds : 0.0};
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string sci(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

double geometric_mean_gain(const std::vector<SamplingRow>& rows) {
  double s = 0.0;
  for (const SamplingRow& r : rows) s += std::log(r.gain());
  return rows.empty() ? 0.0 : std::exp(s / double(rows.size()));
}

}  // namespace

Expected<std::vector<SamplingRow>> sampling_study(const std::string& material,
                                                  const BrdfTable& table, const Model& model,
                                                  const SamplingStudySettings& settings) {
  if (settings.draws < 2) {
    return Status(ErrorCode::kInvalidArgument, "sampling study: draws must be at least 2, not " +
                                                   std::to_string(settings.draws));
  }
  for (double e : settings.elevations_deg) {
    if (!(e >= 0 && e < 90)) {
      return Status(
          ErrorCode::kInvalidArgument,
          "sampling study: an elevation must be from 0 to below 90 degrees, not " + fixed(e, 2));
    }
  }
  const ModelEvaluator evaluator(model);
  const BrdfSampler cbrdf = make_model_sampler(evaluator, settings.sampler);
  // The reference: the measured table itself, a table per 0.1 degree of theta_o (built only for
  // the elevations drawn), twice the default cells on each axis, and the least defensive share.
  SamplerSettings fine;
  fine.theta_o_bins = 900;
  fine.theta_h_cells = 180;
  fine.phi_h_cells = 128;
  fine.cosine_fraction = 0.02;
  fine.min_table_gain = 0;
  const BrdfSampler tabulated(
      [&table](const Vec3& wi, const Vec3& wo, double rgb[3]) {
        lookup_nearest(table, wi, wo, rgb);
        for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] > 0 ? rgb[c] : 0.0;
      },
      fine);
  std::vector<SamplingRow> rows;
  for (double e : settings.elevations_deg) {
    // The same uniform numbers for the three samplers: their variances differ by the samplers
    // alone, and a sampler that draws as cosine does scores a gain of exactly 1.
    std::mt19937_64 rng(settings.seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<double> u(2 * std::size_t(settings.draws));
    for (double& x : u) x = uniform(rng);
    const double t = e * std::numbers::pi / 180, phi = 0.3;  // any azimuth: the BRDF is isotropic
    const Vec3 wo{std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t)};
    const auto from = [](const BrdfSampler& s) {
      return [&s](const Vec3& o, double u1, double u2) {
        const BrdfSample d = s.sample(o, u1, u2);
        return Drawn{d.wi, d.valid ? d.pdf : 0.0};
      };
    };
    SamplingRow row;
    row.material = material;
    row.elevation_deg = e;
    row.cosine = measure(table, wo, u, [](const Vec3&, double u1, double u2) {
      const Vec3 wi = sample_cosine_hemisphere(u1, u2);
      return Drawn{wi, wi.z / std::numbers::pi};
    });
    row.cbrdf = measure(table, wo, u, from(cbrdf));
    row.tabulated = measure(table, wo, u, from(tabulated));
    rows.push_back(row);
  }
  return rows;
}

Expected<std::vector<SamplingRow>> study_material(const Material& material,
                                                  const SamplingStudySettings& settings) {
  const auto prefixed = [&](const Status& s) {
    return Status(s.code(), material.name + ": " + s.message());
  };
  Expected<BrdfTable> table =
      material.builtin ? make_sample(material.name) : read_merl(material.path);
  if (!table.ok()) return prefixed(table.status());
  Expected<EncodeResult> encoded = encode_table(*table, EncoderSettings{});
  if (!encoded.ok()) return prefixed(encoded.status());
  Expected<Model> model = decode_model(encoded->bytes);
  if (!model.ok()) return prefixed(model.status());
  return sampling_study(material.name, *table, *model, settings);
}

TextTable sampling_table(const std::vector<SamplingRow>& rows) {
  TextTable t;
  t.id = "sampling";
  t.title = "Importance sampling: variance of the measured table's albedo estimator";
  t.nav = "Importance sampling";
  t.note =
      "Per material and view elevation, the variance of f cos / pdf (f the measured table) under "
      "cosine-weighted sampling, cbrdf's sampler of the default file, and a tabulated sampler of "
      "the measurement itself (a table per 0.1 degree of theta_o); gains are cosine's variance "
      "over each sampler's (above 1: less noise than cosine at the same number of samples); "
      "draws per second on one thread. Efficiency is 1 / (variance x time per draw).";
  t.header = {"material",       "theta_o",           "albedo",
              "var cosine",     "var cbrdf",         "var tabulated",
              "gain cbrdf",     "gain tabulated",    "Mdraws/s cosine",
              "Mdraws/s cbrdf", "Mdraws/s tabulated"};
  for (const SamplingRow& r : rows) {
    t.rows.push_back({r.material, fixed(r.elevation_deg, 0), fixed(r.cosine.mean, 4),
                      sci(r.cosine.variance), sci(r.cbrdf.variance), sci(r.tabulated.variance),
                      fixed(r.gain(), 3), fixed(r.cosine.variance / r.tabulated.variance, 3),
                      fixed(r.cosine.draws_per_second / 1e6, 2),
                      fixed(r.cbrdf.draws_per_second / 1e6, 2),
                      fixed(r.tabulated.draws_per_second / 1e6, 2)});
  }
  return t;
}

std::string sampling_summary(const std::vector<SamplingRow>& rows) {
  if (rows.empty()) return "No sampling measurements.\n";
  const auto least = std::min_element(
      rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.gain() < b.gain(); });
  std::ostringstream out;
  out << "cbrdf's sampler against cosine-weighted sampling over " << rows.size()
      << " material/elevation pairs: variance gain " << fixed(least->gain(), 3) << " at least ("
      << least->material << " at " << fixed(least->elevation_deg, 0) << " degrees), geometric mean "
      << fixed(geometric_mean_gain(rows), 1) << ".\n";
  return out.str();
}

std::string sampling_csv(const std::vector<SamplingRow>& rows) {
  std::ostringstream out;
  out << "material,theta_o_deg,albedo,var_cosine,var_cbrdf,var_tabulated,draws_per_s_cosine,"
         "draws_per_s_cbrdf,draws_per_s_tabulated\n";
  out.precision(9);
  for (const SamplingRow& r : rows) {
    out << r.material << ',' << r.elevation_deg << ',' << r.cosine.mean << ',' << r.cosine.variance
        << ',' << r.cbrdf.variance << ',' << r.tabulated.variance << ','
        << r.cosine.draws_per_second << ',' << r.cbrdf.draws_per_second << ','
        << r.tabulated.draws_per_second << '\n';
  }
  return out.str();
}

}  // namespace cbrdf::report
