// SPDX-License-Identifier: MIT
/// @file
/// BrdfTable: a full MERL-resolution isotropic BRDF, the one place that knows the MERL layout.
///
/// Values are kept exactly as a MERL .binary stores them (physical value divided by the channel's
/// scale factor), so that reading and writing a file is byte-exact. A negative stored value means
/// "not measured" (below the horizon) and is preserved bit for bit; the mask is the sign.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cbrdf {

/** The MERL grid: theta_h, theta_d and phi_d bins per channel, and the channels (R, G, B). */
///@{
inline constexpr int kThetaHBins = 90;
inline constexpr int kThetaDBins = 90;
inline constexpr int kPhiDBins = 180;
inline constexpr int kChannels = 3;
///@}
inline constexpr std::size_t kBinsPerChannel =
    std::size_t{kThetaHBins} * kThetaDBins * kPhiDBins;  ///< 1,458,000

/// Physical value = stored value * kMerlScale[channel] (R, G, B), as in the MERL reference reader.
inline constexpr std::array<double, 3> kMerlScale = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

/// Index within one channel block: phi_d + 180 * (theta_d + 90 * theta_h).
constexpr std::size_t merl_index(int theta_h, int theta_d, int phi_d) {
  return std::size_t(phi_d) +
         std::size_t{kPhiDBins} *
             (std::size_t(theta_d) + std::size_t{kThetaDBins} * std::size_t(theta_h));
}

/// A bin's position on the MERL grid.
struct BinIndex {
  int theta_h = 0;  ///< 0 to kThetaHBins - 1
  int theta_d = 0;  ///< 0 to kThetaDBins - 1
  int phi_d = 0;    ///< 0 to kPhiDBins - 1
};

/// The inverse of merl_index().
constexpr BinIndex merl_bin(std::size_t index) {
  return BinIndex{int(index / (std::size_t{kThetaDBins} * kPhiDBins)),
                  int((index / kPhiDBins) % kThetaDBins), int(index % kPhiDBins)};
}

/// A MERL table: 3 channels x kBinsPerChannel stored values (see the file's description).
class BrdfTable {
 public:
  /// All bins 0 (measured, black).
  BrdfTable() : stored_(kChannels * kBinsPerChannel, 0.0) {}

  /// Stored (file) value: physical / kMerlScale[channel]; negative = not measured.
  double stored(int channel, std::size_t index) const { return stored_[offset(channel, index)]; }
  /// Sets a stored (file) value; a negative value marks the bin not measured.
  void set_stored(int channel, std::size_t index, double v) { stored_[offset(channel, index)] = v; }

  /// Whether the bin holds a measurement (stored value >= 0).
  bool measured(int channel, std::size_t index) const { return stored(channel, index) >= 0.0; }
  /// Physical BRDF value (1/sr); meaningful only where measured().
  double physical(int channel, std::size_t index) const {
    return stored(channel, index) * kMerlScale[std::size_t(channel)];
  }
  /// Sets a physical value (1/sr); stores v / kMerlScale[channel].
  void set_physical(int channel, std::size_t index, double v) {
    set_stored(channel, index, v / kMerlScale[std::size_t(channel)]);
  }
  /// Marks a bin not measured in every channel with the given negative stored value.
  void set_not_measured(std::size_t index, double stored_value = -1.0) {
    for (int c = 0; c < kChannels; ++c) set_stored(c, index, stored_value);
  }

  /** The channel blocks R, G, B, each kBinsPerChannel values in MERL order. */
  ///@{
  const std::vector<double>& stored_values() const { return stored_; }
  std::vector<double>& stored_values() { return stored_; }
  ///@}
  /** A channel's kBinsPerChannel stored values in MERL order. */
  ///@{
  const double* channel_data(int channel) const { return stored_.data() + offset(channel, 0); }
  double* channel_data(int channel) { return stored_.data() + offset(channel, 0); }
  ///@}

  /// The number of (channel, bin) values not measured.
  std::size_t count_not_measured() const;
  bool operator==(const BrdfTable& other) const = default;  ///< Every stored value identical.

 private:
  static std::size_t offset(int channel, std::size_t index) {
    return std::size_t(channel) * kBinsPerChannel + index;
  }
  std::vector<double> stored_;  ///< one allocation: 3 x 1,458,000 doubles
};

}  // namespace cbrdf
