// SPDX-License-Identifier: MIT
// CbrdfMaterial: a cbrdf model as a three.js material. A ShaderMaterial around cbrdfGlsl
// (glsl.mjs) lit by three's own lights: directional, point and spot lights evaluate the model,
// ambient, hemisphere and light-probe light scale its directional albedo, and an environment map
// is read along the model's reflection lobe (cbrdfAlbedo).
import {
  CubeReflectionMapping, CubeRefractionMapping, Data3DTexture, DataTexture,
  EquirectangularReflectionMapping, EquirectangularRefractionMapping, Euler, FloatType, Material,
  Matrix4, NearestFilter, PMREMGenerator, RGBAFormat, RGBFormat, RedFormat, ShaderMaterial,
  UniformsLib, UniformsUtils,
} from 'three';
import { cbrdfGlsl, kGpuLayout } from './glsl.mjs';

const kFormats = { RGBA32F: RGBAFormat, RGB32F: RGBFormat, R32F: RedFormat };

// Elevations of the albedo table: cos(theta_o) at (i + 0.5) / n.
const kAlbedoSize = 32;

/**
 * The directional albedo of a model, the integral of f(wi, wo) cos(theta_i) over wi, and the
 * reflected light's lobe, per outgoing elevation cos(theta_o) = (i + 0.5) / n, i = 0..n-1:
 * Float32Array of 5 n, the n albedos (RGB), then per elevation the lobe's mean direction (its
 * angle from the normal towards the mirror direction, as a fraction of theta_o) and spread (a
 * roughness for three's PMREM maps, 0 a mirror to 1 a cosine lobe). A midpoint
 * quadrature over the half vector h (wi = h reflecting wo) with theta_h spaced as the MERL grid's
 * (theta_h = t^2 pi / 2: fine where specular peaks are) and `steps` x 2 `steps` points: the same
 * table for the same file, by model.eval alone.
 */
export function cbrdfAlbedo(model, { elevations = kAlbedoSize, steps = 64 } = {}) {
  const nt = steps, np = 2 * steps, n = nt * np;
  const wi = new Float64Array(3 * n), wo = new Float64Array(3 * n), weight = new Float64Array(n);
  const albedo = new Float32Array(5 * elevations);
  for (let e = 0; e < elevations; ++e) {
    const mu = (e + 0.5) / elevations, so = Math.sqrt(1 - mu * mu);
    for (let a = 0; a < nt; ++a) {
      const t = (a + 0.5) / nt, th = 0.5 * Math.PI * t * t;
      const sh = Math.sin(th), ch = Math.cos(th);
      // d omega_i = 4 (wo . h) d omega_h, d omega_h = sin theta_h (pi t dt) dphi.
      const area = sh * (Math.PI * t / nt) * (2 * Math.PI / np);
      for (let b = 0; b < np; ++b) {
        const k = a * np + b, ph = (b + 0.5) * (2 * Math.PI / np);
        const hx = sh * Math.cos(ph), hy = sh * Math.sin(ph);
        const d = so * hx + mu * ch;
        const x = 2 * d * hx - so, y = 2 * d * hy, z = 2 * d * ch - mu;
        const len = Math.hypot(x, y, z);
        wo[3 * k] = so;
        wo[3 * k + 2] = mu;
        if (d <= 0 || z <= 0) {  // wi below the horizon: no contribution (eval gives 0 there)
          wi[3 * k] = wi[3 * k + 1] = 0;
          wi[3 * k + 2] = 1;
          weight[k] = 0;
          continue;
        }
        wi[3 * k] = x / len;
        wi[3 * k + 1] = y / len;
        wi[3 * k + 2] = z / len;
        weight[k] = (z / len) * 4 * d * area;
      }
    }
    const f = model.eval(wi, wo);
    let total = 0, mx = 0, my = 0, mz = 0;
    for (let c = 0; c < 3; ++c) {
      let sum = 0;
      for (let k = 0; k < n; ++k) sum += f[3 * k + c] * weight[k];
      albedo[3 * e + c] = sum;
    }
    for (let k = 0; k < n; ++k) {
      const y = (0.2126 * f[3 * k] + 0.7152 * f[3 * k + 1] + 0.0722 * f[3 * k + 2]) * weight[k];
      total += y;
      mx += y * wi[3 * k];
      my += y * wi[3 * k + 1];
      mz += y * wi[3 * k + 2];
    }
    // The reflected light's lobe: its mean direction (the angle from the normal towards the
    // mirror direction, as a fraction of the mirror direction's: smooth where the view meets the
    // normal and the tangent's azimuth is arbitrary) and its spread, from the mean cosine about
    // that direction as a Phong lobe's of exponent m ((m + 1) / (m + 2)): roughness^4 =
    // alpha^2 = 2 / (m + 2) for narrow lobes, plus 3 / (m + 2)^2 so that a cosine lobe (m = 1)
    // reads the map's most blurred level, as three's irradiance does.
    const rbar = total > 0 ? Math.min(Math.hypot(mx, my, mz) / total, 0.999999) : 2 / 3;
    const m = Math.max((2 * rbar - 1) / (1 - rbar), 0);
    albedo[3 * elevations + 2 * e] = total > 0 ? Math.atan2(-mx, mz) / Math.acos(mu) : 0;
    const roughness4 = 2 / (m + 2) + 3 / ((m + 2) * (m + 2));
    albedo[3 * elevations + 2 * e + 1] = Math.min(1, roughness4 ** 0.25);
  }
  return albedo;
}

const vertexShader = /* glsl */ `
varying vec3 vViewPosition;
#include <common>
#include <batching_pars_vertex>
#include <fog_pars_vertex>
#include <normal_pars_vertex>
#include <morphtarget_pars_vertex>
#include <skinning_pars_vertex>
#include <shadowmap_pars_vertex>
#include <logdepthbuf_pars_vertex>
#include <clipping_planes_pars_vertex>
void main() {
  #include <morphinstance_vertex>
  #include <batching_vertex>
  #include <beginnormal_vertex>
  #include <morphnormal_vertex>
  #include <skinbase_vertex>
  #include <skinnormal_vertex>
  #include <defaultnormal_vertex>
  #include <normal_vertex>
  #include <begin_vertex>
  #include <morphtarget_vertex>
  #include <skinning_vertex>
  #include <project_vertex>
  #include <logdepthbuf_vertex>
  #include <clipping_planes_vertex>
  vViewPosition = - mvPosition.xyz;
  #include <worldpos_vertex>
  #include <shadowmap_vertex>
  #include <fog_vertex>
}
`;

// Direct lights through three's own lights_fragment_begin (attenuation, cones, light maps and
// shadows exactly as for MeshStandardMaterial), whose RE_Direct adds the model's f cos E: its
// loops are unrolled, one cbrdfEval per light, which SwiftShader runs faster than one call in a
// loop over the lights. Its ambient, hemisphere and probe irradiance reflects by the albedo.
const fragmentShader = /* glsl */ `
uniform float opacity;
uniform float cbrdfIntensity;
uniform vec3 cbrdfAlbedo[CBRDF_ALBEDO_SIZE];
uniform vec2 cbrdfLobe[CBRDF_ALBEDO_SIZE];
varying vec3 vViewPosition;
#include <common>
#include <dithering_pars_fragment>
#include <envmap_common_pars_fragment>
#include <envmap_physical_pars_fragment>
#include <fog_pars_fragment>
#include <lights_pars_begin>
#include <normal_pars_fragment>
#include <shadowmap_pars_fragment>
#include <logdepthbuf_pars_fragment>
#include <clipping_planes_pars_fragment>
${cbrdfGlsl}

// The local frame and outgoing direction, passed to RE_Direct as its "material".
struct CbrdfFrame { vec3 tangent; vec3 bitangent; vec3 wo; };

void cbrdfDirect(const in IncidentLight directLight, const in vec3 geometryPosition,
                 const in vec3 geometryNormal, const in vec3 geometryViewDir,
                 const in vec3 geometryClearcoatNormal, const in CbrdfFrame material,
                 inout ReflectedLight reflectedLight) {
  vec3 L = directLight.direction;
  vec3 wi = vec3(dot(L, material.tangent), dot(L, material.bitangent), dot(L, geometryNormal));
  if (wi.z <= 0.0) return;
  reflectedLight.directSpecular += cbrdfEval(normalize(wi), material.wo) * wi.z * directLight.color;
}
void cbrdfIndirect() {}  // never called: defining RE_IndirectDiffuse makes the chunk sum irradiance
#define RE_Direct cbrdfDirect
#define RE_IndirectDiffuse cbrdfIndirect

// The albedo table at cos(theta_o), linear between its elevations.
vec3 cbrdfAlbedoAt(float mu) {
  float x = clamp(mu * float(CBRDF_ALBEDO_SIZE) - 0.5, 0.0, float(CBRDF_ALBEDO_SIZE - 1));
  int i = min(int(x), CBRDF_ALBEDO_SIZE - 2);
  return mix(cbrdfAlbedo[i], cbrdfAlbedo[i + 1], x - float(i));
}
vec2 cbrdfLobeAt(float mu) {
  float x = clamp(mu * float(CBRDF_ALBEDO_SIZE) - 0.5, 0.0, float(CBRDF_ALBEDO_SIZE - 1));
  int i = min(int(x), CBRDF_ALBEDO_SIZE - 2);
  return mix(cbrdfLobe[i], cbrdfLobe[i + 1], x - float(i));
}

void main() {
  #include <clipping_planes_fragment>
  #include <logdepthbuf_fragment>
  #include <normal_fragment_begin>
  vec3 viewDir = isOrthographic ? vec3(0.0, 0.0, 1.0) : normalize(vViewPosition);

  // The local frame: z the normal, x the view direction made orthogonal to it (Gram-Schmidt), so
  // wo lies in the xz plane; the model is isotropic, only the normal matters. Where the view is
  // along the normal any tangent will do. An interpolated normal turned slightly away from the
  // camera (at silhouettes) sees the surface at grazing angle rather than from below.
  float nv = dot(normal, viewDir);
  vec3 tangent = viewDir - normal * nv;
  if (dot(tangent, tangent) < 1e-10) {
    tangent = abs(normal.x) < 0.9 ? vec3(1.0, 0.0, 0.0) - normal * normal.x
                                  : vec3(0.0, 1.0, 0.0) - normal * normal.y;
  }
  tangent = normalize(tangent);
  vec3 bitangent = cross(normal, tangent);
  float woz = max(nv, 1e-3);
  vec3 wo = vec3(sqrt(1.0 - woz * woz), 0.0, woz);

  CbrdfFrame material = CbrdfFrame(tangent, bitangent, wo);
  ReflectedLight reflectedLight = ReflectedLight(vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
  #include <lights_fragment_begin>
  vec3 radiance = reflectedLight.directSpecular;

  // Light from all around (ambient, hemisphere, probes: the chunk's irradiance) reflects by the
  // directional albedo: exact for light of the same radiance from every direction.
  vec3 albedo = cbrdfAlbedoAt(wo.z);
  radiance += albedo * irradiance * RECIPROCAL_PI;
#if defined(USE_ENVMAP) && defined(ENVMAP_TYPE_PMREM)
  // The environment through the model's lobe at this elevation: the PMREM map, prefiltered to
  // the lobe's spread, along its mean direction, times the albedo.
  vec2 lobe = cbrdfLobeAt(wo.z);
  float lobeAngle = lobe.x * acos(wo.z);
  vec3 lobeDir = transformDirectionByInverseViewMatrix(
      normalize(cos(lobeAngle) * normal - sin(lobeAngle) * tangent), viewMatrix);
  radiance += albedo * envMapIntensity *
              textureLod(envMap, envMapRotation * lobeDir, roughnessToMip(lobe.y)).rgb;
#endif

  vec3 outgoingLight = radiance * cbrdfIntensity;
  vec4 diffuseColor = vec4(1.0, 1.0, 1.0, opacity);
  #include <opaque_fragment>
  #include <tonemapping_fragment>
  #include <colorspace_fragment>
  #include <fog_fragment>
  #include <premultiplied_alpha_fragment>
  #include <dithering_fragment>
}
`;

function isTables(t) {
  return t !== null && typeof t === 'object' && Array.isArray(t.textures) &&
         t.uniforms !== null && typeof t.uniforms === 'object';
}

function threeTexture(t) {
  const format = kFormats[t.format];
  if (format === undefined) {
    throw new Error(`CbrdfMaterial: texture ${t.uniform} has format ${t.format}; ` +
                    `this three.mjs knows ${Object.keys(kFormats).join(', ')}`);
  }
  const tex = t.dimension === 3
    ? new Data3DTexture(t.data, t.width, t.height, t.depth)
    : new DataTexture(t.data, t.width, t.height);
  tex.format = format;
  tex.type = FloatType;
  tex.internalFormat = t.format;  // three alone would ask for an unsized RGB float texture
  tex.minFilter = tex.magFilter = NearestFilter;
  tex.generateMipmaps = false;
  tex.flipY = false;
  tex.unpackAlignment = 1;
  tex.needsUpdate = true;
  return tex;
}

const _matrix = new Matrix4();

// Environment maps as PMREM textures, which the shader's lobe lookup needs: three makes them only
// for its standard materials, so the material makes its own, once per map and renderer.
const _generators = new WeakMap();  // renderer -> PMREMGenerator
const _pmrems = new WeakMap();      // renderer -> (map -> PMREM render target)

function pmremOf(renderer, map) {
  if (!map || map.isTexture !== true) return null;
  if (map.isPMREMTexture === true) return map;
  const equirect = map.mapping === EquirectangularReflectionMapping ||
                   map.mapping === EquirectangularRefractionMapping;
  const cube = map.mapping === CubeReflectionMapping || map.mapping === CubeRefractionMapping;
  if (!equirect && !cube) {
    throw new Error('CbrdfMaterial: an environment map must be a PMREM texture, an ' +
                    'equirectangular map or a cube map (texture.mapping)');
  }
  let maps = _pmrems.get(renderer);
  if (!maps) _pmrems.set(renderer, maps = new WeakMap());
  const made = maps.get(map);
  if (made) return made.texture;
  const image = map.image;
  const ready = equirect ? image && image.height > 0
                         : Array.isArray(image) && image.length === 6 && image.every(Boolean);
  if (!ready) return null;  // not loaded yet: no environment light this frame
  let generator = _generators.get(renderer);
  if (!generator) _generators.set(renderer, generator = new PMREMGenerator(renderer));
  const target = equirect ? generator.fromEquirectangular(map) : generator.fromCubemap(map);
  maps.set(map, target);
  map.addEventListener('dispose', () => { target.dispose(); maps.delete(map); });
  return target.texture;
}

/**
 * A cbrdf model as a three.js material (WebGLRenderer, WebGL2). Options: `model` (an open cbrdf
 * Model) or `tables` (its gpuTables()) with `albedo` (cbrdfAlbedo(model), or null for no
 * response to ambient and environment light); `intensity` (scales the reflected radiance,
 * default 1); `envMap` (else the scene's environment) and `envMapIntensity`, `envMapRotation`; any
 * ShaderMaterial parameter (side, transparent, opacity, ...). See three.d.ts.
 */
export class CbrdfMaterial extends ShaderMaterial {
  constructor(options = {}) {
    const { model, tables: given, albedo: givenAlbedo, intensity = 1, envMap = null,
            envMapIntensity = 1, envMapRotation = null, ...rest } = options;
    let tables = given;
    let albedo = givenAlbedo;
    if (model !== undefined && model !== null) {
      if (given !== undefined) throw new TypeError('CbrdfMaterial: give model or tables, not both');
      if (typeof model.gpuTables !== 'function' || typeof model.eval !== 'function') {
        throw new TypeError('CbrdfMaterial: options.model must be a cbrdf Model (open(bytes))');
      }
      try {
        tables = model.gpuTables();
        if (albedo === undefined) albedo = cbrdfAlbedo(model);
      } catch (e) {
        e.message = `CbrdfMaterial: ${e.message}`;  // e.g. a model used after free()
        throw e;
      }
    } else if (!isTables(given)) {
      throw new TypeError('CbrdfMaterial: needs options.model (a cbrdf Model) or options.tables ' +
                          '(model.gpuTables())');
    } else if (albedo === undefined) {
      throw new TypeError('CbrdfMaterial: options.tables needs options.albedo too ' +
                          '(cbrdfAlbedo(model) before the model is freed, or null: no ambient ' +
                          'or environment light)');
    }
    if (tables.layout !== kGpuLayout) {
      throw new Error(`CbrdfMaterial: GPU tables of layout ${tables.layout}; this cbrdfGlsl ` +
                      `reads layout ${kGpuLayout} (cbrdf.mjs and three.mjs of different versions)`);
    }
    if (albedo === null) albedo = new Float32Array(5 * kAlbedoSize);
    if (!(albedo instanceof Float32Array) || albedo.length < 10 || albedo.length % 5 !== 0) {
      throw new TypeError('CbrdfMaterial: options.albedo must be a Float32Array of 5 numbers ' +
                          'per elevation (cbrdfAlbedo(model))');
    }
    const own = { opacity: { value: 1 }, envMapIntensity: { value: 1 } };
    const libs = [UniformsLib.envmap, UniformsLib.fog, UniformsLib.lights];
    const uniforms = UniformsUtils.merge([...libs, own]);
    // Added after the merge, which would copy the textures.
    const textures = tables.textures.map(threeTexture);
    tables.textures.forEach((t, i) => { uniforms[t.uniform] = { value: textures[i] }; });
    for (const [name, value] of Object.entries(tables.uniforms)) uniforms[name] = { value };
    uniforms.cbrdfIntensity = { value: intensity };
    const size = albedo.length / 5;
    uniforms.cbrdfAlbedo = { value: albedo.subarray(0, 3 * size) };
    uniforms.cbrdfLobe = { value: albedo.subarray(3 * size) };

    super({ ...rest, uniforms, vertexShader, fragmentShader, lights: true,
            fog: true, clipping: true });
    this.defines.CBRDF_ALBEDO_SIZE = size;
    this.cbrdfAlbedo = albedo;
    this.isCbrdfMaterial = true;
    this.type = 'CbrdfMaterial';
    this.cbrdfTables = tables;
    this.cbrdfTextures = textures;
    this.cbrdfEnvSource = envMap;
    this.cbrdfEnvPmrem = null;
    this.envMapIntensity = envMapIntensity;
    this.envMapRotation = envMapRotation ?? new Euler();
    this.cbrdfCheckedRenderer = null;
  }

  /** Scales the reflected radiance (1: physical units, radiance = f cos(theta_i) E). */
  get intensity() { return this.uniforms.cbrdfIntensity.value; }
  set intensity(v) { this.uniforms.cbrdfIntensity.value = v; }

  /**
   * The environment map: set a PMREM texture, an equirectangular map or a cube map (null: the
   * scene's environment); reads back as the PMREM texture rendered, which three reads to compile
   * the environment's code.
   */
  get envMap() { return this.cbrdfEnvPmrem ?? null; }
  set envMap(map) { this.cbrdfEnvSource = map; }

  onBeforeRender(renderer, scene) {
    if (this.cbrdfCheckedRenderer !== renderer) this.checkRenderer(renderer);
    const u = this.uniforms;
    u.opacity.value = this.opacity;
    // The material's own map, or else the scene's, with their intensity and rotation as three
    // gives MeshStandardMaterial.
    const own = this.cbrdfEnvSource !== null && this.cbrdfEnvSource !== undefined;
    const source = own ? this.cbrdfEnvSource : scene?.environment ?? null;
    this.cbrdfEnvPmrem = pmremOf(renderer, source);
    u.envMap.value = this.cbrdfEnvPmrem;
    if (this.cbrdfEnvPmrem) {
      u.envMapIntensity.value = own ? this.envMapIntensity : scene.environmentIntensity ?? 1;
      const rotation = own ? this.envMapRotation : scene.environmentRotation ?? this.envMapRotation;
      // WebGLMaterials' rotation for a PMREM map (a render target: no cube-map flip).
      u.envMapRotation.value.setFromMatrix4(_matrix.makeRotationFromEuler(rotation)).transpose();
    }
  }

  // What the GPU must offer, checked once per renderer, before three compiles the program.
  checkRenderer(renderer) {
    if (renderer.isWebGLRenderer !== true) {
      throw new Error('CbrdfMaterial is a WebGL material: it needs three\'s WebGLRenderer');
    }
    const gl = renderer.getContext();
    if (typeof WebGL2RenderingContext === 'undefined' || !(gl instanceof WebGL2RenderingContext)) {
      throw new Error('CbrdfMaterial needs WebGL2 (3D and 32-bit float textures)');
    }
    const max2d = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    const max3d = gl.getParameter(gl.MAX_3D_TEXTURE_SIZE);
    for (const t of this.cbrdfTextures) {
      const img = t.image;
      const limit = t.isData3DTexture ? max3d : max2d;
      if (Math.max(img.width, img.height, img.depth ?? 1) > limit) {
        throw new Error(`CbrdfMaterial: a ${img.width} x ${img.height} x ${img.depth ?? 1} ` +
                        `texture exceeds this GPU's limit of ${limit} texels a side`);
      }
    }
    this.cbrdfCheckedRenderer = renderer;
  }

  // A material of its own textures (ShaderMaterial.copy would share uniforms' values by clone).
  clone() {
    const m = new this.constructor({ tables: this.cbrdfTables, albedo: this.cbrdfAlbedo,
                                     intensity: this.intensity, envMap: this.cbrdfEnvSource,
                                     envMapIntensity: this.envMapIntensity,
                                     envMapRotation: this.envMapRotation.clone() });
    Material.prototype.copy.call(m, this);
    return m;
  }

  dispose() {
    for (const t of this.cbrdfTextures) t.dispose();
    super.dispose();
  }
}

export { cbrdfGlsl, kGpuLayout };
