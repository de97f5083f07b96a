// SPDX-License-Identifier: MIT
// RESD's range-coded codes, the writer (spec 4.6, "Range-coded codes"; the contexts are the
// decoder's bitstream/residual_code_contexts.h, shared with the reader).
#include "bitstream/residual_codes_writer.h"

#include <memory>

#include "bitstream/range_encoder.h"
#include "bitstream/residual_code_contexts.h"

namespace cbrdf::internal {
namespace {

using namespace residual_contexts;

template <class Sink>
void put_code(Sink& s, CodeModel& m, int k, int sk, std::int32_t v) {
  Contexts& c = m.ctx[std::size_t(k)];
  s.bit(m.zero[std::size_t(k)], v == 0 ? 0 : 1);
  if (v == 0) return;
  s.bit(m.sign[std::size_t(sk)], v < 0 ? 1 : 0);
  const std::uint32_t x = std::uint32_t(magnitude(v));
  int n = 0;
  while ((x >> (n + 1)) != 0) ++n;
  for (int j = 0; j < n; ++j) s.bit(c.exponent[std::size_t(j)], 1);
  s.bit(c.exponent[std::size_t(n)], 0);
  for (int j = n - 1; j >= 0; --j)
    s.bit(c.mantissa[std::size_t(n)][std::size_t(j)], int((x >> j) & 1u));
}

}  // namespace

std::vector<std::uint8_t> encode_residual_codes(const std::int32_t* q, const NotMeasured& mask) {
  auto m = std::make_unique<CodeModel>();
  internal::Encoder e;
  Coded coded;  // all of it before the first row: the contexts read earlier rows only
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    if (q[b] == 0) continue;
    coded.magnitude[b] = capped_magnitude(q[b]);
    coded.nonzero[b / kPhiDBins] = 1;
  }
  for_each_row(q, mask, coded, [&](const Row& row) {
    for (const std::size_t p : row.bins) {
      put_code(e, *m, row.k[p], row.signs.context(p), q[row.b0 + p]);
    }
    return true;
  });
  return e.finish();
}

}  // namespace cbrdf::internal
