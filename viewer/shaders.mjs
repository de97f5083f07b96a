// SPDX-License-Identifier: MIT
// GLSL ES 3.00 sources of the viewer's programs, built on the package's cbrdfEval (glsl.mjs,
// served from the wasm folder): pairs (the browser test), sphere, slab and display. A MERL table
// is drawn by the same function as the exact-table mode of the tables (brdfs.mjs).
import { cbrdfGlsl } from './glsl.mjs';

// The includer's defaults cbrdfGlsl needs, then cbrdfGlsl.
const brdfCommon = `
precision highp float;
precision highp int;
const float kPi = 3.14159265358979323846;
const float kDeg = 57.2957795130823208768;
${cbrdfGlsl}
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
  outColor = vec4(cbrdfEval(texelFetch(uWi, t, 0).xyz, texelFetch(uWo, t, 0).xyz), 1.0);
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
  // The directional light, or the environment's lights: one call site of cbrdfEval (a smaller shader).
  int count = uEnvCount > 0 ? uEnvCount : 1;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < count; ++k) {
    vec3 L = uEnvCount > 0 ? texelFetch(uEnv, ivec2(2 * k, 0), 0).xyz : uLight;
    vec3 E = uEnvCount > 0 ? texelFetch(uEnv, ivec2(2 * k + 1, 0), 0).rgb : vec3(1.0);
    vec3 wi = vec3(dot(L, t), dot(L, b), dot(L, n));
    if (wi.z <= 0.0) continue;
    sum += cbrdfEval(normalize(wi), wo) * wi.z * E;
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
  outColor = vec4(cbrdfEval(normalize(wi), normalize(wo)), 1.0);
}
`;
