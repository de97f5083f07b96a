// SPDX-License-Identifier: MIT
// Evaluation speed of cbrdf.wasm under node against the native library, in one run on the same
// direction pairs through the same batch call (cbrdf_model_eval_batch, one thread each; the
// module's time includes cbrdf.mjs copying the pairs in and the values out).
//   node --no-experimental-fetch bench.mjs CBRDF_MJS WASM_REFERENCE FILE.cbrdf [PAIRS] [MS]
import { spawnSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [mjsPath, referencePath, file, pairsArg, msArg] = process.argv.slice(2);
if (!file) {
  console.error('usage: bench.mjs CBRDF_MJS WASM_REFERENCE FILE.cbrdf [PAIRS] [MS]');
  process.exit(2);
}
const pairs = Number(pairsArg ?? 65536), budget = Number(msArg ?? 2000);
const { load } = await import(pathToFileURL(resolve(mjsPath)).href);

// Pairs above the horizon, uniform on the hemisphere, fixed.
let seed = 12345;
const rand = () => (seed = (seed * 16807) % 2147483647) / 2147483647;
function directions(n) {
  const d = new Float64Array(3 * n);
  for (let k = 0; k < n; ++k) {
    const z = rand(), phi = 2 * Math.PI * rand(), r = Math.sqrt(1 - z * z);
    d.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * k);
  }
  return d;
}
const wi = directions(pairs), wo = directions(pairs);

function native() {
  const input = Buffer.concat([Buffer.from(wi.buffer), Buffer.from(wo.buffer)]);
  const r = spawnSync(referencePath, ['bench', file, String(budget)], { input });
  if (r.status !== 0) throw new Error(`wasm_reference bench: ${r.stderr}`);
  return JSON.parse(r.stdout.toString()).ns_per_pair;
}

function wasm(model) {
  model.eval(wi, wo);  // warm up (tiers up the compiled code)
  let reps = 0;
  const start = process.hrtime.bigint();
  let elapsed = 0;
  do {
    model.eval(wi, wo);
    ++reps;
    elapsed = Number(process.hrtime.bigint() - start) / 1e6;
  } while (elapsed < budget);
  return (elapsed * 1e6) / (reps * pairs);
}

const model = (await load()).open(readFileSync(file));
// Alternated, three times each, so that both see the machine's load alike; the medians' ratio.
const n = [], w = [];
for (let i = 0; i < 3; ++i) {
  n.push(native());
  w.push(wasm(model));
}
model.free();
const mid = (a) => a.slice().sort((x, y) => x - y)[a.length >> 1];
console.log(JSON.stringify({ file, pairs, native_ns_per_pair: n, wasm_ns_per_pair: w,
                             ratio_wasm_over_native: +(mid(w) / mid(n)).toFixed(2) }));
