// SPDX-License-Identifier: MIT
// The GPU evaluation of a cbrdf model: `cbrdfGlsl`, GLSL ES 3.00 source of cbrdfEval(wi, wo)
// (ModelEvaluator::eval_f32's formulas), and `packGpuTables`, which turns a model's arrays
// (cbrdf/gpu_tables.h) into the textures and uniform values that source reads. The contract
// between the two is spec/gpu-tables.md, versioned by kGpuLayout.

/** The layout version of packGpuTables's textures, which cbrdfGlsl reads. */
export const kGpuLayout = 2;

const kRawLayout = 1;          // cbrdf/gpu_tables.h's kGpuTablesLayout, what packGpuTables reads
const kTexelsPerRow = 2048;    // of the tables' texture
const kDescriptors = 90;       // texels: one per theta_d bin, before the rows
const kVolumeBins = 90 * 90 * 180;  // texels a volume: theta_h, theta_d, phi_d

// Every identifier is prefixed `cbrdf` so that the source can be pasted into any fragment shader.
// Declarations carry their own precision; the includer's default float and int precision must be
// highp (WebGL2 guarantees it in fragment shaders).
export const cbrdfGlsl = `
uniform highp sampler2D cbrdfTables;     // RGBA32F, ${kTexelsPerRow} texels a row: descriptors, rows, volumes
uniform highp float cbrdfVolumeBase;     // the texel of volume 0's first bin
uniform highp float cbrdfVolumeCount;    // per-bin volumes: 0, 1 or 2
uniform highp float cbrdfGenericVolume;  // 1: volume 0 holds the generic terms
uniform highp float cbrdfResidualMode;   // 0 none, 1 log residual (last volume), 2 exact table
uniform highp float cbrdfKnee;           // the residual's knee, stored units

const highp float cbrdfPi = 3.14159265358979323846;
const highp float cbrdfDeg = 57.2957795130823208768;
const highp float cbrdfFltMax = 3.402823466e38;

// Texel t of the tables.
highp vec4 cbrdfTexel(int t) {
  return texelFetch(cbrdfTables, ivec2(t & ${kTexelsPerRow - 1}, t >> ${Math.log2(kTexelsPerRow)}), 0);
}

// trig.h: atan for |x| <= 7/16 (fdlibm's polynomial) and atan2 in the first quadrant.
highp float cbrdfAtanCore(highp float x) {
  highp float z = x * x, w = z * z;
  highp float s1 = z * (3.33333333333329318027e-01 + w * (1.42857142725034663711e-01 +
             w * (9.09088713343650656196e-02 + w * (6.66107313738753120669e-02 +
             w * (4.97687799461593236017e-02 + w * 1.62858201153657823623e-02)))));
  highp float s2 = w * (-1.99999999998764832476e-01 + w * (-1.11111104054623557880e-01 +
             w * (-7.69187620504482999495e-02 + w * (-5.83357013379057348645e-02 +
             w * -3.65315727442169155270e-02))));
  return x - x * (s1 + s2);
}
highp float cbrdfAtan2q(highp float a, highp float b) {
  const highp float kTanPi8 = 0.41421356237309504880;
  bool above = a > kTanPi8 * b, belowFar = !(b > kTanPi8 * a);
  bool mid = above && !belowFar, far = above && belowFar;
  highp float num = mid ? a - b : (far ? -b : a);
  highp float den = mid ? a + b : (far ? a : b);
  highp float base = mid ? cbrdfPi / 4.0 : (far ? cbrdfPi / 2.0 : 0.0);
  highp float r = base + cbrdfAtanCore(num / den);
  return den > 0.0 ? r : 0.0;
}

// position.h: the continuous MERL grid position (theta_h, theta_d, phi_d bins) of a pair.
highp vec3 cbrdfGridPosition(highp vec3 wi, highp vec3 wo) {
  highp vec3 H = wi + wo, E = wi - wo;
  highp float rho2 = H.x * H.x + H.y * H.y;
  highp float len2 = rho2 + H.z * H.z;
  highp float chord2 = E.x * E.x + E.y * E.y + E.z * E.z;
  highp float rho = sqrt(rho2), len = sqrt(len2), chord = sqrt(chord2);
  highp float th = cbrdfAtan2q(rho, H.z);
  highp float td = cbrdfAtan2q(chord, len);
  bool tilted = rho2 > 1.17549435e-38;
  highp float dx = tilted ? (E.x * H.x + E.y * H.y) * H.z - E.z * rho2 : E.x;
  highp float dy = tilted ? (E.y * H.x - E.x * H.y) * len : E.y;
  highp float alpha = cbrdfAtan2q(abs(dy), abs(dx));
  highp float phi = (dx >= 0.0) == (dy >= 0.0) ? alpha : cbrdfPi - alpha;
  highp float gh = sqrt(th * (2.0 / cbrdfPi));
  return vec3(min(89.0, max(0.0, gh * 90.0)), min(89.0, max(0.0, td * cbrdfDeg)),
              min(180.0, max(0.0, phi * cbrdfDeg)));
}

// One slice's value (scalar_eval.cc's add_slice at interpolated terms) from the descriptor of a
// theta_d bin: the texels of its slice's theta_h row 0, of its own theta_d row, of its slice's
// phi_d row 0, and 2 groups + (1 when the next bin is in the same slice). A row holds per group
// the texels g, w, y: in .rgb the r-th product-form component of R, G and B (theta_h's g times
// the component's k), in .a the slice's constants of the 3 channels: theta_h rows a0 (negated
// when 1 - h uses W), phi_d rows a, theta_d rows b0.
highp vec3 cbrdfSlice(highp vec4 desc, int h0, highp float fh, highp float fd, int k0,
                      highp float fp) {
  int groups = int(desc.w) >> 1, n = 3 * groups;
  int h = int(desc.x) + h0 * n, d = int(desc.y), p = int(desc.z) + k0 * n;
  highp float gh = 1.0 - fh, gd = 1.0 - fd, gp = 1.0 - fp;
  highp vec3 sum = vec3(0.0);
  for (int r = 0; r < groups; ++r) {
    highp vec4 gh0 = cbrdfTexel(h), wh0 = cbrdfTexel(h + 1), yh0 = cbrdfTexel(h + 2);
    highp vec4 gd0 = cbrdfTexel(d), wd0 = cbrdfTexel(d + 1), yd0 = cbrdfTexel(d + 2);
    highp vec4 gp0 = cbrdfTexel(p), wp0 = cbrdfTexel(p + 1), yp0 = cbrdfTexel(p + 2);
    highp vec3 g1 = gh0.rgb * gh + cbrdfTexel(h + n).rgb * fh;
    highp vec3 w1 = wh0.rgb * gh + cbrdfTexel(h + n + 1).rgb * fh;
    highp vec3 y1 = yh0.rgb * gh + cbrdfTexel(h + n + 2).rgb * fh;
    highp vec3 g2 = gd0.rgb * gd + cbrdfTexel(d + n).rgb * fd;
    highp vec3 w2 = wd0.rgb * gd + cbrdfTexel(d + n + 1).rgb * fd;
    highp vec3 y2 = yd0.rgb * gd + cbrdfTexel(d + n + 2).rgb * fd;
    highp vec3 g3 = gp0.rgb * gp + cbrdfTexel(p + n).rgb * fp;
    highp vec3 w3 = wp0.rgb * gp + cbrdfTexel(p + n + 1).rgb * fp;
    highp vec3 y3 = yp0.rgb * gp + cbrdfTexel(p + n + 2).rgb * fp;
    highp vec3 w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
    // 1 - h = a0 + a X and 1 + h = b0 + a Z: (X, Z) = (Y, W), or (W, Y) where a0 is negated.
    highp vec3 a0 = vec3(gh0.a, wh0.a, yh0.a), a = vec3(gp0.a, wp0.a, yp0.a);
    highp vec3 b0 = vec3(gd0.a, wd0.a, yd0.a);
    bvec3 swapped = lessThan(a0, vec3(0.0));
    highp vec3 omh = abs(a0) + a * mix(Y, W, swapped), oph = b0 + a * mix(W, Y, swapped);
    sum += (g1 * g2 * g3) * oph / (omh * omh * omh);
    h += 3;
    d += 3;
    p += 3;
  }
  return sum;
}

// Trilinear between the 8 bins around a grid position in volume v (bin (i, j, k) at texel
// cbrdfVolumeBase + 1458000 v + (90 i + j) 180 + k), theta_h and theta_d clamped, phi_d periodic
// (interp_tables.h).
highp vec3 cbrdfVolume(int v, int i0, highp float fh, int d0, highp float fd, int k0,
                       highp float fp) {
  int i1 = min(i0 + 1, 89), d1 = min(d0 + 1, 89), k1 = k0 == 179 ? 0 : k0 + 1;
  int base = int(cbrdfVolumeBase) + ${kVolumeBins} * v;
  int a = base + i0 * 16200, c = base + i1 * 16200, j0 = d0 * 180, j1 = d1 * 180;
  highp float gh = 1.0 - fh, gp = 1.0 - fp;
  highp vec3 lo = (cbrdfTexel(a + j0 + k0).rgb * gp + cbrdfTexel(a + j0 + k1).rgb * fp) * gh +
                  (cbrdfTexel(c + j0 + k0).rgb * gp + cbrdfTexel(c + j0 + k1).rgb * fp) * fh;
  highp vec3 hi = (cbrdfTexel(a + j1 + k0).rgb * gp + cbrdfTexel(a + j1 + k1).rgb * fp) * gh +
                  (cbrdfTexel(c + j1 + k0).rgb * gp + cbrdfTexel(c + j1 + k1).rgb * fp) * fh;
  return lo * (1.0 - fd) + hi * fd;
}

highp float cbrdfSaturate(highp float v) { return isnan(v) ? 0.0 : min(v, cbrdfFltMax); }

// e^x - 1 (ex = e^x) without its cancellation near 0 (GLSL has no expm1): Taylor to x^6 where
// |x| < 0.1 (relative error below 3e-10 there).
highp vec3 cbrdfExpm1(highp vec3 x, highp vec3 ex) {
  highp vec3 series = x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 +
                                                                        x * (1.0 / 720.0))))));
  return mix(ex - 1.0, series, lessThan(abs(x), vec3(0.1)));
}

// ModelEvaluator::eval_f32: RGB (1/sr) at a pair of unit vectors (z the normal); 0 when either
// is below the horizon. Each part has one call site, in a loop run as often as a pixel needs it:
// a GPU that runs both sides of every branch (SwiftShader does) then pays for each part once.
highp vec3 cbrdfEval(highp vec3 wi, highp vec3 wo) {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return vec3(0.0);
  highp vec3 pos = cbrdfGridPosition(wi, wo);
  int h0 = min(int(pos.x), 89), d0 = min(int(pos.y), 89), p0 = min(int(pos.z), 179);
  highp float fh = pos.x - float(h0), fd = pos.y - float(d0), fp = pos.z - float(p0);
  // The slices: one (its theta_d rows d0 and d0 + 1), or across a slice boundary the two slices
  // at their rows, weighted 1 - fd and fd; likewise across phi_d's wrap (rows 179 and 0).
  bool acrossD = fd != 0.0 && (int(cbrdfTexel(d0).w) & 1) == 0;
  bool acrossP = p0 == 179 && fp != 0.0;
  int np = acrossP ? 2 : 1;
  int count = cbrdfResidualMode == 2.0 ? 0 : (acrossD ? 2 : 1) * np;
  highp vec3 rgb = vec3(0.0);
  for (int e = 0; e < count; ++e) {
    int side = e / np, end = e - side * np, j = d0 + side;
    highp float wd = acrossD ? (side == 0 ? 1.0 - fd : fd) : 1.0;
    highp float wp = acrossP ? (end == 0 ? 1.0 - fp : fp) : 1.0;
    rgb += (wd * wp) * cbrdfSlice(cbrdfTexel(j), h0, fh, acrossD ? 0.0 : fd, end == 0 ? p0 : 0,
                                  acrossP ? 0.0 : fp);
  }
  // The volumes: the generic terms (added to the slices'), the residual layer (last).
  highp vec3 residual = vec3(0.0);
  int volumes = int(cbrdfVolumeCount);
  for (int v = 0; v < volumes; ++v) {
    highp vec3 t = cbrdfVolume(v, h0, fh, d0, fd, p0, fp);
    if (v == 0 && cbrdfGenericVolume == 1.0) rgb += t; else residual = t;
  }
  if (cbrdfResidualMode == 2.0) return residual;
  rgb = vec3(cbrdfSaturate(rgb.r), cbrdfSaturate(rgb.g), cbrdfSaturate(rgb.b));
  // The layer adds r to log1p(v / k): expm1(log1p(v / k) + r) k = v e^r + k expm1(r), which
  // needs no logarithm. (A loop of 0 or 1 pass, as the volumes': code behind an if costs every
  // pixel where both sides of branches run.)
  int transforms = cbrdfResidualMode == 1.0 ? 1 : 0;
  for (int i = 0; i < transforms; ++i) {
    highp vec3 knee = cbrdfKnee * vec3(1.0, 1.15, 1.66) / 1500.0;
    highp vec3 e = exp(residual);
    rgb = min(max(max(rgb, 0.0) * e + knee * cbrdfExpm1(residual, e), 0.0), cbrdfFltMax);
  }
  return rgb;
}
`;

function fail(message) {
  throw new Error(`packGpuTables: ${message}`);
}

// One slice of the raw tables (layout 1, cbrdf/gpu_tables.h) in layout 2 (spec/gpu-tables.md):
// { begin, end, groups, h, d, p } with each axis's rows of texels (4 floats).
function repackSlice(t, d) {
  const [begin, end, R, G, hOff, dOff, pOff, kOff] = t.subarray(d, d + 8);
  if (!(end > begin && R >= 1 && G === Math.ceil(3 * R / 4)) ||
      [hOff, dOff, pOff, kOff].some((o) => o % 4 || o + 12 * G > t.length)) {
    fail(`a slice descriptor at ${d} is not one of layout ${kRawLayout}`);
  }
  const constant = (q, e) => t[kOff + 28 * (q >> 2) + 4 * e + (q & 3)];
  // The product-form slots that add anything (k != 0), per channel.
  const slots = [0, 1, 2].map((c) => {
    const list = [];
    for (let r = 0; r < R; ++r) if (constant(c * R + r, 0) !== 0) list.push(c * R + r);
    return list;
  });
  const groups = Math.max(...slots.map((l) => l.length));
  // Per group and channel: k, a0 (negated when swapped), a, b0; zero slots add 0.
  const k = new Float32Array(3 * groups), a0 = new Float32Array(3 * groups).fill(1);
  const a = new Float32Array(3 * groups), b0 = new Float32Array(3 * groups).fill(1);
  slots.forEach((list, c) => list.forEach((q, r) => {
    const [a1, a2, b1, b2] = [2, 3, 5, 6].map((e) => constant(q, e));
    const swapped = a2 !== 0 || b1 !== 0;
    const [x, z] = swapped ? [a2, b1] : [a1, b2];
    if (x !== z || (swapped ? a1 !== 0 || b2 !== 0 || !(constant(q, 1) > 0)
                            : !(constant(q, 1) >= 0))) {
      fail(`slot constants (${[1, 2, 3, 4, 5, 6].map((e) => constant(q, e)).join(', ')}) are ` +
           `not of a form layout ${kGpuLayout} holds`);
    }
    const i = 3 * r + c;
    k[i] = constant(q, 0);
    a0[i] = swapped ? -constant(q, 1) : constant(q, 1);
    a[i] = x;
    b0[i] = constant(q, 4);
  }));
  const n = 12 * groups;  // floats a row
  // Rows of one axis: g, w, y of each group's slots in .rgb, `extra` (3 per group) in .a.
  const axis = (off, count, scaled, extra) => {
    const out = new Float32Array(count * n);
    for (let i = 0; i < count; ++i) {
      for (let r = 0; r < groups; ++r) {
        const to = i * n + 12 * r;
        for (let c = 0; c < 3; ++c) {
          out[to + 4 * c + 3] = extra[3 * r + c];
          const q = slots[c][r];
          if (q === undefined) continue;
          const from = off + i * 12 * G + 12 * (q >> 2) + (q & 3);
          out[to + c] = scaled ? t[from] * k[3 * r + c] : t[from];
          out[to + 4 + c] = t[from + 4];
          out[to + 8 + c] = t[from + 8];
        }
      }
    }
    return out;
  };
  return { begin, end, groups, h: axis(hOff, 91, true, a0), d: axis(dOff, end - begin + 1, false, b0),
           p: axis(pOff, 181, false, a) };
}

// The texel data of the tables: a descriptor texel per theta_d bin, each slice's theta_h,
// theta_d and phi_d rows, then from the next row the volumes (RGB in RGBA texels).
function tablesTexture(t, volumes) {
  const slices = t[1];
  const packed = [];
  if (t[2] !== 2) {
    for (let s = 0; s < slices; ++s) packed.push(repackSlice(t, 106 + 8 * s));
  }
  let texels = kDescriptors;
  const at = packed.map((sl) => {
    const o = { h: texels, d: texels + sl.h.length / 4, p: texels + (sl.h.length + sl.d.length) / 4 };
    texels = o.p + sl.p.length / 4;
    return o;
  });
  // The volumes from the row after the tables.
  const volumeBase = Math.ceil(texels / kTexelsPerRow) * kTexelsPerRow;
  const rows = Math.max(1, Math.ceil((volumeBase + kVolumeBins * volumes.length) / kTexelsPerRow));
  const data = new Float32Array(rows * 4 * kTexelsPerRow);
  volumes.forEach(([what, v], n) => {
    if (v.length !== 3 * kVolumeBins) {
      fail(`${what} holds ${v.length} floats, expected ${3 * kVolumeBins}`);
    }
    copyRgbToRgba(v, data, 4 * (volumeBase + kVolumeBins * n), kVolumeBins);
  });
  packed.forEach((sl, s) => {
    data.set(sl.h, 4 * at[s].h);
    data.set(sl.d, 4 * at[s].d);
    data.set(sl.p, 4 * at[s].p);
  });
  if (packed.length) {
    for (let j = 0; j < 90; ++j) {
      const s = t[16 + j];
      const sl = packed[s];
      if (!sl || j < sl.begin || j >= sl.end) fail(`theta_d bin ${j} has no slice`);
      const next = j + 1 < sl.end || j === 89 ? 1 : 0;
      data.set([at[s].h, at[s].d + (j - sl.begin) * 3 * sl.groups, at[s].p, 2 * sl.groups + next],
               4 * j);
    }
  }
  return { volumeBase,
           texture: { uniform: 'cbrdfTables', dimension: 2, width: kTexelsPerRow, height: rows,
                      depth: 1, format: 'RGBA32F', data } };
}

function copyRgbToRgba(from, to, offset, count) {
  for (let i = 0, f = 0, o = offset; i < count; ++i, f += 3, o += 4) {
    to[o] = from[f];
    to[o + 1] = from[f + 1];
    to[o + 2] = from[f + 2];
  }
}

/**
 * The textures and uniform values cbrdfGlsl reads, from a model's arrays as cbrdf.wasm gives
 * them (cbrdf_viewer_array: tables, generic, residual; Float32Array or null).
 * See spec/gpu-tables.md for the layout.
 */
export function packGpuTables(raw) {
  const t = raw?.tables;
  if (!(t instanceof Float32Array) || t.length < 106) {
    throw new TypeError('packGpuTables: raw.tables must be the Float32Array of a model\'s tables');
  }
  if (t[0] !== kRawLayout) {
    fail(`tables of layout ${t[0]}; this glsl.mjs reads layout ${kRawLayout} (cbrdf.wasm and ` +
         'glsl.mjs from different versions of cbrdf)');
  }
  const mode = t[2];
  if (![0, 1, 2].includes(mode)) fail(`residual mode ${mode} is not 0, 1 or 2`);
  if (mode !== 0 && !raw.residual) fail(`residual mode ${mode} without a residual array`);
  // In mode 2 the exact table replaces the model: its generic terms are not read.
  const volumes = [];
  if (raw.generic && mode !== 2) volumes.push(['generic', raw.generic]);
  if (mode !== 0) volumes.push(['residual', raw.residual]);
  const { texture, volumeBase } = tablesTexture(t, volumes);
  return {
    layout: kGpuLayout,
    textures: [texture],
    uniforms: {
      cbrdfVolumeBase: volumeBase,
      cbrdfVolumeCount: volumes.length,
      cbrdfGenericVolume: raw.generic && mode !== 2 ? 1 : 0,
      cbrdfResidualMode: mode,
      cbrdfKnee: t[3],
    },
  };
}

/**
 * The textures and uniforms that draw a measured table with cbrdfEval: rgb holds the physical
 * values (1/sr) per MERL bin, RGB interleaved, bin (theta_h 90 + theta_d) 180 + phi_d; 0 where
 * not measured. cbrdfEval then interpolates it trilinearly (the exact-table mode).
 */
export function packTable(rgb) {
  const tables = new Float32Array(106);
  tables[0] = kRawLayout;
  tables[2] = 2;
  return packGpuTables({ tables, generic: null, residual: rgb });
}
