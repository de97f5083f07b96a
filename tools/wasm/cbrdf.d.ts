// SPDX-License-Identifier: MIT
// Types of cbrdf.mjs, the npm package `cbrdf`'s main module: cbrdf's decoder in WebAssembly
// (tools/wasm/README.md describes each call, its errors and its memory).
import type { GpuTables } from 'cbrdf/glsl';

export { cbrdfGlsl, kGpuLayout, packGpuTables } from 'cbrdf/glsl';
export type { GpuTables, GpuTexture, RawGpuTables } from 'cbrdf/glsl';

/** A cbrdf_status name (cbrdf_status_name), or one of this module's own two. */
export type CbrdfStatus =
  | 'io'
  | 'not-found'
  | 'truncated'
  | 'bad-signature'
  | 'unsupported'
  | 'corrupt'
  | 'checksum'
  | 'limit'
  | 'invalid-argument'
  | 'numeric'
  | 'internal'
  | 'cancelled'
  /** Memory ran out (code 11, CBRDF_ERROR_INTERNAL); the instance stays usable. */
  | 'out-of-memory'
  /** The module trapped or exited: this instance cannot be used any more; load() a new one. */
  | 'aborted';

/** Every failure of this module: the C API's code and message, or one of the two above. */
export declare class CbrdfError extends Error {
  constructor(code: number, status: CbrdfStatus, message: string);
  name: 'CbrdfError';
  /** The cbrdf_status number (9: invalid argument, 11: internal, ...). */
  code: number;
  status: CbrdfStatus;
}

/** One copula component of a slice's channel. */
export interface ComponentInfo {
  /** 'independence', 'frank', 'clayton', 'gumbel', 'joe' (cbrdf_family_name), or the number. */
  family: string;
  theta: number;
  scale: number;
}

/** One slice: its theta_d bins [thetaDBegin, thetaDEnd) and the components of R, G and B. */
export interface SliceInfo {
  thetaDBegin: number;
  thetaDEnd: number;
  channels: [ComponentInfo[], ComponentInfo[], ComponentInfo[]];
}

/** What a file holds (cbrdf_model_get_info's fields, camelCase, and the slices and metadata). */
export interface ModelInfo {
  versionMajor: number;
  versionMinor: number;
  slices: number;
  maxComponents: number;
  bits: number;
  fileBytes: number;
  notMeasuredBins: number;
  /** -1 none, 0 bounded log residual, 1 exact (lossless), 2 row steps, 3 interpolated levels. */
  residualMode: number;
  residualMaxError: number;
  residualMinError: number;
  residualKnee: number;
  residualBytes: number;
  sliceList: SliceInfo[];
  /** [key, value] entries in the file's order. */
  metadata: [string, string][];
}

/** One chunk of the container. */
export interface ChunkFacts {
  tag: string;
  offset: number;
  storedBytes: number;
  payloadBytes: number;
  /** zstd-compressed. */
  compressed: boolean;
}

/** The file's layout and the evaluator's sizes, as `cbrdf view` shows them. */
export interface ModelFacts {
  /** The container version, "major.minor". */
  version: string;
  fileBytes: number;
  bits: number;
  /** The native evaluator's memory (ModelEvaluator). */
  footprintBytes: number;
  /** The GPU tables' size: what a GPU holds for the model. */
  gpuTableBytes: number;
  residualMode: number;
  residualMaxError: number;
  residualMinError: number;
  residualKnee: number;
  residualEscapes: number;
  notMeasuredBins: number;
  chunks: ChunkFacts[];
  sliceList: SliceInfo[];
  metadata: [string, string][];
}

/** A slice's marginals and copula in one channel (its first component's). */
export interface SliceMarginals {
  /** The slice's theta_d bins. */
  width: number;
  /** Probability masses of the 90 theta_h bins. */
  thetaH: Float32Array;
  /** Probability masses of the 180 phi_d bins. */
  phiD: Float32Array;
  /** Probability masses of the slice's `width` theta_d bins. */
  thetaD: Float32Array;
  /** Copula density over theta_h x phi_d (90 x 180, row by theta_h), middle theta_d bin. */
  copula: Float32Array;
}

/** A batch of directions or values: n (x, y, z) or (r, g, b) triples. */
export type Batch = Float64Array | Float32Array;
/** A direction [x, y, z]: three numbers, a finite unit vector (or (0, 0, 0), a rejected draw). */
export type Vec3 = readonly number[];

/** A draw of sample() for one direction. */
export interface Sample {
  /** The incident direction; (0, 0, 0) for a rejected draw. */
  wi: number[];
  pdf: number;
  /** f cos(theta_i) / pdf per channel; 0 for a rejected draw. */
  weight: number[];
}

/** Draws of sample() for a batch, in wo's array type: wi 3n, pdf n, weight 3n. */
export interface Samples<T extends Batch> {
  wi: T;
  pdf: T;
  weight: T;
}

/** Options of open(). */
export interface OpenOptions {
  /**
   * Decode the file for gpuTables(), facts() and sliceMarginals() at once, and for the C API's
   * calls (info, eval, sample, pdf, table) only on first use: a page that draws the model on
   * the GPU decodes it once. Default false: the C API's decode at open, the GPU's on first use.
   */
  gpu?: boolean;
}

/** A decoded .cbrdf file. Every method throws a CbrdfError after free(). */
export declare class Model {
  private constructor();
  /** cbrdf_model_get_info's fields, the slices and the metadata. */
  info(): ModelInfo;
  /** f(wi, wo) in 1/sr, linear RGB: one pair -> [r, g, b]. */
  eval(wi: Vec3, wo: Vec3): number[];
  /** n pairs (3n numbers each) -> 3n values in wi's type (Float32Array: rounded to float). */
  eval(wi: Float64Array, wo: Batch): Float64Array;
  eval(wi: Float32Array, wo: Batch): Float32Array;
  /** n pairs into out (3n values, either type), which is returned; nothing is allocated. */
  eval<T extends Batch>(wi: Batch, wo: Batch, out: T): T;
  /** One draw of wi for wo from uniform numbers u = [u1, u2] in [0, 1). */
  sample(wo: Vec3, u: readonly number[]): Sample;
  /** n draws: wo 3n, u 2n numbers. */
  sample(wo: Float64Array, u: Batch): Samples<Float64Array>;
  sample(wo: Float32Array, u: Batch): Samples<Float32Array>;
  /** The sampler's density of wi given wo (one pair). */
  pdf(wi: Vec3, wo: Vec3): number;
  /** The MERL .binary table's 4,374,000 values (channel blocks R, G, B), MERL's stored units. */
  table(): Float64Array;
  /** The evaluator's float32 tables (spec/gpu-tables.md); new copies at every call. */
  gpuArrays(): { tables: Float32Array; generic: Float32Array | null; residual: Float32Array | null };
  /** The textures and uniforms cbrdfGlsl reads: packGpuTables(gpuArrays()). */
  gpuTables(): GpuTables;
  /** The file's chunks and the evaluator's sizes. */
  facts(): ModelFacts;
  /** Slice s's marginals and copula in channel c (0 R, 1 G, 2 B). */
  sliceMarginals(s: number, c: number): SliceMarginals;
  /**
   * Returns the model's memory to the module now; idempotent, never throws. Where the runtime
   * has Symbol.dispose, model[Symbol.dispose]() is the same (`using model = ...`).
   */
  free(): void;
}

/** An instance of cbrdf.wasm (load()). */
export interface CbrdfInstance {
  /** The library's version, e.g. "2.3.0". */
  readonly version: string;
  /** Decodes a .cbrdf file synchronously; throws a CbrdfError for a bad file. */
  open(fileBytes: ArrayBuffer | ArrayBufferView, options?: OpenOptions): Model;
  /** fn(model) with the model freed when fn returns, throws or (a promise) settles. */
  withModel<R>(fileBytes: ArrayBuffer | ArrayBufferView, fn: (model: Model) => R): R;
  /** Models opened and not yet freed. */
  readonly liveModels: number;
  /** null, or the CbrdfError that stopped this instance. */
  readonly failure: CbrdfError | null;
  /** The module's raw exports, each through the same guard as the calls above; no size checks. */
  readonly exports: Record<string, unknown> & { memory: WebAssembly.Memory };
}

/**
 * Creates an instance of cbrdf.wasm from its bytes or a compiled module; by default cbrdf.wasm
 * beside cbrdf.mjs (read from disk under node, fetched in a browser).
 */
export declare function load(
  source?: ArrayBuffer | ArrayBufferView | WebAssembly.Module,
): Promise<CbrdfInstance>;

/** Decodes a .cbrdf file with an instance shared by every call (made on first use). */
export declare function open(
  fileBytes: ArrayBuffer | ArrayBufferView,
  options?: OpenOptions,
): Promise<Model>;

/** Opens the file, runs fn(model) (which may be async) and frees the model when it is done. */
export declare function withModel<R>(
  fileBytes: ArrayBuffer | ArrayBufferView,
  fn: (model: Model) => R | Promise<R>,
): Promise<R>;
