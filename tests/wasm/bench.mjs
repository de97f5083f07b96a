// SPDX-License-Identifier: MIT
// Evaluation speed of cbrdf.wasm under node against the native library, in one run on the same
// direction pairs through the same batch call (cbrdf_model_eval_batch, one thread each). The
// module's time is cbrdf.mjs's eval(wi, wo, out): the pairs copied in, the values copied into the
// caller's array; `alloc` is eval(wi, wo), which returns a new array each call.
//   node --no-experimental-fetch bench.mjs CBRDF_MJS WASM_REFERENCE FILE.cbrdf [PAIRS] [MS]
import { spawnSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { hemisphere } from './directions.mjs';

const [mjsPath, referencePath, file, pairsArg, msArg] = process.argv.slice(2);
if (!file) {
  console.error('usage: bench.mjs CBRDF_MJS WASM_REFERENCE FILE.cbrdf [PAIRS] [MS]');
  process.exit(2);
}
const pairs = Number(pairsArg ?? 65536), budget = Number(msArg ?? 2000);
const { load } = await import(pathToFileURL(resolve(mjsPath)).href);

// Pairs above the horizon, uniform on the hemisphere, fixed.
const directions = hemisphere(12345);
const wi = directions(pairs), wo = directions(pairs);

function native() {
  const input = Buffer.concat([Buffer.from(wi.buffer), Buffer.from(wo.buffer)]);
  const r = spawnSync(referencePath, ['bench', file, String(budget)], { input });
  if (r.status !== 0) throw new Error(`wasm_reference bench: ${r.stderr}`);
  return JSON.parse(r.stdout.toString()).ns_per_pair;
}

const out = new Float64Array(3 * pairs);
function wasm(model, into = true) {
  const run = into ? () => model.eval(wi, wo, out) : () => model.eval(wi, wo);
  run();  // warm up (tiers up the compiled code)
  let reps = 0;
  // CPU time (as wasm_reference measures it), user and system, of every thread of node's: the
  // compiler's and the collector's count against the module.
  const start = process.cpuUsage();
  let elapsed = 0;
  do {
    run();
    ++reps;
    const used = process.cpuUsage(start);
    elapsed = (used.user + used.system) / 1e3;
  } while (elapsed < budget);
  return (elapsed * 1e6) / (reps * pairs);
}

const model = (await load()).open(readFileSync(file));
// Alternated, three times each, so that both see the machine's load alike; the medians' ratio.
const n = [], w = [], a = [];
for (let i = 0; i < 3; ++i) {
  n.push(native());
  w.push(wasm(model));
  a.push(wasm(model, false));
}
model.free();
const mid = (v) => v.slice().sort((x, y) => x - y)[v.length >> 1];
const round = (v) => v.map((x) => +x.toFixed(1));
console.log(JSON.stringify({ file, pairs, native_ns_per_pair: round(n), wasm_ns_per_pair: round(w),
                             ratio_wasm_over_native: +(mid(w) / mid(n)).toFixed(2),
                             alloc_ns_per_pair: round(a),
                             ratio_alloc_over_native: +(mid(a) / mid(n)).toFixed(2) }));
