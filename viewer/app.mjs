// SPDX-License-Identifier: MIT
// The viewer page: files from `cbrdf view` (files.json), an "Open" button or dropped on the page;
// a lit sphere per file side by side (the model evaluated on the GPU, a .binary from its table as
// a volume, interpolated trilinearly) with the false-colour difference and the PSNR of the view;
// plots; file facts.
// window.cbrdfViewer is what the browser test (tests/viewer) drives.
import { Gpu } from './gpu.mjs';
import { openFile } from './brdfs.mjs';
import * as P from './plots.mjs';
import { parseHdr, envLights } from './envmap.mjs';

const $ = (id) => document.getElementById(id);
const kPanel = 320;
const kMerlBytes = 12 + 3 * 90 * 90 * 180 * 8;

const state = {
  brdfs: [],
  a: -1,
  b: -1,
  light: [0.5, 0.45, 0.74],
  exposureEv: 0,
  intensity: 1,
  diffScale: 0.1,
  thetaI: 30,
  phiD: 90,
  psnr: null,
  exposure: 1,
  env: null,       // { name, gpu: { tex, count } } of a dropped .hdr
  useEnv: false,
};
let gpu = null;
let targets = null;
const albedoGrid = P.albedoPairs();

function showError(text) {
  const e = $('error');
  e.textContent = text;
  e.hidden = !text;
}

function luminanceFree(name) {
  return name.length > 40 ? `…${name.slice(-39)}` : name;
}

// p99 over the sphere's pixels and channels (tonemap_exposure of metrics.h), the exposure 1/p99.
function autoExposure(px) {
  const v = [];
  for (let i = 0; i < px.length; i += 4) if (px[i + 3] > 0) v.push(px[i], px[i + 1], px[i + 2]);
  if (!v.length) return 1;
  v.sort((x, y) => x - y);
  const rank = 0.99 * (v.length - 1), lo = Math.floor(rank);
  const p99 = v[lo] + (rank - lo) * (v[Math.min(lo + 1, v.length - 1)] - v[lo]);
  if (p99 > 0) return 1 / p99;
  return v[v.length - 1] > 0 ? 1 / v[v.length - 1] : 1;
}

const tm = (x, e) => { const y = x * e; return y > 0 ? Math.pow(Math.min(y, 1), 1 / 2.2) : 0; };

// Tone-mapped PSNR of the view (metrics.h's sphere_psnr for one light): sphere pixels only, per
// channel with peak 1, the mean of the channels' dB, capped at 100 dB.
function psnr(a, b, e) {
  const dbs = [];
  for (let c = 0; c < 3; ++c) {
    let sum = 0, n = 0;
    for (let i = 0; i < a.length; i += 4) {
      if (!(b[i + 3] > 0)) continue;
      const d = tm(a[i + c], e) - tm(b[i + c], e);
      sum += d * d;
      ++n;
    }
    const mse = sum / n;
    dbs.push(mse === 0 ? 100 : Math.min(100, 10 * Math.log10(1 / mse)));
  }
  return dbs.reduce((x, y) => x + y, 0) / 3;
}

function renderSphere() {
  if (!gpu || state.a < 0) return;
  const A = state.brdfs[state.a], B = state.b >= 0 ? state.brdfs[state.b] : null;
  targets ??= { a: gpu.target(kPanel, kPanel), b: gpu.target(kPanel, kPanel) };
  gpu.sphere(A.gpu, targets.a, state.light, state.intensity, envOn());
  const pa = gpu.read(targets.a);
  let pb = null;
  if (B) {
    gpu.sphere(B.gpu, targets.b, state.light, state.intensity, envOn());
    pb = gpu.read(targets.b);
  }
  state.exposure = autoExposure(pb ?? pa) * Math.pow(2, state.exposureEv);
  const gl = gpu.gl;
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.viewport(0, 0, gpu.canvas.width, gpu.canvas.height);
  gl.clearColor(0.12, 0.12, 0.12, 1);
  gl.clear(gl.COLOR_BUFFER_BIT);
  gpu.display(targets.a, null, [0, 0, kPanel, kPanel], state.exposure, 0, state.diffScale);
  if (B) {
    gpu.display(targets.b, null, [kPanel, 0, kPanel, kPanel], state.exposure, 0, state.diffScale);
    gpu.display(targets.a, targets.b, [2 * kPanel, 0, kPanel, kPanel], state.exposure, 2,
                state.diffScale);
    state.psnr = psnr(pa, pb, state.exposure);
    $('psnr').textContent = `PSNR of this view (tone-mapped, sphere pixels, mean of R, G, B): ` +
      `${state.psnr.toFixed(2)} dB — exposure ${state.exposure.toPrecision(3)}`;
  } else {
    state.psnr = null;
    $('psnr').textContent = 'Open a second file (a .binary measurement) to compare.';
  }
  $('labelA').textContent = luminanceFree(A.name);
  $('labelB').textContent = B ? luminanceFree(B.name) : '';
}

function renderPlots() {
  if (!gpu || !state.brdfs.length) return;
  const lobe = P.lobePairs(state.thetaI);
  const series = state.brdfs.map((b, i) => ({
    name: b.name, colour: P.palette[i % P.palette.length], count: lobe.count,
    values: gpu.evalPairs(b.gpu, lobe.wi, lobe.wo),
  }));
  P.drawLobe($('lobe'), series, { polar: $('polar').checked, log: $('logScale').checked });
  const A = state.brdfs[Math.max(state.a, 0)];
  const t = gpu.target(180, 180);
  gpu.slab(A.gpu, t, state.phiD * Math.PI / 180);
  P.drawSlab($('slab'), gpu.read(t), 180, 180);
  gpu.freeTarget(t);
  P.drawAlbedo($('albedo'), state.brdfs.map((b, i) => {
    b.albedo ??= P.albedoOf(gpu.evalPairs(b.gpu, albedoGrid.wi, albedoGrid.wo), albedoGrid);
    return { colour: P.palette[i % P.palette.length], albedo: b.albedo };
  }));
  renderSlice();
}

function renderSlice() {
  const A = state.brdfs[Math.max(state.a, 0)];
  if (!A || A.kind !== 'model') return;
  const slices = A.info.slices;
  $('slice').max = String(slices - 1);
  const s = Math.min(Number($('slice').value), slices - 1);
  const sl = A.model.sliceMarginals(s, Number($('channel').value));
  const info = A.info.sliceList[s];
  const span = P.drawCopula($('copula'), sl);
  $('sliceOut').textContent = `${s} (theta_d bins ${info.thetaDBegin}-${info.thetaDEnd - 1}, ` +
    `${info.channels[Number($('channel').value)][0].family}; copula ${(1 / span).toPrecision(3)} blue to ` +
    `${span.toPrecision(3)} red)`;
  P.drawMarginals($('marginals'), sl);
}

// What the GPU holds for a file: its textures as packGpuTables gives them.
function gpuBytes(b) { return b.packed.textures.reduce((n, t) => n + t.data.byteLength, 0); }

function kib(n) { return n >= 1 << 20 ? `${(n / (1 << 20)).toFixed(2)} MiB` : n >= 1024 ? `${(n / 1024).toFixed(1)} KiB` : `${n} B`; }

function renderFacts() {
  const rows = state.brdfs.map((b) => {
    if (b.kind === 'table') {
      return `<h3>${esc(b.name)}</h3><table><tr><td>MERL .binary</td><td>${kib(b.bytes)}</td></tr>` +
        `<tr><td>bins not measured (all channels)</td><td>${b.notMeasured}</td></tr>` +
        `<tr><td>GPU texture</td><td>${kib(gpuBytes(b))}</td></tr></table>`;
    }
    const f = b.facts, i = b.info;
    const comps = i.sliceList.reduce((n, s) => n + s.channels.reduce((m, c) => m + c.length, 0), 0);
    const families = [...new Set(i.sliceList.flatMap((s) => s.channels.flat().map((c) => c.family)))];
    const residual = ['none', 'bounded log residual', 'exact (lossless)', 'row steps', 'interpolated levels'][f.residualMode + 1];
    const settings = i.metadata.map(([k, v]) => `${esc(k)} = ${esc(v)}`).join('<br>');
    return `<h3>${esc(b.name)}</h3><table>` +
      `<tr><td>container</td><td>${f.version}, ${kib(f.fileBytes)}</td></tr>` +
      `<tr><td>compression ratio</td><td>${(kMerlBytes / f.fileBytes).toFixed(0)} : 1 against a MERL .binary</td></tr>` +
      `<tr><td>slices, components</td><td>${i.slices} slices, ${comps} components (${families.join(', ')})</td></tr>` +
      `<tr><td>marginal bits</td><td>${f.bits}</td></tr>` +
      `<tr><td>residual layer</td><td>${residual}${f.residualMode >= 0 && f.residualMode !== 1 ? `, bound ${f.residualMaxError.toPrecision(3)} (finest ${f.residualMinError.toPrecision(3)}) in log1p(v / ${f.residualKnee.toPrecision(3)}), ${f.residualEscapes} escapes` : ''}</td></tr>` +
      `<tr><td>evaluator footprint</td><td>${kib(f.footprintBytes)} (native ModelEvaluator)</td></tr>` +
      `<tr><td>GPU textures</td><td>${kib(gpuBytes(b))} (the model's arrays: ${kib(f.gpuTableBytes)})</td></tr>` +
      `<tr><td>not-measured bins</td><td>${f.notMeasuredBins}</td></tr>` +
      (settings ? `<tr><td>settings (metadata)</td><td>${settings}</td></tr>` : '') +
      `</table><table><tr><th>chunk</th><th>offset</th><th>stored</th><th>payload</th></tr>` +
      f.chunks.map((c) => `<tr><td>${esc(c.tag)}</td><td>${c.offset}</td><td>${c.storedBytes}</td><td>${c.payloadBytes}${c.compressed ? ' (zstd)' : ''}</td></tr>`).join('') +
      '</table>';
  });
  $('facts').innerHTML = rows.join('');
}

function esc(s) {
  return String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
}

function fillPickers() {
  for (const [id, key, none] of [['pickA', 'a', false], ['pickB', 'b', true]]) {
    const s = $(id);
    s.innerHTML = (none ? '<option value="-1">(none)</option>' : '') +
      state.brdfs.map((b, i) => `<option value="${i}">${esc(b.name)}</option>`).join('');
    s.value = String(state[key]);
  }
}

function renderAll() {
  renderSphere();
  renderPlots();
  renderFacts();
}

function envOn() {
  return state.useEnv && state.env ? state.env.gpu : null;
}

// An environment map (.hdr): n theta x 2n phi cells, one light each (envmap.mjs).
function setEnvironment(name, bytes, nTheta = 8) {
  const lights = envLights(parseHdr(name, bytes), nTheta, 2 * nTheta);
  state.env = { name, gpu: gpu.envTexture(lights) };
  state.useEnv = true;
  $('useEnv').disabled = false;
  $('useEnv').checked = true;
  $('envName').textContent = `${name} (${lights.length / 8} lights)`;
}

// Adds opened files; the first model is shown against the first table (or the second file).
async function addFiles(list) {
  const errors = [];
  for (const { name, bytes } of list) {
    try {
      if (/\.hdr$/i.test(name)) {
        setEnvironment(name, bytes);
        continue;
      }
      const b = await openFile(name, bytes);
      b.gpu = gpu.brdf(b.packed);
      state.brdfs.push(b);
    } catch (err) {
      // The C API's messages name no file; the page's own (.binary, .hdr) start with its name.
      errors.push(err.status ? `${name}: ${err.message} (${err.status})` :
                  err.message.startsWith(`${name}: `) ? err.message : `${name}: ${err.message}`);
    }
  }
  showError(errors.join('\n'));
  window.cbrdfViewer.lastErrors = errors;
  const models = state.brdfs.map((b, i) => [b, i]).filter(([b]) => b.kind === 'model');
  const tables = state.brdfs.map((b, i) => [b, i]).filter(([b]) => b.kind === 'table');
  if (state.a < 0 && state.brdfs.length) state.a = models.length ? models[0][1] : 0;
  if (state.b < 0) {
    const t = tables.find(([, i]) => i !== state.a) ?? state.brdfs.map((b, i) => [b, i]).find(([, i]) => i !== state.a);
    if (t) state.b = t[1];
  }
  fillPickers();
  $('status').textContent = state.brdfs.length ? `${state.brdfs.length} file(s)` : 'no files: drop some';
}

async function readDropped(files) {
  return Promise.all([...files].map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
}

// Frame times of files' spheres, in milliseconds per frame: `frames` renders of kPanel^2 pixels
// per file, interleaved (file 1, file 2, file 1, ...) so that a change of the machine's load
// weighs on each alike, each waited for (a one-pixel read), after one warm-up frame each.
function timeSpheres(indices, frames) {
  const t = gpu.target(kPanel, kPanel);
  const gl = gpu.gl, px = new Float32Array(4);
  const once = (b) => {
    const t0 = performance.now();
    gpu.sphere(b.gpu, t, state.light, state.intensity, envOn());
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, px);
    return performance.now() - t0;
  };
  const total = indices.map((i) => (once(state.brdfs[i]), 0));
  for (let f = 0; f < frames; ++f) {
    indices.forEach((i, k) => { total[k] += once(state.brdfs[i]); });
  }
  gpu.freeTarget(t);
  return total.map((ms) => ms / frames);
}

// Interactive changes render at most once per animation frame (a slow GPU would queue them).
let spherePending = false;
function requestSphere() {
  if (spherePending) return;
  spherePending = true;
  requestAnimationFrame(() => {
    spherePending = false;
    renderSphere();
  });
}

function lightFromPointer(ev) {
  const r = $('sphere').getBoundingClientRect();
  const x = (ev.clientX - r.left) * ($('sphere').width / r.width);
  const y = (ev.clientY - r.top) * ($('sphere').height / r.height);
  const px = (x % kPanel) / (kPanel / 2) - 1, py = 1 - y / (kPanel / 2);
  const r2 = px * px + py * py;
  if (r2 >= 1) return;
  // The light whose mirror direction is the camera at this point of the sphere: the highlight
  // sits under the pointer.
  const n = [px, py, Math.sqrt(1 - r2)];
  state.light = [2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1];
  requestSphere();
}

async function main() {
  window.cbrdfViewer = { state, lastErrors: [], drops: [] };
  try {
    gpu = new Gpu($('sphere'));
  } catch (err) {
    showError(err.message);
    window.cbrdfViewer.fatal = err.message;
    return;
  }
  Object.assign(window.cbrdfViewer, {
    gpu,
    addFiles: async (list) => { await addFiles(list); renderAll(); },
    evalPairs: (i, wi, wo) => Array.from(gpu.evalPairs(state.brdfs[i].gpu, new Float32Array(wi), new Float32Array(wo))),
    select(a, b) { state.a = a; state.b = b; fillPickers(); renderAll(); },
    setLight(l) { state.light = l; renderSphere(); },
    setEnvironment(name, bytes, nTheta, on) {
      if (bytes) setEnvironment(name, new Uint8Array(bytes), nTheta);
      state.useEnv = on;
      renderSphere();
    },
    timeSpheres,
    render: renderAll,
  });
  const bind = (id, key, fmt, parse = Number) => {
    $(id).addEventListener('input', () => {
      state[key] = parse($(id).value);
      if ($(`${id}Out`)) $(`${id}Out`).textContent = fmt(state[key]);
      if (key === 'thetaI' || key === 'phiD') renderPlots(); else requestSphere();
    });
  };
  bind('exposure', 'exposureEv', (v) => `${v} EV`);
  bind('intensity', 'intensity', (v) => v.toPrecision(3), (v) => Math.pow(2, Number(v)));
  bind('diffScale', 'diffScale', String);
  bind('thetaI', 'thetaI', (v) => `${v}°`);
  bind('phiD', 'phiD', (v) => `${v}°`);
  for (const id of ['polar', 'logScale']) $(id).addEventListener('change', renderPlots);
  $('slice').addEventListener('input', renderSlice);
  $('useEnv').addEventListener('change', () => { state.useEnv = $('useEnv').checked; renderSphere(); });
  $('channel').addEventListener('change', renderSlice);
  $('pickA').addEventListener('change', () => { state.a = Number($('pickA').value); renderAll(); });
  $('pickB').addEventListener('change', () => { state.b = Number($('pickB').value); renderSphere(); });
  $('sphere').addEventListener('pointerdown', lightFromPointer);
  $('sphere').addEventListener('pointermove', (ev) => { if (ev.buttons & 1) lightFromPointer(ev); });
  $('fileInput').addEventListener('change', async () => {
    await addFiles(await readDropped($('fileInput').files));
    renderAll();
  });
  document.addEventListener('dragover', (ev) => { ev.preventDefault(); document.body.classList.add('dragging'); });
  document.addEventListener('dragleave', () => document.body.classList.remove('dragging'));
  document.addEventListener('drop', async (ev) => {
    ev.preventDefault();
    document.body.classList.remove('dragging');
    const t0 = performance.now();
    const before = state.brdfs.length;
    await addFiles(await readDropped(ev.dataTransfer.files));
    const openMs = performance.now() - t0;
    // The dropped file is shown: it becomes the model side when it opened.
    if (state.brdfs.length > before && state.brdfs[before].kind === 'model') state.a = before;
    fillPickers();
    renderSphere();
    window.cbrdfViewer.drops.push({ firstFrameMs: performance.now() - t0, openMs, errors: window.cbrdfViewer.lastErrors });
    renderPlots();
    renderFacts();
  });

  let list = [];
  try {
    const r = await fetch('files.json');
    if (r.ok) list = await r.json();
  } catch { /* a static copy of the page: no served files */ }
  // #only=a.cbrdf,b.binary: only these of the served files.
  const only = new URLSearchParams(location.hash.slice(1)).get('only');
  if (only) list = list.filter((f) => only.split(',').includes(f.name));
  const files = await Promise.all(list.map(async (f) => ({ name: f.name, bytes: new Uint8Array(await (await fetch(f.url)).arrayBuffer()) })));
  await addFiles(files);
  renderAll();
  window.cbrdfViewer.ready = true;
}

main().catch((err) => {
  showError(`viewer: ${err.message}`);
  window.cbrdfViewer.fatal = err.message;
});
