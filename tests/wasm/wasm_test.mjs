// SPDX-License-Identifier: MIT
// cbrdf.wasm (through cbrdf.mjs) against the native library (through tests/wasm/wasm_reference.c,
// the same C API) on every golden file: info fields exactly; the full table, 10,000+ random
// evaluations (double and float batches, single pairs) and 2,000 samples within a tolerance;
// damaged files rejected with the same code and message.
//
// Tolerance, not bit for bit: the two builds share every line of cbrdf but not the C library's
// math functions. Native code calls glibc's exp, expm1, log, log1p, pow, sin, cos, atan2 (glibc
// picks FMA variants on CPUs that have FMA), the module musl's (Emscripten's); they round apart
// in the last bit for some arguments (of those cbrdf calls, only sqrt agrees everywhere), and
// the model's terms carry that bit into a share of the values. Measured on the golden files:
// tables within 1.1e-13 relative (up to 19% of values differ in the last bits), evaluations
// within 3.2e-12, samples within 2e-14 (directions, absolute) and 1.3e-11 (densities, weights,
// relative). The checks allow 1e-10 (relative; absolute for unit-vector components): a real
// divergence (a wrong bin, table or parameter) is many orders larger. The float batches allow
// one float rounding step (2.4e-7 relative). Each check prints how many values are identical.
//   node --no-experimental-fetch wasm_test.mjs CBRDF_MJS WASM_REFERENCE GOLDEN_DIR
// Prints one line per check that fails and "N passed, M failed"; exit status 1 if any failed.
import { spawnSync } from 'node:child_process';
import { readdirSync, readFileSync, statSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { isDeepStrictEqual } from 'node:util';
import { pathToFileURL } from 'node:url';
import { checks } from './checks.mjs';

const [mjsPath, referencePath, goldenDir] = process.argv.slice(2);
if (!goldenDir) {
  console.error('usage: wasm_test.mjs CBRDF_MJS WASM_REFERENCE GOLDEN_DIR');
  process.exit(2);
}
const { load, CbrdfError } = await import(pathToFileURL(resolve(mjsPath)).href);

const { check, finish } = checks(CbrdfError);

// The native program's answer: stdout as a Buffer (or its JSON).
function reference(args, input) {
  const r = spawnSync(referencePath, args, { input, maxBuffer: 64 << 20 });
  if (r.status !== 0) {
    throw new Error(`wasm_reference ${args.join(' ')}: status ${r.status}: ${r.stderr}`);
  }
  return r.stdout;
}
const referenceJson = (args, input) => JSON.parse(reference(args, input).toString('utf8'));
const bytesOf = (typed) => Buffer.from(typed.buffer, typed.byteOffset, typed.byteLength);
const doublesOf = (buffer) =>
  new Float64Array(buffer.buffer.slice(buffer.byteOffset, buffer.byteOffset + buffer.length));

// How a's values compare with b's: how many differ bit for bit, the largest difference relative
// to max(|a|, |b|) (absolute with `absolute`), and how many exceed `tolerance`.
function compare(a, b, tolerance, absolute = false) {
  if (a.length !== b.length) return { differ: Infinity, max: Infinity, over: Infinity, n: b.length };
  let differ = 0, max = 0, over = 0;
  for (let i = 0; i < a.length; ++i) {
    if (Object.is(a[i], b[i])) continue;
    ++differ;
    const d = Math.abs(a[i] - b[i]);
    const e = absolute ? d : d / Math.max(Math.abs(a[i]), Math.abs(b[i]));
    if (!(e <= tolerance)) ++over;  // NaN against a number counts
    if (e > max || Number.isNaN(e)) max = e;
  }
  return { differ, max, over, n: a.length };
}
const kTolerance = 1e-10, kFloatTolerance = 2.4e-7;
function checkClose(what, a, b, tolerance = kTolerance, absolute = false) {
  const c = compare(a, b, tolerance, absolute);
  console.log(`  ${what}: ${c.n - c.differ} of ${c.n} identical, largest ${absolute ? 'absolute' : 'relative'} difference ${c.max.toExponential(2)}`);
  check(c.over === 0, `${what}: ${c.over} of ${c.n} values differ by more than ${tolerance} (largest ${c.max})`);
}

// A fixed sequence of uniform numbers in [0, 1) (mulberry32), so that every run tests the same
// pairs.
function uniforms(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

// n unit directions, uniform on the sphere (one in eight below the horizon: evaluated as 0).
function directions(n, rand) {
  const d = new Float64Array(3 * n);
  for (let k = 0; k < n; ++k) {
    const z = k % 8 === 7 ? -rand() : rand();
    const phi = 2 * Math.PI * rand();
    const r = Math.sqrt(Math.max(0, 1 - z * z));
    d[3 * k] = r * Math.cos(phi);
    d[3 * k + 1] = r * Math.sin(phi);
    d[3 * k + 2] = z;
  }
  return d;
}

// Pairs the evaluator treats apart: wi == wo, along the normal, grazing, h along the normal.
const s = Math.sqrt(0.5);
const kSpecial = [[[0, 0, 1], [0, 0, 1]], [[s, 0, s], [-s, 0, s]], [[s, 0, s], [s, 0, s]],
                  [[1, 0, 0], [0, 0, 1]], [[0, s, s], [0, -s, s]], [[0.6, 0, 0.8], [-0.6, 1e-17, 0.8]]];

// The module's size budget for the web (tools/wasm/README.md, Size), with the default options.
const wasmBytes = statSync(join(dirname(resolve(mjsPath)), 'cbrdf.wasm')).size;
check(wasmBytes <= 400000, `cbrdf.wasm is ${wasmBytes} bytes, over its budget of 400,000 ` +
      '(tools/wasm/README.md, Size: which code is compiled for size)');

const cbrdf = await load();
const files = readdirSync(goldenDir).filter((f) => f.endsWith('.cbrdf')).sort();
check(files.length > 0, `golden files in ${goldenDir}`);

for (const name of files) {
  const path = join(goldenDir, name);
  const bytes = readFileSync(path);
  const model = cbrdf.open(bytes);
  console.log(name);

  // info(): every field, slice, component and metadata entry as the native C API reports them.
  const info = model.info();
  const want = referenceJson(['info', path]);
  check(isDeepStrictEqual(info, want),
        `${name}: info ${JSON.stringify(info)} != native ${JSON.stringify(want)}`);

  // table(): the full MERL table bit for bit.
  const table = model.table();
  const tableWant = doublesOf(reference(['table', path]));
  checkClose(`${name}: table`, table, tableWant);

  // eval(): 10,000 random pairs plus the special ones, batches in double and float, bit for bit.
  const rand = uniforms(0x5eed + name.length);
  const n = 10000 + kSpecial.length;
  const wi = directions(n, rand), wo = directions(n, rand);
  kSpecial.forEach(([a, b], i) => {
    wi.set(a, 3 * (10000 + i));
    wo.set(b, 3 * (10000 + i));
  });
  const rgb = model.eval(wi, wo);
  const rgbWant = doublesOf(reference(['eval', path], Buffer.concat([bytesOf(wi), bytesOf(wo)])));
  check(rgb instanceof Float64Array, `${name}: eval of Float64Arrays returns a Float64Array`);
  checkClose(`${name}: eval (Float64Array)`, rgb, rgbWant);
  const nonzero = rgbWant.filter((v) => v > 0).length;
  check(nonzero > n, `${name}: eval: only ${nonzero} positive values (a model that evaluates)`);
  // Float32Array: the float directions evaluated in double, each result rounded to float.
  const wi32 = new Float32Array(wi), wo32 = new Float32Array(wo);
  const rgb32 = model.eval(wi32, wo32);
  const want32 = new Float32Array(doublesOf(reference(
      ['eval', path], Buffer.concat([bytesOf(new Float64Array(wi32)), bytesOf(new Float64Array(wo32))]))));
  check(rgb32 instanceof Float32Array, `${name}: eval of Float32Arrays returns a Float32Array`);
  checkClose(`${name}: eval (Float32Array)`, rgb32, want32, kFloatTolerance);
  // Single pairs (cbrdf_model_eval) equal the module's batch bit for bit (the same libm).
  let singleDiff = 0;
  for (let k = 0; k < n; k += 97) {
    const one = model.eval(Array.from(wi.subarray(3 * k, 3 * k + 3)),
                           Array.from(wo.subarray(3 * k, 3 * k + 3)));
    singleDiff += compare(new Float64Array(one), rgb.subarray(3 * k, 3 * k + 3), 0).differ;
  }
  check(singleDiff === 0, `${name}: eval (single pairs): ${singleDiff} values differ from the batch`);

  // sample(): 2,000 draws, wi, pdf and weight bit for bit.
  const m = 2000;
  const swo = directions(m, rand);
  const u = new Float64Array(2 * m).map(() => rand());
  const drawn = model.sample(swo, u);
  const sWant = doublesOf(reference(['sample', path], Buffer.concat([bytesOf(swo), bytesOf(u)])));
  checkClose(`${name}: sample wi`, drawn.wi, sWant.subarray(0, 3 * m), kTolerance, true);
  checkClose(`${name}: sample pdf`, drawn.pdf, sWant.subarray(3 * m, 4 * m));
  checkClose(`${name}: sample weight`, drawn.weight, sWant.subarray(4 * m, 7 * m));
  check(drawn.pdf.filter((p) => p > 0).length > m / 2, `${name}: sample: few accepted draws`);
  const one = model.sample(Array.from(swo.subarray(0, 3)), Array.from(u.subarray(0, 2)));
  check(compare(new Float64Array([...one.wi, one.pdf, ...one.weight]),
                new Float64Array([drawn.wi[0], drawn.wi[1], drawn.wi[2], drawn.pdf[0], drawn.weight[0],
                                  drawn.weight[1], drawn.weight[2]]), 0).differ === 0,
        `${name}: sample (single) equals the batch's first draw`);

  // Damaged files: the same code and message as the native library's.
  const damaged = [['truncated to 8 bytes', bytes.subarray(0, 8)],
                   ['truncated by half', bytes.subarray(0, bytes.length >> 1)],
                   ['last byte cut', bytes.subarray(0, bytes.length - 1)]];
  for (const at of [bytes.length >> 2, bytes.length >> 1, bytes.length - 12]) {
    const b = Uint8Array.from(bytes);
    b[at] ^= 0x10;
    damaged.push([`byte ${at} flipped`, b]);
  }
  const sig = Uint8Array.from(bytes);
  sig[1] ^= 0x01;
  damaged.push(['signature', sig]);
  for (const [what, b] of damaged) {
    const native = referenceJson(['open'], Buffer.from(b));
    let got = null;
    try {
      cbrdf.open(b).free();
      got = { code: 0, status: 'ok', message: '' };
    } catch (e) {
      got = e instanceof CbrdfError ? { code: e.code, status: e.status, message: e.message }
                                    : { code: -1, status: String(e), message: '' };
    }
    check(native.code !== 0 && isDeepStrictEqual(got, native),
          `${name}: ${what}: wasm ${JSON.stringify(got)} != native ${JSON.stringify(native)}`);
  }
  model.free();
  let afterFree = null;
  try {
    model.eval([0, 0, 1], [0, 0, 1]);
  } catch (e) {
    afterFree = e;
  }
  check(afterFree instanceof CbrdfError && afterFree.code === 9, `${name}: eval after free()`);
}

// Argument errors: the C API's own for a bad direction (code and message), JavaScript's for
// arrays of the wrong shape.
{
  const path = join(goldenDir, files[0]);
  const model = cbrdf.open(readFileSync(path));
  const badWi = new Float64Array([0, 0, 1, 0, 0, 2]), goodWo = new Float64Array([0, 0, 1, 0, 0, 1]);
  let e = null;
  try {
    model.eval(badWi, goodWo);
  } catch (x) {
    e = x;
  }
  // The native program reports the C API's failure on stderr: "...: eval: MESSAGE (STATUS)".
  const native = spawnSync(referencePath, ['eval', path],
                           { input: Buffer.concat([bytesOf(badWi), bytesOf(goodWo)]) });
  const nativeMessage = native.stderr.toString().trim();
  check(e instanceof CbrdfError && e.code === 9 && native.status === 1 &&
        nativeMessage.endsWith(`: eval: ${e.message} (${e.status})`),
        `bad direction: wasm ${e && e.code} "${e && e.message}", native "${nativeMessage}"`);
  e = null;
  try {
    model.eval(new Float64Array(4), new Float64Array(4));
  } catch (x) {
    e = x;
  }
  check(e instanceof CbrdfError && e.code === 9, 'batch length not a multiple of 3');
  model.free();
}

finish();
