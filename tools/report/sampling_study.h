// SPDX-License-Identifier: MIT
// `cbrdf report --sampling`: how well cbrdf's importance sampler serves a renderer, per material
// and view elevation. The integrand is the measured table's own reflectance (the albedo
// estimator f cos(theta_i) / pdf of the table, not of the model), drawn three ways:
//  - cosine-weighted, the usual baseline;
//  - cbrdf's sampler of the model encoded from that table (the command's default file);
//  - a tabulated reference: BrdfSampler over the measured table itself with fine cells and a
//    table per tenth of a degree of theta_o, the memory-hungry ideal a renderer could build.
// Each gets its estimator's variance and its draws per second (sample() with its pdf, one thread),
// so that efficiency = 1 / (variance x time) can be read off.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/model.h"
#include "cbrdf/sampling.h"
#include "cbrdf/status.h"
#include "report/measure.h"
#include "report/tables.h"

namespace cbrdf::report {

struct SamplingStudySettings {
  int draws = 200000;                                 // per sampler, material and elevation
  std::vector<double> elevations_deg{0, 30, 60, 75};  // theta_o of wo
  std::uint64_t seed = 1;
  SamplerSettings sampler;  // cbrdf's sampler's settings
};

struct SamplerFigures {
  double mean = 0.0;      // the albedo estimate (the three agree within their errors)
  double variance = 0.0;  // of one draw's f cos / pdf
  double draws_per_second = 0.0;
};

struct SamplingRow {
  std::string material;
  double elevation_deg = 0.0;
  SamplerFigures cosine, cbrdf, tabulated;
  /// cosine's variance over cbrdf's: at least 1 where cbrdf's sampler is no worse than cosine.
  double gain() const { return cosine.variance / cbrdf.variance; }
};

/// The study of one material: `table` is the measurement, `model` the model encoded from it.
/// Errors: kInvalidArgument for fewer than 2 draws or an elevation outside [0, 90).
Expected<std::vector<SamplingRow>> sampling_study(const std::string& material,
                                                  const BrdfTable& table, const Model& model,
                                                  const SamplingStudySettings& settings);

/// sampling_study of a report material (a built-in sample or a MERL file) and of the model of
/// `cbrdf encode`'s default file of it (encoded and decoded here). Errors: the reader's, the
/// encoder's and sampling_study's, prefixed with the material's name.
Expected<std::vector<SamplingRow>> study_material(const Material& material,
                                                  const SamplingStudySettings& settings);

/// The study as a table (variances, gains over cosine, draws per second).
TextTable sampling_table(const std::vector<SamplingRow>& rows);
/// One paragraph: the least and the geometric-mean gain over cosine, and where the least is.
std::string sampling_summary(const std::vector<SamplingRow>& rows);
/// Every figure, one row per material and elevation.
std::string sampling_csv(const std::vector<SamplingRow>& rows);

}  // namespace cbrdf::report
