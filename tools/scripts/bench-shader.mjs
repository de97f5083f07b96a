#!/usr/bin/env node
// SPDX-License-Identifier: MIT
// The cost of cbrdf's GPU evaluation against three.js's MeshStandardMaterial: a sphere filling a
// SIZE x SIZE canvas under one directional light, rendered by three.js in headless chromium on
// SwiftShader (the CPU rasterizer the browser tests use), once with MeshStandardMaterial and once
// per file with a ShaderMaterial built on cbrdfGlsl (tools/npm/glsl.mjs), and, when the wasm
// folder is a staged package (three.mjs in it), per file with the package's CbrdfMaterial, the
// material a user renders with (three's lights chunk around the same cbrdfEval). Frames are interleaved
// (standard, file 1, file 2, ..., standard, ...), each timed whole (gl.finish and a one-pixel
// read), after warm-up frames; prints the median per material and each file's ratio to the
// standard material's median. The target of issue 43 is a ratio of at most 4 at 512 x 512.
//
//   node tools/scripts/bench-shader.mjs --three DIR --wasm DIR [--glsl FILE] [--chromium BIN]
//        [--size 512] [--frames 15] [--warmup 2] [--puppeteer DIR] (--cbrdf BIN | FILE.cbrdf...)
//
// --cbrdf: make the three files of issue 43 with this cbrdf command: the sample nickel encoded
// with the defaults (the paper's model: one Frank component per slice), the same with a residual
// layer (--max-error 0.05), and tests/data/viewer's 2-component Clayton nickel.
// --three: a folder with node_modules/three (e.g. `npm install three@0.187.0 --prefix DIR`);
// --wasm: the folder of cbrdf.wasm and cbrdf.mjs (a wasm build's wasm/); --glsl: glsl.mjs
// (default: the wasm folder's, else tools/npm/glsl.mjs), or several separated by commas, whose
// materials are then interleaved too (to compare versions of the shader); --puppeteer: a folder with
// node_modules/puppeteer-core (default tests/viewer, where `npm ci` puts it).
import { readFileSync, existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname, basename, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import http from 'node:http';
import { execFileSync } from 'node:child_process';
import { launchChromium } from './chromium.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, '../..');

function parseArgs(argv) {
  const a = { size: 512, frames: 15, warmup: 2, chromium: '/usr/bin/chromium',
              puppeteer: join(root, 'tests/viewer'), files: [] };
  for (let i = 0; i < argv.length; ++i) {
    const k = argv[i];
    if (!k.startsWith('--')) { a.files.push(k); continue; }
    const v = argv[++i];
    if (v === undefined) throw new Error(`${k} needs a value`);
    a[k.slice(2)] = ['size', 'frames', 'warmup'].includes(k.slice(2)) ? Number(v) : v;
  }
  if (!a.three || !a.wasm || (!a.files.length && !a.cbrdf)) {
    throw new Error('usage: bench-shader.mjs --three DIR --wasm DIR [--glsl FILE] [--chromium BIN] ' +
                    '[--size N] [--frames N] [--warmup N] (--cbrdf BIN | FILE.cbrdf...)');
  }
  a.glsl ??= existsSync(join(a.wasm, 'glsl.mjs')) ? join(a.wasm, 'glsl.mjs')
                                                  : join(root, 'tools/npm/glsl.mjs');
  return a;
}

const args = parseArgs(process.argv.slice(2));
const work = mkdtempSync(join(tmpdir(), 'cbrdf-bench-shader-'));
process.on('exit', () => rmSync(work, { recursive: true, force: true }));
if (!args.files.length) {
  const run = (...a) => execFileSync(args.cbrdf, ['-q', ...a], { stdio: 'inherit' });
  const binary = join(work, 'nickel.binary');
  run('sample', 'nickel', '-o', binary);
  run('encode', binary, '-o', join(work, 'nickel.cbrdf'));
  run('encode', binary, '--max-error', '0.05', '-o', join(work, 'nickel-residual.cbrdf'));
  args.files = [join(work, 'nickel.cbrdf'), join(root, 'tests/data/viewer/nickel-clayton2.cbrdf'),
                join(work, 'nickel-residual.cbrdf')];
}
const threeBuild = join(args.three, 'node_modules/three/build');
if (!existsSync(join(threeBuild, 'three.module.js'))) {
  throw new Error(`${args.three}: no node_modules/three (npm install three@0.187.0 --prefix ${args.three})`);
}
const threeVersion = JSON.parse(readFileSync(join(args.three, 'node_modules/three/package.json'))).version;
const puppeteerPath = join(args.puppeteer, 'node_modules/puppeteer-core/lib/esm/puppeteer/puppeteer-core.js');
if (!existsSync(puppeteerPath)) throw new Error(`no puppeteer-core in ${args.puppeteer} (npm ci there)`);
const puppeteer = (await import(puppeteerPath)).default;

// The page: three.js's scene set-up, the two materials, the timing loop (window.bench).
const page = `<!doctype html><html><body style="margin:0">
<script type="importmap">{ "imports": { "three": "/three.module.js" } }</script>
<script type="module">
import * as THREE from 'three';
import { open } from '/cbrdf.mjs';

const size = ${args.size};
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: false });
renderer.setPixelRatio(1);
renderer.setSize(size, size);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
camera.position.set(0, 0, 3);
const light = new THREE.DirectionalLight(0xffffff, 3);
light.position.set(0.5, 0.45, 0.74);
scene.add(light);
const geometry = new THREE.SphereGeometry(1, 128, 64);
const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: 0xb0a080,
                                                                        roughness: 0.35,
                                                                        metalness: 0.6 }));
scene.add(mesh);

function threeTexture(t) {
  const format = { RGBA32F: THREE.RGBAFormat, RGB32F: THREE.RGBFormat, R32F: THREE.RedFormat }[t.format];
  if (format === undefined) throw new Error('bench: texture format ' + t.format + ' has no three.js format');
  const tex = t.dimension === 3 ? new THREE.Data3DTexture(t.data, t.width, t.height, t.depth)
                                : new THREE.DataTexture(t.data, t.width, t.height);
  tex.format = format;
  tex.type = THREE.FloatType;
  tex.minFilter = tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.unpackAlignment = 1;
  tex.needsUpdate = true;
  return tex;
}

// f(wi, wo) cos(theta_i) E for one directional light, in view space (the orthographic camera
// looks down -z); the tangent frame as the viewer's.
function cbrdfMaterial(packed, cbrdfGlsl) {
  const uniforms = { benchLight: { value: new THREE.Vector3() }, benchIrradiance: { value: 3 } };
  for (const t of packed.textures) uniforms[t.uniform] = { value: threeTexture(t) };
  for (const [k, v] of Object.entries(packed.uniforms)) uniforms[k] = { value: v };
  return new THREE.ShaderMaterial({
    glslVersion: THREE.GLSL3,
    uniforms,
    vertexShader: \`
      out vec3 vNormal;
      void main() {
        vNormal = normalMatrix * normal;
        gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
      }\`,
    fragmentShader: \`
      in vec3 vNormal;
      uniform vec3 benchLight;
      uniform float benchIrradiance;
      out vec4 benchColor;
      \${cbrdfGlsl}
      void main() {
        vec3 n = normalize(vNormal);
        vec3 t = normalize(abs(n.z) < 0.999 ? cross(vec3(0.0, 0.0, 1.0), n)
                                            : vec3(1.0, 0.0, 0.0) - n * n.x);
        vec3 b = cross(n, t);
        vec3 wo = vec3(t.z, b.z, n.z);
        vec3 wi = vec3(dot(benchLight, t), dot(benchLight, b), dot(benchLight, n));
        vec3 f = wi.z > 0.0 ? cbrdfEval(normalize(wi), normalize(wo)) : vec3(0.0);
        benchColor = vec4(f * max(wi.z, 0.0) * benchIrradiance, 1.0);
      }\`,
  });
}

async function packedOf(bytes, packGpuTables) {
  // The model's arrays through cbrdf.mjs, packed by the glsl.mjs under test.
  const model = await open(bytes);
  try {
    if (typeof model.gpuArrays !== 'function') {
      throw new Error('bench: the cbrdf.mjs of --wasm has no gpuArrays(): a wasm build from ' +
                      'before the npm package; build it again (tools/wasm/README.md)');
    }
    return packGpuTables(model.gpuArrays());
  } finally {
    model.free();
  }
}

window.bench = async (fileCount, sourceCount, frames, warmup, withThree) => {
  const materials = [mesh.material];
  // The package's CbrdfMaterial (three.mjs), as a user gets it: three's lights chunk, the albedo
  // lookup for ambient light (none here) and the tangent frame, on the first glsl.mjs.
  if (withThree) {
    const { CbrdfMaterial } = await import('/three.mjs');
    for (let i = 0; i < fileCount; ++i) {
      const model = await open(new Uint8Array(await (await fetch('/f/' + i)).arrayBuffer()));
      try {
        materials.push(new CbrdfMaterial({ model }));
      } finally {
        model.free();
      }
    }
  }
  for (let v = 0; v < sourceCount; ++v) {
    const { cbrdfGlsl, packGpuTables } = await import('/glsl' + v + '.mjs');
    for (let i = 0; i < fileCount; ++i) {
      const bytes = new Uint8Array(await (await fetch('/f/' + i)).arrayBuffer());
      const m = cbrdfMaterial(await packedOf(bytes, packGpuTables), cbrdfGlsl);
      m.uniforms.benchLight.value.copy(light.position).normalize();
      materials.push(m);
    }
  }
  const gl = renderer.getContext(), px = new Uint8Array(4);
  const frame = (m) => {
    mesh.material = m;
    const t0 = performance.now();
    renderer.render(scene, camera);
    gl.finish();
    gl.readPixels(size / 2, size / 2, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    return performance.now() - t0;
  };
  for (let w = 0; w < warmup; ++w) materials.forEach(frame);
  const times = materials.map(() => []);
  for (let f = 0; f < frames; ++f) materials.forEach((m, k) => times[k].push(frame(m)));
  // Pixels each material lit (the check that a shader drew something).
  const all = new Uint8Array(4 * size * size), lit = [];
  for (const m of materials) {
    frame(m);
    gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, all);
    let n = 0;
    for (let i = 0; i < all.length; i += 4) if (all[i] + all[i + 1] + all[i + 2] > 0) ++n;
    lit.push(n);
  }
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  return { times, lit, renderer: gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER) };
};
window.ready = true;
</script></body></html>`;

const served = {
  '/': ['text/html', () => page],
  '/three.module.js': ['text/javascript', () => readFileSync(join(threeBuild, 'three.module.js'))],
  '/three.core.js': ['text/javascript', () => readFileSync(join(threeBuild, 'three.core.js'))],
  '/cbrdf.mjs': ['text/javascript', () => readFileSync(join(args.wasm, 'cbrdf.mjs'))],
  '/cbrdf.wasm': ['application/wasm', () => readFileSync(join(args.wasm, 'cbrdf.wasm'))],
};
// CbrdfMaterial rows when the wasm folder is a staged package (three.mjs beside cbrdf.mjs).
const withThree = existsSync(join(args.wasm, 'three.mjs'));
if (withThree) served['/three.mjs'] = ['text/javascript', () => readFileSync(join(args.wasm, 'three.mjs'))];
const sources = args.glsl.split(',');
sources.forEach((f, v) => { served[`/glsl${v}.mjs`] = ['text/javascript', () => readFileSync(f)]; });
// cbrdf.mjs imports ./glsl.mjs: the first source.
served['/glsl.mjs'] = served['/glsl0.mjs'];
args.files.forEach((f, i) => { served[`/f/${i}`] = ['application/octet-stream', () => readFileSync(f)]; });
const server = http.createServer((req, res) => {
  const entry = served[req.url];
  if (!entry) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'Content-Type': entry[0] });
  res.end(entry[1]());
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const url = `http://127.0.0.1:${server.address().port}/`;

const median = (v) => {
  const s = [...v].sort((x, y) => x - y), m = s.length >> 1;
  return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
};

const profile = join(work, 'profile');
let browser;
try {
  browser = await launchChromium(puppeteer, args.chromium, profile);
  const tab = await browser.newPage();
  const logs = [];
  tab.on('console', (m) => logs.push(m.text()));
  tab.on('pageerror', (e) => logs.push(`page error: ${e.message}`));
  await tab.goto(url);
  await tab.waitForFunction('window.ready === true', { timeout: 60000 }).catch((err) => {
    throw new Error(`the page did not load: ${err.message}\n${logs.join('\n')}`);
  });
  const r = await tab.evaluate((n, v, frames, warmup, three) => window.bench(n, v, frames, warmup, three),
                               args.files.length, sources.length, args.frames, args.warmup, withThree)
    .catch((err) => { throw new Error(`${err.message}\n${logs.join('\n')}`); });
  const names = ['MeshStandardMaterial',
    ...(withThree ? args.files.map((f) => `${basename(f)} (CbrdfMaterial)`) : []),
    ...sources.flatMap((g) => args.files.map((f) =>
    sources.length > 1 ? `${basename(f)} (${basename(g)})` : basename(f)))];
  const base = median(r.times[0]);
  console.log(`${args.size} x ${args.size}, three.js ${threeVersion}, ${r.renderer}; ` +
              `${args.frames} frames each, interleaved, after ${args.warmup} warm-up frames`);
  console.log('| material | median ms | min | max | ratio to standard |');
  console.log('|---|---|---|---|---|');
  names.forEach((name, k) => {
    const t = r.times[k];
    console.log(`| ${name} | ${median(t).toFixed(1)} | ${Math.min(...t).toFixed(1)} | ` +
                `${Math.max(...t).toFixed(1)} | ${(median(t) / base).toFixed(2)}x |`);
  });
  // A sphere of radius size/2 covers pi/4 of the canvas; the light leaves under half of it dark.
  const least = 0.3 * Math.PI / 4 * args.size * args.size;
  names.forEach((name, k) => {
    if (r.lit[k] < least) throw new Error(`${name}: ${r.lit[k]} lit pixels: the shader drew no sphere`);
  });
} finally {
  await browser?.close();
  server.close();
}
