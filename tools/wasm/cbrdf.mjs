// SPDX-License-Identifier: MIT
// cbrdf's decoder in WebAssembly: open a .cbrdf file held in memory, describe it, evaluate it,
// sample it, write its full MERL table and hand its GPU tables to a shader, from JavaScript (node
// or a browser).
//
//   import { open } from './cbrdf.mjs';
//   const model = await open(bytes);            // Uint8Array / ArrayBuffer of a .cbrdf file
//   model.info();                               // { slices, bits, ..., sliceList, metadata }
//   model.eval([0, 0, 1], [0.6, 0, 0.8]);       // [r, g, b] (1/sr)
//   model.eval(wi, wo);                         // n pairs: Float64Array/Float32Array of 3n
//   model.eval(wi, wo, out);                    // the same into out (3n), without allocating
//   model.sample(wo, u);                        // { wi, pdf, weight }
//   model.pdf(wi, wo);                          // the sampler's density of wi given wo
//   model.table();                              // Float64Array, a MERL .binary's values
//   model.gpuTables();                          // textures and uniforms for cbrdfGlsl (glsl.mjs)
//   model.facts(); model.sliceMarginals(s, c);  // the file's layout; a slice's marginals
//   model.free();                               // its memory is returned now
//   await withModel(bytes, (m) => m.eval(wi, wo));  // opens, runs, frees in finally
//
// Every call goes to the C API (cbrdf/cbrdf_c.h) compiled into cbrdf.wasm (tools/wasm/README.md),
// so results are the native library's; the GPU tables, facts and marginals come from the module's
// cbrdf_viewer_* calls (viewer_tables.cc). A failure throws a CbrdfError carrying the C API's code
// (err.code, a cbrdf_status number; err.status, its name such as "checksum") and message. Sizes
// and array lengths are checked here before anything is allocated in the module; memory is
// returned by free(), withModel or Symbol.dispose, and by the finalizer only as a best effort
// (README: Memory).
// cbrdf.wasm is a standalone module (no Emscripten JavaScript runtime): it imports only a memory
// growth notice and a few WASI calls (exit; output, environment with some builds), supplied here.
import { packGpuTables } from './glsl.mjs';

// The GPU evaluation (glsl.mjs) from this module too, so that one import serves a renderer.
export { cbrdfGlsl, kGpuLayout, packGpuTables } from './glsl.mjs';

const kInfoFields = [
  'versionMajor', 'versionMinor', 'slices', 'maxComponents', 'bits', 'fileBytes',
  'notMeasuredBins', 'residualMode', 'residualMaxError', 'residualMinError', 'residualKnee',
  'residualBytes',
];  // cbrdf_wasm_info's order (cbrdf_wasm.c)
const kInvalidArgument = 9, kInternal = 11;  // cbrdf_status
// Every size this module asks of cbrdf.wasm stays below 2^31 bytes, checked before anything is
// allocated: the module is wasm32 with at most 2 GiB of memory (MAXIMUM_MEMORY,
// tools/wasm/CMakeLists.txt), and a size reaches malloc's size_t as an i32, so that a JavaScript
// number of 2^32 + 32 would arrive as 32 and the copy after it overwrite the heap.
const kMaxBytes = 2 ** 31;
// Statuses of this module's own, beside the C API's names (err.code stays a cbrdf_status).
const kOutOfMemory = 'out-of-memory', kAborted = 'aborted';
// Batch calls reuse one block of the module's heap per instance, kept between calls up to this
// size (116,508 pairs of eval); a larger call allocates its own and frees it.
const kScratchKeep = 8 << 20;
// cbrdf_viewer_slice's output: 90 theta_h, 180 phi_d and 90 theta_d masses, a 90 x 180 copula.
const kSliceFloats = 360 + 90 * 180;

// An error of the C API: code (cbrdf_status), status (its name) and the C API's message. Two
// statuses are this module's: "out-of-memory" (code CBRDF_ERROR_INTERNAL, as the C API reports
// running out of memory) and "aborted" (the instance stopped: see load()).
export class CbrdfError extends Error {
  constructor(code, status, message) {
    super(message);
    this.name = 'CbrdfError';
    this.code = code;
    this.status = status;
  }
}

function argumentError(message) {
  return new CbrdfError(kInvalidArgument, 'invalid-argument', message);
}

// count * unit bytes, or an INVALID_ARGUMENT (as the C API's "n = ... is too large") when that
// reaches 2^31.
function checkedBytes(what, count, unit) {
  const bytes = count * unit;
  if (!Number.isSafeInteger(count) || count < 0 || bytes >= kMaxBytes) {
    throw argumentError(`${what}: n = ${count} is too large: ${unit} bytes each, ${bytes} bytes ` +
                        'in all, and cbrdf.wasm holds less than 2^31');
  }
  return bytes;
}

async function wasmBytes(source) {
  if (source !== undefined) return source;
  const url = new URL('./cbrdf.wasm', import.meta.url);
  if (url.protocol === 'file:') {
    const { readFile } = await import('node:fs/promises');
    return readFile(url);
  }
  const response = await fetch(url);
  if (!response.ok) throw new Error(`cbrdf: fetching ${url} failed: ${response.status}`);
  return response.arrayBuffer();
}

// cbrdf.wasm called exit (abort() does, e.g. on an uncaught C++ exception).
class WasmExit extends Error {
  constructor(code) {
    super(`cbrdf.wasm exited with status ${code}`);
    this.exitCode = code;
  }
}

// One instance of cbrdf.wasm and the calls on its memory.
class Runtime {
  constructor(instance) {
    this.memory = instance.exports.memory;
    this.decoder = new TextDecoder();
    this.failure = null;  // the CbrdfError that stopped the instance (stop())
    this.liveModels = 0;  // opened and not yet freed
    this.scratchPtr = 0;  // withScratch's block, scratchSize bytes
    this.scratchSize = 0;
    // Every exported function through enter(), so that a trap or exit stops the instance.
    this.x = {};
    for (const [name, value] of Object.entries(instance.exports)) {
      this.x[name] = typeof value === 'function' ? (...args) => this.enter(value, args) : value;
    }
    // A model dropped without free() is freed when collected: a best effort only (README). The
    // registry holds the model's handles (an object the model shares), not the model.
    this.registry = typeof FinalizationRegistry === 'function'
      ? new FinalizationRegistry((handles) => this.release(handles, null))
      : null;
  }

  enter(f, args) {
    if (this.failure) throw this.failure;
    let result;
    try {
      result = f(...args);
    } catch (e) {
      this.stop(e);
      throw this.failure;
    }
    // An exit thrown through C++'s catch (...) (which catches JavaScript exceptions too) returns.
    if (this.failure) throw this.failure;
    return result;
  }

  // The module trapped or exited in the middle of a call: its memory may be inconsistent
  // (half-built objects, its stack pointer not restored), so nothing may run in it any more.
  stop(cause) {
    if (this.failure) return;
    const what = cause instanceof WasmExit ? `exited with status ${cause.exitCode}`
                                           : `stopped (${cause})`;
    // Near the 2 GiB maximum the cause was memory (an allocation inside a noexcept function).
    const full = this.memory.buffer.byteLength > kMaxBytes - (64 << 20);
    this.failure = full
      ? new CbrdfError(kInternal, kOutOfMemory, `out of memory: cbrdf.wasm ${what} with its ` +
                       `2 GiB full (${this.liveModels} models open); this instance cannot be ` +
                       'used any more: load() a new one, and free() models when done with them')
      : new CbrdfError(kInternal, kAborted, `cbrdf.wasm ${what}: this instance cannot be used ` +
                       'any more: load() a new one');
    this.failure.cause = cause;
  }

  bytes() { return new Uint8Array(this.memory.buffer); }  // fresh: memory may have grown
  f64(ptr, n) { return new Float64Array(this.memory.buffer, ptr, n); }
  f32(ptr, n) { return new Float32Array(this.memory.buffer, ptr, n); }
  i32(ptr, n) { return new Int32Array(this.memory.buffer, ptr, n); }

  string(ptr) {
    const b = this.bytes();
    let end = ptr;
    while (end < b.length && b[end] !== 0) ++end;  // bounded even for a bad pointer
    return this.decoder.decode(b.subarray(ptr, end));
  }

  outOfMemory(what) {
    return new CbrdfError(kInternal, kOutOfMemory, `out of memory: ${what} (cbrdf.wasm holds at ` +
                          `most 2 GiB; ${this.liveModels} models are open: free() those no ` +
                          'longer needed)');
  }

  // size bytes of the module's heap. Every caller has checked its sizes (checkedBytes); this
  // check stands behind them, so that no size can wrap on its way to malloc.
  malloc(size) {
    if (!Number.isSafeInteger(size) || size < 0 || size >= kMaxBytes) {
      throw argumentError(`malloc: ${size} bytes: not a size below 2^31`);
    }
    const p = this.x.malloc(Math.max(size, 1));
    if (p === 0) throw this.outOfMemory(`${size} bytes could not be allocated`);
    return p;
  }

  // Runs body(allocate) and frees what it allocated, whatever happens.
  scoped(body) {
    const blocks = [];
    try {
      return body((size) => {
        const p = this.malloc(size);
        blocks.push(p);
        return p;
      });
    } finally {
      if (!this.failure) for (const p of blocks) this.x.free(p);
    }
  }

  // Runs body(p) with size bytes of the module's heap at p: one block reused by every call (batch
  // calls of any size would otherwise cost a malloc and a free each), grown as needed; a request
  // above kScratchKeep gets a block of its own, freed after body. Calls never nest (body runs
  // nothing that reaches back here).
  withScratch(size, body) {
    if (size > kScratchKeep) return this.scoped((alloc) => body(alloc(size)));
    if (size > this.scratchSize) {
      const grown = Math.min(kScratchKeep, Math.max(size, 2 * this.scratchSize, 4096));
      if (this.scratchPtr !== 0) this.x.free(this.scratchPtr);
      this.scratchPtr = 0;
      this.scratchSize = 0;
      this.scratchPtr = this.malloc(grown);
      this.scratchSize = grown;
    }
    return body(this.scratchPtr);
  }

  // Copies a file's bytes into the module and runs open(p, size) on them (the copy is freed).
  withFile(bytes, open) {
    return this.scoped((alloc) => {
      const p = alloc(bytes.length);
      this.bytes().set(bytes, p);
      return open(p, bytes.length);
    });
  }

  // A C API handle of a file (cbrdf_model_open_memory), or the C API's error thrown.
  openHandle(bytes) {
    const m = this.withFile(bytes, (p, n) => this.x.cbrdf_model_open_memory(p, n));
    if (m === 0) throw this.lastError();
    return m;
  }

  lastError() {
    const code = this.x.cbrdf_last_error_code();
    const message = this.string(this.x.cbrdf_last_error_message());
    // The C API reports std::bad_alloc as CBRDF_ERROR_INTERNAL "out of memory" (cbrdf_decode.h).
    if (code === kInternal && message === 'out of memory') {
      return this.outOfMemory('the library could not allocate');
    }
    return new CbrdfError(code, this.string(this.x.cbrdf_status_name(code)), message);
  }

  check(status) {
    if (status !== 0) throw this.lastError();
  }

  // A Model of a file whose C API handle (api) or viewer handle (gpu), or both, are open (the
  // other is made from `file` when first needed).
  adopt(file, api, gpu) {
    const handles = { api, gpu };
    const model = new Model(this, handles, file);
    ++this.liveModels;
    this.registry?.register(model, handles, model);
    return model;
  }

  // Frees a model's handles (model: null from the finalizer). Never throws: it runs in finally
  // blocks and finalizers; a stopped instance's memory is beyond use anyway.
  release(handles, model) {
    if (model) this.registry?.unregister(model);
    --this.liveModels;
    const { api, gpu } = handles;
    handles.api = 0;
    handles.gpu = 0;
    if (this.failure) return;
    try {
      if (api !== 0) this.x.cbrdf_model_free(api);
      if (gpu !== 0) this.x.cbrdf_viewer_free(gpu);
    } catch {
      // stop() has recorded why; every later call throws that.
    }
  }
}

// A typed array's elements as doubles at p (Float32 values convert exactly).
function put(rt, p, values) {
  rt.f64(p, values.length).set(values);
}

// n results read as doubles at p, in the type of the caller's input (Float32Array: each double
// rounded to the nearest float, as C's (float) conversion).
function take(rt, p, count, like) {
  const v = rt.f64(p, count);
  return like instanceof Float32Array ? new Float32Array(v) : new Float64Array(v);
}

function isBatch(a) {
  return a instanceof Float64Array || a instanceof Float32Array;
}

function triples(name, a) {
  if (!isBatch(a)) throw argumentError(`${name}: expected a Float64Array or Float32Array`);
  if (a.length % 3 !== 0) {
    throw argumentError(`${name}: length ${a.length} is not a multiple of 3 (x, y, z per pair)`);
  }
  return a.length / 3;
}

function single(name, a, size) {
  if (!Array.isArray(a) || a.length !== size) {
    throw argumentError(`${name}: expected an array of ${size} numbers, or a Float64Array or ` +
                        'Float32Array batch');
  }
  return a;
}

// A copy of a Float32Array in the module's memory (null when count is 0).
function floats(rt, ptr, count) {
  return count === 0 ? null : new Float32Array(rt.f32(ptr, count));
}

export class Model {
  // handles: { api, gpu }, the C API's handle and the viewer's (cbrdf_viewer_open), 0 until made;
  // file: the file's bytes, from which the missing one is made.
  constructor(rt, handles, file) {
    this.rt = rt;
    this.handles = handles;
    this.file = file;
  }

  // The C API's handle (0 once freed).
  get handle() { return this.handles.api; }

  check() {
    if (this.file === null) throw argumentError('model: used after free()');
    if (this.rt.failure) throw this.rt.failure;
  }

  // The C API's handle, made on first use for a model opened with { gpu: true }.
  live() {
    this.check();
    if (this.handles.api === 0) this.handles.api = this.rt.openHandle(this.file);
    return this.handles.api;
  }

  // The viewer's handle (GPU tables, facts, marginals), made on first use: a second decode of the
  // file, kept until free(), unless the model was opened with { gpu: true }.
  gpu() {
    this.check();
    const { rt } = this;
    if (this.handles.gpu === 0) {
      const v = rt.withFile(this.file, (p, n) => rt.x.cbrdf_viewer_open(p, n));
      // The C API decoded this file, so only memory can be missing.
      if (v === 0) throw rt.outOfMemory('the GPU tables could not be built');
      this.handles.gpu = v;
    }
    return this.handles.gpu;
  }

  // What the file holds: cbrdf_model_info's fields (camelCase), the slices (theta_d ranges and
  // each channel's components: family, theta, scale) and the metadata entries [key, value].
  info() {
    const { rt } = this;
    const h = this.live();
    return rt.scoped((alloc) => {
      const fields = rt.x.cbrdf_wasm_info_fields();
      const p = alloc(8 * fields);
      rt.check(rt.x.cbrdf_wasm_info(h, p));
      const v = rt.f64(p, fields);
      const info = {};
      kInfoFields.forEach((name, i) => { info[name] = v[i]; });
      const ints = alloc(8), doubles = alloc(16);
      info.sliceList = [];
      for (let s = 0; s < info.slices; ++s) {
        rt.check(rt.x.cbrdf_model_get_slice(h, s, ints, ints + 4));
        const [begin, end] = rt.i32(ints, 2);
        const channels = [];
        for (let c = 0; c < 3; ++c) {
          rt.check(rt.x.cbrdf_model_get_component_count(h, s, c, ints));
          const count = rt.i32(ints, 1)[0];
          const components = [];
          for (let k = 0; k < count; ++k) {
            rt.check(rt.x.cbrdf_model_get_component(h, s, c, k, ints, doubles, doubles + 8));
            const family = rt.i32(ints, 1)[0];
            const [theta, scale] = rt.f64(doubles, 2);
            // The name from the library's family table (cbrdf_family_name).
            const name = rt.string(rt.x.cbrdf_family_name(family));
            components.push({ family: name === 'unknown' ? String(family) : name, theta, scale });
          }
          channels.push(components);
        }
        info.sliceList.push({ thetaDBegin: begin, thetaDEnd: end, channels });
      }
      info.metadata = [];
      rt.check(rt.x.cbrdf_model_metadata_count(h, ints));
      const n = rt.i32(ints, 1)[0];  // a size_t: 32 bits in wasm32
      for (let i = 0; i < n; ++i) {
        rt.check(rt.x.cbrdf_model_metadata_at(h, i, ints, ints + 4));
        const [key, value] = rt.i32(ints, 2);
        info.metadata.push([rt.string(key), rt.string(value)]);
      }
      return info;
    });
  }

  // f(wi, wo) in RGB (1/sr). Single pair: arrays [x, y, z] -> [r, g, b]. Batch: Float64Array or
  // Float32Array of n (x, y, z) triples each -> the same type of n (r, g, b) triples
  // (cbrdf_model_eval_batch, in double; a Float32Array gets the doubles rounded to float), or,
  // given out (a Float64Array or Float32Array of 3n, either type), written into out, which is
  // returned: nothing is allocated, so repeated batches cost the evaluation and two copies, not a
  // new array each and the collector's work after it.
  eval(wi, wo, out) {
    const { rt } = this;
    const h = this.live();
    if (!isBatch(wi) && !isBatch(wo)) {
      single('wi', wi, 3);
      single('wo', wo, 3);
      if (out !== undefined) {
        throw argumentError('out: only a batch (Float64Array or Float32Array wi and wo) writes ' +
                            'into out; a single pair returns [r, g, b]');
      }
      return rt.withScratch(72, (p) => {
        put(rt, p, wi);
        put(rt, p + 24, wo);
        rt.check(rt.x.cbrdf_model_eval(h, p, p + 24, p + 48));
        return Array.from(rt.f64(p + 48, 3));
      });
    }
    const n = triples('wi', wi);
    if (triples('wo', wo) !== n) {
      throw argumentError(`wo: ${wo.length / 3} directions for ${n} in wi`);
    }
    if (out !== undefined && (!isBatch(out) || out.length !== 3 * n)) {
      throw argumentError(`out: expected a Float64Array or Float32Array of ${3 * n} numbers ` +
                          `(r, g, b per pair), got ${isBatch(out) ? `length ${out.length}` :
                                                                   typeof out}`);
    }
    const bytes = checkedBytes('eval', n, 8 * 9);  // wi 3n, wo 3n, rgb 3n
    return rt.withScratch(bytes, (p) => {
      put(rt, p, wi);
      put(rt, p + 24 * n, wo);
      rt.check(rt.x.cbrdf_model_eval_batch(h, n, p, p + 24 * n, p + 48 * n, 1));
      if (out === undefined) return take(rt, p + 48 * n, 3 * n, wi);
      out.set(rt.f64(p + 48 * n, 3 * n));
      return out;
    });
  }

  // Importance sampling (cbrdf_model_sample_batch): incident directions wi drawn for outgoing
  // directions wo from uniform numbers u, with their densities and weights f cos / pdf. Single:
  // wo [x, y, z], u [u1, u2] -> { wi: [3], pdf, weight: [3] }. Batch: wo of n triples, u of n
  // pairs (Float64Array or Float32Array) -> { wi, pdf, weight } of 3n, n, 3n in wo's type.
  // A rejected draw (wo at or below the horizon, wi reflected below it) has wi = (0, 0, 0),
  // pdf 0 and weight 0; eval and pdf give 0 for that wi, so draws pass straight back:
  //   const s = model.sample(wo, u);  const f = model.eval(s.wi, wo);  // 0 where rejected
  sample(wo, u) {
    const { rt } = this;
    const h = this.live();
    const batch = isBatch(wo) || isBatch(u);
    let n = 1;
    if (batch) {
      n = triples('wo', wo);
      if (!isBatch(u) || u.length !== 2 * n) {
        throw argumentError(`u: expected a Float64Array or Float32Array of ${2 * n} numbers ` +
                            `(two per direction in wo), got ${isBatch(u) ? u.length : typeof u}`);
      }
    } else {
      single('wo', wo, 3);
      single('u', u, 2);
    }
    const bytes = checkedBytes('sample', n, 8 * 12);  // wo 3n, u 2n, wi 3n, pdf n, weight 3n
    return rt.withScratch(bytes, (p) => {
      const pu = p + 24 * n, pwi = pu + 16 * n, ppdf = pwi + 24 * n, pw = ppdf + 8 * n;
      put(rt, p, wo);
      put(rt, pu, u);
      rt.check(rt.x.cbrdf_model_sample_batch(h, n, p, pu, pwi, ppdf, pw, 1));
      if (!batch) {
        return { wi: Array.from(rt.f64(pwi, 3)), pdf: rt.f64(ppdf, 1)[0],
                 weight: Array.from(rt.f64(pw, 3)) };
      }
      return { wi: take(rt, pwi, 3 * n, wo), pdf: take(rt, ppdf, n, wo),
               weight: take(rt, pw, 3 * n, wo) };
    });
  }

  // The sampler's density of drawing wi given wo (cbrdf_model_sample_pdf), single pairs; (wi, wo)
  // as every call here.
  pdf(wi, wo) {
    const { rt } = this;
    const h = this.live();
    single('wi', wi, 3);
    single('wo', wo, 3);
    return rt.withScratch(56, (p) => {
      put(rt, p, wi);
      put(rt, p + 24, wo);
      rt.check(rt.x.cbrdf_model_sample_pdf(h, p, p + 24, p + 48));
      return rt.f64(p + 48, 1)[0];
    });
  }

  // The full MERL table as a .binary file stores it (cbrdf_model_table): 4,374,000 doubles,
  // channel blocks R, G, B of index phi_d + 180 (theta_d + 90 theta_h), in MERL's stored units.
  table() {
    const { rt } = this;
    const h = this.live();
    const count = rt.x.cbrdf_merl_table_size();
    const bytes = checkedBytes('table', count, 8);
    return rt.scoped((alloc) => {
      const p = alloc(bytes);
      rt.check(rt.x.cbrdf_model_table(h, p, count));
      return new Float64Array(rt.f64(p, count));
    });
  }

  // The evaluator's tables as float32 arrays (cbrdf/gpu_tables.h, spec/gpu-tables.md):
  // { tables, generic, residual }, generic and residual null when the model has none. Copies:
  // each call returns new arrays.
  gpuArrays() {
    const { rt } = this;
    const v = this.gpu();
    return rt.scoped((alloc) => {
      const count = alloc(4);
      const get = (which) => {
        const ptr = rt.x.cbrdf_viewer_array(v, which, count);
        return floats(rt, ptr, new Uint32Array(rt.memory.buffer, count, 1)[0]);
      };
      return { tables: get(0), generic: get(1), residual: get(2) };
    });
  }

  // What a renderer binds to evaluate the model with cbrdfGlsl (glsl.mjs): { layout, textures,
  // uniforms }, packGpuTables of gpuArrays().
  gpuTables() {
    return packGpuTables(this.gpuArrays());
  }

  // The file's layout and the evaluator's sizes, as `cbrdf view` shows them: { version, fileBytes,
  // bits, footprintBytes (the native evaluator's), gpuTableBytes, residualMode, residualMaxError,
  // residualMinError, residualKnee, residualEscapes, notMeasuredBins, chunks: [{ tag, offset,
  // storedBytes, payloadBytes, compressed }], sliceList, metadata } (sliceList and metadata as
  // info() gives them).
  facts() {
    const { rt } = this;
    return JSON.parse(rt.string(rt.x.cbrdf_viewer_facts(this.gpu())));
  }

  // Slice s's marginals and copula in channel c (0 R, 1 G, 2 B), its first component's:
  // { width, thetaH, phiD, thetaD, copula } (Float32Arrays): the probability masses of the 90
  // theta_h bins, the 180 phi_d bins and the slice's `width` theta_d bins, and the copula density
  // over the theta_h x phi_d bins (90 x 180, row by theta_h) at the slice's middle theta_d bin.
  sliceMarginals(s, c) {
    const { rt } = this;
    const v = this.gpu();
    if (!Number.isInteger(c) || c < 0 || c > 2) {
      throw argumentError(`sliceMarginals: channel ${c} is not 0, 1 or 2 (R, G, B)`);
    }
    return rt.withScratch(4 * kSliceFloats, (p) => {
      const width = Number.isInteger(s) ? rt.x.cbrdf_viewer_slice(v, s, c, p) : -1;
      if (width === -2) throw rt.outOfMemory(`sliceMarginals: slice ${s}'s copula plane`);
      if (width < 0) {
        const slices = this.facts().sliceList.length;
        throw argumentError(`sliceMarginals: slice ${s} is out of range (the model has ${slices}, ` +
                            `0 to ${slices - 1})`);
      }
      const a = new Float32Array(rt.f32(p, kSliceFloats));
      return { width, thetaH: a.subarray(0, 90), phiD: a.subarray(90, 270),
               thetaD: a.subarray(270, 270 + width), copula: a.subarray(360) };
    });
  }

  // Frees the model's memory in the module now; the model cannot be used afterwards. Idempotent;
  // never throws. Call it (or use withModel, or `using` where the runtime has it) for every model:
  // the finalizer frees a dropped model only if the garbage collector gets to it (README).
  free() {
    if (this.file === null) return;
    this.file = null;
    this.rt.release(this.handles, this);
  }
}
// `using model = cbrdf.open(bytes);` frees at the end of the block, where the runtime has
// explicit resource management (Symbol.dispose); elsewhere free() or withModel.
if (typeof Symbol.dispose === 'symbol') {
  Model.prototype[Symbol.dispose] = function dispose() { this.free(); };
}

// Runs fn(model) and frees the model when fn returns, throws or (for a promise) settles.
function freeAfter(model, fn) {
  let result;
  try {
    result = fn(model);
  } catch (e) {
    model.free();
    throw e;
  }
  if (result !== null && typeof result === 'object' && typeof result.then === 'function') {
    return Promise.resolve(result).finally(() => model.free());
  }
  model.free();
  return result;
}

// Creates an instance of cbrdf.wasm. `source`: its bytes (ArrayBuffer, typed array) or a compiled
// WebAssembly.Module; by default cbrdf.wasm beside this file (read from disk under node, fetched
// in a browser). Returns { open(bytes, options), withModel(bytes, fn), version, liveModels, failure,
// exports }: open decodes synchronously. Running out of memory throws a CbrdfError "out-of-memory"
// and the instance stays usable; if the module itself aborts (a trap, an exit), that call and
// every later one on this instance and its models throw a CbrdfError ("aborted", or
// "out-of-memory" if memory was full), `failure` holds it, and a new instance is needed.
export async function load(source) {
  let rt = null;
  const memory = () => rt.memory;
  const wasi = {
    // stdout/stderr (the library writes nothing there; a failed assertion would).
    fd_write(fd, iovs, count, written) {
      const view = new DataView(memory().buffer);
      let text = '', total = 0;
      for (let i = 0; i < count; ++i) {
        const ptr = view.getUint32(iovs + 8 * i, true), len = view.getUint32(iovs + 8 * i + 4, true);
        text += new TextDecoder().decode(new Uint8Array(memory().buffer, ptr, len));
        total += len;
      }
      (fd === 1 ? console.log : console.error)(text.replace(/\n$/, ''));
      view.setUint32(written, total, true);
      return 0;
    },
    // An empty environment (link-time-optimized builds ask for it).
    environ_sizes_get(count, size) {
      const view = new DataView(memory().buffer);
      view.setUint32(count, 0, true);
      view.setUint32(size, 0, true);
      return 0;
    },
    environ_get: () => 0,
    fd_close: () => 0,
    fd_seek: () => 70,  // ESPIPE: no seekable streams
    proc_exit(code) {
      const exit = new WasmExit(code);
      rt?.stop(exit);  // before a C++ catch (...) in between can swallow the throw
      throw exit;
    },
  };
  const imports = {
    env: { emscripten_notify_memory_growth() {} },  // views are made afresh at every use
    wasi_snapshot_preview1: wasi,
  };
  const bytes = await wasmBytes(source);
  const { instance } = bytes instanceof WebAssembly.Module
    ? { instance: await WebAssembly.instantiate(bytes, imports) }
    : await WebAssembly.instantiate(bytes, imports);
  rt = new Runtime(instance);
  rt.x._initialize();  // static constructors (a WASI reactor)
  rt.x.cbrdf_wasm_init();
  const api = {
    version: rt.string(rt.x.cbrdf_version_string()),
    // The module's exports (the viewer's cbrdf_viewer_*: viewer_tables.cc), each function through
    // the same guard as this module's calls (a trap stops the instance); sizes unchecked.
    exports: rt.x,
    // Models opened and not yet freed (by free(), withModel, dispose or the finalizer).
    get liveModels() { return rt.liveModels; },
    // null, or the CbrdfError that stopped this instance.
    get failure() { return rt.failure; },
    // Decodes a .cbrdf file (Uint8Array, ArrayBuffer or other typed array) with the C API's full
    // validation (cbrdf_model_open_memory); throws a CbrdfError for a bad file. The model keeps a
    // copy of the file: gpuTables(), facts() and sliceMarginals() decode it a second time on first
    // use. options.gpu: decode it for those at once instead (cbrdf_viewer_open, the same
    // validation), and for the C API's calls (info, eval, sample, pdf, table) only on first use:
    // a page that draws the model on the GPU then decodes it once.
    open(fileBytes, options = {}) {
      let b = fileBytes;
      if (b instanceof ArrayBuffer) b = new Uint8Array(b);
      else if (ArrayBuffer.isView(b)) b = new Uint8Array(b.buffer, b.byteOffset, b.byteLength);
      else throw argumentError('open: expected the file as a Uint8Array or ArrayBuffer');
      if (options === null || typeof options !== 'object') {
        throw argumentError('open: options must be an object such as { gpu: true }');
      }
      if (rt.failure) throw rt.failure;
      if (b.length >= kMaxBytes) {
        throw argumentError(`open: ${b.length} bytes is too large: cbrdf.wasm holds less than ` +
                            '2^31 (and a .cbrdf file has at most 64 MiB)');
      }
      const file = b.slice();  // the caller may change its array afterwards
      if (options.gpu) {
        const v = rt.withFile(file, (p, n) => rt.x.cbrdf_viewer_open(p, n));
        // The viewer's decode names no reason: the C API's open does (and, should the file have
        // decoded but memory run short, gives the model its handle, the GPU's made later).
        return v !== 0 ? rt.adopt(file, 0, v) : rt.adopt(file, rt.openHandle(file), 0);
      }
      return rt.adopt(file, rt.openHandle(file), 0);
    },
    // fn(model) with the file opened, the model freed when fn returns or throws (or, when fn
    // returns a promise, when that settles); returns what fn returns.
    withModel(fileBytes, fn) {
      return freeAfter(api.open(fileBytes), fn);
    },
  };
  return api;
}

let shared = null;

// The instance shared by open() and withModel(), made on first use and made afresh after it
// stopped (its models then throw its failure).
async function sharedInstance() {
  shared ??= load();
  let instance;
  try {
    instance = await shared;
  } catch (e) {
    shared = null;  // a failed fetch or compile is tried again by the next call
    throw e;
  }
  if (instance.failure) {
    shared = load();
    instance = await shared;
  }
  return instance;
}

// Decodes a .cbrdf file with a module instance shared by every call (made on first use); options
// as the instance's open() (load()).
export async function open(fileBytes, options) {
  return (await sharedInstance()).open(fileBytes, options);
}

// Opens the file, runs fn(model) (which may be async) and frees the model in `finally`: memory is
// returned when fn is done, whatever happens. Returns (a promise of) what fn returns.
export async function withModel(fileBytes, fn) {
  const model = await open(fileBytes);
  try {
    return await fn(model);
  } finally {
    model.free();
  }
}
