// The skybake viewer: renders a bake's textures as a game would (docs/runtime.md). The scene goes
// into an RGBA32F target (linear cd/m^2, Linear Rec.2020), then through the OCIO display view
// (luts/display.json) or a false-colour luminance map onto the canvas. window.skybake is the API
// the browser tests drive (tests/viewer/test_viewer.py): fixed dome views, fog points, presets,
// fetch counts and frame times.
import { loadBake } from "./bake.js";

const $ = (id) => document.getElementById(id);
const DEG = Math.PI / 180;
const SUN_RADIUS = 959.63 / 3600 * DEG;  // the Sun's mean angular radius (IAU 2015 nominal solar radius at 1 au: 959.63")

async function text(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.text();
}

function compile(gl, type, src, name) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`${name}: ${gl.getShaderInfoLog(s)}`);
  return s;
}

// A program with a table of its active uniforms, set by name (struct fields as "uSkyP[0].time.r").
function program(gl, vert, frag, name) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, vert, name + " (vertex)"));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, frag, name));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`${name}: ${gl.getProgramInfoLog(p)}`);
  const uniforms = new Map();
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; ++i) {
    const info = gl.getActiveUniform(p, i);
    uniforms.set(info.name.replace(/\[0\]$/, ""), { loc: gl.getUniformLocation(p, info.name), type: info.type, size: info.size });
  }
  return { p, uniforms, name, units: new Map() };
}

function setUniform(gl, prog, name, v) {
  const u = prog.uniforms.get(name);
  if (!u) return;  // not used by this program (optimised out)
  const a = typeof v === "number" ? [v] : v;
  switch (u.type) {
    case gl.FLOAT: gl.uniform1fv(u.loc, a); break;
    case gl.FLOAT_VEC2: gl.uniform2fv(u.loc, a); break;
    case gl.FLOAT_VEC3: gl.uniform3fv(u.loc, a); break;
    case gl.FLOAT_VEC4: gl.uniform4fv(u.loc, a); break;
    case gl.INT: gl.uniform1iv(u.loc, a.map(Math.round)); break;
    default: throw new Error(`${prog.name}: uniform ${name} of type 0x${u.type.toString(16)} set as a number`);
  }
}

// Sets the fields of a struct uniform from an object ("prefix.field", nested).
function setStruct(gl, prog, prefix, obj) {
  for (const [k, v] of Object.entries(obj)) {
    if (v !== null && typeof v === "object" && !Array.isArray(v)) setStruct(gl, prog, `${prefix}.${k}`, v);
    else setUniform(gl, prog, `${prefix}.${k}`, v);
  }
}

// Binds a texture to the sampler `name` (units assigned per program, in order of first use).
function bindSampler(gl, prog, name, target, tex) {
  const u = prog.uniforms.get(name);
  if (!u) return;
  if (!prog.units.has(name)) prog.units.set(name, prog.units.size);
  const unit = prog.units.get(name);
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(target, tex);
  gl.uniform1i(u.loc, unit);
}

function floatTarget(gl, w, h, attachments = 1) {
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  const textures = [];
  for (let i = 0; i < attachments; ++i) {
    const t = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, null);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, t, 0);
    textures.push(t);
  }
  gl.drawBuffers(textures.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
  const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
  if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`RGBA32F framebuffer incomplete (0x${status.toString(16)})`);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  return { fb, textures, w, h, free() { gl.deleteFramebuffer(fb); textures.forEach((t) => gl.deleteTexture(t)); } };
}

function readFloats(gl, target, attachment = 0) {
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, target.fb);
  gl.readBuffer(gl.COLOR_ATTACHMENT0 + attachment);
  const out = new Float32Array(target.w * target.h * 4);
  gl.readPixels(0, 0, target.w, target.h, gl.RGBA, gl.FLOAT, out);
  gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
  return out;
}

// ------------------------------------------------------------------------------------ state

// Sun position from the time of day (h) on a given day and latitude: the solar declination and
// hour angle of Cooper 1969 (Solar Energy 12:333), cos z = sin(lat) sin(dec) + cos(lat) cos(dec) cos(h).
function sunFromTime(hours, latDeg, dayOfYear) {
  const dec = 23.45 * DEG * Math.sin(2 * Math.PI * (284 + dayOfYear) / 365);
  const h = (hours - 12) * 15 * DEG, lat = latDeg * DEG;
  const cz = Math.sin(lat) * Math.sin(dec) + Math.cos(lat) * Math.cos(dec) * Math.cos(h);
  const z = Math.acos(Math.max(-1, Math.min(1, cz)));
  // Azimuth from north towards east, then to the world frame's angle from +x (east) towards +y (north).
  const az = Math.atan2(-Math.sin(h) * Math.cos(dec), Math.cos(lat) * Math.sin(dec) - Math.sin(lat) * Math.cos(dec) * Math.cos(h));
  return { zenith: z, azimuth: Math.PI / 2 - az };
}

export const state = {
  sunElevationDeg: 20, sunAzimuthDeg: 0, useTime: false, hours: 16, latitudeDeg: 45, day: 172,
  haziness: 0, cloudiness: 0, fog: true, clouds: true, ev: 13, falseColour: false,
  yawDeg: 0, pitchDeg: 5, fovDeg: 70, cloudSteps: 160,
};

function sunOf(s) {
  if (s.useTime) return sunFromTime(s.hours, s.latitudeDeg, s.day);
  return { zenith: (90 - s.sunElevationDeg) * DEG, azimuth: s.sunAzimuthDeg * DEG };
}

// sbWeatherWeights (skybake_runtime.glsl) in JS, to pick the slots' skies: the ladder sunny,
// cloudy0 .. cloudy(M-1) over the cloudiness, the sunny weight split by the haziness.
export function weatherWeights(bake, h, c) {
  const cloudy = bake.names.filter((n) => /^cloudy\d+$/.test(n)).sort((a, b) => Number(a.slice(6)) - Number(b.slice(6)));
  const m = cloudy.length;
  h = Math.min(1, Math.max(0, h));
  c = m > 0 ? Math.min(1, Math.max(0, c)) : 0;
  const s = c * m, sunny = Math.max(0, 1 - s), pos = Math.max(s - 1, 0);
  const j = Math.min(Math.floor(pos), Math.max(m - 2, 0));
  const f = m > 1 ? Math.min(1, Math.max(0, pos - j)) : 0;
  const w = { clear: sunny * (1 - h), hazed: sunny * h };
  if (m > 0) {
    w[cloudy[j]] = (w[cloudy[j]] || 0) + (1 - sunny) * (1 - f);
    if (m > 1) w[cloudy[j + 1]] = (w[cloudy[j + 1]] || 0) + (1 - sunny) * f;
  }
  return w;
}

// ------------------------------------------------------------------------------------- app

class Viewer {
  constructor(canvas, gl, bake, sources) {
    this.canvas = canvas;
    this.gl = gl;
    this.bake = bake;
    this.sources = sources;
  }

  static async create(canvas, base, log) {
    const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error("WebGL2 is not available");
    if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("EXT_color_buffer_float is not available (float render targets)");
    const bake = await loadBake(gl, base, log);
    const names = ["skybake_runtime.glsl", "common.glsl", "fullscreen.vert", "dome.frag", "fogpoints.frag", "scene.frag", "display.frag"];
    const src = {};
    for (const n of names) src[n] = await text(`glsl/${n}`);
    const v = new Viewer(canvas, gl, bake, src);
    v.build();
    return v;
  }

  // Compiles every program (also with SB_COUNT_FETCHES for the fetch counts).
  build() {
    const gl = this.gl, s = this.sources;
    const head = (defs) => "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2DArray;\n" +
      "precision highp sampler3D;\n" + defs.map((d) => `#define ${d}\n`).join("");
    const vert = "#version 300 es\n" + s["fullscreen.vert"];
    const frag = (main, defs = []) => head(defs) + s["skybake_runtime.glsl"] + "\n" + s["common.glsl"] + "\n" + s[main];
    this.programs = {
      dome: program(gl, vert, frag("dome.frag"), "dome.frag"),
      domeCount: program(gl, vert, frag("dome.frag", ["SB_COUNT_FETCHES"]), "dome.frag (counting)"),
      fogPoints: program(gl, vert, frag("fogpoints.frag"), "fogpoints.frag"),
      scene: program(gl, vert, frag("scene.frag"), "scene.frag"),
      sceneCount: program(gl, vert, frag("scene.frag", ["SB_COUNT_FETCHES"]), "scene.frag (counting)"),
      display: program(gl, vert, head([]) + this.bake.display.glsl + "\n" + s["display.frag"], "display.frag"),
    };
    this.vao = gl.createVertexArray();
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`WebGL error 0x${err.toString(16)} after building the programs`);
  }

  // Binds the sky slots, the other LUTs and the fog for weights {sky: w} (at most 4 skies).
  bindSky(prog, weights) {
    const gl = this.gl, b = this.bake;
    const active = Object.entries(weights).filter(([, w]) => w > 0);
    if (active.length > 4) throw new Error("at most 4 basis skies at once");
    const w4 = [0, 0, 0, 0], rows = [0, 0, 0, 0], fogHave = [0, 0, 0, 0];
    for (let i = 0; i < 4; ++i) {
      const [name, w] = active[i] || [active.length ? active[0][0] : b.names[0], 0];
      const sky = b.skies.find((x) => x.name === name);
      if (!sky) throw new Error(`no basis sky '${name}' in this bake (it has ${b.names.join(", ")})`);
      w4[i] = w;
      rows[i] = sky.row;
      bindSampler(gl, prog, `uSkyLut${i}`, gl.TEXTURE_2D_ARRAY, sky.tex.texture);
      setStruct(gl, prog, `uSkyP[${i}]`, sky.params);
      if (b.fog) {
        const k = b.fog.names.indexOf(name);
        const f = b.fog.info[Math.max(k, 0)];
        fogHave[i] = k >= 0 ? 1 : 0;
        setStruct(gl, prog, `uFogP[${i}]`, {
          lut: f.lutParams, planetRadius: f.planetRadius, observerAltitude: f.observerAltitude, cutAltitude: f.cutAltitude,
          pathAngle: f.pathAngle, nodes: f.nodes, attSize: f.attSize, attInvScale: f.attInvScale, sky: f.sky,
        });
      }
    }
    setUniform(gl, prog, "uWeights", w4);
    setUniform(gl, prog, "uSkyRow", rows);
    setUniform(gl, prog, "uRows", b.names.length);
    setUniform(gl, prog, "uOtherInvScale", [b.sun.invScale, b.ambient.invScale, b.transmittance.invScale]);
    bindSampler(gl, prog, "uSunLut", gl.TEXTURE_2D, b.sun.tex.texture);
    bindSampler(gl, prog, "uAmbientLut", gl.TEXTURE_2D, b.ambient.tex.texture);
    bindSampler(gl, prog, "uTransLut", gl.TEXTURE_2D, b.transmittance.tex.texture);
    setUniform(gl, prog, "uFogHave", fogHave);
    if (b.fog) {
      bindSampler(gl, prog, "uFogLut", gl.TEXTURE_2D_ARRAY, b.fog.lut);
      bindSampler(gl, prog, "uFogShadowedLut", gl.TEXTURE_2D_ARRAY, b.fog.shadowed);
      bindSampler(gl, prog, "uFogParams", gl.TEXTURE_2D_ARRAY, b.fog.params);
      bindSampler(gl, prog, "uFogAtt", gl.TEXTURE_2D_ARRAY, b.fog.att);
    }
  }

  draw(prog, target) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, target ? target.fb : null);
    gl.viewport(0, 0, target ? target.w : this.canvas.width, target ? target.h : this.canvas.height);
    gl.bindVertexArray(this.vao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  }

  weightsOf(s) { return weatherWeights(this.bake, s.haziness, s.cloudiness); }

  // The game view into an RGBA32F target of the canvas' size.
  renderScene(s, { count = false, target = null } = {}) {
    const gl = this.gl, b = this.bake;
    const w = this.canvas.width, h = this.canvas.height;
    if (!this.hdr || this.hdr.w !== w || this.hdr.h !== h) {
      if (this.hdr) this.hdr.free();
      this.hdr = floatTarget(gl, w, h);
    }
    const prog = count ? this.programs.sceneCount : this.programs.scene;
    gl.useProgram(prog.p);
    this.bindSky(prog, this.weightsOf(s));
    const sun = sunOf(s);
    const yaw = s.yawDeg * DEG, pitch = s.pitchDeg * DEG;
    const fwd = [Math.cos(pitch) * Math.cos(yaw), Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch)];
    const right = [Math.sin(yaw), -Math.cos(yaw), 0];
    const up = [right[1] * fwd[2] - right[2] * fwd[1], right[2] * fwd[0] - right[0] * fwd[2], right[0] * fwd[1] - right[1] * fwd[0]];
    setUniform(gl, prog, "uResolution", [w, h]);
    setUniform(gl, prog, "uCamForward", fwd);
    setUniform(gl, prog, "uCamRight", right);
    setUniform(gl, prog, "uCamUp", up);
    setUniform(gl, prog, "uTanHalfFov", Math.tan(0.5 * s.fovDeg * DEG));
    setUniform(gl, prog, "uSunZenith", sun.zenith);
    setUniform(gl, prog, "uSunAzimuth", sun.azimuth);
    setUniform(gl, prog, "uSunRadius", SUN_RADIUS);
    setUniform(gl, prog, "uGroundAlbedo", 0.15);
    setUniform(gl, prog, "uEyeHeight", 2.0);
    setUniform(gl, prog, "uFogOn", s.fog && b.fog ? 1 : 0);
    const c = b.clouds;
    setUniform(gl, prog, "uCloudsOn", s.clouds && c ? 1 : 0);
    if (c) {
      bindSampler(gl, prog, "uNoiseLow", gl.TEXTURE_3D, c.low.texture);
      bindSampler(gl, prog, "uNoiseHigh", gl.TEXTURE_3D, c.high.texture);
      bindSampler(gl, prog, "uCumulus", gl.TEXTURE_2D, c.map.texture);
      bindSampler(gl, prog, "uCoverage", gl.TEXTURE_2D_ARRAY, c.cov.texture);
      setUniform(gl, prog, "uNoiseTile", [c.tileLow, c.tileHigh]);
      setUniform(gl, prog, "uCumulusMap", [c.mapA, c.mapHalf]);
      setUniform(gl, prog, "uCoverageAlt", [c.altBottom, c.altTop]);
      setUniform(gl, prog, "uCoverageSize", [c.cov.width, c.cov.height]);
      setUniform(gl, prog, "uCloudTypes", c.types);
      setUniform(gl, prog, "uCloudSteps", s.cloudSteps);
    }
    this.draw(prog, target || this.hdr);
    return target || this.hdr;
  }

  // The HDR target onto the canvas through the display view or the false-colour map.
  present(s) {
    const gl = this.gl, prog = this.programs.display;
    gl.useProgram(prog.p);
    bindSampler(gl, prog, "uHdr", gl.TEXTURE_2D, this.hdr.textures[0]);
    setUniform(gl, prog, "uExposure", 1 / (1.2 * Math.pow(2, s.ev)));
    setUniform(gl, prog, "uFalseColour", s.falseColour ? 1 : 0);
    setUniform(gl, prog, "uLogRange", FALSE_COLOUR_RANGE);
    setUniform(gl, prog, "uLuminance", this.bake.display.luminance_from_rgb);
    this.draw(prog, null);
  }

  frame(s) {
    this.renderScene(s);
    this.present(s);
  }

  // Linear radiance at canvas pixel (x, y from the top left): [r, g, b, depth].
  probe(x, y) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, this.hdr.fb);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    const px = new Float32Array(4);
    gl.readPixels(Math.floor(x), this.hdr.h - 1 - Math.floor(y), 1, 1, gl.RGBA, gl.FLOAT, px);
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
    return px;
  }

  luminance(rgb) {
    const k = this.bake.display.luminance_from_rgb;
    return k[0] * rgb[0] + k[1] * rgb[1] + k[2] * rgb[2];
  }

  // Dome views (lut/dome_view.h) of the weighted blend at each sun zenith angle: W*H*3 floats each,
  // rows top to bottom (row 0 the zenith), and the mean fetches per pixel.
  domes(weights, sunZenithDeg, width, height) {
    const gl = this.gl;
    const target = floatTarget(gl, width, height);
    const out = [];
    let fetches = 0;
    for (const z of sunZenithDeg) {
      for (const [key, count] of [["dome", false], ["domeCount", true]]) {
        const prog = this.programs[key];
        gl.useProgram(prog.p);
        this.bindSky(prog, weights);
        setUniform(gl, prog, "uSunZenith", z * DEG);
        setUniform(gl, prog, "uDomeSize", [width, height]);
        this.draw(prog, target);
        const px = readFloats(gl, target);
        if (count) {
          for (let i = 0; i < width * height; ++i) fetches += px[i * 4 + 3];
          continue;
        }
        const rgb = new Array(width * height * 3);
        for (let y = 0; y < height; ++y) {
          const src = (height - 1 - y) * width;  // readPixels rows are bottom-up
          for (let x = 0; x < width; ++x) for (let c = 0; c < 3; ++c) rgb[(y * width + x) * 3 + c] = px[(src + x) * 4 + c];
        }
        out.push(rgb);
      }
    }
    target.free();
    return { views: out, fetchesPerPixel: fetches / (width * height * sunZenithDeg.length) };
  }

  // The dome of the weighted blend at one sun zenith angle through the display pass (exposure
  // 1 / white, the OCIO sRGB view) into an RGBA8 target: W*H*3 display codes, rows top to bottom.
  // The check that the viewer and the PNG previews (OCIO's CPU path) show the same picture.
  domeDisplay(weights, sunZenithDeg, width, height, whiteCdM2) {
    const gl = this.gl;
    const hdr = floatTarget(gl, width, height);
    let prog = this.programs.dome;
    gl.useProgram(prog.p);
    this.bindSky(prog, weights);
    setUniform(gl, prog, "uSunZenith", sunZenithDeg * DEG);
    setUniform(gl, prog, "uDomeSize", [width, height]);
    this.draw(prog, hdr);
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, width, height, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    prog = this.programs.display;
    gl.useProgram(prog.p);
    bindSampler(gl, prog, "uHdr", gl.TEXTURE_2D, hdr.textures[0]);
    setUniform(gl, prog, "uExposure", 1 / whiteCdM2);
    setUniform(gl, prog, "uFalseColour", 0);
    setUniform(gl, prog, "uLuminance", this.bake.display.luminance_from_rgb);
    this.draw(prog, { fb, w: width, h: height });
    const px = new Uint8Array(width * height * 4);
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, fb);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
    gl.deleteFramebuffer(fb);
    gl.deleteTexture(tex);
    hdr.free();
    const out = new Array(width * height * 3);
    for (let y = 0; y < height; ++y) {
      for (let x = 0; x < width; ++x) for (let c = 0; c < 3; ++c) out[(y * width + x) * 3 + c] = px[((height - 1 - y) * width + x) * 4 + c];
    }
    return out;
  }

  // Fog of one sky at explicit points [{sun_zenith_deg, view_zenith_deg, relative_azimuth_deg,
  // depth_m, occlusion}]: [{inscattered: [r, g, b], transmittance: [r, g, b]}].
  fogPoints(sky, points) {
    const gl = this.gl, b = this.bake;
    if (!b.fog || !b.fog.names.includes(sky)) throw new Error(`no fog products for '${sky}'`);
    const n = points.length;
    const a = new Float32Array(n * 4), o = new Float32Array(n * 4);
    points.forEach((p, i) => {
      a.set([p.sun_zenith_deg, p.view_zenith_deg, p.relative_azimuth_deg, p.depth_m], i * 4);
      o[i * 4] = p.occlusion || 0;
    });
    const tex = (data) => {
      const t = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, n, 1, 0, gl.RGBA, gl.FLOAT, data);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      return t;
    };
    const ta = tex(a), to = tex(o);
    const target = floatTarget(gl, n, 1, 2);
    const prog = this.programs.fogPoints;
    gl.useProgram(prog.p);
    this.bindSky(prog, { [sky]: 1 });
    setUniform(gl, prog, "uFogSlot", 0);
    bindSampler(gl, prog, "uPoints", gl.TEXTURE_2D, ta);
    bindSampler(gl, prog, "uPoints2", gl.TEXTURE_2D, to);
    this.draw(prog, target);
    const ins = readFloats(gl, target, 0), tr = readFloats(gl, target, 1);
    target.free();
    gl.deleteTexture(ta);
    gl.deleteTexture(to);
    return points.map((_, i) => ({ inscattered: [...ins.slice(i * 4, i * 4 + 3)], transmittance: [...tr.slice(i * 4, i * 4 + 3)] }));
  }

  // Mean texture fetches per pixel of the game view with the current state, split by what the
  // pixels show: sky (and clouds) above the horizon, ground (and fog) below.
  fetchCounts(s) {
    const target = this.renderScene(s, { count: true });
    const px = readFloats(this.gl, target);
    let sky = 0, nSky = 0, ground = 0, nGround = 0;
    const w = target.w, h = target.h;
    // The count shader has no depth channel: the upper half of a level view is sky.
    for (let y = 0; y < h; ++y) {
      for (let x = 0; x < w; ++x) {
        const f = px[(y * w + x) * 4 + 3];
        if (y >= h / 2) { sky += f; nSky++; } else { ground += f; nGround++; }
      }
    }
    return { sky: sky / Math.max(nSky, 1), ground: ground / Math.max(nGround, 1) };
  }
}

const FALSE_COLOUR_RANGE = [-1, 5];  // log10 cd/m^2: 0.1 to 100 000 cd/m^2

// ----------------------------------------------------------------------------------- page

const CONTROLS = [
  ["sunElevation", "sunElevationDeg"], ["sunAzimuth", "sunAzimuthDeg"], ["hours", "hours"], ["latitude", "latitudeDeg"],
  ["haziness", "haziness"], ["cloudiness", "cloudiness"], ["ev", "ev"], ["fov", "fovDeg"],
];
const CHECKBOXES = [["fog", "fog"], ["clouds", "clouds"], ["falseColour", "falseColour"], ["useTime", "useTime"]];

// The controls show the state (after a preset or a test set it).
function syncControls() {
  for (const [id, key] of CONTROLS) $(id).value = state[key];
  for (const [id, key] of CHECKBOXES) $(id).checked = state[key];
}

function bindControls(viewer, redraw) {
  const s = state;
  for (const [id, key] of CONTROLS) {
    const el = $(id);
    el.value = s[key];
    el.addEventListener("input", () => { s[key] = Number(el.value); redraw(); });
  }
  for (const [id, key] of CHECKBOXES) {
    const el = $(id);
    el.checked = s[key];
    el.addEventListener("change", () => { s[key] = el.checked; redraw(); });
  }
  const canvas = viewer.canvas;
  let drag = null;
  canvas.addEventListener("mousedown", (e) => { drag = { x: e.clientX, y: e.clientY, yaw: s.yawDeg, pitch: s.pitchDeg }; });
  window.addEventListener("mouseup", () => { drag = null; });
  canvas.addEventListener("mousemove", (e) => {
    const r = canvas.getBoundingClientRect();
    const x = (e.clientX - r.left) * canvas.width / r.width, y = (e.clientY - r.top) * canvas.height / r.height;
    if (drag) {
      const k = s.fovDeg / canvas.height;
      s.yawDeg = drag.yaw + (e.clientX - drag.x) * k;
      s.pitchDeg = Math.max(-89, Math.min(89, drag.pitch + (e.clientY - drag.y) * k));
      redraw();
      return;
    }
    const px = viewer.probe(x, y);
    const lum = viewer.luminance(px);
    $("probe").textContent = `${lum.toPrecision(4)} cd/m²` + (px[3] > 0 ? ` at ${(px[3] / 1000).toFixed(2)} km` : " (sky)");
  });
}

function drawScale() {
  const c = $("scale"), g = c.getContext("2d");
  const ramp = (t) => {
    const stops = [[0.05, 0.02, 0.25], [0.1, 0.3, 0.9], [0.0, 0.8, 0.9], [0.1, 0.8, 0.2], [0.95, 0.9, 0.1], [0.9, 0.15, 0.1], [1, 1, 1]];
    const x = Math.min(1, Math.max(0, t)) * 6, i = Math.min(5, Math.floor(x)), f = x - i;
    return stops[i].map((v, k) => Math.round(255 * (v + (stops[i + 1][k] - v) * f)));
  };
  for (let x = 0; x < c.width; ++x) {
    const [r, gg, b] = ramp(x / (c.width - 1));
    g.fillStyle = `rgb(${r},${gg},${b})`;
    g.fillRect(x, 0, 1, 14);
  }
  g.fillStyle = "#ddd";
  g.font = "11px sans-serif";
  const [lo, hi] = FALSE_COLOUR_RANGE;
  for (let e = lo; e <= hi; ++e) {
    const x = (e - lo) / (hi - lo) * (c.width - 1);
    g.fillRect(x, 14, 1, 4);
    const label = e < 0 ? `0.${"0".repeat(-e - 1)}1` : e < 3 ? `${10 ** e}` : `${10 ** (e - 3)}k`;
    g.fillText(label, Math.min(Math.max(x - 0.5 * g.measureText(label).width, 0), c.width - g.measureText(label).width), 30);
  }
}

async function start() {
  const params = new URLSearchParams(location.search);
  const base = params.get("outputs") || "/outputs/";
  const status = $("status");
  const log = (m) => { status.textContent = m; };
  const errors = [];
  window.skybake = { errors, ready: null };
  window.skybake.ready = (async () => {
    const canvas = $("view");
    const w = Number(params.get("width") || 960), h = Number(params.get("height") || 540);
    canvas.width = w;
    canvas.height = h;
    const viewer = await Viewer.create(canvas, base, log);
    let pending = false;
    const redraw = () => {
      if (pending) return;
      pending = true;
      requestAnimationFrame(() => {
        pending = false;
        const t0 = performance.now();
        viewer.frame(state);
        viewer.gl.readPixels(0, 0, 1, 1, viewer.gl.RGBA, viewer.gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the frame
        const sun = sunOf(state);
        $("info").textContent = `sun elevation ${(90 - sun.zenith / DEG).toFixed(2)}°, ` +
          `frame ${(performance.now() - t0).toFixed(0)} ms; skies ` +
          Object.entries(viewer.weightsOf(state)).filter(([, w]) => w > 0).map(([n, w]) => `${n} ${w.toFixed(2)}`).join(", ");
      });
    };
    bindControls(viewer, redraw);
    const presets = (await (await fetch("presets.json")).json()).presets;
    for (const p of presets) {
      const button = document.createElement("button");
      button.textContent = p.name;
      button.addEventListener("click", () => { Object.assign(state, p.state); syncControls(); redraw(); });
      $("presets").appendChild(button);
    }
    drawScale();
    redraw();
    log(`${base}: ${viewer.bake.names.length} basis skies` + (viewer.bake.fog ? ", fog" : "") + (viewer.bake.clouds ? ", clouds" : ""));
    Object.assign(window.skybake, {
      viewer, state, weatherWeights: (h, c) => weatherWeights(viewer.bake, h, c),
      names: viewer.bake.names, fogSkies: viewer.bake.fog ? viewer.bake.fog.names : [], hasClouds: !!viewer.bake.clouds,
      // Renders the game view with `overrides` of the state, synchronously, onto the canvas.
      presets,
      show(overrides) { Object.assign(state, overrides); syncControls(); viewer.frame(state); viewer.gl.finish(); return true; },
      domes: (weights, sza, w, h) => viewer.domes(weights, sza, w, h),
      domeDisplay: (weights, sza, w, h, white) => viewer.domeDisplay(weights, sza, w, h, white),
      fogPoints: (sky, points) => viewer.fogPoints(sky, points),
      fetchCounts: (overrides) => { Object.assign(state, overrides); return viewer.fetchCounts(state); },
      // Mean time of `frames` frames of the game view (ms). Each frame ends with a one-pixel
      // readPixels of the canvas, which waits for the GPU (gl.finish does not in Chromium).
      frameTime(overrides, frames = 5) {
        Object.assign(state, overrides);
        const gl = viewer.gl, px = new Uint8Array(4);
        const one = () => { viewer.frame(state); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px); };
        one();
        const t0 = performance.now();
        for (let i = 0; i < frames; ++i) one();
        return (performance.now() - t0) / frames;
      },
      glError: () => viewer.gl.getError(),
      renderer() {
        const gl = viewer.gl, ext = gl.getExtension("WEBGL_debug_renderer_info");
        return { version: gl.getParameter(gl.VERSION), renderer: ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER) };
      },
    });
    return true;
  })().catch((e) => {
    errors.push(String(e && e.message ? e.message : e));
    log(`error: ${e && e.message ? e.message : e}`);
    throw e;
  });
}

start();
