// SPDX-License-Identifier: MIT
// spec/gpu-tables.md is enough to write a shader: the evaluation it describes, written here from
// the spec alone in JavaScript over packGpuTables's texture, must give the native library's values
// (cbrdf.wasm's model.eval) at random pairs, relative error <= 1e-3 where the value is above 1e-6
// of the file's peak (the viewer test's bound for cbrdfGlsl), on the golden files and the
// 2-component Clayton file; and packGpuTables refuses bad input with messages naming the problem.
//
//   node gpu_tables_spec_test.mjs CBRDF_MJS GLSL_MJS FILE.cbrdf...
import { readFileSync } from 'node:fs';
import { basename } from 'node:path';
import { pathToFileURL } from 'node:url';

const [cbrdfPath, glslPath, ...files] = process.argv.slice(2);
const { load } = await import(pathToFileURL(cbrdfPath).href);
const { packGpuTables, packTable, kGpuLayout } = await import(pathToFileURL(glslPath).href);
const rt = await load();
let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) ++failures;
};

// --- The spec's evaluation (sections "The grid position" to "The result").
function evalBySpec(g, wi, wo) {
  if (!(wi[2] > 0) || !(wo[2] > 0)) return [0, 0, 0];
  const data = g.textures[0].data, u = g.uniforms;
  const T = (t) => data.subarray(4 * t, 4 * t + 4);
  const H = [0, 1, 2].map((c) => wi[c] + wo[c]), E = [0, 1, 2].map((c) => wi[c] - wo[c]);
  const rho2 = H[0] * H[0] + H[1] * H[1], len = Math.hypot(...H), chord = Math.hypot(...E);
  const thetaH = Math.atan2(Math.sqrt(rho2), H[2]), thetaD = Math.atan2(chord, len);
  const tilted = rho2 > 1.17549435e-38;
  const dx = tilted ? (E[0] * H[0] + E[1] * H[1]) * H[2] - E[2] * rho2 : E[0];
  const dy = tilted ? (E[1] * H[0] - E[0] * H[1]) * len : E[1];
  const alpha = Math.atan2(Math.abs(dy), Math.abs(dx));
  const phiD = (dx >= 0) === (dy >= 0) ? alpha : Math.PI - alpha;
  const clamp = (x, hi) => Math.min(hi, Math.max(0, x));
  const h = clamp(90 * Math.sqrt(thetaH / (Math.PI / 2)), 89);
  const d = clamp(thetaD * 180 / Math.PI, 89), p = clamp(phiD * 180 / Math.PI, 180);
  const i0 = Math.min(Math.floor(h), 89), j = Math.min(Math.floor(d), 89);
  const k0 = Math.min(Math.floor(p), 179);
  const fh = h - i0, fd = d - j, fp = p - k0;
  const mode = u.cbrdfResidualMode;

  // One slice's value at descriptor desc (H, D, P, 2 G + same).
  const slice = (desc, fdUsed, k, fpUsed) => {
    const G = Math.floor(desc[3] / 2), n = 3 * G, out = [0, 0, 0];
    for (let r = 0; r < G; ++r) {
      const rows = [[desc[0] + i0 * n, fh], [desc[1], fdUsed], [desc[2] + k * n, fpUsed]];
      const terms = rows.map(([t0, f]) => [0, 1, 2].map((q) => {
        const a = T(t0 + 3 * r + q), b = T(t0 + n + 3 * r + q);
        return [0, 1, 2].map((c) => a[c] * (1 - f) + b[c] * f);
      }));
      for (let c = 0; c < 3; ++c) {
        const [g1, w1, y1] = terms[0].map((v) => v[c]), [g2, w2, y2] = terms[1].map((v) => v[c]);
        const [g3, w3, y3] = terms[2].map((v) => v[c]);
        const W = w1 * w2 * w3, Y = y1 + w1 * y2 + w1 * w2 * y3;
        const a0 = T(rows[0][0] + 3 * r + c)[3], a = T(rows[2][0] + 3 * r + c)[3];
        const b0 = T(rows[1][0] + 3 * r + c)[3];
        const [X, Z] = a0 < 0 ? [W, Y] : [Y, W];
        const omh = Math.abs(a0) + a * X, oph = b0 + a * Z;
        out[c] += g1 * g2 * g3 * oph / (omh * omh * omh);
      }
    }
    return out;
  };
  let rgb = [0, 0, 0];
  if (mode !== 2) {
    const same = T(j)[3] % 2 === 1;
    const sides = !same && fd !== 0 ? [[j, 1 - fd], [j + 1, fd]] : [[j, 1]];
    const ends = k0 === 179 && fp !== 0 ? [[179, 1 - fp], [0, fp]] : [[k0, 1]];
    for (const [jj, wd] of sides) {
      for (const [k, wp] of ends) {
        const v = slice(T(jj), sides.length > 1 ? 0 : fd, k, ends.length > 1 ? 0 : fp);
        for (let c = 0; c < 3; ++c) rgb[c] += wd * wp * v[c];
      }
    }
  }
  const volume = (v) => {
    const i1 = Math.min(i0 + 1, 89), j1 = Math.min(j + 1, 89), k1 = (k0 + 1) % 180;
    const bin = (i, jj, k) => T(u.cbrdfVolumeBase + 1458000 * v + (90 * i + jj) * 180 + k);
    return [0, 1, 2].map((c) => {
      const at = (i, jj) => bin(i, jj, k0)[c] * (1 - fp) + bin(i, jj, k1)[c] * fp;
      const lo = at(i0, j) * (1 - fh) + at(i1, j) * fh, hi = at(i0, j1) * (1 - fh) + at(i1, j1) * fh;
      return lo * (1 - fd) + hi * fd;
    });
  };
  if (u.cbrdfGenericVolume === 1) rgb = volume(0).map((x, c) => rgb[c] + x);
  const residual = mode !== 0 ? volume(u.cbrdfVolumeCount - 1) : null;
  if (mode === 2) return residual;
  const max = 3.4028234663852886e38;
  rgb = rgb.map((x) => (Number.isNaN(x) ? 0 : Math.min(x, max)));
  if (mode === 1) {
    const scale = [1, 1.15, 1.66];
    rgb = rgb.map((x, c) => {
      const k = u.cbrdfKnee * scale[c] / 1500, r = residual[c];
      return Math.min(max, Math.max(0, Math.max(x, 0) * Math.exp(r) + k * Math.expm1(r)));
    });
  }
  return rgb;
}

// Random pairs over the hemisphere (a fixed generator: the same pairs each run).
let seed = 12345;
const random = () => ((seed = (seed * 1103515245 + 12345) >>> 0) / 4294967296);
const direction = () => {
  const z = random(), phi = 2 * Math.PI * random(), s = Math.sqrt(1 - z * z);
  return [s * Math.cos(phi), s * Math.sin(phi), z];
};
const kPairs = 1000;
const wi = new Float64Array(3 * kPairs), wo = new Float64Array(3 * kPairs);
for (let n = 0; n < kPairs; ++n) {
  wi.set(direction(), 3 * n);
  wo.set(direction(), 3 * n);
}

for (const file of files) {
  const model = rt.open(readFileSync(file));
  const packed = packGpuTables(model.gpuArrays());
  const native = model.eval(wi, wo);
  model.free();
  const peak = Math.max(...native);
  let worst = 0, compared = 0;
  for (let n = 0; n < kPairs; ++n) {
    const mine = evalBySpec(packed, wi.subarray(3 * n, 3 * n + 3), wo.subarray(3 * n, 3 * n + 3));
    for (let c = 0; c < 3; ++c) {
      const ref = native[3 * n + c];
      if (!(ref > 1e-6 * peak)) continue;
      ++compared;
      worst = Math.max(worst, Math.abs(mine[c] - ref) / ref);
    }
  }
  check(packed.layout === kGpuLayout && compared > kPairs && worst <= 1e-3,
        `${basename(file)}: the spec's evaluation of packGpuTables's texture against the native ` +
        `eval at ${kPairs} pairs (${compared} values): max rel. error ${worst.toExponential(2)}`);
}

// A measured table in the exact-table mode: a bin's value comes back at its centre.
{
  const rgb = new Float32Array(3 * 1458000);
  for (let i = 0; i < rgb.length; ++i) rgb[i] = (i % 997) / 997;
  const g = packTable(rgb);
  const data = g.textures[0].data, b = (45 * 90 + 30) * 180 + 60;
  const t = 4 * (g.uniforms.cbrdfVolumeBase + b);
  check(g.uniforms.cbrdfResidualMode === 2 && data[t] === rgb[3 * b] && data[t + 2] === rgb[3 * b + 2],
        'packTable: bin (45, 30, 60) at texel cbrdfVolumeBase + (90 i + j) 180 + k');
}

// Refusals.
const refuses = (f, pattern, what) => {
  try {
    f();
    check(false, `${what}: accepted`);
  } catch (err) {
    check(pattern.test(err.message), `${what}: "${err.message}"`);
  }
};
const golden = rt.open(readFileSync(files[0]));
const raw = golden.gpuArrays();
golden.free();
refuses(() => packGpuTables({ tables: [1, 2, 3] }), /raw\.tables must be the Float32Array/,
        'tables not a Float32Array');
const other = raw.tables.slice();
other[0] = 7;
refuses(() => packGpuTables({ ...raw, tables: other }), /tables of layout 7; this glsl\.mjs reads layout 1/,
        'tables of another layout');
const lossy = raw.tables.slice();
lossy[2] = 1;
refuses(() => packGpuTables({ ...raw, tables: lossy, residual: null }),
        /residual mode 1 without a residual array/, 'a residual mode without its array');
refuses(() => packGpuTables({ ...raw, tables: lossy, residual: new Float32Array(5) }),
        /residual holds 5 floats, expected 4374000/, 'a residual volume of the wrong size');

if (failures) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all gpu-tables spec checks passed');
