// SPDX-License-Identifier: MIT
// Opening files: a .cbrdf through cbrdf.wasm (the C API's validation and messages; the GPU arrays
// of viewer_tables.cc), a MERL .binary parsed here. Each gives a "brdf" record the page draws.
import { load } from './cbrdf.mjs';
import { packGpuTables, packTable } from './glsl.mjs';

export const kMerlScale = [1 / 1500, 1.15 / 1500, 1.66 / 1500];
const kBins = 90 * 90 * 180;

let runtime = null;
export function wasm() {
  runtime ??= load();
  return runtime;
}

function cString(x, ptr) {
  const b = new Uint8Array(x.memory.buffer);
  let end = ptr;
  while (b[end] !== 0) ++end;
  return new TextDecoder().decode(b.subarray(ptr, end));
}

// The viewer's arrays of a .cbrdf, from its one decode: { tables, generic, residual, facts,
// slice(s, c) } (viewer_tables.cc), or null when the file does not decode. facts also holds the
// slices and metadata as cbrdf.mjs's info() gives them. The module's handle stays open for
// slice(), which returns the marginals and copula image of slice s, channel c:
// { width, h, p, d, copula } (cbrdf_viewer_slice's layout).
function viewerArrays(x, bytes) {
  const p = x.malloc(bytes.length);
  new Uint8Array(x.memory.buffer).set(bytes, p);
  const v = x.cbrdf_viewer_open(p, bytes.length);
  x.free(p);
  if (v === 0) return null;
  const countPtr = x.malloc(4);
  const get = (which) => {
    const ptr = x.cbrdf_viewer_array(v, which, countPtr);
    const n = new Uint32Array(x.memory.buffer, countPtr, 1)[0];
    return n ? new Float32Array(new Float32Array(x.memory.buffer, ptr, n)) : null;
  };
  const out = { tables: get(0), generic: get(1), residual: get(2),
                facts: JSON.parse(cString(x, x.cbrdf_viewer_facts(v))) };
  x.free(countPtr);
  out.slice = (s, c) => {
    const buf = x.malloc(16560 * 4);
    try {
      const width = x.cbrdf_viewer_slice(v, s, c, buf);
      if (width < 0) return null;
      const a = new Float32Array(new Float32Array(x.memory.buffer, buf, 16560));
      return { width, h: a.subarray(0, 90), p: a.subarray(90, 270), d: a.subarray(270, 270 + width),
               copula: a.subarray(360) };
    } finally {
      x.free(buf);
    }
  };
  return out;
}

// A .cbrdf, decoded once (cbrdf_viewer_open). A file that does not decode is opened through the
// C API to throw its CbrdfError (code, status, message): the message cbrdf info gives natively.
export async function openCbrdf(name, bytes) {
  const rt = await wasm();
  const arrays = viewerArrays(rt.exports, bytes);
  if (!arrays) {
    rt.open(bytes).free();  // throws for the file the viewer's decode refused
    throw new Error('the viewer could not decode a file the C API accepts');
  }
  const { sliceList, metadata } = arrays.facts;
  const info = { slices: sliceList.length, sliceList, metadata };
  return { kind: 'model', name, bytes: bytes.length, info, arrays, packed: packGpuTables(arrays) };
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
