// SPDX-License-Identifier: MIT
// WebGL2 plumbing: a BRDF's textures (packGpuTables's, bound by their sampler names), the
// programs of shaders.mjs, and renders into float framebuffers read back for the test and PSNR.
import * as S from './shaders.mjs';

export class Gpu {
  constructor(canvas) {
    const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    if (!gl.getExtension('EXT_color_buffer_float')) {
      throw new Error('WebGL2 lacks EXT_color_buffer_float (float render targets)');
    }
    this.gl = gl;
    this.canvas = canvas;
    this.programs = {};
    const buf = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
    this.quad = buf;
    // A 1x1 texture for the environment's sampler when no environment is on.
    this.emptyTab = this.texture({ dimension: 2, width: 1, height: 1, depth: 1, format: 'RGBA32F',
                                   data: new Float32Array(4) }).tex;
  }

  program(name) {
    if (this.programs[name]) return this.programs[name];
    const { gl } = this;
    const src = { pairs: S.pairsShader, sphere: S.sphereShader, display: S.displayShader,
                  slab: S.slabShader }[name];
    const compile = (type, text) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
        throw new Error(`shader ${name}: ${gl.getShaderInfoLog(s)}`);
      }
      return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, S.vertexShader));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, src));
    gl.bindAttribLocation(p, 0, 'aPos');
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) {
      throw new Error(`program ${name}: ${gl.getProgramInfoLog(p)}`);
    }
    const u = {};
    const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; ++i) {
      const info = gl.getActiveUniform(p, i);
      u[info.name] = gl.getUniformLocation(p, info.name);
    }
    this.programs[name] = { p, u };
    return this.programs[name];
  }

  // A texture of packGpuTables's list (glsl.mjs), sampled with texelFetch.
  texture({ dimension, width, height, depth, format, data }) {
    const { gl } = this;
    const [internal, layout] = { RGBA32F: [gl.RGBA32F, gl.RGBA], RGB32F: [gl.RGB32F, gl.RGB],
                                 R32F: [gl.R32F, gl.RED] }[format];
    const target = dimension === 3 ? gl.TEXTURE_3D : gl.TEXTURE_2D;
    const t = gl.createTexture();
    this.scratch(target, t);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    if (dimension === 3) {
      gl.texImage3D(target, 0, internal, width, height, depth, 0, layout, gl.FLOAT, data);
    } else {
      gl.texImage2D(target, 0, internal, width, height, 0, layout, gl.FLOAT, data);
    }
    this.nearest(target);
    gl.bindTexture(target, null);
    return { target, tex: t };
  }

  // Textures are created on unit 7, which no program samples, and unbound afterwards: a texture
  // left bound where a program samples would form a feedback loop when it is a render target.
  scratch(target, tex) {
    this.gl.activeTexture(this.gl.TEXTURE7);
    this.gl.bindTexture(target, tex);
  }

  // Unbinds units 0..6 (after a draw that sampled render targets).
  unbindAll() {
    const { gl } = this;
    for (let i = 0; i < 7; ++i) {
      gl.activeTexture(gl.TEXTURE0 + i);
      gl.bindTexture(gl.TEXTURE_2D, null);
      gl.bindTexture(gl.TEXTURE_3D, null);
    }
  }

  nearest(target) {
    const { gl } = this;
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texParameteri(target, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(target, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  }

  // A BRDF's GPU state from packGpuTables's output (a model's, or a MERL table's in the
  // exact-table mode): its textures by sampler name, and its uniform values.
  brdf(packed) {
    return { textures: packed.textures.map((t) => ({ uniform: t.uniform, ...this.texture(t) })),
             uniforms: packed.uniforms };
  }

  // Binds a BRDF's textures to units 0.. and sets its uniforms (all floats); returns the next
  // free texture unit.
  bindBrdf(prog, brdf) {
    const { gl } = this;
    const { u } = prog;
    brdf.textures.forEach(({ uniform, target, tex }, i) => {
      gl.activeTexture(gl.TEXTURE0 + i);
      gl.bindTexture(target, tex);
      if (u[uniform]) gl.uniform1i(u[uniform], i);
    });
    for (const [name, value] of Object.entries(brdf.uniforms)) {
      if (u[name]) gl.uniform1f(u[name], value);
    }
    return brdf.textures.length;
  }

  target(w, h) {
    const { gl } = this;
    const tex = gl.createTexture();
    this.scratch(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, null);
    this.nearest(gl.TEXTURE_2D);
    gl.bindTexture(gl.TEXTURE_2D, null);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return { tex, fb, w, h };
  }

  freeTarget(t) {
    this.gl.deleteTexture(t.tex);
    this.gl.deleteFramebuffer(t.fb);
  }

  draw(prog, target, viewport) {
    const { gl } = this;
    gl.bindFramebuffer(gl.FRAMEBUFFER, target ? target.fb : null);
    if (viewport) gl.viewport(...viewport);
    else gl.viewport(0, 0, target.w, target.h);
    gl.useProgram(prog.p);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.quad);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 2, gl.FLOAT, false, 0, 0);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  }

  read(target) {
    const { gl } = this;
    const out = new Float32Array(target.w * target.h * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.fb);
    gl.readPixels(0, 0, target.w, target.h, gl.RGBA, gl.FLOAT, out);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return out;
  }

  // The BRDF at n pairs (Float32Array of 3n each): Float32Array of 3n (the browser test).
  evalPairs(brdf, wi, wo) {
    const { gl } = this;
    const n = wi.length / 3;
    const w = Math.min(n, 1024), h = Math.ceil(n / w);
    const pack = (a) => {
      const t = new Float32Array(w * h * 4);
      for (let k = 0; k < n; ++k) t.set(a.subarray(3 * k, 3 * k + 3), 4 * k);
      const tex = gl.createTexture();
      this.scratch(gl.TEXTURE_2D, tex);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, t);
      this.nearest(gl.TEXTURE_2D);
      gl.bindTexture(gl.TEXTURE_2D, null);
      return tex;
    };
    const twi = pack(wi), two = pack(wo);
    const prog = this.program('pairs');
    gl.useProgram(prog.p);
    const unit = this.bindBrdf(prog, brdf);
    [[prog.u.uWi, twi], [prog.u.uWo, two]].forEach(([loc, tex], i) => {
      gl.activeTexture(gl.TEXTURE0 + unit + i);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.uniform1i(loc, unit + i);
    });
    const target = this.target(w, h);
    this.draw(prog, target);
    const px = this.read(target);
    this.unbindAll();
    this.freeTarget(target);
    gl.deleteTexture(twi);
    gl.deleteTexture(two);
    const out = new Float32Array(3 * n);
    for (let k = 0; k < n; ++k) out.set(px.subarray(4 * k, 4 * k + 3), 3 * k);
    return out;
  }

  // Environment lights (envmap.mjs's envLights) as a texture: { tex, count }.
  envTexture(lights) {
    const { gl } = this;
    const tex = gl.createTexture();
    this.scratch(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, lights.length / 4, 1, 0, gl.RGBA, gl.FLOAT, lights);
    this.nearest(gl.TEXTURE_2D);
    gl.bindTexture(gl.TEXTURE_2D, null);
    return { tex, count: lights.length / 8 };
  }

  // The lit sphere of a BRDF into a float target (linear radiance, alpha = inside): the
  // directional light, or the environment's lights when env is given.
  sphere(brdf, target, light, intensity, env = null) {
    const { gl } = this;
    const prog = this.program('sphere');
    gl.useProgram(prog.p);
    const unit = this.bindBrdf(prog, brdf);
    gl.uniform3fv(prog.u.uLight, light);
    gl.uniform1f(prog.u.uIntensity, intensity);
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, env ? env.tex : this.emptyTab);
    gl.uniform1i(prog.u.uEnv, unit);
    gl.uniform1i(prog.u.uEnvCount, env ? env.count : 0);
    this.draw(prog, target);
    this.unbindAll();
  }

  slab(brdf, target, phiD) {
    const { gl } = this;
    const prog = this.program('slab');
    gl.useProgram(prog.p);
    this.bindBrdf(prog, brdf);
    gl.uniform1f(prog.u.uPhiD, phiD);
    this.draw(prog, target);
  }

  // Shows target a (show 0) or the false-colour difference of a and b (show 2) in a viewport.
  display(a, b, viewport, exposure, show, diffScale) {
    const { gl } = this;
    const prog = this.program('display');
    gl.useProgram(prog.p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, a.tex);
    gl.uniform1i(prog.u.uA, 0);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, (b ?? a).tex);
    gl.uniform1i(prog.u.uB, 1);
    gl.uniform1f(prog.u.uExposure, exposure);
    gl.uniform1i(prog.u.uShow, show);
    gl.uniform1f(prog.u.uDiffScale, diffScale);
    this.draw(prog, null, viewport);
    this.unbindAll();
  }
}
