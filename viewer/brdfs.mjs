// SPDX-License-Identifier: MIT
// Opening files: a .cbrdf through the package's module (cbrdf.mjs: the C API's validation and
// messages, the GPU tables of glsl.mjs's layout), a MERL .binary parsed here. Each gives a "brdf"
// record the page draws: `packed`, the textures and uniforms cbrdfEval reads.
import { load } from './cbrdf.mjs';
import { packTable } from './glsl.mjs';

export const kMerlScale = [1 / 1500, 1.15 / 1500, 1.66 / 1500];
const kBins = 90 * 90 * 180;

// The page's instance of cbrdf.wasm (its exports are what the browser test counts decodes on).
let runtime = null;
export function wasm() {
  runtime ??= load();
  return runtime;
}

// A .cbrdf, decoded once (open with { gpu: true }: cbrdf_viewer_open, whose facts carry the
// slices and metadata; a file it refuses is opened through the C API, which throws its
// CbrdfError: code, status and the message cbrdf info gives natively). The model stays open for
// the slice plot (model.sliceMarginals).
export async function openCbrdf(name, bytes) {
  const model = (await wasm()).open(bytes, { gpu: true });
  try {
    const facts = model.facts();
    const { sliceList, metadata } = facts;
    const info = { slices: sliceList.length, sliceList, metadata };
    return { kind: 'model', name, bytes: bytes.length, info, facts, model,
             packed: model.gpuTables() };
  } catch (err) {
    model.free();
    throw err;
  }
}

// A MERL .binary: three int32 dimensions (90, 90, 180), then 3 x 1,458,000 doubles (R, G, B
// blocks) in stored units; negative values are bins not measured (read as 0, as lookup_linear).
export function parseMerl(name, bytes) {
  const buf = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  if (buf.byteLength < 12) throw new Error(`${name}: ${buf.byteLength} bytes, too short for a MERL .binary header`);
  const dims = new Int32Array(buf, 0, 3);
  if (dims[0] !== 90 || dims[1] !== 90 || dims[2] !== 180) {
    throw new Error(`${name}: MERL dimensions ${dims.join(' x ')}, expected 90 x 90 x 180`);
  }
  const need = 12 + 3 * kBins * 8;
  if (buf.byteLength !== need) {
    throw new Error(`${name}: ${buf.byteLength} bytes, a MERL .binary has ${need}`);
  }
  const v = new Float64Array(buf.slice(12));
  const rgb = new Float32Array(3 * kBins);
  let notMeasured = 0;
  for (let c = 0; c < 3; ++c) {
    for (let i = 0; i < kBins; ++i) {
      const s = v[c * kBins + i];
      if (!(s >= 0)) ++notMeasured;
      rgb[3 * i + c] = s >= 0 ? s * kMerlScale[c] : 0;
    }
  }
  return { kind: 'table', name, bytes: bytes.length, rgb, notMeasured, packed: packTable(rgb) };
}

export async function openFile(name, bytes) {
  if (/\.binary$/i.test(name)) return parseMerl(name, bytes);
  return openCbrdf(name, bytes);
}
