// SPDX-License-Identifier: MIT
// The npm package as a three.js user gets it: packs it (tools/npm/pack.sh on the wasm build's
// staging folder), installs three from consumer/'s lock file and then the tarball into an empty
// folder, serves that folder on 127.0.0.1 and renders, in headless chromium (SwiftShader), a
// sphere with CbrdfMaterial under one directional light into a float render target (page/: no
// tone mapping, linear output). `cbrdf render` draws the same sphere, camera, light and exposure
// (kCases: perspective, and orthographic for one file); the test fails when, inside the sphere,
// the PSNR is below 40 dB or a channel's median ratio to the reference is more than 1% from 1, or
// when a light 3 degrees off would pass.
//   node package_test.mjs --cbrdf CBRDF --wasm-build DIR --chromium CHROMIUM
//        --puppeteer .../node_modules/puppeteer-core --golden DIR --out DIR [--tarball TGZ]
//        [--files A.cbrdf,B.cbrdf,...]
// --tarball: an already packed package instead of packing DIR/wasm; --files: other .cbrdf files
// instead of the three golden ones (then no --golden). Prints "SKIPPED: ..." (ctest reads it as
// skipped) only when chromium cannot start; fails without puppeteer-core (`npm ci` in
// tests/viewer) or without three in npm's cache or registry.
import { execFileSync } from 'node:child_process';
import { copyFileSync, cpSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import http from 'node:http';
import { tmpdir } from 'node:os';
import { basename, dirname, extname, join, normalize, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { readExr } from './exr_read.mjs';
import { compare, interiorMask } from './sphere_compare.mjs';
import { launchChromium } from '../../tools/scripts/chromium.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
for (const k of ['cbrdf', 'wasm-build', 'chromium', 'puppeteer', 'out', ...(args.files ? [] : ['golden'])]) {
  if (!args[k]) { console.error(`package_test: --${k} is required`); process.exit(2); }
}
let puppeteer;
try {
  puppeteer = (await import(pathToFileURL(resolve(args.puppeteer, 'lib/esm/puppeteer/puppeteer-core.js')))).default;
} catch {
  console.error(`package_test: puppeteer-core is not at ${args.puppeteer}: run \`npm ci\` in tests/viewer (tools/scripts/install-deps.sh does)`);
  process.exit(1);
}

// A default Frank file, a three-component mixture, a residual file.
const kGolden = ['v1.3-frank6-b10.cbrdf', 'v1.3-mixture3-b12.cbrdf', 'v1.3-residual-frank6-b10.cbrdf'];
const kPaths = args.files ? args.files.split(',') : kGolden.map((f) => join(args.golden, f));
const kFiles = kPaths.map((p) => basename(p));
const kMinPsnr = 40;
// The largest difference of a channel's median ratio to the reference from 1: an exposure or
// light unit error of a few percent keeps the PSNR above 40 dB (5% gave 51.6 dB with the Frank
// file).
const kMaxScaleError = 0.01;
const psnrPasses = (r) => r.psnr >= kMinPsnr;
const scalePasses = (r) => r.ratios.every((q) => Math.abs(q - 1) <= kMaxScaleError);
// The scene, in the page's terms (page/sphere.mjs); `cbrdf render` gets it as JSON (scene.h) with
// irradiance x exposure. A unit sphere at the origin, the camera on +z looking at it, +y up.
const kScene = { width: 256, height: 256, position: [0, 0, 4], fovDeg: 32, radius: 1,
                 toLight: [0.5, 0.45, 0.74], irradiance: 2, exposure: 1.5 };
// Every file with that scene; the first also through an orthographic camera (view height 2.4),
// where three's view direction is the camera's axis.
const kCases = [...kFiles.map((file) => ({ file, scene: kScene, name: file })),
                { file: kFiles[0], scene: { ...kScene, orthographic: true, viewHeight: 2.4 },
                  name: `${kFiles[0]}, orthographic` }];

const failures = [];
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
};
const seconds = (t0) => `${((Date.now() - t0) / 1000).toFixed(1)} s`;
const run = (cmd, argv, opts = {}) =>
  execFileSync(cmd, argv, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], ...opts });

// Pack, then install as a user would: three from the lock file, then the tarball. Returns the site.
function install(work) {
  let t0 = Date.now();
  const tarball = args.tarball ?? run(join(here, '../../tools/npm/pack.sh'), [args['wasm-build'], join(work, 'pack')]).trim();
  console.log(`packed ${basename(tarball)} in ${seconds(t0)}`);
  const site = join(work, 'site');
  mkdirSync(site);
  for (const f of ['package.json', 'package-lock.json']) copyFileSync(join(here, 'consumer', f), join(site, f));
  const npm = ['--no-audit', '--no-fund', '--prefer-offline', '--loglevel=error', '--no-update-notifier'];
  t0 = Date.now();
  try {
    run('npm', ['ci', ...npm], { cwd: site });
  } catch (e) {
    throw new Error(`npm ci in a copy of tests/npm/consumer failed: three ${JSON.parse(readFileSync(join(site, 'package.json'))).dependencies.three} ` +
                    `must be in npm's cache or its registry reachable\n${e.stderr ?? e.message}`);
  }
  const ci = seconds(t0);
  t0 = Date.now();
  run('npm', ['install', '--no-save', ...npm, tarball], { cwd: site });
  console.log(`npm ci (three) ${ci}, npm install of the tarball ${seconds(t0)}`);
  const json = (p) => JSON.parse(readFileSync(join(site, p), 'utf8'));
  const cbrdf = json('node_modules/cbrdf/package.json'), three = json('node_modules/three/package.json');
  check(cbrdf.name === 'cbrdf' && three.version === json('package.json').dependencies.three,
        `installed cbrdf ${cbrdf.version} beside three ${three.version}`);
  cpSync(join(here, 'page'), site, { recursive: true });
  mkdirSync(join(site, 'files'));
  kPaths.forEach((p, i) => copyFileSync(p, join(site, 'files', kFiles[i])));
  return site;
}

// `cbrdf render` of each case: one ray through each pixel centre, direct light only.
function references(work, site) {
  const t0 = Date.now();
  const refs = kCases.map(({ file, scene: s }, i) => {
    const json = join(work, `case${i}.json`), exr = join(work, `case${i}.exr`);
    const camera = { position: s.position, look_at: [0, 0, 0], up: [0, 1, 0] };
    Object.assign(camera, s.orthographic ? { type: 'orthographic', height: s.viewHeight }
                                         : { type: 'perspective', fov_deg: s.fovDeg });
    writeFileSync(json, JSON.stringify({
      image: { width: s.width, height: s.height },
      camera,
      materials: { m: { type: 'cbrdf', file: join(site, 'files', file) } },
      objects: [{ type: 'sphere', center: [0, 0, 0], radius: s.radius, material: 'm' }],
      lights: [{ type: 'directional', to_light: s.toLight, irradiance: s.irradiance * s.exposure }],
    }));
    run(args.cbrdf, ['--quiet', 'render', json, '-o', exr, '--threads', '2']);
    return readExr(exr).rgb;
  });
  console.log(`cbrdf render: ${kCases.length} references in ${seconds(t0)}`);
  return refs;
}

// The site's static files on 127.0.0.1 (an ephemeral port).
async function serve(site) {
  const types = { '.html': 'text/html', '.mjs': 'text/javascript', '.js': 'text/javascript',
                  '.wasm': 'application/wasm', '.json': 'application/json' };
  const server = http.createServer((req, res) => {
    let path = normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname));
    if (path.includes('..')) { res.writeHead(400).end(); return; }
    if (path.endsWith('/')) path += 'index.html';
    let body;
    try { body = readFileSync(join(site, path)); } catch { res.writeHead(404).end(); return; }
    res.writeHead(200, { 'Content-Type': types[extname(path)] ?? 'application/octet-stream' }).end(body);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return server;
}

// The page's render of a scene with a file: RGB, row 0 at the top.
async function pageRender(page, logs, file, scene) {
  const b64 = await page.evaluate((p) => window.cbrdfTest.render(p), { ...scene, file: `files/${file}` })
    .catch((e) => { throw new Error(`${file}: ${e.message}\n${logs.join('\n')}`); });
  const rgba = new Float32Array(new Uint8Array(Buffer.from(b64, 'base64')).buffer);
  const { width: w, height: h } = scene, rgb = new Float32Array(w * h * 3);
  for (let y = 0; y < h; ++y) {  // WebGL reads the bottom row first
    for (let x = 0; x < w; ++x) {
      for (let c = 0; c < 3; ++c) rgb[(y * w + x) * 3 + c] = rgba[((h - 1 - y) * w + x) * 4 + c];
    }
  }
  return rgb;
}

async function renderAndCompare(browser, url, refs) {
  const page = await browser.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(`page error: ${e.message}`));
  await page.goto(url);
  await page.waitForFunction('window.cbrdfTest && (window.cbrdfTest.ready || window.cbrdfTest.fatal)', { timeout: 60000 })
    .catch(() => { throw new Error(`the page did not load:\n${logs.join('\n')}`); });
  const fatal = await page.evaluate('window.cbrdfTest.fatal');
  if (fatal) throw new Error(`the page failed: ${fatal}\n${logs.join('\n')}`);
  const results = {};
  const t0 = Date.now();
  for (const [i, { file, scene, name }] of kCases.entries()) {
    const mask = interiorMask(scene);
    const r = compare(refs[i], await pageRender(page, logs, file, scene), mask);
    results[name] = r;
    const [R, G, B] = r.channels.map((v) => v.toFixed(2));
    check(psnrPasses(r), `${name}: PSNR ${r.psnr.toFixed(2)} dB inside the sphere (${r.pixels} ` +
          `pixels; R ${R}, G ${G}, B ${B}; peak ${r.peak.toPrecision(4)}), at least ${kMinPsnr}`);
    check(scalePasses(r), `${name}: median of the pixels' ratio to the reference: ` +
          `${r.ratios.map((q) => q.toFixed(5)).join(', ')} (within ${kMaxScaleError} of 1)`);
  }
  console.log(`chromium: ${kCases.length} spheres in ${seconds(t0)}`);
  // The comparison notices a wrong material: the first file lit from 3 degrees further right.
  const a = (3 * Math.PI) / 180, [lx, ly, lz] = kScene.toLight;
  const turned = [lx * Math.cos(a) + lz * Math.sin(a), ly, lz * Math.cos(a) - lx * Math.sin(a)];
  const wrong = compare(refs[0], await pageRender(page, logs, kFiles[0], { ...kScene, toLight: turned }), interiorMask(kScene));
  check(!psnrPasses(wrong) || !scalePasses(wrong),
        `${kFiles[0]} with the light 3 degrees off fails: PSNR ${wrong.psnr.toFixed(2)} dB, median ratios ` +
        `${wrong.ratios.map((q) => q.toFixed(5)).join(', ')}`);
  writeFileSync(join(args.out, 'package_psnr.json'), JSON.stringify({ scene: kScene, results, lightOff3Degrees: wrong }, null, 1));
}

mkdirSync(args.out, { recursive: true });
const work = mkdtempSync(join(tmpdir(), 'cbrdf-npm-'));
const profile = mkdtempSync(join(tmpdir(), 'cbrdf-chromium-'));
let browser, server, skipped = null;
try {
  const site = install(work);
  const refs = references(work, site);
  server = await serve(site);
  try {
    browser = await launchChromium(puppeteer, args.chromium, profile);
  } catch (err) {
    skipped = `chromium cannot start here: ${err.message.split('\n')[0]}`;
  }
  if (browser) await renderAndCompare(browser, `http://127.0.0.1:${server.address().port}/`, refs);
} catch (err) {
  console.error(`package_test: ${err.stack ?? err}`);
  failures.push(String(err.message ?? err));
} finally {
  await browser?.close();
  server?.close();
  rmSync(profile, { recursive: true, force: true });
  rmSync(work, { recursive: true, force: true });
}
if (failures.length) {
  console.error(`package_test: ${failures.length} check(s) failed`);
  process.exit(1);
}
if (skipped) console.log(`SKIPPED: ${skipped}`);
