// SPDX-License-Identifier: MIT
// The JavaScript side of the (wi, wo) convention and rejected-draw tests (issue 42): cbrdf.wasm
// through cbrdf.mjs.
//   node --no-experimental-fetch convention_test.mjs CBRDF_MJS C_REFERENCE MODELS_DIR MODEL...
// (1) For each MODEL, the pairs and C's f and pdf from `C_REFERENCE pairs MODEL`
// (convention_reference.c) against model.eval (batch and single) and model.pdf(wi, wo). The
// tolerance is 1e-10 relative, not 1e-12: the module calls musl's exp, log, pow and atan2 where
// native code calls glibc's, and they round apart in the last bit (tests/wasm/wasm_test.mjs
// measured evaluations within 3.2e-12 of native); swapping wi and wo changes a pdf by far more.
// (2) 100,000 draws over the models in MODELS_DIR (*.cbrdf; none: this part is skipped, saying
// so) and 16 elevations, fed straight back into model.eval (batch) and model.pdf: no exception,
// no NaN, a rejected draw exactly 0.
// Prints "N passed, M failed"; exit status 1 if any check failed.
import { spawnSync } from 'node:child_process';
import { existsSync, readdirSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [mjsPath, referencePath, modelsDir, ...pairModels] = process.argv.slice(2);
if (!pairModels.length) {
  console.error('usage: convention_test.mjs CBRDF_MJS C_REFERENCE MODELS_DIR MODEL...');
  process.exit(2);
}
const { open } = await import(pathToFileURL(resolve(mjsPath)).href);

let passed = 0, failed = 0;
function check(ok, what) {
  if (ok) {
    ++passed;
  } else {
    if (failed < 20) console.log(`FAIL ${what}`);
    ++failed;
  }
}
const close = (a, b, tol) => Math.abs(a - b) <= tol * Math.max(Math.abs(a), Math.abs(b));

for (const path of pairModels) {
  const r = spawnSync(referencePath, ['pairs', path], { maxBuffer: 16 << 20 });
  check(r.status === 0, `${referencePath} pairs ${path}: status ${r.status}: ${r.stderr}`);
  const rows = r.stdout.toString('utf8').trim().split('\n').map((l) => l.split(' ').map(Number));
  const n = rows.length;
  check(n >= 300, `${path}: ${n} pairs from the C reference`);
  const wi = new Float64Array(3 * n), wo = new Float64Array(3 * n);
  rows.forEach((v, k) => {
    wi.set(v.slice(0, 3), 3 * k);
    wo.set(v.slice(3, 6), 3 * k);
  });
  const model = await open(readFileSync(path));
  try {
    const f = model.eval(wi, wo);
    let bad = 0, badPdf = 0;
    rows.forEach((v, k) => {
      const one = model.eval(v.slice(0, 3), v.slice(3, 6));
      for (let c = 0; c < 3; ++c) {
        if (!close(f[3 * k + c], v[6 + c], 1e-10) || !close(one[c], v[6 + c], 1e-10)) ++bad;
      }
      if (!close(model.pdf(v.slice(0, 3), v.slice(3, 6)), v[9], 1e-10)) ++badPdf;
    });
    check(bad === 0, `${path}: ${bad} eval values differ from C's (wi, wo)`);
    check(badPdf === 0, `${path}: ${badPdf} of ${n} pdf(wi, wo) differ from C's sample_pdf(wi, wo)`);
  } finally {
    model.free();
  }
}

const models = existsSync(modelsDir)
  ? readdirSync(modelsDir).filter((f) => f.endsWith('.cbrdf')).sort() : [];
if (!models.length) {
  console.log(`rejected draws skipped: no models in ${modelsDir} (../shared is absent)`);
} else {
  const perElevation = Math.max(1, Math.floor(100000 / models.length / 16));
  let draws = 0, rejected = 0, bad = 0;
  let seed = 12345;
  const uniform = () => ((seed = (Math.imul(seed, 1103515245) + 12345) >>> 0) / 4294967296);
  for (const name of models) {
    const model = await open(readFileSync(join(modelsDir, name)));
    try {
      for (let e = 0; e < 16; ++e) {
        const theta = (89 * e / 15) * Math.PI / 180;
        const wo = new Float64Array(3 * perElevation), u = new Float64Array(2 * perElevation);
        for (let k = 0; k < perElevation; ++k) {
          const phi = 2 * Math.PI * uniform();
          wo.set([Math.sin(theta) * Math.cos(phi), Math.sin(theta) * Math.sin(phi),
                  Math.cos(theta)], 3 * k);
          u.set([uniform(), uniform()], 2 * k);
        }
        const s = model.sample(wo, u);
        const f = model.eval(s.wi, wo);  // throws on a refused direction
        for (let k = 0; k < perElevation; ++k) {
          const wi = Array.from(s.wi.subarray(3 * k, 3 * k + 3));
          const p = model.pdf(wi, Array.from(wo.subarray(3 * k, 3 * k + 3)));
          const fk = f.subarray(3 * k, 3 * k + 3);
          if ([p, s.pdf[k], ...fk].some(Number.isNaN)) ++bad;
          if (s.pdf[k] === 0) {
            ++rejected;
            if (wi.some((x) => x !== 0) || p !== 0 || fk.some((x) => x !== 0)) ++bad;
          } else if (p !== s.pdf[k]) {
            ++bad;
          }
        }
        draws += perElevation;
      }
    } finally {
      model.free();
    }
  }
  console.log(`${draws} draws over ${models.length} models and 16 elevations, ${rejected} rejected`);
  check(bad === 0, `${bad} drawn directions passed back gave NaN, a wrong pdf or a non-zero reject`);
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
