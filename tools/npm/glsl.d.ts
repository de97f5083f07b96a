// SPDX-License-Identifier: MIT
// Types of glsl.mjs (`cbrdf/glsl`): the GPU evaluation of a cbrdf model. The layout of the
// textures and uniforms is spec/gpu-tables.md.

/**
 * The layout version of {@link packGpuTables}'s textures and uniforms, which `cbrdfGlsl` reads
 * (spec/gpu-tables.md). Raised when a texture, its index formulas or a uniform change.
 */
export declare const kGpuLayout: number;

/**
 * GLSL ES 3.00 source (no `#version` line) declaring the uniforms of {@link packGpuTables}'s
 * output (all named `cbrdf*`) and `vec3 cbrdfEval(vec3 wi, vec3 wo)`: the BRDF in 1/sr, linear
 * RGB, at unit vectors in the local frame (z the normal), 0 when either is below the horizon.
 * Paste it into a fragment shader after `precision highp float; precision highp int;`.
 * Sampler: `cbrdfTables` (2D); floats: `cbrdfVolumeBase`, `cbrdfVolumeCount`,
 * `cbrdfGenericVolume`, `cbrdfResidualMode`, `cbrdfKnee`.
 */
export declare const cbrdfGlsl: string;

/** A model's arrays as cbrdf.wasm gives them (cbrdf_viewer_array); absent arrays null. */
export interface RawGpuTables {
  tables: Float32Array;
  generic: Float32Array | null;
  residual: Float32Array | null;
  facts?: unknown;
}

/** One texture `cbrdfGlsl` samples (with texelFetch: nearest, no mipmaps). */
export interface GpuTexture {
  /** The sampler uniform's name in `cbrdfGlsl`. */
  uniform: string;
  /** 2: sampler2D (depth 1), 3: sampler3D. */
  dimension: 2 | 3;
  width: number;
  height: number;
  depth: number;
  /** WebGL2 internal format; the data is float, RGBA, RGB or RED to match. */
  format: 'RGBA32F' | 'RGB32F' | 'R32F';
  /** width x height x depth texels of 4, 3 or 1 floats, row by row, layer by layer. */
  data: Float32Array;
}

/** What a renderer binds to evaluate a model with `cbrdfGlsl`. */
export interface GpuTables {
  /** The layout version ({@link kGpuLayout}). */
  layout: number;
  /** Every sampler `cbrdfGlsl` declares (1 x 1 (x 1) when the model does not use it). */
  textures: GpuTexture[];
  /** Every other uniform `cbrdfGlsl` declares, by name: all are floats. */
  uniforms: Record<string, number>;
}

/**
 * The textures and uniform values of a model's arrays. Throws a TypeError when `raw.tables` is
 * not a Float32Array of tables, and an Error when the tables are of another layout version
 * (cbrdf.wasm and glsl.mjs of different releases), are inconsistent or a volume has the wrong
 * size; each message starts with `packGpuTables:`.
 */
export declare function packGpuTables(raw: RawGpuTables): GpuTables;

/**
 * The textures and uniform values that draw a measured table with `cbrdfEval` (trilinear
 * between bins, as cbrdf's lookup_linear): `rgb` holds 3 x 90 x 90 x 180 physical values
 * (1/sr), RGB interleaved per MERL bin, bin (theta_h 90 + theta_d) 180 + phi_d, 0 where not
 * measured.
 */
export declare function packTable(rgb: Float32Array): GpuTables;
