// SPDX-License-Identifier: MIT
// The viewer (viewer/) in Debian's headless chromium with WebGL2 on SwiftShader, served by
// `cbrdf view --no-open --port 0`, driven by puppeteer-core:
//   1. the shader's values at 10,000 random direction pairs per file against the native
//      ModelEvaluator::eval_f32 (viewer_reference): relative error <= 1e-3 where the native value
//      is above 1e-6 of the file's peak; on every golden file and the sample nickel encoded with
//      the defaults, with Clayton and lossless;
//      and the lit sphere's centre (32 x 32 pixels) of a 2-component Clayton file against the
//      native values at each pixel's pair (the tangent frame near the view direction);
//   2. screenshots of each view have content; the sphere's highlight is where the light puts it;
//      the difference view of a file against itself is black (PSNR at the 100 dB cap); a file
//      against its measurement shows a finite PSNR;
//   3. a dropped bad file shows the C API's message (the native library's, from viewer_reference's
//      sibling cbrdf info);
//   4. frame time of the model's sphere against the table's sphere (one run), and the time
//      from dropping a small file to its first frame: printed.
// Prints "SKIPPED: ..." (ctest reads it as skipped) only where chromium cannot start; without
// puppeteer-core (`npm ci` in tests/viewer) it fails.
//
//   node viewer_test.mjs --cbrdf BIN --reference BIN --wasm DIR --chromium BIN --golden DIR
//                        --out DIR [--screenshot docs/viewer.png] [--encoder BIN]
// --encoder: the cbrdf that makes the nickel files (default --cbrdf). The sanitizer suite passes
// the release build's, so that its time goes to the server under test, not to encodes that the
// encoder's own tests check under the sanitizers.
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, mkdirSync, readFileSync, readdirSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { inflateSync } from 'node:zlib';
import http from 'node:http';
import { launchChromium } from '../../tools/scripts/chromium.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
for (const k of ['cbrdf', 'reference', 'wasm', 'chromium', 'golden', 'out']) {
  if (!args[k]) { console.error(`viewer_test: --${k} is required`); process.exit(2); }
}

let puppeteer;
try {
  puppeteer = (await import(join(here, 'node_modules/puppeteer-core/lib/esm/puppeteer/puppeteer-core.js'))).default;
} catch {
  console.error('viewer_test: puppeteer-core is not installed: run `npm ci` in tests/viewer (tools/scripts/install-deps.sh does)');
  process.exit(1);
}

let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) ++failures;
};

mkdirSync(args.out, { recursive: true });
const work = mkdtempSync(join(tmpdir(), 'cbrdf-viewer-'));

// Files: the golden files, and the sample nickel encoded with the defaults (and its table).
const golden = readdirSync(args.golden).filter((f) => f.endsWith('.cbrdf')).sort().map((f) => join(args.golden, f));
const encoder = args.encoder ?? args.cbrdf;
const nickelBinary = join(work, 'nickel.binary'), nickel = join(work, 'nickel.cbrdf');
execFileSync(encoder, ['-q', 'sample', 'nickel', '-o', nickelBinary]);
execFileSync(encoder, ['-q', 'encode', nickelBinary, '-o', nickel]);
// And two paths the golden files do not take on a real material: Clayton everywhere (the generic
// terms' volume) and the lossless residual (the exact table replaces the model).
const nickelClayton = join(work, 'nickel-clayton.cbrdf'), nickelLossless = join(work, 'nickel-lossless.cbrdf');
execFileSync(encoder, ['-q', 'encode', nickelBinary, '--family', 'clayton', '-o', nickelClayton]);
execFileSync(encoder, ['-q', 'encode', nickelBinary, '--lossless', '-o', nickelLossless]);
// Two Clayton components (committed: tests/data/viewer/README.md): the sphere's centre test.
const clayton2 = join(here, '../data/viewer/nickel-clayton2.cbrdf');
const files = [...golden, clayton2, nickelClayton, nickelLossless, nickel, nickelBinary];

// A PNG's pixels (8-bit RGB or RGBA, non-interlaced: what chromium writes).
function decodePng(buf) {
  let p = 8, w = 0, h = 0, channels = 4;
  const idat = [];
  while (p < buf.length) {
    const len = buf.readUInt32BE(p), type = buf.toString('latin1', p + 4, p + 8);
    const data = buf.subarray(p + 8, p + 8 + len);
    if (type === 'IHDR') {
      w = data.readUInt32BE(0); h = data.readUInt32BE(4);
      channels = data[9] === 6 ? 4 : 3;
      if (data[8] !== 8 || (data[9] !== 6 && data[9] !== 2) || data[12] !== 0) throw new Error('unexpected PNG format');
    }
    if (type === 'IDAT') idat.push(data);
    p += 12 + len;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = w * channels, out = new Uint8Array(w * h * 3);
  let prev = new Uint8Array(stride);
  for (let y = 0; y < h; ++y) {
    const f = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const cur = new Uint8Array(stride);
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? cur[x - channels] : 0, b = prev[x], c = x >= channels ? prev[x - channels] : 0;
      let v = line[x];
      if (f === 1) v += a; else if (f === 2) v += b; else if (f === 3) v += (a + b) >> 1;
      else if (f === 4) { const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c); v += pa <= pb && pa <= pc ? a : pb <= pc ? b : c; }
      cur[x] = v & 255;
    }
    for (let x = 0; x < w; ++x) for (let c = 0; c < 3; ++c) out[3 * (y * w + x) + c] = cur[x * channels + c];
    prev = cur;
  }
  return { w, h, px: out };
}

// Distinct colours and the brightest point of a region of a screenshot.
function regionStats(png, x0, y0, w, h) {
  const colours = new Set();
  let best = -1, bx = 0, by = 0, lit = 0;
  for (let y = y0; y < y0 + h; ++y) {
    for (let x = x0; x < x0 + w; ++x) {
      const i = 3 * (y * png.w + x);
      const r = png.px[i], g = png.px[i + 1], b = png.px[i + 2];
      colours.add((r << 16) | (g << 8) | b);
      const l = r + g + b;
      if (l > 60) ++lit;
      best = Math.max(best, l);
    }
  }
  // The highlight: the centroid of the pixels within 2% of the brightest (tone mapping clips its
  // core to white).
  let sx = 0, sy = 0, n = 0;
  for (let y = y0; y < y0 + h; ++y) {
    for (let x = x0; x < x0 + w; ++x) {
      const i = 3 * (y * png.w + x);
      if (png.px[i] + png.px[i + 1] + png.px[i + 2] >= 0.98 * best) { sx += x - x0; sy += y - y0; ++n; }
    }
  }
  bx = Math.round(sx / n);
  by = Math.round(sy / n);
  return { colours: colours.size, best, bx, by, lit };
}

// The server.
const server = spawn(args.cbrdf, ['view', '--no-open', '--port', '0', '--wasm', args.wasm, ...files],
                     { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let text = '';
  server.stdout.on('data', (d) => {
    text += d;
    const m = text.match(/http:\/\/127\.0\.0\.1:\d+\//);
    if (m) resolve(m[0]);
  });
  server.on('exit', (code) => reject(new Error(`cbrdf view exited with status ${code}`)));
});
console.log(`cbrdf view serves ${url}`);
{
  let status = 0, stderr = '';
  try { execFileSync(args.cbrdf, ['view', '--no-open', join(work, 'missing.cbrdf')], { stdio: ['ignore', 'pipe', 'pipe'] }); } catch (e) { status = e.status; stderr = String(e.stderr); }
  check(status === 1 && /missing\.cbrdf: no such file/.test(stderr), `cbrdf view of a missing file fails: ${stderr.trim()}`);
  const get = (path, host) => new Promise((resolve) => {
    const u = new URL(url);
    const req = http.get({ host: '127.0.0.1', port: u.port, path, headers: host ? { Host: host } : {} }, (res) => {
      let body = '';
      res.on('data', (d) => { body += d; });
      res.on('end', () => resolve({ status: res.statusCode, type: res.headers['content-type'], body }));
    });
    req.on('error', (e) => resolve({ status: -1, body: e.message }));
  });
  const list = await get('/files.json');
  check(list.status === 200 && JSON.parse(list.body).length === files.length, `files.json lists the ${files.length} files`);
  const wasmFile = await get('/cbrdf.wasm');
  check(wasmFile.status === 200 && wasmFile.type === 'application/wasm', 'cbrdf.wasm is served as application/wasm');
  check((await get('/../CMakeLists.txt')).status === 400 && (await get('/files/99')).status === 404, 'paths outside the page: 400, unknown files: 404');
  check((await get('/', 'evil.example:80')).status === 403, 'a Host header not naming the loopback: 403');
}

let browser;
const profile = mkdtempSync(join(tmpdir(), 'cbrdf-chromium-'));
try {
  browser = await launchChromium(puppeteer, args.chromium, profile);
} catch (err) {
  server.kill('SIGINT');
  rmSync(profile, { recursive: true, force: true });
  rmSync(work, { recursive: true, force: true });
  console.log(`SKIPPED: chromium cannot start here: ${err.message.split('\n')[0]}`);
  process.exit(0);
}

const t0 = Date.now();
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1500, height: 1100 });
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(`page error: ${e.message}`));
  await page.goto(url);
  await page.waitForFunction('window.cbrdfViewer && (window.cbrdfViewer.ready || window.cbrdfViewer.fatal)', { timeout: 240000 });
  const fatal = await page.evaluate('window.cbrdfViewer.fatal');
  if (fatal) throw new Error(`the page failed: ${fatal}\n${logs.join('\n')}`);
  const names = await page.evaluate('window.cbrdfViewer.state.brdfs.map((b) => b.name)');
  check(names.length === files.length, `the page opened the ${files.length} served files (${names.length})`);

  // 1. Shader against the native float32 evaluation.
  const n = 10000;
  let seed = 12345;
  const rand = () => { seed = (seed * 1103515245 + 12345) % 2147483648; return seed / 2147483648; };
  const dir = () => {
    // Uniform over the upper hemisphere, with a fifth of the pairs near the mirror direction
    // (where the lobe peaks and varies fastest).
    const z = rand(), phi = 2 * Math.PI * rand(), s = Math.sqrt(1 - z * z);
    return [s * Math.cos(phi), s * Math.sin(phi), z];
  };
  const wi = new Float32Array(3 * n), wo = new Float32Array(3 * n);
  for (let k = 0; k < n; ++k) {
    const a = dir();
    let b = dir();
    if (k % 5 === 0) {
      const j = [rand() - 0.5, rand() - 0.5, rand() - 0.5].map((v) => 0.1 * v);
      b = [-a[0] + j[0], -a[1] + j[1], a[2] + j[2]];
      const l = Math.hypot(...b);
      b = b.map((v) => v / l);
      if (b[2] <= 0.01) b = dir();
    }
    wi.set(a, 3 * k);
    wo.set(b, 3 * k);
  }
  const table = [];
  for (let f = 0; f < files.length - 1; ++f) {
    const input = Buffer.concat([Buffer.from(wi.buffer), Buffer.from(wo.buffer)]);
    const ref = new Float32Array(new Uint8Array(execFileSync(args.reference, [files[f]], { input, maxBuffer: 1 << 26 })).buffer);
    const gpuValues = await page.evaluate((i, a, b) => window.cbrdfViewer.evalPairs(i, a, b), f, Array.from(wi), Array.from(wo));
    let peak = 0;
    for (const v of ref) peak = Math.max(peak, v);
    const errs = [];
    let worst = null;
    for (let i = 0; i < ref.length; ++i) {
      if (!(ref[i] > 1e-6 * peak)) continue;
      const e = Math.abs(gpuValues[i] - ref[i]) / ref[i];
      errs.push(Number.isFinite(e) ? e : Infinity);
      if (!worst || !(e <= worst.e)) worst = { e, i, gpu: gpuValues[i], ref: ref[i] };
    }
    errs.sort((x, y) => x - y);
    const row = { file: names[f], pairs: n, compared: errs.length, max: errs[errs.length - 1], median: errs[errs.length >> 1] };
    table.push(row);
    check(row.compared > 0.5 * 3 * n && row.max <= 1e-3,
          `${row.file}: shader vs native eval_f32 at ${n} pairs (${row.compared} values above 1e-6 of the peak): max rel. error ${row.max.toExponential(2)}, median ${row.median.toExponential(2)}` +
          (row.max > 1e-3 ? ` (worst: pair ${Math.floor(worst.i / 3)} channel ${worst.i % 3}: gpu ${worst.gpu} native ${worst.ref})` : ''));
  }
  console.log('\n| file | pairs | values compared | max rel. error | median rel. error |\n|---|---|---|---|---|');
  for (const r of table) console.log(`| ${r.file} | ${r.pairs} | ${r.compared} | ${r.max.toExponential(2)} | ${r.median.toExponential(2)} |`);
  console.log('');
  writeFileSync(join(args.out, 'shader_errors.json'), JSON.stringify(table, null, 1));

  // 1a. Each file is decoded once, by cbrdf_viewer_open, whose facts carry the slices and metadata:
  // they must be what the C API's info() reports of the same bytes.
  {
    const differ = await page.evaluate(async () => {
      const rt = await (await import('/brdfs.mjs')).wasm();
      const out = [];
      const brdfs = window.cbrdfViewer.state.brdfs;
      for (let i = 0; i < brdfs.length; ++i) {
        if (brdfs[i].kind !== 'model') continue;
        const bytes = new Uint8Array(await (await fetch(`files/${i}`)).arrayBuffer());
        const m = rt.open(bytes), info = m.info();
        m.free();
        const mine = brdfs[i].info;
        if (mine.slices !== info.slices || JSON.stringify(mine.sliceList) !== JSON.stringify(info.sliceList) ||
            JSON.stringify(mine.metadata) !== JSON.stringify(info.metadata)) out.push(brdfs[i].name);
      }
      return out;
    });
    check(differ.length === 0, `the page's slices and metadata are the C API's info() (${differ.length ? `differ: ${differ.join(', ')}` : 'all files'})`);
  }

  // 1b. The sphere's centre, where the shader's tangent frame is built differently (normals within
  // 2.6 degrees of the view): each pixel of the 32 x 32 around the centre of the lit sphere against
  // the native eval_f32 at that pixel's (wi, wo) in an orthonormal frame, times cos theta_i. A
  // frame that is not orthonormal there skews the pair (25-180% off on this file).
  {
    const iClayton = files.indexOf(clayton2), size = 320, half = size / 2, R = 16;
    for (const light of [[0, 0, 1], [0.5, 0.45, 0.74].map((v) => v / Math.hypot(0.5, 0.45, 0.74))]) {
      const px = await page.evaluate((L, i, sz) => {
        const g = window.cbrdfViewer.gpu, t = g.target(sz, sz);
        g.sphere(window.cbrdfViewer.state.brdfs[i].gpu, t, L, 1);
        const out = g.read(t);
        g.freeTarget(t);
        return Array.from(out);
      }, light, iClayton, size);
      const pixels = [], pwi = [], pwo = [];
      const dot = (u, v) => u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
      for (let y = half - R; y < half + R; ++y) {
        for (let x = half - R; x < half + R; ++x) {
          // The pixel's normal (gl.readPixels' rows run bottom up, as the shader's vUv.y).
          const p = [(x + 0.5) / half - 1, (y + 0.5) / half - 1];
          const nrm = [p[0], p[1], Math.sqrt(1 - p[0] * p[0] - p[1] * p[1])];
          const tl = Math.hypot(1 - nrm[0] * nrm[0], nrm[1] * nrm[0], nrm[2] * nrm[0]);
          const t = [(1 - nrm[0] * nrm[0]) / tl, -nrm[1] * nrm[0] / tl, -nrm[2] * nrm[0] / tl];
          const b = [nrm[1] * t[2] - nrm[2] * t[1], nrm[2] * t[0] - nrm[0] * t[2], nrm[0] * t[1] - nrm[1] * t[0]];
          const local = (v) => [dot(v, t), dot(v, b), dot(v, nrm)];
          const a = local(light);
          if (a[2] <= 0) continue;
          pixels.push({ x, y, r: Math.hypot(p[0], p[1]) * half, cos: a[2] });
          pwi.push(...a);
          pwo.push(...local([0, 0, 1]));
        }
      }
      const input = Buffer.concat([Buffer.from(new Float32Array(pwi).buffer), Buffer.from(new Float32Array(pwo).buffer)]);
      const ref = new Float32Array(new Uint8Array(execFileSync(args.reference, [clayton2], { input })).buffer);
      const worst = [0, 0];  // within the 2.6-degree zone (7.2 px), and the ring outside it
      pixels.forEach((q, k) => {
        for (let c = 0; c < 3; ++c) {
          const want = ref[3 * k + c] * q.cos, got = px[4 * (q.y * size + q.x) + c];
          const e = Math.abs(got - want) / Math.max(want, 1e-30);
          const z = q.r < half * Math.sin(Math.acos(0.999)) ? 0 : 1;
          worst[z] = Number.isFinite(e) ? Math.max(worst[z], e) : Infinity;
        }
      });
      check(pixels.length === 4 * R * R && worst[0] <= 1e-3 && worst[1] <= 1e-3,
            `nickel-clayton2.cbrdf, sphere centre lit from (${light.map((v) => v.toFixed(2)).join(', ')}): ` +
            `${pixels.length} pixels against the native eval_f32: max rel. error ${worst[0].toExponential(2)} ` +
            `within 2.6 degrees of the view, ${worst[1].toExponential(2)} in the ring around it`);
    }
  }

  // 2. The sphere: nickel.cbrdf against nickel.binary, light from the upper right.
  const iModel = files.length - 2, iTable = files.length - 1;
  const shot = async (name) => {
    const el = await page.$(name);
    const buf = await el.screenshot({ type: 'png' });
    writeFileSync(join(args.out, `${name.slice(1)}.png`), buf);
    return decodePng(buf);
  };
  const n0 = [0.45, 0.35, Math.sqrt(1 - 0.45 * 0.45 - 0.35 * 0.35)];  // highlight's normal
  await page.evaluate((a, b, n) => {
    window.cbrdfViewer.select(a, b);
    window.cbrdfViewer.setLight([2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1]);
  }, iModel, iTable, n0);
  const sphere = await shot('#sphere');
  const px = Math.round(160 * (1 + n0[0])), py = Math.round(160 * (1 - n0[1]));
  for (const [panel, label] of [[0, 'model'], [1, 'measurement']]) {
    const s = regionStats(sphere, panel * 320, 0, 320, 320);
    check(s.colours > 500 && s.lit > 5000, `sphere (${label}) has content: ${s.colours} colours, ${s.lit} lit pixels`);
    const d = Math.hypot(s.bx - px, s.by - py);
    check(d < 8, `sphere (${label}): the highlight is at (${s.bx}, ${s.by}), where the light puts it (${px}, ${py}): ${d.toFixed(1)} px off`);
  }
  // A click on the sphere moves the light so that the highlight comes under the pointer.
  {
    const box = await (await page.$('#sphere')).boundingBox();
    const cx = 100, cy = 230;  // canvas pixels in the first panel
    await page.mouse.click(box.x + cx * box.width / 960, box.y + cy * box.height / 320);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    const light = await page.evaluate('window.cbrdfViewer.state.light');
    const nx = cx / 160 - 1, ny = 1 - cy / 160, nz = Math.sqrt(1 - nx * nx - ny * ny);
    const want = [2 * nz * nx, 2 * nz * ny, 2 * nz * nz - 1];
    const err = Math.hypot(...light.map((v, i) => v - want[i]));
    const clicked = await shot('#sphere');
    const st = regionStats(clicked, 0, 0, 320, 320);
    check(err < 0.02 && Math.hypot(st.bx - cx, st.by - cy) < 8,
          `a click at (${cx}, ${cy}) moves the light (off by ${err.toFixed(3)}) and the highlight to (${st.bx}, ${st.by})`);
    await page.evaluate((n) => window.cbrdfViewer.setLight([2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1]), n0);
  }
  const psnrPair = await page.evaluate('window.cbrdfViewer.state.psnr');
  check(Number.isFinite(psnrPair) && psnrPair > 20 && psnrPair < 100, `nickel.cbrdf against nickel.binary: PSNR of the view ${psnrPair?.toFixed(2)} dB`);
  const diff = regionStats(sphere, 640, 0, 320, 320);
  check(diff.best > 0, `the difference view of the model against its measurement is not all black (brightest ${diff.best})`);
  // Against itself: black difference, PSNR at its cap.
  await page.evaluate((a) => window.cbrdfViewer.select(a, a), iModel);
  const self = await shot('#sphere');
  const sd = regionStats(self, 640, 0, 320, 320);
  const psnrSelf = await page.evaluate('window.cbrdfViewer.state.psnr');
  let nonBlack = 0;
  for (let y = 0; y < 320; ++y) for (let x = 640; x < 960; ++x) {
    const i = 3 * (y * self.w + x), r2 = (x - 800) ** 2 + (y - 160) ** 2;
    if (r2 < 155 * 155 && self.px[i] + self.px[i + 1] + self.px[i + 2] > 0) ++nonBlack;
  }
  check(nonBlack === 0 && psnrSelf === 100, `a file against itself: difference view black inside the sphere (${nonBlack} non-black pixels, ${sd.colours} colours), PSNR ${psnrSelf} dB`);
  await page.evaluate((a, b) => window.cbrdfViewer.select(a, b), iModel, iTable);
  for (const id of ['#lobe', '#slab', '#albedo', '#copula', '#marginals']) {
    const s = await shot(id);
    const st = regionStats(s, 0, 0, s.w, s.h);
    check(st.colours > 20, `${id.slice(1)} plot has content: ${st.colours} colours`);
  }
  const facts = await page.$eval('#facts', (e) => e.textContent);
  check(/compression ratio/.test(facts) && /evaluator footprint/.test(facts) && /HEAD|PARM|MARG|END/i.test(facts),
        'file facts list the ratio, the footprint and the chunks');
  if (args.screenshot) {
    // The README's picture: the page showing the sample and its encoding only.
    const shotPage = await browser.newPage();
    await shotPage.setViewport({ width: 1480, height: 900 });
    await shotPage.goto(`${url}#only=nickel.cbrdf,nickel.binary`);
    await shotPage.waitForFunction('window.cbrdfViewer && (window.cbrdfViewer.ready || window.cbrdfViewer.fatal)', { timeout: 240000 });
    await shotPage.evaluate((n) => window.cbrdfViewer.setLight([2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1]), n0);
    writeFileSync(args.screenshot, await shotPage.screenshot({ type: 'png', fullPage: true }));
    await shotPage.close();
    console.log(`screenshot: ${args.screenshot}`);
  }

  // 3. A dropped bad file: the C API's message (as cbrdf info reports it natively).
  const bad = Buffer.from(readFileSync(golden[0]));
  bad[bad.length >> 1] ^= 0x5a;
  const badPath = join(work, 'damaged.cbrdf');
  writeFileSync(badPath, bad);
  let native = '';
  try { execFileSync(args.cbrdf, ['info', badPath], { stdio: ['ignore', 'pipe', 'pipe'] }); } catch (e) { native = String(e.stderr); }
  const drop = async (name, bytes) => page.evaluate(async (nm, b) => {
    const dt = new DataTransfer();
    dt.items.add(new File([new Uint8Array(b)], nm));
    const count = window.cbrdfViewer.drops.length;
    document.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    while (window.cbrdfViewer.drops.length === count) await new Promise((r) => setTimeout(r, 5));
    return { drop: window.cbrdfViewer.drops[count], shown: document.getElementById('error').hidden ? '' : document.getElementById('error').textContent };
  }, name, Array.from(bytes));
  const badDrop = await drop('damaged.cbrdf', bad);
  const message = badDrop.shown.replace(/^damaged\.cbrdf: /, '').replace(/ \([a-z-]+\)$/, '');
  check(message.length > 10 && native.includes(message),
        `a dropped damaged file shows the C API's message: "${badDrop.shown}" (native: "${native.trim()}")`);
  await shot('#error');

  // An environment map (a synthetic .hdr: a dim sky and one bright cell up, right and in front):
  // the sphere shows the sun's highlight where its half vector with the camera puts it.
  {
    const w = 32, h = 16, sunRow = 4, sunCol = 20;
    const header = Buffer.from(`#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${h} +X ${w}\n`, 'latin1');
    const px = Buffer.alloc(4 * w * h);
    for (let i = 0; i < w * h; ++i) px.set([204, 204, 204, 124], 4 * i);      // 0.05
    px.set([200, 200, 200, 138], 4 * (sunRow * w + sunCol));                    // 800
    const theta = Math.PI * (sunRow + 0.5) / h, phi = 2 * Math.PI * (sunCol + 0.5) / w;
    const L = [-Math.sin(theta) * Math.sin(phi), Math.cos(theta), -Math.sin(theta) * Math.cos(phi)];
    const hv = [L[0], L[1], L[2] + 1], hl = Math.hypot(...hv);
    const ex = Math.round(160 * (1 + hv[0] / hl)), ey = Math.round(160 * (1 - hv[1] / hl));
    await page.evaluate((b) => window.cbrdfViewer.setEnvironment('sky.hdr', b, 4, true), Array.from(Buffer.concat([header, px])));
    const env = await shot('#sphere');
    for (const [panel, label] of [[0, 'model'], [1, 'measurement']]) {
      const st = regionStats(env, panel * 320, 0, 320, 320);
      const d = Math.hypot(st.bx - ex, st.by - ey);
      check(st.colours > 100 && d < 10, `environment-lit sphere (${label}): ${st.colours} colours, the sun's highlight at (${st.bx}, ${st.by}), expected (${ex}, ${ey}): ${d.toFixed(1)} px off`);
    }
    const envPsnr = await page.evaluate('window.cbrdfViewer.state.psnr');
    console.log(`environment-lit view: PSNR ${envPsnr.toFixed(2)} dB`);
    await page.evaluate(() => window.cbrdfViewer.setEnvironment(null, null, 0, false));
    const badHdr = await drop('broken.hdr', Buffer.from('#?RADIANCE\n\n-Y 4 +X 4\n\x01\x02', 'latin1'));
    check(badHdr.shown === 'broken.hdr: truncated pixel data', `a dropped broken .hdr is reported: "${badHdr.shown}"`);
  }

  // 4. Speed: the same sphere from the model's tables and from the measured table (a volume), one run.
  const frames = 8;
  // Three rounds of interleaved frames; the ratio quoted is the rounds' median.
  const rounds = [];
  for (let r = 0; r < 3; ++r) {
    rounds.push(await page.evaluate((a, b, f) => window.cbrdfViewer.timeSpheres([a, b], f), iModel, iTable, frames));
  }
  const ratios = rounds.map(([m, t]) => m / t).sort((x, y) => x - y);
  console.log(`frame time, 320x320 sphere on SwiftShader (${frames} frames each, interleaved, 3 rounds): ` +
              rounds.map(([m, t]) => `model ${m.toFixed(1)} ms / table ${t.toFixed(1)} ms`).join('; ') +
              `; ratio model/table, median ${ratios[1].toFixed(2)}x (${ratios[0].toFixed(2)}-${ratios[2].toFixed(2)})`);
  check(rounds.every(([m, t]) => m > 0 && t > 0), 'frame times measured');
  // A 6 KB file (the residual golden file), then a mixture with Clayton/Gumbel terms (whose
  // per-bin volume is computed on opening).
  // Decodes counted: each dropped file is decoded once (cbrdf_model_open_memory or
  // cbrdf_viewer_open; the page used to call both).
  await page.evaluate(async () => {
    const rt = await (await import('/brdfs.mjs')).wasm();
    window.cbrdfDecodes = 0;
    for (const name of ['cbrdf_model_open_memory', 'cbrdf_viewer_open']) {
      const f = rt.exports[name];
      rt.exports[name] = (...a) => { ++window.cbrdfDecodes; return f(...a); };
    }
  });
  for (const re of [/v1\.2-residual-frank6/, /mixture3/]) {
    const small = golden.find((f) => re.test(f)) ?? golden[0];
    const good = await drop(`dropped-${small.split('/').pop()}`, readFileSync(small));
    check(good.shown === '' && good.drop.firstFrameMs > 0,
          `dropping ${small.split('/').pop()} (${readFileSync(small).length} bytes): first frame after ${good.drop.firstFrameMs.toFixed(0)} ms ` +
          `(decoding and upload ${good.drop.openMs.toFixed(0)} ms, the two 320x320 spheres ${(good.drop.firstFrameMs - good.drop.openMs).toFixed(0)} ms)`);
  }
  const decodes = await page.evaluate('window.cbrdfDecodes');
  check(decodes === 2, `the two dropped files were decoded ${decodes} times (once each)`);
  if (logs.some((l) => /error/i.test(l))) console.log(`page console:\n${logs.join('\n')}`);
} finally {
  await browser.close();
  server.kill('SIGINT');
  rmSync(work, { recursive: true, force: true });
  rmSync(profile, { recursive: true, force: true });
}
console.log(`browser part: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
if (failures) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all viewer checks passed');
