// A bake's runtime textures, found from lut-pack's report (luts/report.json names the basis skies)
// and the pipeline's fixed output names (docs/pipeline.md): luts/sky_<sky>_array.ktx2,
// luts/{sun,ambient,transmittance}.ktx2, luts/display.json, fog/fog_<sky>.json and the textures it
// names, clouds/noise/noise_{low,high}.ktx2, clouds/cumulus_map_t0s.ktx2, clouds/coverage.ktx2.
// Fog and clouds are optional (a bake without them shows the sky alone); the sky LUTs are not.
import { loadKtx2, keyString, keyNumbers } from "./textures.js";

async function json(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.json();
}

// The JSON at url, or null when the server answers 404 (an optional product the bake lacks).
async function optionalJson(url) {
  const r = await fetch(url);
  if (r.status === 404) return null;
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.json();
}

// "gt7-quadratic:3+2" -> {upper, lower, power} (lut/gt7_mapping.h TimeMapping::ParseName).
function parseTimeMapping(name, file) {
  const m = /^(gt7|gt7-quadratic)(?::(\d+)\+(\d+))?$/.exec(name || "");
  if (!m) throw new Error(`${file}: KTX2 key 'skybake.time_mapping.name' is not a GT7 time mapping: "${name}"`);
  return { upper: m[2] ? Number(m[2]) : 48, lower: m[3] ? Number(m[3]) : 16, power: m[1] === "gt7" ? 1 : 2 };
}

// The SbSkyLut uniform values of a sky or fog LUT (lut/decoder.h SkyLutDecoder::FromKtx2).
export function skyLutParams(t, layerBase = 0) {
  const c = t.container, f = t.file;
  const tm = parseTimeMapping(keyString(c, "skybake.time_mapping.name"), f);
  const slices = t.layers || t.depth;
  if (slices !== tm.upper + tm.lower) throw new Error(`${f}: ${slices} slices, but the time mapping has ${tm.upper + tm.lower}`);
  const scale = keyNumbers(c, "skybake.scale", f)[0];
  if (!(scale > 0)) throw new Error(`${f}: skybake.scale must be positive`);
  const grid = keyString(c, "skybake.texel_grid") || "centres";
  if (grid !== "centres" && grid !== "nodes") throw new Error(`${f}: skybake.texel_grid must be centres or nodes, got "${grid}"`);
  return {
    time: {
      upper: tm.upper, lower: tm.lower, power: tm.power,
      r: keyNumbers(c, "skybake.time_mapping.observer_radius_m", f)[0],
      R: keyNumbers(c, "skybake.time_mapping.top_radius_m", f)[0],
    },
    thresholdZenith: (90 - keyNumbers(c, "skybake.sphere_mapping.threshold_elevation_deg", f)[0]) * Math.PI / 180,
    size: [t.width, t.height],
    nodes: grid === "nodes" ? 1 : 0,
    invScale: 1 / scale,
    night: keyNumbers(c, "skybake.night_rgb", f),
    nightEnd: keyNumbers(c, "skybake.night_end_zenith_deg", f)[0] * Math.PI / 180,
    geometric: (keyString(c, "skybake.time_interpolation") || "geometric").startsWith("linear") ? 0 : 1,
    layerBase,
  };
}

function invScaleOf(t) {
  const s = keyNumbers(t.container, "skybake.scale", t.file)[0];
  if (!(s > 0)) throw new Error(`${t.file}: skybake.scale must be positive`);
  return 1 / s;
}

// Stacks equally sized 2D-array textures (the fog LUTs of every basis sky) into one array, so that
// one sampler serves any number of skies: layer = sky * layers + k.
function stackArrays(gl, parts, internal, format, type, bytesPerTexel) {
  const w = parts[0].width, h = parts[0].height, layers = parts[0].layers || 1;
  for (const p of parts) {
    if (p.width !== w || p.height !== h || (p.layers || 1) !== layers) {
      throw new Error(`${p.file}: ${p.width}x${p.height}x${p.layers || 1}, but ${parts[0].file} is ${w}x${h}x${layers}: ` +
                      "the fog textures of all basis skies must share their size");
    }
  }
  const per = w * h * layers * bytesPerTexel;
  const all = new Uint8Array(per * parts.length);
  parts.forEach((p, i) => all.set(p.container.levels[0].levelData.subarray(0, per), i * per));
  const view = type === gl.FLOAT ? new Float32Array(all.buffer) : new Uint32Array(all.buffer);
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
  gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, internal, w, h, layers * parts.length, 0, format, type, view);
  const filter = type === gl.FLOAT ? gl.NEAREST : gl.LINEAR;
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, filter);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, filter);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, null);
  for (const p of parts) gl.deleteTexture(p.texture);
  return tex;
}

// Loads everything. `base` is the outputs folder's URL ending in "/"; `log` reports progress.
export async function loadBake(gl, base, log = () => {}) {
  const report = await json(base + "luts/report.json");
  const names = (report.skies || []).map((s) => s.name);
  if (names.length === 0) throw new Error(`${base}luts/report.json: no basis skies`);
  const bake = { base, names, skies: [], fog: null, clouds: null };
  log(`sky LUTs: ${names.join(", ")}`);
  for (const [row, name] of names.entries()) {
    const t = await loadKtx2(gl, `${base}luts/sky_${name}_array.ktx2`);
    bake.skies.push({ name, row, tex: t, params: skyLutParams(t) });
  }
  const other = async (n) => { const t = await loadKtx2(gl, `${base}luts/${n}.ktx2`); return { tex: t, invScale: invScaleOf(t) }; };
  bake.sun = await other("sun");
  bake.ambient = await other("ambient");
  bake.transmittance = await other("transmittance");
  bake.display = await json(base + "luts/display.json");

  // Fog: every sky with a fog-fit parameter file (fog/fog_<sky>.json).
  const fogSkies = [], fogJson = [];
  for (const name of names) {
    const j = await optionalJson(`${base}fog/fog_${name}.json`);
    if (j) { fogSkies.push(name); fogJson.push(j); }
  }
  if (fogSkies.length > 0) {
    log(`fog: ${fogSkies.join(", ")}`);
    const lut = [], shadowed = [], params = [], att = [], info = [];
    for (const [i, name] of fogSkies.entries()) {
      const j = fogJson[i];
      const m = j.model;
      const f = (k) => `${base}fog/${j.files[k]}`;
      const L = await loadKtx2(gl, f("fog_array")), S = await loadKtx2(gl, f("shadowed_array"));
      const A = await loadKtx2(gl, f("attenuation")), P = await loadKtx2(gl, f("parameters_texture"));
      const nodeV = keyString(P.container, "skybake.fog.elevation_nodes_v");
      const nodes = P.width - 1;
      if (nodeV !== undefined && nodeV !== "none" && nodes > 1) {
        // The shader takes the nodes as uniform in v (docs/fog.md: the depth tables' elevations
        // 90 deg (j/(m-1))^2); anything else is refused rather than decoded wrongly.
        const v = nodeV.trim().split(/\s+/).map(Number);
        if (v.length !== nodes || v.some((x, i) => Math.abs(x - i / (nodes - 1)) > 1e-6)) {
          throw new Error(`${P.file}: elevation nodes ${nodeV} are not uniform in v`);
        }
      }
      lut.push(L); shadowed.push(S); att.push({ ...A, layers: 1 }); params.push(P);
      info.push({
        name, lutParams: skyLutParams(L), planetRadius: m.planet_radius_m, observerAltitude: m.observer_altitude_m,
        cutAltitude: m.cut_altitude_m, pathAngle: m.angle === "path" ? 1 : 0, nodes, attSize: [A.width, A.height],
        attInvScale: invScaleOf(A),
      });
    }
    const slices = lut[0].layers;
    info.forEach((x, i) => { x.lutParams.layerBase = i * slices; x.sky = i; });
    bake.fog = {
      names: fogSkies, info,
      lut: stackArrays(gl, lut, gl.R11F_G11F_B10F, gl.RGB, gl.UNSIGNED_INT_10F_11F_11F_REV, 4),
      shadowed: stackArrays(gl, shadowed, gl.R11F_G11F_B10F, gl.RGB, gl.UNSIGNED_INT_10F_11F_11F_REV, 4),
      params: stackArrays(gl, params, gl.RGBA32F, gl.RGBA, gl.FLOAT, 16),
      att: stackArrays(gl, att, gl.R11F_G11F_B10F, gl.RGB, gl.UNSIGNED_INT_10F_11F_11F_REV, 4),
    };
  }

  // Clouds: the pipeline's noise volumes, the map at t = 0 and the coverage texture, when the
  // bake has a clouds section (probed by the coverage texture; a 404 means none).
  const cloudFiles = ["clouds/noise/noise_low.ktx2", "clouds/noise/noise_high.ktx2", "clouds/cumulus_map_t0s.ktx2", "clouds/coverage.ktx2"];
  const probe = await fetch(base + cloudFiles[3]);
  if (probe.status !== 404 && !probe.ok) throw new Error(`${base}${cloudFiles[3]}: HTTP ${probe.status}`);
  if (probe.ok) {
    log("clouds: noise volumes, cumulus map, coverage");
    const low = await loadKtx2(gl, base + cloudFiles[0], { repeat: true });
    const high = await loadKtx2(gl, base + cloudFiles[1], { repeat: true });
    const map = await loadKtx2(gl, base + cloudFiles[2]);
    const cov = await loadKtx2(gl, base + cloudFiles[3]);
    const alt = keyNumbers(cov.container, "skybake.altitude_axis_m", cov.file);
    bake.clouds = {
      low, high, map, cov,
      tileLow: keyNumbers(low.container, "skybake.tile_size_m", low.file)[0],
      tileHigh: keyNumbers(high.container, "skybake.tile_size_m", high.file)[0],
      mapA: keyNumbers(map.container, "skybake.mapping.a", map.file)[0],
      mapHalf: keyNumbers(map.container, "skybake.mapping.half_extent_m", map.file)[0],
      altBottom: alt[0], altTop: alt[alt.length - 1], types: cov.layers || 1,
    };
  }
  return bake;
}
