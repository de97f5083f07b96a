// SPDX-License-Identifier: MIT
// The GPU evaluation of a cbrdf model: `cbrdfGlsl`, GLSL ES 3.00 source of cbrdfEval(wi, wo)
// (ModelEvaluator::eval_f32's formulas), and `packGpuTables`, which turns a model's arrays
// (cbrdf/gpu_tables.h) into the textures and uniform values that source reads. The contract
// between the two is spec/gpu-tables.md, versioned by kGpuLayout.

/** The layout version of the tables this source reads (cbrdf/gpu_tables.h's kGpuTablesLayout). */
export const kGpuLayout = 1;

const kTableWidth = 4096;  // floats a row of the tables' texture (1024 RGBA texels)
const kVolume = [180, 90, 90];  // a MERL-grid volume's texels: phi_d, theta_d, theta_h

// Every identifier is prefixed `cbrdf` so that the source can be pasted into any fragment shader.
// Declarations carry their own precision; the includer's default float and int precision must be
// highp (WebGL2 guarantees it in fragment shaders).
export const cbrdfGlsl = `
uniform highp sampler2D cbrdfTables;        // the tables, RGBA32F, ${kTableWidth} floats a row
uniform highp sampler3D cbrdfGenericTerms;  // generic terms per bin, RGB32F 180 x 90 x 90
uniform highp sampler3D cbrdfResidualTerms; // residual (log1p units) or exact table, same shape
uniform highp float cbrdfHasGeneric;        // 1: add cbrdfGenericTerms
uniform highp float cbrdfResidualMode;      // 0 none, 1 log residual, 2 exact table
uniform highp float cbrdfKnee;              // the residual's knee, stored units

const highp float cbrdfPi = 3.14159265358979323846;
const highp float cbrdfDeg = 57.2957795130823208768;
const highp float cbrdfFltMax = 3.402823466e38;

// The tables as RGBA texels: float i, and the 4 floats from i (a multiple of 4).
highp vec4 cbrdfV(int i) {
  return texelFetch(cbrdfTables, ivec2((i >> 2) & ${kTableWidth / 4 - 1}, i >> ${Math.log2(kTableWidth)}), 0);
}
highp float cbrdfT(int i) { return cbrdfV(i & ~3)[i & 3]; }

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

// A slice's value at interpolated terms (scalar_eval.cc's add_slice), times weight.
highp vec3 cbrdfAddSlice(int s, int i0, highp float fh, int jl0, highp float fd, int k0,
                         highp float fp, highp float weight) {
  int base = 106 + 8 * s;
  int R = int(cbrdfT(base + 2)), G = int(cbrdfT(base + 3));
  int n = G * 12;
  int h0 = int(cbrdfT(base + 4)) + i0 * n, h1 = h0 + n;
  int d0 = int(cbrdfT(base + 5)) + jl0 * n, d1 = d0 + n;
  int p0 = int(cbrdfT(base + 6)) + k0 * n, p1 = p0 + n;
  int ko = int(cbrdfT(base + 7));
  highp float gh = 1.0 - fh, gd = 1.0 - fd, gp = 1.0 - fp;
  highp vec3 rgb = vec3(0.0);
  // A group of 4 slots at once (one RGBA texel per term), each lane's arithmetic that of one slot
  // in scalar_eval.cc; slot q adds to channel q / R, in the order of q.
  for (int grp = 0; grp < G; ++grp) {
    int o = grp * 12;
    highp vec4 g1 = cbrdfV(h0 + o) * gh + cbrdfV(h1 + o) * fh,
               w1 = cbrdfV(h0 + o + 4) * gh + cbrdfV(h1 + o + 4) * fh,
               y1 = cbrdfV(h0 + o + 8) * gh + cbrdfV(h1 + o + 8) * fh;
    highp vec4 g2 = cbrdfV(d0 + o) * gd + cbrdfV(d1 + o) * fd,
               w2 = cbrdfV(d0 + o + 4) * gd + cbrdfV(d1 + o + 4) * fd,
               y2 = cbrdfV(d0 + o + 8) * gd + cbrdfV(d1 + o + 8) * fd;
    highp vec4 g3 = cbrdfV(p0 + o) * gp + cbrdfV(p1 + o) * fp,
               w3 = cbrdfV(p0 + o + 4) * gp + cbrdfV(p1 + o + 4) * fp,
               y3 = cbrdfV(p0 + o + 8) * gp + cbrdfV(p1 + o + 8) * fp;
    int k = ko + grp * 28;
    highp vec4 w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
    highp vec4 omh = cbrdfV(k + 4) + cbrdfV(k + 8) * Y + cbrdfV(k + 12) * W;
    highp vec4 oph = cbrdfV(k + 16) + cbrdfV(k + 20) * Y + cbrdfV(k + 24) * W;
    highp vec4 term = cbrdfV(k) * (g1 * g2 * g3) * oph / (omh * omh * omh);
    for (int l = 0; l < 4; ++l) {
      int q = grp * 4 + l;
      if (q < 3 * R) rgb[q / R] += term[l];
    }
  }
  return weight * rgb;
}

int cbrdfSliceOf(int j) { return int(cbrdfT(16 + j)); }
int cbrdfSliceBegin(int s) { return int(cbrdfT(106 + 8 * s)); }
int cbrdfSliceEnd(int s) { return int(cbrdfT(106 + 8 * s + 1)); }

highp vec3 cbrdfAlongP(int s, int h0, highp float fh, int jl, highp float fd, int p0,
                       highp float fp, highp float weight) {
  if (p0 + 1 < 180 || fp == 0.0) return cbrdfAddSlice(s, h0, fh, jl, fd, p0, fp, weight);
  return cbrdfAddSlice(s, h0, fh, jl, fd, p0, 0.0, weight * (1.0 - fp)) +
         cbrdfAddSlice(s, h0, fh, jl, fd, 0, 0.0, weight * fp);
}

// A per-bin RGB volume (bin (i, j, k) at texel (k, j, i)).
highp vec3 cbrdfBin(highp sampler3D v, int i, int j, int k) {
  return texelFetch(v, ivec3(k, j, i), 0).rgb;
}

// Trilinear between the 8 bins around a position, theta_h and theta_d clamped, phi_d periodic
// (lookup_linear and the residual's interpolation).
highp vec3 cbrdfTrilinear(highp sampler3D v, highp vec3 pos) {
  highp float h = clamp(pos.x, 0.0, 89.0), d = clamp(pos.y, 0.0, 89.0), p = clamp(pos.z, 0.0, 180.0);
  int h0 = min(int(h), 88), d0 = min(int(d), 88), p0 = min(int(p), 179);
  int p1 = p0 + 1 == 180 ? 0 : p0 + 1;
  highp float fh = h - float(h0), fd = d - float(d0), fp = p - float(p0);
  highp vec3 a = cbrdfBin(v, h0, d0, p0) * (1.0 - fp) + cbrdfBin(v, h0, d0, p1) * fp;
  highp vec3 b = cbrdfBin(v, h0, d0 + 1, p0) * (1.0 - fp) + cbrdfBin(v, h0, d0 + 1, p1) * fp;
  highp vec3 c = cbrdfBin(v, h0 + 1, d0, p0) * (1.0 - fp) + cbrdfBin(v, h0 + 1, d0, p1) * fp;
  highp vec3 e = cbrdfBin(v, h0 + 1, d0 + 1, p0) * (1.0 - fp) + cbrdfBin(v, h0 + 1, d0 + 1, p1) * fp;
  return (a * (1.0 - fd) + b * fd) * (1.0 - fh) + (c * (1.0 - fd) + e * fd) * fh;
}

// The generic terms (interp_tables.h): trilinear between the 8 bins' summed values.
highp vec3 cbrdfGeneric(int i0, highp float fh, int d0, highp float fd, int k0, highp float fp) {
  int i1 = min(i0 + 1, 89), d1 = min(d0 + 1, 89), k1 = (k0 + 1) % 180;
  highp vec3 lo = (cbrdfBin(cbrdfGenericTerms, i0, d0, k0) * (1.0 - fp) +
                   cbrdfBin(cbrdfGenericTerms, i0, d0, k1) * fp) * (1.0 - fh) +
                  (cbrdfBin(cbrdfGenericTerms, i1, d0, k0) * (1.0 - fp) +
                   cbrdfBin(cbrdfGenericTerms, i1, d0, k1) * fp) * fh;
  highp vec3 hi = (cbrdfBin(cbrdfGenericTerms, i0, d1, k0) * (1.0 - fp) +
                   cbrdfBin(cbrdfGenericTerms, i0, d1, k1) * fp) * (1.0 - fh) +
                  (cbrdfBin(cbrdfGenericTerms, i1, d1, k0) * (1.0 - fp) +
                   cbrdfBin(cbrdfGenericTerms, i1, d1, k1) * fp) * fh;
  return lo * (1.0 - fd) + hi * fd;
}

highp float cbrdfSaturate(highp float v) { return isnan(v) ? 0.0 : min(v, cbrdfFltMax); }

// log1p and expm1 without their cancellation near 0 (GLSL has neither).
highp float cbrdfLog1p(highp float x) {
  highp float u = 1.0 + x;
  return u == 1.0 ? x : log(u) * (x / (u - 1.0));
}
highp float cbrdfExpm1(highp float x) {
  if (abs(x) < 1e-5) return x + 0.5 * x * x;
  highp float u = exp(x);
  return u == 1.0 ? x : (u - 1.0) * (x / log(u));
}

// ModelEvaluator::eval_f32: RGB (1/sr) at a pair of unit vectors (z the normal); 0 when either
// is below the horizon.
highp vec3 cbrdfEval(highp vec3 wi, highp vec3 wo) {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return vec3(0.0);
  highp vec3 pos = cbrdfGridPosition(wi, wo);
  if (cbrdfResidualMode == 2.0) return cbrdfTrilinear(cbrdfResidualTerms, pos);
  int h0 = min(int(pos.x), 89), d0 = min(int(pos.y), 89), p0 = min(int(pos.z), 179);
  highp float fh = pos.x - float(h0), fd = pos.y - float(d0), fp = pos.z - float(p0);
  int s0 = cbrdfSliceOf(d0);
  highp vec3 rgb;
  if (d0 + 1 < cbrdfSliceEnd(s0) || fd == 0.0) {
    rgb = cbrdfAlongP(s0, h0, fh, d0 - cbrdfSliceBegin(s0), fd, p0, fp, 1.0);
  } else {
    int s1 = cbrdfSliceOf(d0 + 1);
    rgb = cbrdfAlongP(s0, h0, fh, d0 - cbrdfSliceBegin(s0), 0.0, p0, fp, 1.0 - fd);
    rgb += cbrdfAlongP(s1, h0, fh, d0 + 1 - cbrdfSliceBegin(s1), 0.0, p0, fp, fd);
  }
  if (cbrdfHasGeneric == 1.0) rgb += cbrdfGeneric(h0, fh, d0, fd, p0, fp);
  rgb = vec3(cbrdfSaturate(rgb.r), cbrdfSaturate(rgb.g), cbrdfSaturate(rgb.b));
  if (cbrdfResidualMode == 1.0) {
    highp vec3 r = cbrdfTrilinear(cbrdfResidualTerms, pos);
    highp vec3 scale = vec3(1.0, 1.15, 1.66) / 1500.0;
    for (int c = 0; c < 3; ++c) {
      highp float k = cbrdfKnee * scale[c];
      highp float y = cbrdfLog1p(max(rgb[c], 0.0) / k) + r[c];
      rgb[c] = y > 0.0 ? min(cbrdfExpm1(y) * k, cbrdfFltMax) : 0.0;
    }
  }
  return rgb;
}
`;

/**
 * The textures and uniform values cbrdfGlsl reads, from a model's arrays as cbrdf.wasm gives
 * them (cbrdf_viewer_array: tables, generic, residual; Float32Array or null).
 * See spec/gpu-tables.md for the layout.
 */
export function packGpuTables(raw) {
  const tables = raw?.tables;
  if (!(tables instanceof Float32Array) || tables.length < 106) {
    throw new TypeError('packGpuTables: raw.tables must be the Float32Array of a model\'s tables');
  }
  if (tables[0] !== kGpuLayout) {
    throw new Error(`packGpuTables: tables of layout ${tables[0]}, this cbrdfGlsl reads layout ` +
                    `${kGpuLayout} (a cbrdf.wasm and glsl.mjs of different versions)`);
  }
  const volumeBins = kVolume[0] * kVolume[1] * kVolume[2];
  const volume = (uniform, data, what) => {
    if (data && data.length !== 3 * volumeBins) {
      throw new Error(`packGpuTables: ${what} holds ${data.length} floats, expected ${3 * volumeBins}`);
    }
    return data ? { uniform, dimension: 3, width: kVolume[0], height: kVolume[1], depth: kVolume[2],
                    format: 'RGB32F', data }
                : { uniform, dimension: 3, width: 1, height: 1, depth: 1, format: 'RGB32F',
                    data: new Float32Array(3) };
  };
  const rows = Math.max(1, Math.ceil(tables.length / kTableWidth));
  const padded = new Float32Array(rows * kTableWidth);
  padded.set(tables);
  return {
    layout: kGpuLayout,
    textures: [
      { uniform: 'cbrdfTables', dimension: 2, width: kTableWidth / 4, height: rows, depth: 1,
        format: 'RGBA32F', data: padded },
      volume('cbrdfGenericTerms', raw.generic, 'generic'),
      volume('cbrdfResidualTerms', raw.residual, 'residual'),
    ],
    uniforms: {
      cbrdfHasGeneric: tables[4] === 1 ? 1 : 0,
      cbrdfResidualMode: tables[2],
      cbrdfKnee: tables[3],
    },
  };
}
