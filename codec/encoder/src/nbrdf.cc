// SPDX-License-Identifier: MIT
// Parsing and evaluating NBRDF weight files (see nbrdf.h).
#include "nbrdf.h"

#include <bit>
#include <cmath>
#include <string>

#include "grid_table.h"

namespace cbrdf::internal {
namespace {

// Reads the weights in file order into the network's blocks, checking each is finite.
class WeightReader {
 public:
  WeightReader(std::span<const std::uint8_t> bytes, std::string_view name)
      : bytes_(bytes), name_(name) {}

  template <std::size_t N>
  Status read(const char* block, std::array<double, N>* out) {
    return read_row(block, -1, out);
  }

  template <std::size_t R, std::size_t C>
  Status read(const char* block, std::array<std::array<double, C>, R>* out) {
    for (std::size_t r = 0; r < R; ++r) CBRDF_RETURN_IF_ERROR(read_row(block, int(r), &(*out)[r]));
    return ok_status();
  }

 private:
  // Row `row` of a matrix, or a vector when row < 0.
  template <std::size_t N>
  Status read_row(const char* block, int row, std::array<double, N>* out) {
    for (std::size_t i = 0; i < N; ++i, ++next_) {
      const std::uint8_t* p = bytes_.data() + 4 * next_;
      const std::uint32_t bits = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 |
                                 std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
      const float v = std::bit_cast<float>(bits);
      if (!std::isfinite(v)) {
        const std::string where = std::string(block) +
                                  (row >= 0 ? "[" + std::to_string(row) + "]" : std::string()) +
                                  "[" + std::to_string(i) + "]";
        return error(ErrorCode::kNumeric, std::string(name_) + ": weight " + std::to_string(next_) +
                                              " (" + where + ", byte offset " +
                                              std::to_string(4 * next_) + ") is " +
                                              (std::isnan(v) ? "NaN" : "infinite"));
      }
      (*out)[i] = double(v);
    }
    return ok_status();
  }

  std::span<const std::uint8_t> bytes_;
  std::string_view name_;
  std::size_t next_ = 0;
};

template <std::size_t In, std::size_t Out>
void dense_relu(const std::array<std::array<double, Out>, In>& w, const std::array<double, Out>& b,
                const std::array<double, In>& x, std::array<double, Out>* y) {
  for (std::size_t o = 0; o < Out; ++o) {
    double s = b[o];
    for (std::size_t i = 0; i < In; ++i) s += x[i] * w[i][o];
    (*y)[o] = s > 0 ? s : 0;
  }
}

}  // namespace

Expected<NbrdfNet> parse_nbrdf(std::span<const std::uint8_t> bytes, std::string_view name) {
  const std::string expected = "; an NBRDF weight file holds exactly " +
                               std::to_string(kNbrdfBytes) + " bytes (" +
                               std::to_string(kNbrdfFloats) + " float32 weights)";
  if (bytes.size() < kNbrdfBytes) {
    return error(ErrorCode::kTruncated,
                 std::string(name) + ": " + std::to_string(bytes.size()) + " bytes" + expected);
  }
  if (bytes.size() > kNbrdfBytes) {
    return error(ErrorCode::kCorrupt,
                 std::string(name) + ": " + std::to_string(bytes.size()) + " bytes" + expected);
  }
  NbrdfNet net;
  WeightReader r(bytes, name);
  CBRDF_RETURN_IF_ERROR(r.read("W1", &net.w1));
  CBRDF_RETURN_IF_ERROR(r.read("b1", &net.b1));
  CBRDF_RETURN_IF_ERROR(r.read("W2", &net.w2));
  CBRDF_RETURN_IF_ERROR(r.read("b2", &net.b2));
  CBRDF_RETURN_IF_ERROR(r.read("W3", &net.w3));
  CBRDF_RETURN_IF_ERROR(r.read("b3", &net.b3));
  return net;
}

void eval_nbrdf(const NbrdfNet& net, const std::array<double, kNbrdfInputs>& x, double rgb[3]) {
  std::array<double, kNbrdfHidden> h1, h2;
  dense_relu(net.w1, net.b1, x, &h1);
  dense_relu(net.w2, net.b2, h1, &h2);
  for (std::size_t o = 0; o < kNbrdfOutputs; ++o) {
    double s = net.b3[o];
    for (std::size_t i = 0; i < kNbrdfHidden; ++i) s += h2[i] * net.w3[i][o];
    const double v = std::expm1(s);
    rgb[o] = v < 0 ? 0 : v;  // an overflow (inf or NaN) passes through for the caller to report
  }
}

std::array<double, kNbrdfInputs> nbrdf_input(double theta_h, double theta_d, double phi_d) {
  const double sd = std::sin(theta_d);
  return {std::sin(theta_h), 0.0, std::cos(theta_h), sd * std::cos(phi_d), sd * std::sin(phi_d),
          std::cos(theta_d)};
}

Expected<BrdfTable> tabulate_nbrdf(const NbrdfNet& net) {
  return tabulate_grid(
      [&net](const HalfDiff& hd, double rgb[3]) {
        eval_nbrdf(net, nbrdf_input(hd.theta_h, hd.theta_d, hd.phi_d), rgb);
      },
      "neural BRDF");
}

}  // namespace cbrdf::internal
