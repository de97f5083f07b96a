// SPDX-License-Identifier: MIT
// The plots of BRDF Explorer's kind, drawn with Canvas 2D from values the GPU evaluates: the lobe
// in the plane of incidence (polar or Cartesian, linear or log), a (theta_h, theta_d) image at
// one phi_d, and directional albedo against theta_i. Several files are overlaid in their colours.

export const palette = ['#4fc3f7', '#ffb74d', '#81c784', '#e57373', '#ba68c8', '#fff176'];

const mean3 = (v, k) => (v[3 * k] + v[3 * k + 1] + v[3 * k + 2]) / 3;

// The pairs of the lobe: wi at theta_i in the x-z plane, wo from -90 to 90 degrees in that plane
// (positive angles on the mirror side).
export function lobePairs(thetaI, count = 181) {
  const wi = new Float32Array(3 * count), wo = new Float32Array(3 * count);
  const ti = thetaI * Math.PI / 180;
  for (let k = 0; k < count; ++k) {
    const to = (-90 + 180 * k / (count - 1)) * Math.PI / 180;
    wi.set([-Math.sin(ti), 0, Math.cos(ti)], 3 * k);
    wo.set([Math.sin(to), 0, Math.max(Math.cos(to), 1e-6)], 3 * k);
  }
  return { wi, wo, count };
}

export function drawLobe(canvas, series, { polar, log }) {
  const g = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  g.fillStyle = '#1f1f1f';
  g.fillRect(0, 0, W, H);
  let peak = 0;
  for (const s of series) for (let k = 0; k < s.count; ++k) peak = Math.max(peak, mean3(s.values, k));
  if (!(peak > 0)) return;
  const decades = 4;
  const scale = (v) => log ? Math.max(0, Math.log10(Math.max(v, 1e-30) / peak) / decades + 1) : v / peak;
  g.strokeStyle = '#444';
  g.fillStyle = '#888';
  g.font = '11px sans-serif';
  if (polar) {
    const cx = W / 2, cy = H - 20, R = Math.min(W / 2 - 10, H - 30);
    for (const f of [0.25, 0.5, 0.75, 1]) {
      g.beginPath();
      g.arc(cx, cy, R * f, Math.PI, 2 * Math.PI);
      g.stroke();
    }
    g.fillText(log ? `${decades} decades below the peak ${peak.toPrecision(3)} /sr` :
                     `peak ${peak.toPrecision(3)} /sr`, 6, 14);
    series.forEach((s, i) => {
      g.strokeStyle = s.colour ?? palette[i % palette.length];
      g.lineWidth = 1.5;
      g.beginPath();
      for (let k = 0; k < s.count; ++k) {
        const a = (-90 + 180 * k / (s.count - 1)) * Math.PI / 180;
        const r = R * scale(mean3(s.values, k));
        const x = cx + r * Math.sin(a), y = cy - r * Math.cos(a);
        k ? g.lineTo(x, y) : g.moveTo(x, y);
      }
      g.stroke();
    });
  } else {
    const x0 = 40, x1 = W - 10, y0 = H - 20, y1 = 20;
    g.strokeRect(x0, y1, x1 - x0, y0 - y1);
    g.fillText('-90°', x0 - 10, H - 5);
    g.fillText('90°', x1 - 20, H - 5);
    g.fillText(log ? `log, ${decades} decades` : `peak ${peak.toPrecision(3)} /sr`, x0 + 4, 14);
    series.forEach((s, i) => {
      g.strokeStyle = s.colour ?? palette[i % palette.length];
      g.lineWidth = 1.5;
      g.beginPath();
      for (let k = 0; k < s.count; ++k) {
        const x = x0 + (x1 - x0) * k / (s.count - 1);
        const y = y0 - (y0 - y1) * scale(mean3(s.values, k));
        k ? g.lineTo(x, y) : g.moveTo(x, y);
      }
      g.stroke();
    });
  }
  series.forEach((s, i) => {
    g.fillStyle = s.colour ?? palette[i % palette.length];
    g.fillText(s.name, W - 200, 14 + 13 * i);
  });
}

// Directional albedo: for each theta_i, the integral of f cos(theta_o) over the hemisphere of wo
// by the midpoint rule on nt x np cells of (theta_o, phi_o).
export const albedoAngles = Array.from({ length: 18 }, (_, i) => i * 5);
export function albedoPairs(nt = 24, np = 48) {
  const n = albedoAngles.length * nt * np;
  const wi = new Float32Array(3 * n), wo = new Float32Array(3 * n), weight = new Float64Array(nt * np);
  let k = 0;
  for (const a of albedoAngles) {
    const ti = a * Math.PI / 180;
    for (let i = 0; i < nt; ++i) {
      const to = (i + 0.5) / nt * Math.PI / 2;
      for (let j = 0; j < np; ++j) {
        const po = (j + 0.5) / np * 2 * Math.PI;
        wi.set([Math.sin(ti), 0, Math.cos(ti)], 3 * k);
        wo.set([Math.sin(to) * Math.cos(po), Math.sin(to) * Math.sin(po), Math.cos(to)], 3 * k);
        weight[i * np + j] = Math.cos(to) * Math.sin(to) * (Math.PI / 2 / nt) * (2 * Math.PI / np);
        ++k;
      }
    }
  }
  return { wi, wo, weight, cells: nt * np };
}

export function albedoOf(values, pairs) {
  return albedoAngles.map((_, a) => {
    let sum = 0;
    for (let c = 0; c < pairs.cells; ++c) sum += pairs.weight[c] * mean3(values, a * pairs.cells + c);
    return sum;
  });
}

export function drawAlbedo(canvas, series) {
  const g = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  g.fillStyle = '#1f1f1f';
  g.fillRect(0, 0, W, H);
  const x0 = 34, x1 = W - 8, y0 = H - 18, y1 = 16;
  let top = 0;
  for (const s of series) for (const v of s.albedo) top = Math.max(top, v);
  top = top > 0 ? top * 1.1 : 1;
  g.strokeStyle = '#444';
  g.strokeRect(x0, y1, x1 - x0, y0 - y1);
  g.fillStyle = '#888';
  g.font = '11px sans-serif';
  g.fillText(`albedo (max ${top.toPrecision(2)}) vs theta_i 0-85°`, x0, 12);
  series.forEach((s, i) => {
    g.strokeStyle = s.colour ?? palette[i % palette.length];
    g.lineWidth = 1.5;
    g.beginPath();
    s.albedo.forEach((v, k) => {
      const x = x0 + (x1 - x0) * albedoAngles[k] / 85, y = y0 - (y0 - y1) * v / top;
      k ? g.lineTo(x, y) : g.moveTo(x, y);
    });
    g.stroke();
  });
}

// A (theta_h, theta_d) image (RGBA floats, w x h, theta_h along x, theta_d along y upwards) in
// log scale: 4 decades below its peak to black.
export function drawSlab(canvas, px, w, h) {
  const g = canvas.getContext('2d');
  const img = g.createImageData(w, h);
  let peak = 0;
  for (let i = 0; i < w * h; ++i) peak = Math.max(peak, px[4 * i], px[4 * i + 1], px[4 * i + 2]);
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const s = 4 * ((h - 1 - y) * w + x), d = 4 * (y * w + x);
      for (let c = 0; c < 3; ++c) {
        const v = px[s + c] > 0 && peak > 0 ? Math.max(0, Math.log10(px[s + c] / peak) / 4 + 1) : 0;
        img.data[d + c] = Math.round(255 * v);
      }
      img.data[d + 3] = 255;
    }
  }
  g.putImageData(img, 0, 0);
}

// The copula density of a slice (theta_h bins down, phi_d bins across; log scale, blue below 1,
// red above, full colour at the image's largest |log c|, which it returns) and its marginals
// (masses per bin of theta_h, theta_d, phi_d, each scaled to its peak).
export function drawCopula(canvas, sl) {
  const g = canvas.getContext('2d');
  const img = g.createImageData(180, 90);
  let range = 0;
  for (const c of sl.copula) if (c > 0 && Number.isFinite(c)) range = Math.max(range, Math.abs(Math.log10(c)));
  range = Math.max(range, 1e-6);
  for (let i = 0; i < 90; ++i) {
    for (let k = 0; k < 180; ++k) {
      const c = sl.copula[180 * i + k], d = 4 * (i * 180 + k);
      const l = c > 0 ? Math.max(-1, Math.min(1, Math.log10(c) / range)) : -1;
      img.data[d] = Math.round(255 * Math.max(0, l));
      img.data[d + 1] = Math.round(255 * (1 - Math.abs(l)) * 0.6);
      img.data[d + 2] = Math.round(255 * Math.max(0, -l));
      img.data[d + 3] = 255;
    }
  }
  g.putImageData(img, 0, 0);
  return Math.pow(10, range);
}

export function drawMarginals(canvas, sl) {
  const g = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  g.fillStyle = '#1f1f1f';
  g.fillRect(0, 0, W, H);
  g.font = '10px sans-serif';
  const parts = [['theta_h', sl.thetaH], ['theta_d', sl.thetaD], ['phi_d', sl.phiD]];
  const w = W / 3;
  parts.forEach(([name, m], n) => {
    const peak = Math.max(...m);
    g.strokeStyle = '#444';
    g.strokeRect(n * w + 2, 12, w - 4, H - 14);
    g.fillStyle = '#888';
    g.fillText(name, n * w + 4, 10);
    if (!(peak > 0)) return;
    g.strokeStyle = palette[n];
    g.beginPath();
    for (let i = 0; i < m.length; ++i) {
      const x = n * w + 2 + (w - 4) * (m.length > 1 ? i / (m.length - 1) : 0.5);
      const y = H - 2 - (H - 16) * m[i] / peak;
      i ? g.lineTo(x, y) : g.moveTo(x, y);
    }
    g.stroke();
  });
}
