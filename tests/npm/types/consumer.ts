// SPDX-License-Identifier: MIT
// A TypeScript consumer of the npm package `cbrdf`: every export of `cbrdf`, `cbrdf/glsl` and
// `cbrdf/three` used as a web page would (coverage.mjs checks that none is left out), the types
// a user relies on asserted, and wrong uses marked @ts-expect-error (tsc fails if a declaration
// stops rejecting them). Type-checked only (types_test.sh), never run.
import {
  CbrdfError, Model, cbrdfGlsl, kGpuLayout as mainLayout, load, open, packGpuTables as mainPack,
  withModel,
} from 'cbrdf';
import type {
  Batch, CbrdfInstance, CbrdfStatus, ChunkFacts, ComponentInfo, GpuTables as MainTables,
  GpuTexture as MainTexture, ModelFacts, ModelInfo, OpenOptions, RawGpuTables as MainRaw,
  Sample, Samples, SliceInfo, SliceMarginals, Vec3,
} from 'cbrdf';
import { cbrdfGlsl as glslSource, kGpuLayout, packGpuTables, packTable } from 'cbrdf/glsl';
import type { GpuTables, GpuTexture, RawGpuTables } from 'cbrdf/glsl';
import {
  CbrdfMaterial, cbrdfAlbedo, cbrdfGlsl as threeGlsl, kGpuLayout as threeLayout,
} from 'cbrdf/three';
import type { AlbedoOptions, CbrdfMaterialParameters } from 'cbrdf/three';
import * as THREE from 'three';

// `expect<T>()(value)` fails to compile unless value's type is assignable to T and is not `any`
// (an undeclared result would be `any`, which any T accepts).
type IsAny<V> = 0 extends 1 & V ? true : false;
function expect<T>() {
  return <V extends T>(value: IsAny<V> extends true ? never : V): V => value;
}

function describe(info: ModelInfo, facts: ModelFacts): string {
  const slices: SliceInfo[] = info.sliceList;
  const parts: string[] = [];
  for (const slice of slices) {
    const red: ComponentInfo[] = slice.channels[0];
    for (const c of red) parts.push(`${c.family} ${c.theta} ${c.scale}`);
    parts.push(`${slice.thetaDBegin}-${slice.thetaDEnd}`);
  }
  for (const chunk of facts.chunks) {
    const c: ChunkFacts = chunk;
    parts.push(`${c.tag} ${c.offset} ${c.storedBytes} ${c.payloadBytes} ${c.compressed}`);
  }
  for (const [key, value] of info.metadata) parts.push(`${key}=${value}`);
  expect<number>()(info.versionMajor + info.versionMinor + info.slices + info.maxComponents);
  expect<number>()(info.bits + info.fileBytes + info.notMeasuredBins + info.residualMode);
  expect<number>()(info.residualMaxError + info.residualMinError + info.residualKnee);
  expect<number>()(info.residualBytes + facts.footprintBytes + facts.gpuTableBytes);
  expect<string>()(facts.version);
  return parts.join('\n');
}

export async function decode(bytes: Uint8Array): Promise<string> {
  const options: OpenOptions = { gpu: true };
  const model: Model = await open(bytes, options);
  const text = describe(model.info(), model.facts());

  const single: Vec3 = [0, 0, 1];
  expect<number[]>()(model.eval(single, [0.6, 0, 0.8]));
  const wi = new Float64Array([0, 0, 1]), wo = new Float64Array([0.6, 0, 0.8]);
  expect<Float64Array>()(model.eval(wi, wo));
  expect<Float32Array>()(model.eval(new Float32Array(wi), wo));
  const out: Batch = new Float32Array(3);
  expect<Batch>()(model.eval(wi, wo, out));
  // @ts-expect-error: directions are numbers, not a string
  model.eval('0 0 1', wo);

  const one: Sample = model.sample([0.6, 0, 0.8], [0.25, 0.5]);
  expect<number>()(one.pdf + one.wi[0]! + one.weight[0]!);
  const many: Samples<Float64Array> = model.sample(wo, new Float64Array([0.25, 0.5]));
  expect<Float64Array>()(many.wi);
  expect<Float64Array>()(many.pdf);
  expect<Float64Array>()(many.weight);
  expect<Samples<Float32Array>>()(model.sample(new Float32Array(wo), new Float32Array(2)));
  expect<number>()(model.pdf([0, 0, 1], [0.6, 0, 0.8]));
  expect<Float64Array>()(model.table());

  const marginals: SliceMarginals = model.sliceMarginals(0, 1);
  expect<number>()(marginals.width);
  for (const a of [marginals.thetaH, marginals.phiD, marginals.thetaD, marginals.copula]) {
    expect<Float32Array>()(a);
  }
  const arrays: MainRaw = model.gpuArrays();
  const tables: MainTables = mainPack(arrays);
  expect<GpuTables>()(model.gpuTables());

  const albedoOptions: AlbedoOptions = { elevations: 16, steps: 45 };
  const albedo: Float32Array = cbrdfAlbedo(model, albedoOptions);
  const fromModel: CbrdfMaterialParameters = { model, intensity: 2, side: THREE.DoubleSide };
  const material = new CbrdfMaterial(fromModel);
  const copy = new CbrdfMaterial({ tables, albedo, envMap: null, envMapIntensity: 0.5,
                                   envMapRotation: new THREE.Euler(0, 1, 0) });
  // @ts-expect-error: tables without albedo
  void new CbrdfMaterial({ tables, intensity: 1 });
  // @ts-expect-error: a material's shaders are its own
  void new CbrdfMaterial({ model, fragmentShader: 'void main() {}' });
  material.intensity = 0.5;
  material.envMapIntensity = 2;
  material.envMapRotation.set(0, Math.PI, 0);
  material.envMap = new THREE.Texture();
  expect<true>()(material.isCbrdfMaterial);
  expect<GpuTables>()(material.cbrdfTables);
  expect<THREE.Texture[]>()(material.cbrdfTextures);
  const scene = new THREE.Scene();
  scene.add(new THREE.Mesh(new THREE.SphereGeometry(1, 64, 32), material.clone()));
  scene.add(new THREE.DirectionalLight(0xffffff, 3));
  const asShader: THREE.ShaderMaterial = copy;
  asShader.dispose();
  material.dispose();
  model.free();
  // @ts-expect-error: free() takes nothing
  model.free(true);

  const instance: CbrdfInstance = await load();
  expect<string>()(instance.version);
  expect<number>()(instance.liveModels);
  expect<CbrdfError | null>()(instance.failure);
  expect<WebAssembly.Memory>()(instance.exports.memory);
  instance.open(bytes.buffer as ArrayBuffer, { gpu: false }).free();
  expect<number>()(instance.withModel(bytes, (m) => m.info().slices));
  const n: number = await withModel(bytes, async (m) => m.eval([0, 0, 1], [0, 0, 1])[0] ?? 0);
  try {
    await open(new Uint8Array(0));
  } catch (e) {
    if (e instanceof CbrdfError) {
      const status: CbrdfStatus = e.status;
      // @ts-expect-error: not a status this module reports
      const wrong: CbrdfStatus = 'bad-magic';
      return `${text} ${n} ${e.code} ${status} ${e.message} ${e.name} ${wrong}`;
    }
  }
  return text;
}

export function shader(raw: RawGpuTables): string {
  const packed: GpuTables = packGpuTables(raw);
  if (packed.layout !== kGpuLayout || mainLayout !== threeLayout) throw new Error('layout');
  for (const t of packed.textures) {
    const texture: GpuTexture = t;
    const same: MainTexture = texture;
    expect<string>()(same.uniform);
    expect<2 | 3>()(texture.dimension);
    expect<number>()(texture.width * texture.height * texture.depth);
    expect<'RGBA32F' | 'RGB32F' | 'R32F'>()(texture.format);
    expect<Float32Array>()(texture.data);
  }
  for (const [name, value] of Object.entries(packed.uniforms)) expect<number>()(value + name.length);
  const measured: GpuTables = packTable(new Float32Array(3 * 90 * 90 * 180));
  expect<number>()(measured.textures.length);
  // @ts-expect-error: a measured table is float32, not float64 (model.table()'s type)
  packTable(new Float64Array(3 * 90 * 90 * 180));
  // @ts-expect-error: the layout version is read-only
  kGpuLayout = 2;
  const source = cbrdfGlsl === glslSource && cbrdfGlsl === threeGlsl ? cbrdfGlsl : glslSource;
  return `#version 300 es\nprecision highp float;\nprecision highp int;\n${source}\n` +
         'out vec4 color;\nvoid main() { color = vec4(cbrdfEval(vec3(0, 0, 1), vec3(0, 0, 1)), 1); }\n';
}
