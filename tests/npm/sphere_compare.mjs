// SPDX-License-Identifier: MIT
// The package test's comparison: which pixels lie inside the sphere, and the PSNR there.

// Pixels whose centre ray (`cbrdf render`'s camera, tools/render/integrator.cc: perspective with a
// vertical fovDeg, or orthographic with viewHeight; looking at the origin with +y up) meets the
// sphere at the origin where n.v >= minCos: away from the silhouette, where a tessellated sphere's
// outline and normals depart from the true sphere's (minCos 0.2 leaves out a rim of about 2 pixels
// here). 1 inside, 0 elsewhere, row 0 at the top.
export function interiorMask({ width, height, position, fovDeg, orthographic, viewHeight, radius }, minCos = 0.2) {
  const len = Math.hypot(...position);
  const fwd = position.map((v) => -v / len);
  // right = normalize(forward x (0, 1, 0)), up = right x forward
  let right = [-fwd[2], 0, fwd[0]];
  const rl = Math.hypot(...right);
  right = right.map((v) => v / rl);
  const up = [right[1] * fwd[2] - right[2] * fwd[1], right[2] * fwd[0] - right[0] * fwd[2],
              right[0] * fwd[1] - right[1] * fwd[0]];
  const tanHalf = Math.tan((fovDeg * Math.PI) / 360), aspect = width / height;
  const mask = new Uint8Array(width * height);
  for (let y = 0; y < height; ++y) {
    for (let x = 0; x < width; ++x) {
      const sx = (((x + 0.5) / width) * 2 - 1) * aspect, sy = 1 - ((y + 0.5) / height) * 2;
      let o = position, d = fwd;
      if (orthographic) {
        o = [0, 1, 2].map((k) => position[k] + (right[k] * sx + up[k] * sy) * (viewHeight / 2));
      } else {
        d = [0, 1, 2].map((k) => fwd[k] + (right[k] * sx + up[k] * sy) * tanHalf);
        const dl = Math.hypot(...d);
        d = d.map((v) => v / dl);
      }
      // |o + t d| = r: t^2 + 2 (o.d) t + |o|^2 - r^2 = 0, the nearer root.
      const b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
      const disc = b * b - (o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - radius * radius);
      if (disc < 0) continue;
      const t = -b - Math.sqrt(disc);
      const n = [0, 1, 2].map((k) => (o[k] + t * d[k]) / radius);
      if (-(n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) >= minCos) mask[y * width + x] = 1;
    }
  }
  return mask;
}

// `got` against `ref` (RGB float arrays) over the masked pixels: { psnr, peak, pixels } with the
// reference's largest value there as the peak and the MSE over all three channels; `channels`,
// each channel's PSNR with its own peak; `ratios`, each channel's median of got / ref over the
// pixels above 1e-3 of its peak: a scale error (exposure, light units), which a PSNR against the
// peak forgives when the highlight is small. A median, as a sharp highlight's few pixels depend
// on the sphere's tessellation more than on the material.
export function compare(ref, got, mask) {
  const se = [0, 0, 0], peaks = [0, 0, 0];
  let n = 0;
  for (let i = 0; i < mask.length; ++i) {
    if (!mask[i]) continue;
    ++n;
    for (let c = 0; c < 3; ++c) {
      const r = ref[3 * i + c], g = got[3 * i + c];
      // A NaN or infinity in the render is an error, not a small difference.
      se[c] += Number.isFinite(g) ? (r - g) ** 2 : Infinity;
      peaks[c] = Math.max(peaks[c], r);
    }
  }
  if (n === 0) throw new Error('psnr: no pixel inside the mask');
  const peak = Math.max(...peaks);
  const db = (p, mse) => (mse === 0 ? Infinity : 10 * Math.log10((p * p) / mse));
  return { psnr: db(peak, (se[0] + se[1] + se[2]) / (3 * n)), peak, pixels: n,
           channels: se.map((s, c) => db(peaks[c], s / n)),
           ratios: peaks.map((p, c) => medianRatio(ref, got, mask, c, 1e-3 * p)) };
}

function medianRatio(ref, got, mask, c, floor) {
  const q = [];
  for (let i = 0; i < mask.length; ++i) {
    if (mask[i] && ref[3 * i + c] > floor) q.push(got[3 * i + c] / ref[3 * i + c]);
  }
  if (q.length === 0) return 1;  // a black channel: the PSNR judges it
  q.sort((a, b) => a - b);
  return q[q.length >> 1];
}
