// SPDX-License-Identifier: MIT
// Reads the OpenEXR images `cbrdf render -o` writes (codec/extras/src/exr_channels.cc): scan
// lines, FLOAT channels, no, ZIPS or ZIP compression. Enough for the package test's reference;
// any other file is refused with what it holds.
import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

const kLinesPerBlock = { 0: 1, 2: 1, 3: 16 };  // NO, ZIPS, ZIP compression

// OpenEXR's ZIP predictor and byte interleaving, undone.
function unzipBlock(packed, bytes) {
  const t = inflateSync(packed);
  if (t.length !== bytes) throw new Error(`a block inflates to ${t.length} bytes, expected ${bytes}`);
  for (let i = 1; i < t.length; ++i) t[i] = (t[i - 1] + t[i] - 128) & 255;
  const out = Buffer.alloc(bytes), half = (bytes + 1) >> 1;
  for (let i = 0; i < bytes; ++i) out[i] = (i & 1) ? t[half + (i >> 1)] : t[i >> 1];
  return out;
}

/** { width, height, rgb: Float32Array of width * height * 3, row 0 at the top }. */
export function readExr(path) {
  const b = readFileSync(path);
  const fail = (what) => { throw new Error(`${path}: ${what}`); };
  if (b.readUInt32LE(0) !== 20000630) fail('not an OpenEXR file');
  if (b.readUInt32LE(4) & 0x200) fail('a tiled OpenEXR file (only scan lines are read)');
  let p = 8, channels = [], compression = -1, box = null;
  const cstr = () => { const e = b.indexOf(0, p); const s = b.toString('latin1', p, e); p = e + 1; return s; };
  for (;;) {
    const name = cstr();
    if (name === '') break;
    const type = cstr(), size = b.readInt32LE(p), v = p + 4;
    p = v + size;
    if (name === 'channels' && type === 'chlist') {
      for (let q = v; b[q] !== 0;) {
        const e = b.indexOf(0, q);
        channels.push({ name: b.toString('latin1', q, e), type: b.readInt32LE(e + 1) });
        q = e + 17;
      }
    } else if (name === 'compression') {
      compression = b[v];
    } else if (name === 'dataWindow') {
      box = [0, 1, 2, 3].map((k) => b.readInt32LE(v + 4 * k));
    }
  }
  if (!box) fail('no dataWindow');
  if (!(compression in kLinesPerBlock)) fail(`compression ${compression} (only none, ZIPS and ZIP are read)`);
  channels.sort((x, y) => (x.name < y.name ? -1 : 1));  // stored in name order
  if (channels.some((c) => c.type !== 2)) fail('a channel that is not FLOAT');
  const rgb = ['R', 'G', 'B'].map((n) => channels.findIndex((c) => c.name === n));
  if (rgb.includes(-1)) fail(`channels ${channels.map((c) => c.name).join(',')}, expected R, G, B`);
  const width = box[2] - box[0] + 1, height = box[3] - box[1] + 1;
  const lines = kLinesPerBlock[compression], blocks = Math.ceil(height / lines);
  const out = new Float32Array(width * height * 3), lineBytes = width * 4 * channels.length;
  for (let k = 0; k < blocks; ++k) {
    const at = Number(b.readBigUInt64LE(p + 8 * k));
    const y0 = b.readInt32LE(at) - box[1], size = b.readInt32LE(at + 4);
    const n = Math.min(lines, height - y0), bytes = n * lineBytes;
    const packed = b.subarray(at + 8, at + 8 + size);
    const data = size < bytes ? unzipBlock(packed, bytes) : packed;
    for (let y = 0; y < n; ++y) {
      for (let c = 0; c < 3; ++c) {
        const from = y * lineBytes + rgb[c] * width * 4;
        for (let x = 0; x < width; ++x) out[((y0 + y) * width + x) * 3 + c] = data.readFloatLE(from + 4 * x);
      }
    }
  }
  return { width, height, rgb: out };
}
