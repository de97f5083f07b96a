// SPDX-License-Identifier: MIT
// A TypeScript consumer of the npm package `cbrdf`: every export of `cbrdf`, `cbrdf/glsl` and
// `cbrdf/three` used as its README shows, with the types a user relies on asserted, and wrong
// uses marked @ts-expect-error (tsc fails if a declaration stops rejecting them). Type-checked
// only (types_test.sh), never run.
import { CbrdfError, Model, cbrdfGlsl, load, open, withModel } from 'cbrdf';
import { cbrdfGlsl as glslSource, kGpuLayout, packGpuTables } from 'cbrdf/glsl';
import type { GpuTables, GpuTexture, RawGpuTables } from 'cbrdf/glsl';
import { CbrdfMaterial, cbrdfAlbedo } from 'cbrdf/three';
import * as THREE from 'three';

// `expect<T>()(value)` fails to compile unless value's type is assignable to T and is not `any`
// (an undeclared result would be `any`, which any T accepts).
type IsAny<V> = 0 extends 1 & V ? true : false;
function expect<T>() {
  return <V extends T>(value: IsAny<V> extends true ? never : V): V => value;
}

export async function decode(bytes: Uint8Array): Promise<void> {
  const model: Model = await open(bytes);
  const info = model.info();
  expect<number>()(info.slices);
  expect<number>()(info.bits);
  const first = info.sliceList[0];
  if (first) expect<number>()(first.thetaDBegin);
  for (const [key, value] of info.metadata) expect<string>()(key + value);

  expect<number[]>()(model.eval([0, 0, 1], [0.6, 0, 0.8]));
  const wi = new Float64Array([0, 0, 1]), wo = new Float64Array([0.6, 0, 0.8]);
  expect<Float64Array>()(model.eval(wi, wo));
  expect<Float32Array>()(model.eval(new Float32Array(wi), new Float32Array(wo)));
  // @ts-expect-error: directions are arrays of numbers, not strings
  model.eval('0 0 1', wo);

  const one = model.sample([0.6, 0, 0.8], [0.25, 0.5]);
  expect<number>()(one.pdf);
  expect<number[]>()(one.wi);
  const many = model.sample(wo, new Float64Array([0.25, 0.5]));
  expect<Float64Array>()(many.pdf);
  expect<Float64Array>()(many.weight);
  expect<number>()(model.pdf([0, 0, 1], [0.6, 0, 0.8]));
  expect<Float64Array>()(model.table());

  const tables: GpuTables = model.gpuTables();
  expect<number>()(tables.layout);
  const albedo: Float32Array = cbrdfAlbedo(model);
  const material = new CbrdfMaterial({ model, intensity: 2, side: THREE.DoubleSide });
  const copy = new CbrdfMaterial({ tables, albedo });
  // @ts-expect-error: tables without albedo
  void new CbrdfMaterial({ tables: model.gpuTables(), intensity: 1 });
  material.intensity = 0.5;
  expect<number>()(material.intensity);
  const scene = new THREE.Scene();
  scene.add(new THREE.Mesh(new THREE.SphereGeometry(1, 64, 32), material));
  scene.add(new THREE.DirectionalLight(0xffffff, 3));
  const asMaterial: THREE.ShaderMaterial = copy;
  asMaterial.dispose();
  model.free();
  // @ts-expect-error: free() takes nothing
  model.free(true);

  const instance = await load();
  expect<string>()(instance.version);
  const again = instance.open(bytes.buffer as ArrayBuffer);
  again.free();
  const n: number = await withModel(bytes, (m) => m.eval([0, 0, 1], [0, 0, 1])[0] ?? 0);
  expect<number>()(n);
  try {
    await open(new Uint8Array(0));
  } catch (e) {
    if (e instanceof CbrdfError) {
      expect<number>()(e.code);
      expect<string>()(e.status);
      expect<string>()(e.message);
    }
  }
}

export function shader(raw: RawGpuTables): string {
  const packed: GpuTables = packGpuTables(raw);
  if (packed.layout !== kGpuLayout) throw new Error('layout');
  for (const t of packed.textures) {
    const texture: GpuTexture = t;
    expect<2 | 3>()(texture.dimension);
    expect<'RGBA32F' | 'RGB32F' | 'R32F'>()(texture.format);
    expect<Float32Array>()(texture.data);
  }
  for (const [name, value] of Object.entries(packed.uniforms)) expect<number>()(value + name.length);
  // @ts-expect-error: the layout version is read-only
  kGpuLayout = 2;
  const same: string = cbrdfGlsl === glslSource ? cbrdfGlsl : glslSource;
  return `#version 300 es\nprecision highp float;\nprecision highp int;\n${same}\n` +
         'out vec4 color;\nvoid main() { color = vec4(cbrdfEval(vec3(0, 0, 1), vec3(0, 0, 1)), 1); }\n';
}
