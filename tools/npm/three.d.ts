// SPDX-License-Identifier: MIT
// Types of three.mjs (`cbrdf/three`): a cbrdf model as a three.js material.
import { Euler, ShaderMaterial, Texture } from 'three';
import type { ShaderMaterialParameters } from 'three';
import type { Model } from 'cbrdf';
import type { GpuTables } from 'cbrdf/glsl';

export { cbrdfGlsl, kGpuLayout } from 'cbrdf/glsl';

/** Options of {@link cbrdfAlbedo}. */
export interface AlbedoOptions {
  /** Outgoing elevations of the table, at cos(theta_o) = (i + 0.5) / n. Default 32. */
  elevations?: number;
  /** Quadrature points over theta_h (and twice as many over phi_h) per elevation. Default 64. */
  steps?: number;
}

/**
 * The model's directional albedo (the integral of f cos(theta_i) over wi) and reflection lobe per
 * outgoing elevation cos(theta_o) = (i + 0.5) / n, i = 0..n-1, by a quadrature of `model.eval`
 * over the half vector: 5 n numbers, the n albedos (RGB), then per elevation the lobe's mean
 * direction (its angle from the normal towards the mirror direction, as a fraction of theta_o)
 * and its spread (a PMREM roughness, 0 to 1). CbrdfMaterial scales ambient, hemisphere and
 * light-probe light by the albedo, and reads environment maps along the lobe.
 */
export declare function cbrdfAlbedo(model: Model, options?: AlbedoOptions): Float32Array;

/** Options common to both ways of giving the model. */
interface CbrdfMaterialCommon
  extends Omit<ShaderMaterialParameters,
                'uniforms' | 'vertexShader' | 'fragmentShader' | 'lights'> {
  /** Scales the reflected radiance (an exposure); 1: radiance = f cos(theta_i) E. Default 1. */
  intensity?: number;
  /**
   * An environment map: a PMREM texture (three's PMREMGenerator), an equirectangular map or a
   * cube map, made PMREM at the first render. Null: the scene's environment. Read along the
   * model's mean reflection direction, blurred to its lobe's spread, times the albedo (exact for
   * a uniform environment; one lobe per elevation, so a mixed diffuse and glossy material is
   * approximated).
   */
  envMap?: Texture | null;
  /** Scales the environment map's light. Default 1. */
  envMapIntensity?: number;
  /** Rotates the environment map. Default no rotation. */
  envMapRotation?: Euler | null;
}

/** Options of CbrdfMaterial. */
export type CbrdfMaterialParameters = CbrdfMaterialCommon & (
  | {
      /** An open cbrdf Model: its gpuTables() and cbrdfAlbedo() are taken now; free it after. */
      model: Model;
      tables?: undefined;
      /** Overrides cbrdfAlbedo(model); null: no ambient or environment light. */
      albedo?: Float32Array | null;
    }
  | {
      model?: undefined | null;
      /** model.gpuTables(), for a model already freed. */
      tables: GpuTables;
      /** cbrdfAlbedo(model) taken before the model was freed, or null: no ambient light. */
      albedo: Float32Array | null;
    }
);

/**
 * A cbrdf model as a three.js material (WebGLRenderer on WebGL2). Lit by three's directional,
 * point and spot lights (with their shadows) through the model itself, by ambient, hemisphere
 * and light-probe light through its albedo, by an environment map (its own or the scene's)
 * through its albedo and reflection lobe; three's tone mapping and output colour space apply as
 * to MeshStandardMaterial. Any mesh with normals.
 *
 * Throws a TypeError for missing or wrong options, an Error (or the model's CbrdfError) for a
 * freed model or tables of another layout version, and at the first render an Error where the
 * renderer is not a WebGL2 WebGLRenderer or a texture exceeds the GPU's size limits.
 */
export declare class CbrdfMaterial extends ShaderMaterial {
  constructor(parameters: CbrdfMaterialParameters);
  readonly isCbrdfMaterial: true;
  /** Scales the reflected radiance. */
  intensity: number;
  /** Set: as the option; read: the PMREM texture last rendered (of this map or the scene's). */
  envMap: Texture | null;
  envMapIntensity: number;
  envMapRotation: Euler;
  /** The tables the material was made from (model.gpuTables()). */
  readonly cbrdfTables: GpuTables;
  /** The material's own textures, released by dispose(). */
  readonly cbrdfTextures: Texture[];
  clone(): this;
  /** Releases the material's textures and program. */
  dispose(): void;
}
