// SPDX-License-Identifier: MIT
/// @file
/// Error metrics between a reference BRDF and a test BRDF, in BRDF space and in image space, and
/// the image helpers every report reuses (sphere renders, tone mapping, false-colour differences).
///
/// BRDF space (brdf_metrics), over the bins measured in the reference, per channel c, physical
/// values r (reference) and t (test), test bins not measured read as 0:
///   rel_rmse = sqrt(sum (t - r)^2 / sum r^2)  (0 when both sums are 0, +inf when only r's is)
///   log_rmse = sqrt(mean (log(1 + max(t, 0)) - log(1 + r))^2)
///   cos_rmse = sqrt(sum w (t - r)^2 / sum w)  (absolute, 1/sr; after Ngan et al. 2005)
/// with w = cos(theta_i) cos(theta_o) * measure(bin). The cosines are taken at the bin's grid
/// direction pair (bin angles of coords.h, phi_h = 0) and clamped at 0. measure(bin) is the bin's
/// exact volume in Rusinkiewicz coordinates under dw_i dw_o = 4 cos(theta_d) sin(theta_d)
/// sin(theta_h) dtheta_h dphi_h dtheta_d dphi_d: (cos a_h - cos b_h) * (sin^2 b_d - sin^2 a_d) / 2
/// for the bin's theta_h range [a_h, b_h) (non-linear) and theta_d range [a_d, b_d); the phi_h and
/// phi_d factors are the same for every bin and cancel in the ratio.
///
/// Image space (sphere_psnr): for each light, the scene of render_sphere rendered with both BRDFs;
/// PSNR over the pixels inside the sphere only (background pixels are excluded, not counted as
/// matching zeros), per channel:
///   linear:      peak = the reference image's maximum in that channel;
///   tone-mapped: both images through tonemap(image, e) with e = tonemap_exposure(reference image)
///                (its 99th percentile over sphere pixels and all channels maps to 1), peak 1.
/// The summary is the arithmetic mean of the dB values over lights and channels. Identical images
/// give kPsnrCapDb, never +inf, so means stay finite; any PSNR above the cap is reported as the
/// cap. Renders are float images: when the reference's largest rendered value is outside [2^-60,
/// 2^60] both BRDFs are scaled by the power of two that brings it to [1, 2) first (PSNR does not
/// depend on a common scale), so a table of values near 1e300 or 1e-300 is measured, not read as a
/// match of two overflowed or underflowed images.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "cbrdf/brdf_fn.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/coords.h"
#include "cbrdf/image.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// A table's nearest-bin lookup (coords.h lookup_nearest; not-measured bins read as 0). The table
/// is referenced, not copied: it must outlive the returned function.
BrdfFn nearest_lookup_fn(const BrdfTable& table);

/// The BRDF-space errors of a test against a reference (formulas in the file's description).
struct BrdfMetrics {
  std::array<double, 3> rel_rmse{};   ///< relative RMS error per channel (R, G, B)
  std::array<double, 3> log_rmse{};   ///< RMS error of log(1 + value) per channel
  std::array<double, 3> cos_rmse{};   ///< cosine- and measure-weighted RMS error per channel, 1/sr
  double rel_rmse_mean = 0.0;         ///< mean of rel_rmse over the three channels
  double log_rmse_mean = 0.0;         ///< mean of log_rmse over the three channels
  double cos_rmse_mean = 0.0;         ///< mean of cos_rmse over the three channels
  std::array<std::size_t, 3> bins{};  ///< reference bins measured, per channel
};

/// Bin against bin: the test table's stored values at the reference's measured bins.
BrdfMetrics brdf_metrics(const BrdfTable& reference, const BrdfTable& test);
/// The test evaluated at each measured reference bin's grid direction pair (phi_h = 0), so a model
/// is measured without materializing a table. Calls test from several threads. Not for table
/// lookups: grid angles sit on bin edges, so a nearest-bin lookup there may read the neighbouring
/// bin; compare tables with the overload above.
BrdfMetrics brdf_metrics(const BrdfTable& reference, const BrdfFn& test);

// ---- Sphere images ----

/// The largest image side render_sphere draws.
inline constexpr int kMaxSphereSize = 8192;

/// The scenes sphere_psnr renders: one image of `size` x `size` per light angle.
struct SphereSetup {
  int size = 256;                                       ///< image side, pixels
  std::vector<double> light_angles_deg = {10, 45, 75};  ///< one render per angle, degrees
  int threads = 0;  ///< most threads (cbrdf/parallel.h); 0: no cap of its own
};

/// A size x size orthographic view of a unit sphere, lit from light_angle_deg. Pixel (x, y) has its
/// centre at u = (x + 0.5) / size * 2 - 1, v = 1 - (y + 0.5) / size * 2 (row 0 at the top); it is
/// inside the sphere when u^2 + v^2 < 1, with normal n = (u, v, sqrt(1 - u^2 - v^2)). The viewer
/// looks down -z: wo = (0, 0, 1). One directional light of unit irradiance (at normal incidence)
/// from L = (sin a, 0, cos a): the view direction rotated by a about the y axis, toward +x (a = 0
/// is a head-on light). The local frame is (t, b, n) from Duff et al. 2017 ("Building an
/// orthonormal basis, revisited"); the BRDF sees wi, wo in it. Radiance = f(wi, wo) * cos(theta_i),
/// 0 where cos(theta_i) <= 0; background pixels are 0. Rows are rendered on several threads. Sizes
/// outside [1, kMaxSphereSize] give an empty image.
Image render_sphere(const BrdfFn& f, double light_angle_deg, int size = 256, int threads = 0);
/// The same image as render_sphere(nearest_lookup_fn(table), ...), bit for bit, but each pixel's
/// MERL bin is computed once per (size, light angle) and cached (a few dozen settings at most), so
/// rendering another table with the same setup is a gather.
Image render_sphere(const BrdfTable& table, double light_angle_deg, int size = 256,
                    int threads = 0);
/// 1 for pixels inside the sphere of render_sphere, 0 for the background; size * size entries.
std::vector<std::uint8_t> sphere_mask(int size);

/// The PSNR reported for identical images (and the most reported for any).
inline constexpr double kPsnrCapDb = 100.0;

/// The PSNRs of one light's renders, dB.
struct LightMetrics {
  double light_angle_deg = 0.0;         ///< the light, degrees
  std::array<double, 3> psnr_linear{};  ///< peak: the reference image's maximum in the channel
  std::array<double, 3>
      psnr_tonemapped{};  ///< peak 1 after tonemap() with the reference's exposure
  double exposure = 1.0;  ///< the reference's 99th-percentile exposure
};

/// Image-space errors of a test against a reference (see the file's description).
struct ImageMetrics {
  double psnr_linear = 0.0;             ///< mean over lights and channels, dB
  double psnr_tonemapped = 0.0;         ///< mean over lights and channels, dB
  std::vector<LightMetrics> per_light;  ///< one entry per SphereSetup::light_angles_deg, in order
};

/// The sphere PSNRs of a test BRDF against a reference, both as functions (called from several
/// threads).
ImageMetrics sphere_psnr(const BrdfFn& reference, const BrdfFn& test,
                         const SphereSetup& setup = {});
/// Tables render through the cached-bin path above; the results equal the BrdfFn overload's with
/// nearest_lookup_fn.
ImageMetrics sphere_psnr(const BrdfTable& reference, const BrdfTable& test,
                         const SphereSetup& setup = {});
/// A reference table (cached-bin renders) against a test function.
ImageMetrics sphere_psnr(const BrdfTable& reference, const BrdfFn& test,
                         const SphereSetup& setup = {});

/// sphere_psnr against one reference table, for measuring many candidates (rate control, --bits
/// auto): the reference's renders, exposures and tone-mapped images are made once, and a model is
/// evaluated only at the bins the spheres read (331 of its 8,100 phi_d rows at the default setup:
/// each light sees about one theta_d) instead of decoding its whole table. score() equals
/// sphere_psnr(reference, table) with the table, or the model's table(), bit for bit. The reference
/// must outlive the scorer.
class SphereScorer {
 public:
  /// Renders the reference's spheres once. The reference must outlive the scorer.
  explicit SphereScorer(const BrdfTable& reference, SphereSetup setup = {});
  /// Frees the cached renders.
  ~SphereScorer();
  /// Moves the cached renders.
  SphereScorer(SphereScorer&&) noexcept;
  /// Moves the cached renders.
  SphereScorer& operator=(SphereScorer&&) noexcept;

  /// sphere_psnr(reference, test), bit for bit.
  ImageMetrics score(const BrdfTable& test) const;
  /// A model with a residual layer is scored through its table().
  ImageMetrics score(const Model& test) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A model written as a file and decoded again, scored against the scorer's reference: what
/// rate control, `--bits auto` and the report measure for every setting they try.
struct ScoredEncoding {
  std::vector<std::uint8_t> bytes;  ///< the .cbrdf file encode_model() wrote
  ImageMetrics metrics;             ///< the decoded file's sphere PSNR against the reference
};

/// encode_model(model, container), then decode_model() of its bytes scored by `scorer`: the PSNR
/// is that of the file a reader gets, quantization included. Errors are encode_model()'s (a model
/// it cannot write) or decode_model()'s (a bug: the file was just written).
Expected<ScoredEncoding> encode_and_score(const Model& model, const ContainerSettings& container,
                                          const SphereScorer& scorer);

// ---- Image comparison helpers (mask: nullptr or one byte per pixel, nonzero = counted) ----

/// PSNR of one channel, 10 log10(peak^2 / MSE), capped at kPsnrCapDb (so MSE = 0 gives the cap);
/// -inf when peak is 0 and the images differ, or when a pixel differs by an infinite amount (an
/// inf or NaN against any other value). NaN when the sizes differ or nothing is counted.
double psnr(const Image& reference, const Image& test, int channel, double peak,
            const std::vector<std::uint8_t>* mask = nullptr);
/// The p-th percentile (p in [0, 100]) of all channel values of the counted pixels, linearly
/// interpolated between order statistics (value at rank p/100 * (n - 1)). 0 when nothing counts.
double percentile(const Image& image, double p, const std::vector<std::uint8_t>* mask = nullptr);
/// Exposure that maps the 99th percentile to 1: 1 / percentile(image, 99, mask). When that
/// percentile is 0, 1 / max instead; 1 for an all-black image.
double tonemap_exposure(const Image& reference, const std::vector<std::uint8_t>* mask = nullptr);
/// Display encoding: clamp(x * exposure, 0, 1)^(1 / gamma) per channel (NaN becomes 0).
Image tonemap(const Image& image, double exposure, double gamma = 2.2);

/// The viridis colour map at t in [0, 1] (clamped), as display-encoded RGB in [0, 1]: linear
/// interpolation between matplotlib's viridis at t = 0, 1/9, ..., 1.
std::array<float, 3> viridis(double t);
/// False-colour difference: d = mean over channels of |a - b|, shown as viridis(d / scale), so 0 is
/// dark purple and scale (and above) is yellow. Pixels outside the mask are black. An empty image
/// when the sizes differ or scale is not positive.
Image difference_image(const Image& a, const Image& b, double scale,
                       const std::vector<std::uint8_t>* mask = nullptr);

}  // namespace cbrdf
