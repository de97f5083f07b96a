// SPDX-License-Identifier: MIT
// The package test's page: window.cbrdfTest.render(scene) draws a unit sphere at the origin with
// CbrdfMaterial under one DirectionalLight (three's units: the light's intensity is the
// irradiance at normal incidence, the material's intensity the exposure), seen by a perspective
// (vertical fovDeg) or orthographic (viewHeight) camera, into a float render target: three applies neither tone mapping nor an output colour
// space there, so the pixels are linear radiance f cos(theta_i) E x exposure, as `cbrdf render`
// writes them. Returns the RGBA float32 pixels (bottom row first) as base64.
import * as THREE from 'three';
import { open } from 'cbrdf';
import { CbrdfMaterial } from 'cbrdf/three';

// Fine enough that the interpolated normals inside the test's mask are within about 1e-4 rad of
// the true sphere's.
const geometry = new THREE.SphereGeometry(1, 512, 256);

function base64(floats) {
  const bytes = new Uint8Array(floats.buffer);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

// A file's material, kept for the next render of the same file (its textures' upload takes
// SwiftShader seconds).
const materials = new Map();
async function material(file, exposure) {
  if (!materials.has(file)) {
    const model = await open(new Uint8Array(await (await fetch(file)).arrayBuffer()));
    try {
      materials.set(file, new CbrdfMaterial({ model, intensity: exposure }));
    } finally {
      model.free();  // the material holds its tables
    }
  }
  const m = materials.get(file);
  m.intensity = exposure;
  return m;
}

async function render(renderer, { file, width, height, position, fovDeg, orthographic, viewHeight, radius,
                                  toLight, irradiance, exposure }) {
  const scene = new THREE.Scene();
  const sphere = new THREE.Mesh(geometry, await material(file, exposure));
  sphere.scale.setScalar(radius);
  scene.add(sphere);
  const light = new THREE.DirectionalLight(0xffffff, irradiance);
  light.position.set(...toLight);  // shines towards its target, the origin
  scene.add(light);
  const halfHeight = viewHeight / 2, halfWidth = halfHeight * (width / height);
  const camera = orthographic
    ? new THREE.OrthographicCamera(-halfWidth, halfWidth, halfHeight, -halfHeight, 0.1, 100)
    : new THREE.PerspectiveCamera(fovDeg, width / height, 0.1, 100);
  camera.position.set(...position);
  camera.lookAt(0, 0, 0);
  const target = new THREE.WebGLRenderTarget(width, height, {
    type: THREE.FloatType, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
    generateMipmaps: false,
  });
  try {
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, camera);
    const pixels = new Float32Array(width * height * 4);
    renderer.readRenderTargetPixels(target, 0, 0, width, height, pixels);
    return base64(pixels);
  } finally {
    renderer.setRenderTarget(null);
    target.dispose();
  }
}

try {
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  if (!renderer.extensions.has('EXT_color_buffer_float')) {
    throw new Error('this WebGL2 has no EXT_color_buffer_float: no float render target');
  }
  window.cbrdfTest = { ready: true, render: (scene) => render(renderer, scene) };
} catch (e) {
  window.cbrdfTest = { fatal: String(e.stack ?? e) };
}
