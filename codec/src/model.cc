#include "cbrdf/model.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "fit/grid_copula.h"
#include "fit/marginals.h"

namespace cbrdf {

std::size_t NotMeasured::count() const {
  std::size_t n = 0;
  for (std::uint64_t w : bits) n += std::size_t(__builtin_popcountll(w));
  return n;
}

NotMeasured NotMeasured::from_table(const BrdfTable& table) {
  NotMeasured nm;
  nm.values.clear();
  bool uniform = true;
  for (int c = 0; c < kChannels; ++c) {
    const double* data = table.channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (data[i] >= 0.0) continue;
      nm.set(c, i);
      // Bit-exact comparison: -1.0 and a NaN-free negative value compare by their bits.
      if (uniform && !nm.values.empty() &&
          std::memcmp(&nm.values.front(), &data[i], sizeof(double)) != 0) {
        uniform = false;
      }
      nm.values.push_back(data[i]);
    }
  }
  if (uniform) {
    const double v = nm.values.empty() ? -1.0 : nm.values.front();
    nm.values.assign(1, v);
  }
  return nm;
}

int Model::slice_of(int theta_d_bin) const {
  for (std::size_t s = 0; s < slices.size(); ++s) {
    if (theta_d_bin < slices[s].theta_d_end) return int(s);
  }
  return int(slices.size()) - 1;
}

BrdfTable Model::table() const { return ModelEvaluator(*this).table(); }

struct ModelEvaluator::Part {
  const ChannelSlice* cs = nullptr;
  std::unique_ptr<fit::GridCopula> copula;
};

ModelEvaluator::ModelEvaluator(const Model& model) : model_(&model) {
  slice_of_bin_.resize(kThetaDBins);
  for (int j = 0; j < kThetaDBins; ++j) slice_of_bin_[j] = model.slice_of(j);
  parts_.resize(model.slices.size());
  for (std::size_t s = 0; s < model.slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      auto part = std::make_unique<Part>();
      const ChannelSlice& cs = model.slices[s].channel[c];
      part->cs = &cs;
      part->copula = fit::make_grid_copula(cs.family);
      std::vector<double> u1, u2, u3;
      fit::midpoint_cdf(cs.pdf_h, &u1);
      fit::midpoint_cdf(cs.pdf_d, &u2);
      fit::midpoint_cdf(cs.pdf_p, &u3);
      part->copula->prepare(cs.theta, u1, u2, u3);
      parts_[s][c] = std::move(part);
    }
  }
}

ModelEvaluator::~ModelEvaluator() = default;
ModelEvaluator::ModelEvaluator(ModelEvaluator&&) noexcept = default;
ModelEvaluator& ModelEvaluator::operator=(ModelEvaluator&&) noexcept = default;

double ModelEvaluator::bin_value(int channel, int theta_h, int theta_d, int phi_d) const {
  const int s = slice_of_bin_[theta_d];
  const Part& p = *parts_[s][channel];
  const int j = theta_d - model_->slices[s].theta_d_begin;
  const double f = p.cs->pdf_h[theta_h] * p.cs->pdf_d[j] * p.cs->pdf_p[phi_d];
  if (f == 0.0 || p.cs->scale == 0.0) return 0.0;
  return p.cs->scale * p.copula->density(theta_h, j, phi_d) * f;
}

void ModelEvaluator::eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  if (wi.z <= 0.0 || wo.z <= 0.0) return;
  const HalfDiff hd = to_half_diff(wi, wo);
  const double ph = std::clamp(theta_h_position(hd.theta_h), 0.0, double(kThetaHBins - 1));
  const double pd = std::clamp(theta_d_position(hd.theta_d), 0.0, double(kThetaDBins - 1));
  const double pp = phi_d_position(hd.phi_d);
  const int h0 = std::min(int(ph), kThetaHBins - 1), d0 = std::min(int(pd), kThetaDBins - 1);
  const int p0 = std::min(int(pp), kPhiDBins - 1);
  const double fh = ph - h0, fd = pd - d0, fp = pp - p0;
  for (int a = 0; a < 2; ++a) {
    const double wa = a ? fh : 1 - fh;
    if (wa == 0.0) continue;
    for (int b = 0; b < 2; ++b) {
      const double wb = wa * (b ? fd : 1 - fd);
      if (wb == 0.0) continue;
      for (int e = 0; e < 2; ++e) {
        const double w = wb * (e ? fp : 1 - fp);
        if (w == 0.0) continue;
        const int i = h0 + a, j = d0 + b, k = (p0 + e) % kPhiDBins;
        for (int c = 0; c < kChannels; ++c) rgb[c] += w * bin_value(c, i, j, k);
      }
    }
  }
}

BrdfTable ModelEvaluator::table() const {
  BrdfTable t;
  const NotMeasured& nm = model_->not_measured;
  const bool uniform = nm.values.size() == 1;
  std::size_t next_value = 0;
  for (int c = 0; c < kChannels; ++c) {
    double* out = t.channel_data(c);
    const double inv_scale = 1.0 / kMerlScale[c];
    for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
      if (nm.test(c, idx)) {
        out[idx] = uniform ? nm.values[0] : nm.values[next_value++];
        continue;
      }
      const BinIndex b = merl_bin(idx);
      out[idx] = bin_value(c, b.theta_h, b.theta_d, b.phi_d) * inv_scale;
    }
  }
  return t;
}

}  // namespace cbrdf
