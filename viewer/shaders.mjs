// SPDX-License-Identifier: MIT
// GLSL ES 3.00 sources of the viewer: the copula model evaluated from the evaluator's float32
// tables (ModelEvaluator::eval_f32's formulas, eval/interp_tables.h and scalar_eval.cc, read from
// the flat layout of cbrdf/gpu_tables.h), a MERL table as a 3D texture (trilinear, as
// lookup_linear), and the programs built on them: pairs (the browser test), sphere and images.

export const kTableWidth = 4096;  // the tables' 2D texture: one float per texel, rows of 4096

// The BRDF of one viewport: MODEL evaluates the tables; otherwise the 3D texture is the BRDF.
const brdfCommon = `
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler3D;
const float kPi = 3.14159265358979323846;
const float kDeg = 57.2957795130823208768;
const float kFltMax = 3.402823466e38;
uniform sampler2D uTab;   // the tables (viewer_tables.cc), RGBA32F
uniform sampler3D uGen;   // generic terms per bin, RGB32F 180 x 90 x 90 (phi_d, theta_d, theta_h)
uniform sampler3D uVol;   // residual (log1p) or exact/measured table (physical), same shape
uniform int uMode;        // 0 model tables, 1 a table in uVol alone (a .binary)
uniform int uGeneric;     // 1: add uGen
uniform int uResidual;    // 0 none, 1 log residual in uVol, 2 exact table in uVol
uniform float uKnee;      // the residual's knee, stored units

// The tables as RGBA texels, ${kTableWidth} floats a row: float i, and the 4 floats from i (a
// multiple of 4: a group's g, w or y, or constant, of its 4 slots).
vec4 V(int i) { return texelFetch(uTab, ivec2((i >> 2) & ${kTableWidth / 4 - 1}, i >> ${Math.log2(kTableWidth)}), 0); }
float T(int i) { return V(i & ~3)[i & 3]; }

// trig.h: atan for |x| <= 7/16 (fdlibm's polynomial) and atan2 in the first quadrant.
float atanCore(float x) {
  float z = x * x, w = z * z;
  float s1 = z * (3.33333333333329318027e-01 + w * (1.42857142725034663711e-01 +
             w * (9.09088713343650656196e-02 + w * (6.66107313738753120669e-02 +
             w * (4.97687799461593236017e-02 + w * 1.62858201153657823623e-02)))));
  float s2 = w * (-1.99999999998764832476e-01 + w * (-1.11111104054623557880e-01 +
             w * (-7.69187620504482999495e-02 + w * (-5.83357013379057348645e-02 +
             w * -3.65315727442169155270e-02))));
  return x - x * (s1 + s2);
}
float atan2q(float a, float b) {
  const float kTanPi8 = 0.41421356237309504880;
  bool above = a > kTanPi8 * b, belowFar = !(b > kTanPi8 * a);
  bool mid = above && !belowFar, far = above && belowFar;
  float num = mid ? a - b : (far ? -b : a);
  float den = mid ? a + b : (far ? a : b);
  float base = mid ? kPi / 4.0 : (far ? kPi / 2.0 : 0.0);
  float r = base + atanCore(num / den);
  return den > 0.0 ? r : 0.0;
}

// position.h: the continuous MERL grid position (theta_h, theta_d, phi_d bins) of a pair.
vec3 gridPosition(vec3 wi, vec3 wo) {
  vec3 H = wi + wo, E = wi - wo;
  float rho2 = H.x * H.x + H.y * H.y;
  float len2 = rho2 + H.z * H.z;
  float chord2 = E.x * E.x + E.y * E.y + E.z * E.z;
  float rho = sqrt(rho2), len = sqrt(len2), chord = sqrt(chord2);
  float th = atan2q(rho, H.z);
  float td = atan2q(chord, len);
  bool tilted = rho2 > 1.17549435e-38;
  float dx = tilted ? (E.x * H.x + E.y * H.y) * H.z - E.z * rho2 : E.x;
  float dy = tilted ? (E.y * H.x - E.x * H.y) * len : E.y;
  float alpha = atan2q(abs(dy), abs(dx));
  float phi = (dx >= 0.0) == (dy >= 0.0) ? alpha : kPi - alpha;
  float gh = sqrt(th * (2.0 / kPi));
  return vec3(min(89.0, max(0.0, gh * 90.0)), min(89.0, max(0.0, td * kDeg)),
              min(180.0, max(0.0, phi * kDeg)));
}

// A slice's value at interpolated terms (scalar_eval.cc's add_slice), times weight.
vec3 addSlice(int s, int i0, float fh, int jl0, float fd, int k0, float fp, float weight) {
  int base = 106 + 8 * s;
  int R = int(T(base + 2)), G = int(T(base + 3));
  int n = G * 12;
  int h0 = int(T(base + 4)) + i0 * n, h1 = h0 + n;
  int d0 = int(T(base + 5)) + jl0 * n, d1 = d0 + n;
  int p0 = int(T(base + 6)) + k0 * n, p1 = p0 + n;
  int ko = int(T(base + 7));
  float gh = 1.0 - fh, gd = 1.0 - fd, gp = 1.0 - fp;
  vec3 rgb = vec3(0.0);
  // A group of 4 slots at once (one RGBA texel per term), each lane's arithmetic that of one slot
  // in scalar_eval.cc; slot q adds to channel q / R, in the order of q.
  for (int grp = 0; grp < G; ++grp) {
    int o = grp * 12;
    vec4 g1 = V(h0 + o) * gh + V(h1 + o) * fh, w1 = V(h0 + o + 4) * gh + V(h1 + o + 4) * fh,
         y1 = V(h0 + o + 8) * gh + V(h1 + o + 8) * fh;
    vec4 g2 = V(d0 + o) * gd + V(d1 + o) * fd, w2 = V(d0 + o + 4) * gd + V(d1 + o + 4) * fd,
         y2 = V(d0 + o + 8) * gd + V(d1 + o + 8) * fd;
    vec4 g3 = V(p0 + o) * gp + V(p1 + o) * fp, w3 = V(p0 + o + 4) * gp + V(p1 + o + 4) * fp,
         y3 = V(p0 + o + 8) * gp + V(p1 + o + 8) * fp;
    int k = ko + grp * 28;
    vec4 w12 = w1 * w2, W = w12 * w3, Y = y1 + w1 * y2 + w12 * y3;
    vec4 omh = V(k + 4) + V(k + 8) * Y + V(k + 12) * W;
    vec4 oph = V(k + 16) + V(k + 20) * Y + V(k + 24) * W;
    vec4 term = V(k) * (g1 * g2 * g3) * oph / (omh * omh * omh);
    for (int l = 0; l < 4; ++l) {
      int q = grp * 4 + l;
      if (q < 3 * R) rgb[q / R] += term[l];
    }
  }
  return weight * rgb;
}

int sliceOf(int j) { return int(T(16 + j)); }
int sliceBegin(int s) { return int(T(106 + 8 * s)); }
int sliceEnd(int s) { return int(T(106 + 8 * s + 1)); }

vec3 alongP(int s, int h0, float fh, int jl, float fd, int p0, float fp, float weight) {
  if (p0 + 1 < 180 || fp == 0.0) return addSlice(s, h0, fh, jl, fd, p0, fp, weight);
  return addSlice(s, h0, fh, jl, fd, p0, 0.0, weight * (1.0 - fp)) +
         addSlice(s, h0, fh, jl, fd, 0, 0.0, weight * fp);
}

// A per-bin RGB volume (bin (i, j, k) at texel (k, j, i)).
vec3 bin(sampler3D v, int i, int j, int k) { return texelFetch(v, ivec3(k, j, i), 0).rgb; }

// Trilinear between the 8 bins around a position, theta_h and theta_d clamped, phi_d periodic
// (lookup_linear and the residual's interpolation).
vec3 trilinear(sampler3D v, vec3 pos) {
  float h = clamp(pos.x, 0.0, 89.0), d = clamp(pos.y, 0.0, 89.0), p = clamp(pos.z, 0.0, 180.0);
  int h0 = min(int(h), 88), d0 = min(int(d), 88), p0 = min(int(p), 179);
  int p1 = p0 + 1 == 180 ? 0 : p0 + 1;
  float fh = h - float(h0), fd = d - float(d0), fp = p - float(p0);
  vec3 a = bin(v, h0, d0, p0) * (1.0 - fp) + bin(v, h0, d0, p1) * fp;
  vec3 b = bin(v, h0, d0 + 1, p0) * (1.0 - fp) + bin(v, h0, d0 + 1, p1) * fp;
  vec3 c = bin(v, h0 + 1, d0, p0) * (1.0 - fp) + bin(v, h0 + 1, d0, p1) * fp;
  vec3 e = bin(v, h0 + 1, d0 + 1, p0) * (1.0 - fp) + bin(v, h0 + 1, d0 + 1, p1) * fp;
  return (a * (1.0 - fd) + b * fd) * (1.0 - fh) + (c * (1.0 - fd) + e * fd) * fh;
}

// The generic terms (interp_tables.h): trilinear between the 8 bins' summed values.
vec3 generic(int i0, float fh, int d0, float fd, int k0, float fp) {
  int i1 = min(i0 + 1, 89), d1 = min(d0 + 1, 89), k1 = (k0 + 1) % 180;
  vec3 lo = (bin(uGen, i0, d0, k0) * (1.0 - fp) + bin(uGen, i0, d0, k1) * fp) * (1.0 - fh) +
            (bin(uGen, i1, d0, k0) * (1.0 - fp) + bin(uGen, i1, d0, k1) * fp) * fh;
  vec3 hi = (bin(uGen, i0, d1, k0) * (1.0 - fp) + bin(uGen, i0, d1, k1) * fp) * (1.0 - fh) +
            (bin(uGen, i1, d1, k0) * (1.0 - fp) + bin(uGen, i1, d1, k1) * fp) * fh;
  return lo * (1.0 - fd) + hi * fd;
}

float saturateF(float v) { return isnan(v) ? 0.0 : min(v, kFltMax); }

// log1p and expm1 without their cancellation near 0 (GLSL has neither).
float log1pF(float x) { float u = 1.0 + x; return u == 1.0 ? x : log(u) * (x / (u - 1.0)); }
float expm1F(float x) {
  if (abs(x) < 1e-5) return x + 0.5 * x * x;
  float u = exp(x);
  return u == 1.0 ? x : (u - 1.0) * (x / log(u));
}

// ModelEvaluator::eval_f32: RGB (1/sr) at a pair of unit vectors (z the normal).
vec3 brdf(vec3 wi, vec3 wo) {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return vec3(0.0);
  vec3 pos = gridPosition(wi, wo);
  if (uMode == 1) return trilinear(uVol, pos);
  if (uResidual == 2) return trilinear(uVol, pos);
  int h0 = min(int(pos.x), 89), d0 = min(int(pos.y), 89), p0 = min(int(pos.z), 179);
  float fh = pos.x - float(h0), fd = pos.y - float(d0), fp = pos.z - float(p0);
  int s0 = sliceOf(d0);
  vec3 rgb;
  if (d0 + 1 < sliceEnd(s0) || fd == 0.0) {
    rgb = alongP(s0, h0, fh, d0 - sliceBegin(s0), fd, p0, fp, 1.0);
  } else {
    int s1 = sliceOf(d0 + 1);
    rgb = alongP(s0, h0, fh, d0 - sliceBegin(s0), 0.0, p0, fp, 1.0 - fd);
    rgb += alongP(s1, h0, fh, d0 + 1 - sliceBegin(s1), 0.0, p0, fp, fd);
  }
  if (uGeneric == 1) rgb += generic(h0, fh, d0, fd, p0, fp);
  rgb = vec3(saturateF(rgb.r), saturateF(rgb.g), saturateF(rgb.b));
  if (uResidual == 1) {
    vec3 r = trilinear(uVol, pos);
    vec3 scale = vec3(1.0, 1.15, 1.66) / 1500.0;
    for (int c = 0; c < 3; ++c) {
      float k = uKnee * scale[c];
      float y = log1pF(max(rgb[c], 0.0) / k) + r[c];
      rgb[c] = y > 0.0 ? min(expm1F(y) * k, kFltMax) : 0.0;
    }
  }
  return rgb;
}
`;

export const vertexShader = `#version 300 es
in vec2 aPos;
out vec2 vUv;
void main() { vUv = aPos * 0.5 + 0.5; gl_Position = vec4(aPos, 0.0, 1.0); }
`;

// Pairs: texel (x, y) of uWi/uWo (RGBA32F, xyz) -> the BRDF's RGB at that texel.
export const pairsShader = `#version 300 es
${brdfCommon}
uniform sampler2D uWi, uWo;
out vec4 outColor;
void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  outColor = vec4(brdf(texelFetch(uWi, t, 0).xyz, texelFetch(uWo, t, 0).xyz), 1.0);
}
`;

// A sphere seen from +z (orthographic), lit by a directional light: radiance f cos(theta_i) E
// (linear, float) in rgb; alpha 1 inside the sphere, 0 outside.
export const sphereShader = `#version 300 es
${brdfCommon}
in vec2 vUv;
uniform vec3 uLight;      // unit, towards the light, world space (camera looks down -z)
uniform float uIntensity; // irradiance at normal incidence (a scale of the environment's)
uniform sampler2D uEnv;   // environment lights (envmap.mjs): texel 2k direction, 2k + 1 irradiance
uniform int uEnvCount;    // 0: the directional light
out vec4 outColor;
void main() {
  vec2 p = vUv * 2.0 - 1.0;
  float r2 = dot(p, p);
  if (r2 >= 1.0) { outColor = vec4(0.0); return; }
  vec3 n = vec3(p, sqrt(1.0 - r2));
  // An orthonormal frame around n (the model is isotropic: the tangent's azimuth does not
  // matter). Near the pole, x made orthogonal to n (Gram-Schmidt): x itself is up to 2.6 degrees
  // off the tangent plane there, which skews wi and wo (a dark disk at the centre).
  vec3 t = normalize(abs(n.z) < 0.999 ? cross(vec3(0.0, 0.0, 1.0), n)
                                      : vec3(1.0, 0.0, 0.0) - n * n.x);
  vec3 b = cross(n, t);
  vec3 v = vec3(0.0, 0.0, 1.0);
  vec3 wo = normalize(vec3(dot(v, t), dot(v, b), dot(v, n)));
  // The directional light, or the environment's lights: one call site of brdf (a smaller shader).
  int count = uEnvCount > 0 ? uEnvCount : 1;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < count; ++k) {
    vec3 L = uEnvCount > 0 ? texelFetch(uEnv, ivec2(2 * k, 0), 0).xyz : uLight;
    vec3 E = uEnvCount > 0 ? texelFetch(uEnv, ivec2(2 * k + 1, 0), 0).rgb : vec3(1.0);
    vec3 wi = vec3(dot(L, t), dot(L, b), dot(L, n));
    if (wi.z <= 0.0) continue;
    sum += brdf(normalize(wi), wo) * wi.z * E;
  }
  outColor = vec4(sum * uIntensity, 1.0);
}
`;

// Display: two linear float images (A, and B for the difference), tone mapped as the report
// (tonemap: x = v exposure, pow(min(x, 1), 1 / 2.2)); uShow 0 A, 2 |tm(A) - tm(B)| in false colour
// (black at 0, mean over channels divided by uDiffScale).
export const displayShader = `#version 300 es
precision highp float;
in vec2 vUv;
uniform sampler2D uA, uB;
uniform float uExposure, uDiffScale;
uniform int uShow;
out vec4 outColor;
vec3 tm(vec3 v) { vec3 x = v * uExposure; return mix(vec3(0.0), pow(min(x, vec3(1.0)), vec3(1.0 / 2.2)), vec3(greaterThan(x, vec3(0.0)))); }
vec3 heat(float t) {
  t = clamp(t, 0.0, 1.0);
  return vec3(clamp(3.0 * t, 0.0, 1.0), clamp(3.0 * t - 1.0, 0.0, 1.0), clamp(3.0 * t - 2.0, 0.0, 1.0));
}
void main() {
  vec4 a = texture(uA, vUv);
  if (uShow == 0) { outColor = vec4(a.a > 0.0 ? tm(a.rgb) : vec3(0.12), 1.0); return; }
  vec4 b = texture(uB, vUv);
  if (a.a == 0.0) { outColor = vec4(vec3(0.12), 1.0); return; }
  vec3 d = abs(tm(a.rgb) - tm(b.rgb));
  outColor = vec4(heat((d.r + d.g + d.b) / 3.0 / uDiffScale), 1.0);
}
`;

// (theta_h, theta_d) image at one phi_d: uv.x theta_h position / 89, uv.y theta_d / 89; linear
// RGB of the BRDF at the pair with phi_h = 0.
export const slabShader = `#version 300 es
${brdfCommon}
in vec2 vUv;
uniform float uPhiD;  // radians
out vec4 outColor;
void main() {
  float hp = vUv.x * 89.0, th = (hp / 90.0) * (hp / 90.0) * kPi / 2.0;
  float td = vUv.y * 89.0 / kDeg;
  vec3 d = vec3(sin(td) * cos(uPhiD), sin(td) * sin(uPhiD), cos(td));
  vec3 wi = vec3(d.x * cos(th) + d.z * sin(th), d.y, -d.x * sin(th) + d.z * cos(th));
  vec3 h = vec3(sin(th), 0.0, cos(th));
  vec3 wo = 2.0 * dot(wi, h) * h - wi;
  outColor = vec4(brdf(normalize(wi), normalize(wo)), 1.0);
}
`;
