// SPDX-License-Identifier: MIT
// cbrdf.mjs's GPU side and output arrays: gpuArrays(), facts() and sliceMarginals() equal what
// the module's cbrdf_viewer_* exports give when called directly (the viewer's path before the
// package had them), gpuTables() is glsl.mjs's packGpuTables of those arrays, a model opened with
// { gpu: true } decodes its file once until a C API call needs it, eval(wi, wo, out) writes what
// eval(wi, wo) returns, batch calls reuse their memory, and misuse throws CbrdfErrors that say
// what was wrong.
//   node --no-experimental-fetch wasm_api_test.mjs CBRDF_MJS GOLDEN_DIR
// Prints one line per check that fails and "N passed, M failed"; exit status 1 if any failed.
import { readFileSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { isDeepStrictEqual } from 'node:util';
import { pathToFileURL } from 'node:url';
import { checks } from './checks.mjs';
import { hemisphere } from './directions.mjs';

const [mjsPath, goldenDir] = process.argv.slice(2);
if (!goldenDir) {
  console.error('usage: wasm_api_test.mjs CBRDF_MJS GOLDEN_DIR');
  process.exit(2);
}
const cbrdfUrl = pathToFileURL(resolve(mjsPath)).href;
const { load, CbrdfError, cbrdfGlsl, packGpuTables } = await import(cbrdfUrl);
const glsl = await import(pathToFileURL(join(dirname(resolve(mjsPath)), 'glsl.mjs')).href);

const { check, thrown, finish } = checks(CbrdfError);
function checkThrows(what, got, status, messagePart) {
  check(got.status === status && got.message.includes(messagePart),
        `${what}: expected CbrdfError ${status} "...${messagePart}...", got ${JSON.stringify(got)}`);
}

// Equal element for element, bit for bit (NaN equal to NaN), and of one type and length.
function sameArray(a, b) {
  if (a === null || b === null) return a === b;
  return a.constructor === b.constructor && a.length === b.length && a.every((v, i) => Object.is(v, b[i]));
}

const directions = hemisphere(271828);

const cbrdf = await load();
const x = cbrdf.exports;

// The viewer's arrays of a file through the raw exports, as viewer/brdfs.mjs read them.
function rawViewer(bytes) {
  const p = x.malloc(bytes.length);
  new Uint8Array(x.memory.buffer).set(bytes, p);
  const v = x.cbrdf_viewer_open(p, bytes.length);
  x.free(p);
  const countPtr = x.malloc(4);
  const get = (which) => {
    const ptr = x.cbrdf_viewer_array(v, which, countPtr);
    const n = new Uint32Array(x.memory.buffer, countPtr, 1)[0];
    return n ? new Float32Array(new Float32Array(x.memory.buffer, ptr, n)) : null;
  };
  const facts = (() => {
    const b = new Uint8Array(x.memory.buffer);
    const at = x.cbrdf_viewer_facts(v);
    let end = at;
    while (b[end] !== 0) ++end;
    return JSON.parse(new TextDecoder().decode(b.subarray(at, end)));
  })();
  const out = { tables: get(0), generic: get(1), residual: get(2), facts };
  x.free(countPtr);
  out.slice = (s, c) => {
    const buf = x.malloc(16560 * 4);
    const width = x.cbrdf_viewer_slice(v, s, c, buf);
    const a = new Float32Array(new Float32Array(x.memory.buffer, buf, 16560));
    x.free(buf);
    return { width, a };
  };
  out.free = () => x.cbrdf_viewer_free(v);
  return out;
}

// Decodes counted by wrapping the two exports that decode a file (the model calls them through
// the same object).
let decodes = { api: 0, gpu: 0 };
for (const [name, key] of [['cbrdf_model_open_memory', 'api'], ['cbrdf_viewer_open', 'gpu']]) {
  const f = x[name];
  x[name] = (...a) => { ++decodes[key]; return f(...a); };
}

check(cbrdfGlsl === glsl.cbrdfGlsl && packGpuTables === glsl.packGpuTables,
      'cbrdf.mjs re-exports glsl.mjs\'s cbrdfGlsl and packGpuTables');

// Plain, generic terms (a mixture), a residual layer, an interpolated residual layer.
const names = ['v1.0-frank6-b10.cbrdf', 'v1.3-mixture3-b12.cbrdf', 'v1.3-residual-frank6-b10.cbrdf',
               'v1.2-residual-interp-frank6-b10.cbrdf'];
const wi = directions(500), wo = directions(500);
for (const name of names) {
  const bytes = readFileSync(join(goldenDir, name));
  const raw = rawViewer(bytes);
  decodes = { api: 0, gpu: 0 };
  const model = cbrdf.open(bytes);
  check(decodes.api === 1 && decodes.gpu === 0, `${name}: open decodes once, for the C API ` +
        `(${JSON.stringify(decodes)})`);
  const arrays = model.gpuArrays();
  check(decodes.gpu === 1, `${name}: gpuArrays() decodes the file for the GPU once`);
  for (const k of ['tables', 'generic', 'residual']) {
    check(sameArray(arrays[k], raw[k]), `${name}: gpuArrays().${k} equals cbrdf_viewer_array's`);
  }
  const packed = model.gpuTables();
  check(packed.layout === glsl.kGpuLayout, `${name}: gpuTables().layout ${packed.layout} is ` +
        `glsl.mjs's kGpuLayout ${glsl.kGpuLayout}`);
  check(isDeepStrictEqual(packed, packGpuTables(raw)), `${name}: gpuTables() is packGpuTables ` +
        'of the viewer\'s arrays');
  check(decodes.gpu === 1 && decodes.api === 1, `${name}: gpuTables() after gpuArrays() decodes ` +
        `nothing more (${JSON.stringify(decodes)})`);
  const facts = model.facts();
  check(isDeepStrictEqual(facts, raw.facts), `${name}: facts() equals cbrdf_viewer_facts`);
  const info = model.info();
  check(isDeepStrictEqual(facts.sliceList, info.sliceList) &&
        isDeepStrictEqual(facts.metadata, info.metadata) && facts.fileBytes === bytes.length,
        `${name}: facts()'s slices, metadata and size are info()'s`);
  for (const [s, c] of [[0, 0], [info.slices - 1, 2], [info.slices >> 1, 1]]) {
    const m = model.sliceMarginals(s, c);
    const r = raw.slice(s, c);
    const width = info.sliceList[s].thetaDEnd - info.sliceList[s].thetaDBegin;
    check(m.width === r.width && m.width === width && m.thetaH.length === 90 &&
          m.phiD.length === 180 && m.thetaD.length === width && m.copula.length === 90 * 180 &&
          sameArray(m.thetaH, r.a.subarray(0, 90)) && sameArray(m.phiD, r.a.subarray(90, 270)) &&
          sameArray(m.thetaD, r.a.subarray(270, 270 + width)) &&
          sameArray(m.copula, r.a.subarray(360)),
          `${name}: sliceMarginals(${s}, ${c}) equals cbrdf_viewer_slice's`);
    const mass = m.thetaH.reduce((a, b) => a + b, 0);
    check(Math.abs(mass - 1) < 1e-3, `${name}: slice ${s}: theta_h masses sum to ${mass}, not 1`);
  }
  raw.free();

  // { gpu: true }: one decode for the GPU at open, the C API's on first use, values alike.
  decodes = { api: 0, gpu: 0 };
  const gpuFirst = cbrdf.open(bytes, { gpu: true });
  const same = isDeepStrictEqual(gpuFirst.gpuTables(), packed) &&
               isDeepStrictEqual(gpuFirst.facts(), facts);
  check(same && decodes.gpu === 1 && decodes.api === 0, `${name}: open(bytes, { gpu: true }): ` +
        `the same tables and facts from one decode (${JSON.stringify(decodes)})`);
  check(sameArray(gpuFirst.eval(wi, wo), model.eval(wi, wo)) && decodes.api === 1,
        `${name}: { gpu: true }: eval() decodes for the C API on first use and equals the other's`);
  check(isDeepStrictEqual(gpuFirst.info(), info) && decodes.api === 1,
        `${name}: { gpu: true }: info() as the other's, no third decode`);
  gpuFirst.free();
  model.free();
}

// eval(wi, wo, out): out written with what eval(wi, wo) returns, in out's type, and returned;
// out may be one of the inputs (they are copied in first).
{
  const model = cbrdf.open(readFileSync(join(goldenDir, 'v1.0-frank6-b10.cbrdf')));
  const want = model.eval(wi, wo);
  const out = new Float64Array(wi.length).fill(-1);
  check(model.eval(wi, wo, out) === out && sameArray(out, want), 'eval(wi, wo, out) fills and ' +
        'returns out (Float64Array)');
  const out32 = new Float32Array(wi.length);
  check(model.eval(wi, wo, out32) === out32 && sameArray(out32, new Float32Array(want)),
        'eval(wi, wo, out) into a Float32Array: the doubles rounded to float');
  const wi32 = new Float32Array(wi), wo32 = new Float32Array(wo);
  check(sameArray(model.eval(wi32, wo32, new Float32Array(wi.length)), model.eval(wi32, wo32)),
        'eval(Float32Array, Float32Array, out) equals eval(Float32Array, Float32Array)');
  const inPlace = Float64Array.from(wi);
  model.eval(inPlace, wo, inPlace);
  check(sameArray(inPlace, want), 'eval(wi, wo, wi): out may be an input');

  checkThrows('out of the wrong length', thrown(() => model.eval(wi, wo, new Float64Array(3))),
              'invalid-argument', `out: expected a Float64Array or Float32Array of ${wi.length}`);
  checkThrows('out as a plain array', thrown(() => model.eval(wi, wo, [])), 'invalid-argument',
              'got object');
  checkThrows('out with a single pair', thrown(() => model.eval([0, 0, 1], [0, 0, 1],
                                                                 new Float64Array(3))),
              'invalid-argument', 'out: only a batch');

  // A bad direction deep in a batch: the C API's message names its index.
  const bad = Float64Array.from(wi);
  bad[3 * 417 + 2] = NaN;
  checkThrows('NaN in wi[417]', thrown(() => model.eval(bad, wo, out)), 'invalid-argument',
              'wi[417] must be a finite unit vector');
  const badWo = Float64Array.from(wo);
  badWo[3 * 9] = 3;
  checkThrows('wo[9] too long', thrown(() => model.eval(wi, badWo)), 'invalid-argument', 'wo[9]');

  // Batches reuse one block of the module's heap: repeated calls of one size, and calls too large
  // to keep a block for (freed after each), leave the module's memory as it was after the first.
  const big = directions(150000);
  const bigOut = new Float64Array(big.length);
  model.eval(big, big, bigOut);
  model.eval(wi, wo, out);
  const grown = x.memory.buffer.byteLength;
  for (let i = 0; i < 6; ++i) {
    model.eval(big, big, bigOut);
    model.eval(wi, wo);
    model.sample(wo, new Float64Array(2 * (wo.length / 3)).fill(0.5));
  }
  check(x.memory.buffer.byteLength === grown, `batches leave memory at ${grown} bytes, not ` +
        `${x.memory.buffer.byteLength}`);
  model.free();

  // After free(): every call throws.
  for (const [what, call] of [['eval', () => model.eval(wi, wo, out)], ['gpuTables', () => model.gpuTables()],
                              ['facts', () => model.facts()], ['sliceMarginals', () => model.sliceMarginals(0, 0)],
                              ['gpuArrays', () => model.gpuArrays()], ['info', () => model.info()]]) {
    checkThrows(`${what} after free()`, thrown(call), 'invalid-argument', 'used after free()');
  }
}

// sliceMarginals' arguments; open's options.
{
  const model = cbrdf.open(readFileSync(join(goldenDir, 'v1.0-tiny1-b6.cbrdf')));
  const slices = model.info().slices;
  checkThrows('slice out of range', thrown(() => model.sliceMarginals(slices, 0)),
              'invalid-argument', `slice ${slices} is out of range (the model has ${slices}, 0 to ` +
              `${slices - 1})`);
  checkThrows('slice not an integer', thrown(() => model.sliceMarginals(0.5, 0)),
              'invalid-argument', 'slice 0.5 is out of range');
  checkThrows('channel 3', thrown(() => model.sliceMarginals(0, 3)), 'invalid-argument',
              'channel 3 is not 0, 1 or 2');
  checkThrows('options not an object', thrown(() => cbrdf.open(readFileSync(join(goldenDir,
              'v1.0-tiny1-b6.cbrdf')), 'gpu')), 'invalid-argument', 'options must be an object');
  model.free();
  // A damaged file opened with { gpu: true }: the C API's error, as without it.
  const damaged = readFileSync(join(goldenDir, 'v1.0-tiny1-b6.cbrdf')).subarray(0, 40);
  const plain = thrown(() => cbrdf.open(damaged));
  const gpu = thrown(() => cbrdf.open(damaged, { gpu: true }));
  check(plain.code === 3 && isDeepStrictEqual(gpu, plain), `a truncated file with { gpu: true }: ` +
        `${JSON.stringify(gpu)}, without: ${JSON.stringify(plain)}`);
  check(cbrdf.liveModels === 0, `every model freed (liveModels ${cbrdf.liveModels})`);
}

finish();
