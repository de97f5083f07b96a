// SPDX-License-Identifier: MIT
// Environment lighting: a Radiance .hdr (RGBE) latitude-longitude map, pre-filtered into a few
// directional lights that the sphere shader sums (sphereShader's uEnv): the map is split into
// nTheta x nPhi cells of equal angle, and each cell becomes one light carrying the cell's
// irradiance at normal incidence (the sum of radiance x solid angle over its pixels) from the
// cell's power-weighted mean direction. Exact for the cell's power, approximate in direction within
// a cell (at most its size); 8 x 16 = 128 lights by default. EXR is not read.

// Pixels of a .hdr file: { w, h, rgb: Float32Array(3 w h) }, rows from the top. Throws an Error
// naming what is wrong.
export function parseHdr(name, bytes) {
  const text = new TextDecoder('latin1').decode(bytes.subarray(0, Math.min(bytes.length, 4096)));
  if (!/^#\?(RADIANCE|RGBE)/.test(text)) throw new Error(`${name}: not a Radiance .hdr file (no #?RADIANCE header)`);
  const end = text.indexOf('\n\n');
  if (end < 0) throw new Error(`${name}: the .hdr header does not end`);
  if (/FORMAT=/.test(text.slice(0, end)) && !/FORMAT=32-bit_rle_rgbe/.test(text.slice(0, end))) {
    throw new Error(`${name}: only FORMAT=32-bit_rle_rgbe is read`);
  }
  const lineEnd = text.indexOf('\n', end + 2);
  const m = text.slice(end + 2, lineEnd).match(/^-Y (\d+) \+X (\d+)$/);
  if (!m) throw new Error(`${name}: resolution line "${text.slice(end + 2, lineEnd)}" is not "-Y H +X W"`);
  const h = Number(m[1]), w = Number(m[2]);
  if (!(w > 0 && h > 0 && w * h <= 1 << 24)) throw new Error(`${name}: size ${w} x ${h} out of range`);
  let p = lineEnd + 1;
  const rgbe = new Uint8Array(4 * w * h);
  const need = (n) => { if (p + n > bytes.length) throw new Error(`${name}: truncated pixel data`); };
  for (let y = 0; y < h; ++y) {
    const row = rgbe.subarray(4 * w * y, 4 * w * (y + 1));
    need(4);
    const rle = w >= 8 && w < 32768 && bytes[p] === 2 && bytes[p + 1] === 2 && (bytes[p + 2] & 0x80) === 0;
    if (!rle) {
      need(4 * w);
      row.set(bytes.subarray(p, p + 4 * w));
      p += 4 * w;
      continue;
    }
    if (((bytes[p + 2] << 8) | bytes[p + 3]) !== w) throw new Error(`${name}: scanline ${y} has the wrong width`);
    p += 4;
    for (let c = 0; c < 4; ++c) {
      for (let x = 0; x < w;) {
        need(1);
        let n = bytes[p++];
        if (n > 128) {
          n -= 128;
          need(1);
          if (x + n > w) throw new Error(`${name}: scanline ${y} overruns`);
          const v = bytes[p++];
          for (let i = 0; i < n; ++i) row[4 * (x++) + c] = v;
        } else {
          if (n === 0 || x + n > w) throw new Error(`${name}: scanline ${y} overruns`);
          need(n);
          for (let i = 0; i < n; ++i) row[4 * (x++) + c] = bytes[p++];
        }
      }
    }
  }
  const rgb = new Float32Array(3 * w * h);
  for (let i = 0; i < w * h; ++i) {
    const e = rgbe[4 * i + 3];
    const f = e ? Math.pow(2, e - 136) : 0;  // (m + 0.5) / 256 * 2^(e - 128), Radiance's convention
    for (let c = 0; c < 3; ++c) rgb[3 * i + c] = e ? (rgbe[4 * i + c] + 0.5) * f : 0;
  }
  return { w, h, rgb };
}

// The lights: Float32Array of 8 per light (direction x, y, z, 0, irradiance r, g, b, 0). World
// space as the sphere's: y up, the camera on +z; the map's centre column faces the camera.
export function envLights(env, nTheta = 8, nPhi = 16) {
  const { w, h, rgb } = env;
  const cells = Array.from({ length: nTheta * nPhi }, () => ({ e: [0, 0, 0], d: [0, 0, 0] }));
  for (let y = 0; y < h; ++y) {
    const theta = Math.PI * (y + 0.5) / h;
    const dOmega = Math.sin(theta) * (Math.PI / h) * (2 * Math.PI / w);
    for (let x = 0; x < w; ++x) {
      const phi = 2 * Math.PI * (x + 0.5) / w;
      const dir = [-Math.sin(theta) * Math.sin(phi), Math.cos(theta), -Math.sin(theta) * Math.cos(phi)];
      const cell = cells[Math.min(nTheta - 1, Math.floor(y * nTheta / h)) * nPhi + Math.min(nPhi - 1, Math.floor(x * nPhi / w))];
      const i = 3 * (y * w + x);
      const lum = (rgb[i] + rgb[i + 1] + rgb[i + 2]) * dOmega + 1e-30 * dOmega;
      for (let c = 0; c < 3; ++c) {
        cell.e[c] += rgb[i + c] * dOmega;
        cell.d[c] += dir[c] * lum;
      }
    }
  }
  const out = new Float32Array(8 * cells.length);
  cells.forEach((cell, k) => {
    const l = Math.hypot(...cell.d) || 1;
    out.set([cell.d[0] / l, cell.d[1] / l, cell.d[2] / l, 0, cell.e[0], cell.e[1], cell.e[2], 0], 8 * k);
  });
  return out;
}
