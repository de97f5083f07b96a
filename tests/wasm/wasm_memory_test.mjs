// SPDX-License-Identifier: MIT
// cbrdf.mjs's sizes and memory: every size is checked against 2^31 before it reaches malloc (a
// JavaScript number passed to malloc's i32 wraps at 2^32: 96 n for sample and 72 n for eval
// became 32 bytes and the copy after it overwrote the heap); arrays of mismatched lengths are
// refused; running out of memory throws a CbrdfError "out-of-memory" and the instance stays
// usable; a trap stops the instance with a CbrdfError on every later call; withModel, dispose
// and free() return memory when they say.
//   node --no-experimental-fetch wasm_memory_test.mjs CBRDF_MJS GOLDEN_DIR
// Prints one line per check that fails and "N passed, M failed"; exit status 1 if any failed.
//
// The huge batches below are typed arrays that are never written: node gets them zero-filled
// from the system, which maps their pages only when touched, so they cost address space, not
// memory. Running out of memory is reached by first filling the module's 2 GiB with blocks of its
// own malloc (never touched either), leaving a few hundred MB, so the test takes seconds.
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { checks } from './checks.mjs';

const [mjsPath, goldenDir] = process.argv.slice(2);
if (!goldenDir) {
  console.error('usage: wasm_memory_test.mjs CBRDF_MJS GOLDEN_DIR');
  process.exit(2);
}
const wasm = await import(pathToFileURL(resolve(mjsPath)).href);
const { load, CbrdfError } = wasm;

const { check, thrown, thrownAsync, finish } = checks(CbrdfError);
const kInvalidArgument = 9, kInternal = 11;
function checkThrows(what, got, code, status, messagePart = '') {
  check(got.code === code && got.status === status && got.message.includes(messagePart),
        `${what}: expected CbrdfError ${code} ${status} "...${messagePart}...", got ` +
        JSON.stringify(got));
}

const golden = (name) => readFileSync(join(goldenDir, name));
const small = golden('v1.0-frank6-b10.cbrdf');
// A residual layer rebuilt per bin: about 52 MB of the module's memory per open model.
const big = golden('v1.2-residual-interp-frank6-b10.cbrdf');
const wi1 = [0.48, 0, 0.8774964387392122], wo1 = [-0.6, 0, 0.8];
const sameRgb = (a, b) => a.length === 3 && a.every((v, i) => Object.is(v, b[i]));

const cbrdf = await load();
const model = cbrdf.open(small);
const rgb = model.eval(wi1, wo1);
check(rgb.every((v) => v > 0), `reference evaluation ${rgb} is positive`);
const other = cbrdf.open(big);
const rgbBig = other.eval(wi1, wo1);
const drawn = other.sample(wo1, [0.3, 0.7]);

// Size wrap: n = 44,739,243 makes sample's 96 n = 2^32 + 32 bytes, n = 59,652,324 eval's 72 n.
{
  const n = 44739243;
  check(96 * n - 2 ** 32 === 32, 'sample: 96 n wraps to 32');
  const wo = new Float32Array(3 * n), u = new Float32Array(2 * n);
  checkThrows('sample, 96 n = 2^32 + 32 bytes', thrown(() => other.sample(wo, u)),
              kInvalidArgument, 'invalid-argument', `n = ${n} is too large`);
  const m = Math.ceil(2 ** 32 / 72);
  check(m === 59652324 && 72 * m - 2 ** 32 === 32, 'eval: 72 n wraps to 32');
  const wi = new Float32Array(3 * m), wo2 = new Float32Array(3 * m);
  checkThrows('eval, 72 n = 2^32 + 32 bytes', thrown(() => other.eval(wi, wo2)),
              kInvalidArgument, 'invalid-argument', `n = ${m} is too large`);
  // The smallest n whose bytes reach 2^31, in double batches.
  const k = Math.ceil(2 ** 31 / 96);
  checkThrows('sample, 96 n just above 2^31 bytes',
              thrown(() => other.sample(new Float64Array(3 * k), new Float64Array(2 * k))),
              kInvalidArgument, 'invalid-argument', `n = ${k} is too large`);
  // One below: a size malloc gets as asked, and cannot have in 2 GiB with a heap in use.
  checkThrows('sample, 96 n just below 2^31 bytes',
              thrown(() => other.sample(new Float32Array(3 * (k - 1)), new Float32Array(2 * (k - 1)))),
              kInternal, 'out-of-memory', 'out of memory');
  // A 2 GiB file (a .cbrdf file has at most 64 MiB).
  checkThrows('open, 2^31 bytes', thrown(() => cbrdf.open(new Uint8Array(2 ** 31))),
              kInvalidArgument, 'invalid-argument', `${2 ** 31} bytes is too large`);
  // The heap is intact: both models evaluate as before and new ones open.
  check(sameRgb(model.eval(wi1, wo1), rgb), 'after the refused sizes, a model evaluates as before');
  check(sameRgb(other.eval(wi1, wo1), rgbBig), 'after the refused sizes, the other model too');
  const again = other.sample(wo1, [0.3, 0.7]);
  check(sameRgb(again.wi, drawn.wi) && again.pdf === drawn.pdf, 'and samples as before');
  const fresh = cbrdf.open(small);
  check(sameRgb(fresh.eval(wi1, wo1), rgb), 'after the refused sizes, a new open works');
  fresh.free();
  check(cbrdf.failure === null, 'the instance is not stopped by refused sizes');
}

// Arrays whose lengths do not match are refused before anything is allocated.
{
  const d = (n) => new Float64Array(3 * n).map((_, i) => (i % 3 === 2 ? 1 : 0));
  checkThrows('eval: wo shorter than wi', thrown(() => model.eval(d(5), d(4))), kInvalidArgument,
              'invalid-argument', 'wo: 4 directions for 5');
  checkThrows('eval: wo longer than wi', thrown(() => model.eval(d(4), d(5))), kInvalidArgument,
              'invalid-argument', 'wo: 5 directions for 4');
  checkThrows('eval: wi not a multiple of 3', thrown(() => model.eval(new Float64Array(7), d(2))),
              kInvalidArgument, 'invalid-argument', 'wi: length 7');
  checkThrows('eval: a batch with a plain array', thrown(() => model.eval(d(1), [0, 0, 1])),
              kInvalidArgument, 'invalid-argument', 'wo: expected a Float64Array');
  checkThrows('eval: a single pair of 2', thrown(() => model.eval([0, 0, 1], [0, 1])),
              kInvalidArgument, 'invalid-argument', 'wo: expected an array of 3');
  checkThrows('sample: u of 2n - 2', thrown(() => model.sample(d(4), new Float64Array(6))),
              kInvalidArgument, 'invalid-argument', 'of 8 numbers');
  checkThrows('sample: u of 2n + 1', thrown(() => model.sample(d(4), new Float64Array(9))),
              kInvalidArgument, 'invalid-argument', 'of 8 numbers');
  checkThrows('sample: u a plain array', thrown(() => model.sample(d(1), [0.5, 0.5])),
              kInvalidArgument, 'invalid-argument', 'of 2 numbers');
  checkThrows('pdf: wi of 4', thrown(() => model.pdf([0, 0, 1, 0], [0, 0, 1])), kInvalidArgument,
              'invalid-argument', 'wi: expected an array of 3');
  check(sameRgb(model.eval(wi1, wo1), rgb), 'after the refused lengths, the model evaluates');
}

// Out of memory: fill the module's 2 GiB with untouched blocks, give back 4 x 64 MiB, then
// open 52 MB models until the memory runs out.
{
  const x = cbrdf.exports;
  check(x.memory instanceof WebAssembly.Memory, 'exports keeps the memory (the viewer reads it)');
  const ballast = [];
  for (let p; (p = x.malloc(64 << 20)) !== 0;) ballast.push(p);
  check(ballast.length > 20, `ballast: ${ballast.length} blocks of 64 MiB before malloc failed`);
  for (let i = 0; i < 4; ++i) x.free(ballast.pop());
  const opened = [];
  let error = null;
  const start = performance.now();
  try {
    for (let i = 0; i < 64; ++i) opened.push(cbrdf.open(big));
  } catch (e) {
    error = e;
  }
  console.log(`  out of memory after ${opened.length} open models ` +
              `(${(performance.now() - start).toFixed(0)} ms): ${error && error.message}`);
  check(error instanceof CbrdfError && error.code === kInternal && error.status === 'out-of-memory',
        `opening until memory runs out: expected CbrdfError ${kInternal} out-of-memory, got ` +
        `${error && error.constructor.name} ${error && error.status} "${error && error.message}"`);
  check(opened.length >= 1 && opened.length < 64, `${opened.length} models opened before that`);
  check(cbrdf.failure === null, 'the instance is still usable after running out of memory');
  check(cbrdf.liveModels === opened.length + 2, `liveModels ${cbrdf.liveModels} counts the open`);
  // Memory is full, and still the open models evaluate, and errors are reported, not trapped.
  check(opened.length === 0 || sameRgb(opened[opened.length - 1].eval(wi1, wo1), rgbBig),
        'with memory full, the last model opened evaluates');
  check(sameRgb(model.eval(wi1, wo1), rgb), 'with memory full, an earlier model evaluates');
  for (const m of opened) m.free();
  check(cbrdf.liveModels === 2, `after free(), liveModels ${cbrdf.liveModels} is 2`);
  // Freed memory is used again: as many opens as before in a row, each freed by withModel (with
  // nothing freed, the second would already run out).
  let reopened = 0;
  const retry = thrown(() => {
    for (let i = 0; i < opened.length + 2; ++i) {
      cbrdf.withModel(big, (m) => {
        if (sameRgb(m.eval(wi1, wo1), rgbBig)) ++reopened;
      });
    }
  });
  check(reopened === opened.length + 2,
        `after free(), ${reopened} of ${opened.length + 2} opens through withModel evaluate ` +
        `(${JSON.stringify(retry)})`);
  check(cbrdf.liveModels === 2, `withModel leaves liveModels at 2, not ${cbrdf.liveModels}`);
  // Explicit resource management where the runtime has it (using / Symbol.dispose).
  if (typeof Symbol.dispose === 'symbol') {
    let disposed = 0;
    for (let i = 0; i < opened.length + 2; ++i) {
      const m = cbrdf.open(big);
      m[Symbol.dispose]();
      if (m.handle === 0) ++disposed;
    }
    check(disposed === opened.length + 2 && cbrdf.liveModels === 2,
          `Symbol.dispose freed ${disposed} models, liveModels ${cbrdf.liveModels}`);
  } else {
    console.log('  Symbol.dispose: not in this runtime (not checked)');
  }
  for (const p of ballast) x.free(p);
  const last = cbrdf.open(big);
  check(sameRgb(last.eval(wi1, wo1), rgbBig), 'with the ballast freed, a new open');
  last.free();
}

// withModel: frees when fn returns, throws, or its promise settles; returns fn's result.
{
  const before = cbrdf.liveModels;
  let inside = -1, kept = null;
  const result = cbrdf.withModel(small, (m) => {
    inside = cbrdf.liveModels;
    kept = m;
    return m.eval(wi1, wo1);
  });
  check(sameRgb(result, rgb) && inside === before + 1 && cbrdf.liveModels === before,
        `withModel: result, ${inside} live inside, ${cbrdf.liveModels} after (${before} before)`);
  checkThrows('withModel: the model after it returned', thrown(() => kept.eval(wi1, wo1)),
              kInvalidArgument, 'invalid-argument', 'used after free()');
  const boom = new Error('boom');
  let caught = null;
  try {
    cbrdf.withModel(small, () => { throw boom; });
  } catch (e) {
    caught = e;
  }
  check(caught === boom && cbrdf.liveModels === before, 'withModel: fn throws: rethrown, freed');
  let settledInside = -1;
  const pending = cbrdf.withModel(small, async (m) => {
    await new Promise((r) => setTimeout(r, 5));
    settledInside = cbrdf.liveModels;
    return m.eval(wi1, wo1);
  });
  check(cbrdf.liveModels === before + 1, 'withModel: async fn: open while it runs');
  check(sameRgb(await pending, rgb) && settledInside === before + 1 &&
        cbrdf.liveModels === before, 'withModel: async fn: freed when it settles');
  const shared = await wasm.withModel(small, async (m) => m.eval(wi1, wo1));
  check(sameRgb(shared, rgb), 'withModel (the shared instance) returns fn\'s result');
  const sharedError = await thrownAsync(() => wasm.withModel(small.subarray(0, 8), () => 0));
  check(sharedError.code === 3 && sharedError.status === 'truncated',
        `withModel: a damaged file throws its CbrdfError: ${JSON.stringify(sharedError)}`);
  // free() and dispose are idempotent and never throw.
  const m = cbrdf.open(small);
  m.free();
  m.free();
  check(cbrdf.liveModels === before, 'free() twice frees once');
}

// A trap (a bad pointer through the raw exports) stops the instance: every later call, and its
// models, throw a CbrdfError "aborted"; free() still does not throw; a new instance works.
{
  const kFar = 2 ** 31 - 8;  // an address beyond a fresh instance's memory
  const doomed = await load();
  const m = doomed.open(small);
  const trap = thrown(() => doomed.exports.cbrdf_model_eval(m.handle, kFar, kFar, kFar));
  checkThrows('a trap', trap, kInternal, 'aborted', 'cannot be used any more');
  check(doomed.failure instanceof CbrdfError, 'failure records it');
  checkThrows('eval after the trap', thrown(() => m.eval(wi1, wo1)), kInternal, 'aborted',
              'load() a new one');
  checkThrows('open after the trap', thrown(() => doomed.open(small)), kInternal, 'aborted');
  checkThrows('raw exports after the trap', thrown(() => doomed.exports.malloc(8)), kInternal,
              'aborted');
  check(thrown(() => m.free()).other === 'nothing thrown', 'free() after the trap does not throw');
  // The shared instance is made afresh after it stopped.
  const sm = await wasm.open(small);
  thrown(() => sm.rt.x.cbrdf_model_eval(sm.handle, kFar, kFar, kFar));
  checkThrows('the shared instance\'s model after its trap', thrown(() => sm.eval(wi1, wo1)),
              kInternal, 'aborted');
  const sm2 = await wasm.open(small);
  check(sameRgb(sm2.eval(wi1, wo1), rgb), 'open() after the shared instance stopped works');
  sm2.free();
  check(sameRgb(model.eval(wi1, wo1), rgb), 'another instance is not affected');
}

model.free();
other.free();
finish();
