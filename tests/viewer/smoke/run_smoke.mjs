// Smoke test of the viewer test infrastructure: serves tests/viewer/smoke/ with
// scripts/view_server.py (--root override, an empty temporary outputs folder), opens it in
// headless Chromium through tests/viewer/browser.mjs and checks what the viewer will rely on:
//   - a WebGL2 context on SwiftShader, EXT_color_buffer_float;
//   - R11F_G11F_B10F TEXTURE_2D_ARRAY and TEXTURE_3D uploads (packed
//     UNSIGNED_INT_10F_11F_11F_REV) read back through an RGBA32F framebuffer as floats:
//     texel centres exactly the packed values (decoded here, independently of the page's
//     encoder), half-way / cell-centre samples the (tri)linear average within 1e-3 (relative
//     above 1);
//   - the bilinear weight precision (a sweep of 1025 samples from a 0 texel to a 1 texel, and
//     the value at 1/3), printed;
//   - a 1280x720 page screenshot (PNG, decoded here) showing the canvas and the label text.
// Prints the renderer, timings and precision figures; exit 0 when every check passes, else 1.
//
//   node tests/viewer/smoke/run_smoke.mjs [--screenshot out.png]

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import zlib from 'node:zlib';
import {fileURLToPath} from 'node:url';
import {startViewServer, withPage} from '../browser.mjs';

const HERE = path.dirname(fileURLToPath(import.meta.url));

// R11F_G11F_B10F channel decode (OpenGL ES 3.0 §2.1.3, 2.1.4): 5-bit exponent, bias 15.
function decodeUFloat(bits, mantissaBits) {
  const e = bits >>> mantissaBits, m = bits & ((1 << mantissaBits) - 1);
  if (e === 0) return 2 ** -14 * (m / (1 << mantissaBits));
  if (e === 31) return m ? NaN : Infinity;
  return 2 ** (e - 15) * (1 + m / (1 << mantissaBits));
}
function decodeTexel(p) {
  return [decodeUFloat(p & 0x7ff, 6), decodeUFloat((p >>> 11) & 0x7ff, 6),
          decodeUFloat((p >>> 22) & 0x3ff, 5)];
}

// Linear filtering as OpenGL ES 3.0 §3.8.10 defines it, in exact (double) weights:
// i0 = floor(u - 1/2), weight of i0 + 1 = frac(u - 1/2), indices clamped (CLAMP_TO_EDGE).
function axis(coord, size) {
  const u = coord * size - 0.5, i0 = Math.floor(u), f = u - i0;
  const clamp = i => Math.min(Math.max(i, 0), size - 1);
  return [[clamp(i0), 1 - f], [clamp(i0 + 1), f]];
}
function expected(texels, w, h, d, [s, t, r], layered) {
  const out = [0, 0, 0];
  const zs = layered ? [[Math.min(Math.max(Math.round(r), 0), d - 1), 1]] : axis(r, d);
  for (const [z, wz] of zs)
    for (const [y, wy] of axis(t, h))
      for (const [x, wx] of axis(s, w)) {
        const v = texels[(z * h + y) * w + x];
        for (let c = 0; c < 3; c++) if (wx * wy * wz) out[c] += wx * wy * wz * v[c];
      }
  return out;
}

// A minimal PNG decoder (8-bit RGB/RGBA, non-interlaced, as page.screenshot writes) so the
// screenshot's pixels can be checked without another npm package.
function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('not a PNG');
  let off = 8, width, height, channels;
  const idat = [];
  while (off < buf.length) {
    const len = buf.readUInt32BE(off), type = buf.toString('latin1', off + 4, off + 8);
    const data = buf.subarray(off + 8, off + 8 + len);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      const depth = data[8], colour = data[9], interlace = data[12];
      if (depth !== 8 || (colour !== 2 && colour !== 6) || interlace)
        throw new Error(`unsupported PNG (depth ${depth}, colour ${colour}, interlace ${interlace})`);
      channels = colour === 6 ? 4 : 3;
    } else if (type === 'IDAT') idat.push(data);
    else if (type === 'IEND') break;
    off += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels, px = Buffer.alloc(height * stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? px[y * stride + i - channels] : 0;
      const b = y ? px[(y - 1) * stride + i] : 0;
      const c = y && i >= channels ? px[(y - 1) * stride + i - channels] : 0;
      let p;
      switch (filter) {
        case 0: p = 0; break;
        case 1: p = a; break;
        case 2: p = b; break;
        case 3: p = (a + b) >> 1; break;
        case 4: {
          const q = a + b - c, pa = Math.abs(q - a), pb = Math.abs(q - b), pc = Math.abs(q - c);
          p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw new Error(`bad PNG filter ${filter}`);
      }
      px[y * stride + i] = (line[i] + p) & 0xff;
    }
  }
  return {width, height, channels, pixel: (x, y) => Array.from(px.subarray((y * width + x) * channels, (y * width + x) * channels + 3))};
}

const checks = [];
function check(ok, what) {
  checks.push({ok, what});
  if (!ok) console.log(`FAIL ${what}`);
}
const fmt = v => v.map(x => x.toPrecision(7)).join(', ');

async function main() {
  const shotArg = process.argv.indexOf('--screenshot');
  const shotPath = shotArg > 0 ? process.argv[shotArg + 1] : null;
  const outputs = fs.mkdtempSync(path.join(os.tmpdir(), 'skybake-smoke-outputs-'));
  const tStart = performance.now();
  const server = await startViewServer({outputs, root: HERE});
  const tServer = performance.now() - tStart;
  let r, shot, timings, tEval, tShot;
  try {
    await withPage(server.url, async (page, log) => {
      timings = log.timings;
      let t = performance.now();
      r = await page.evaluate(() => window.runSmoke());
      tEval = performance.now() - t;
      t = performance.now();
      shot = await page.screenshot({type: 'png'});
      tShot = performance.now() - t;
    }, {width: 1280, height: 720});
  } finally {
    await server.close();
    fs.rmSync(outputs, {recursive: true, force: true});
  }
  const tTotal = performance.now() - tStart;

  console.log(`renderer: ${r.renderer}`);
  console.log(`vendor:   ${r.vendor}`);
  console.log(`version:  ${r.version}`);
  check(r.version.startsWith('WebGL 2.0'), 'WebGL 2.0 context');
  check(r.colorBufferFloat, 'EXT_color_buffer_float');

  // Read-back pixel (x, row) of the RGBA32F target.
  const at = (x, row) => r.floats.slice((row * r.width + x) * 4, (row * r.width + x) * 4 + 3);
  const arrayTexels = r.array.packed.map(decodeTexel);
  const volumeTexels = r.volume.packed.map(decodeTexel);
  // The page's encoder must have packed the intended values exactly.
  check(arrayTexels.every((v, i) => v.every((x, c) => x === r.array.texels[i][c])) &&
        volumeTexels.every((v, i) => v.every((x, c) => x === r.volume.texels[i][c])),
        'packed texels decode to the intended values');

  let exact = 0, exactOk = 0, filtered = 0, filteredOk = 0, worstRel = 0;
  r.points.forEach(([s, t, q, which], i) => {
    const layered = which === 0;
    const tex = layered ? r.array : r.volume;
    const texels = layered ? arrayTexels : volumeTexels;
    const want = expected(texels, tex.w, tex.h, layered ? tex.layers : tex.d, [s, t, q], layered);
    const got = at(i, 0);
    const centre = [[s, tex.w], [t, tex.h]].concat(layered ? [] : [[q, tex.d]])
      .every(([c, n]) => Math.abs(c * n - 0.5 - Math.round(c * n - 0.5)) < 1e-9);
    if (centre) {
      exact++;
      const ok = got.every((g, c) => g === want[c]);
      if (ok) exactOk++;
      else console.log(`  centre ${layered ? 'array' : '3D'} (${fmt([s, t, q])}): got ${fmt(got)}, want ${fmt(want)}`);
    } else {
      filtered++;
      const rel = Math.max(...got.map((g, c) => Math.abs(g - want[c]) / Math.max(1, Math.abs(want[c]))));
      worstRel = Math.max(worstRel, rel);
      if (rel <= 1e-3) filteredOk++;
      console.log(`  filtered ${layered ? 'array' : '3D   '} at (${fmt([s, t, q])}): got ${fmt(got)}, want ${fmt(want)}`);
    }
  });
  check(exact === exactOk, `${exactOk}/${exact} texel centres read back exactly (RGBA32F, R11F_G11F_B10F)`);
  check(filtered === filteredOk, `${filteredOk}/${filtered} filtered samples within 1e-3 (worst ${worstRel.toExponential(2)})`);

  // Bilinear weight precision: sweep rows 1 (array, along s) and 2 (3D, along r).
  for (const [row, name] of [[1, 'array s'], [2, '3D r']]) {
    let maxErr = 0;
    const levels = new Set();
    for (let x = 0; x <= r.sweepSteps; x++) {
      const g = at(x, row)[0], f = x / r.sweepSteps;
      maxErr = Math.max(maxErr, Math.abs(g - f));
      levels.add(g);
    }
    // n distinct values over the 1/1024 steps: about log2(n - 1) bits of weight (8 on many
    // GPUs); all 1025 distinct means finer than the sweep can resolve (see the 1/3 sample).
    const bits = Math.log2(levels.size - 1);
    console.log(`  weight sweep ${name}: ${levels.size} distinct values over ${r.sweepSteps + 1} samples ` +
                `(${levels.size === r.sweepSteps + 1 ? '>= ' : '~'}${bits.toFixed(1)} bits of weight), ` +
                `max |error| ${maxErr.toExponential(3)}`);
    check(maxErr < 1e-2, `weight sweep ${name} within 1e-2`);
  }
  const third = r.points.findIndex(([s, , q, w]) => w === 0 && q === 1 && Math.abs(s - (0.5 + 1 / 3) / 4) < 1e-9);
  const thirdZ = r.points.length - 1;
  console.log(`  1/3 sample (array, s): ${at(third, 0)[0].toPrecision(9)} (1/3 = 0.333333333, error ${(at(third, 0)[0] - 1 / 3).toExponential(3)})`);
  console.log(`  1/3 sample (3D, r):    ${at(thirdZ, 0)[0].toPrecision(9)} (error ${(at(thirdZ, 0)[0] - 1 / 3).toExponential(3)})`);

  // Screenshot: 1280x720; left half the flat (0.2, 0.6, 0.8) = (51, 153, 204); the label text
  // (white) present; the right half a gradient from the layer-1 sweep.
  if (shotPath) fs.writeFileSync(shotPath, shot);
  const png = decodePng(shot);
  check(png.width === 1280 && png.height === 720, `screenshot is ${png.width}x${png.height}`);
  const flat = png.pixel(320, 600);
  check(flat.every((v, c) => Math.abs(v - [51, 153, 204][c]) <= 1), `canvas flat colour in screenshot: ${flat}`);
  let white = 0;
  const L = r.label;
  for (let y = Math.floor(L.y); y < L.y + L.h; y++)
    for (let x = Math.floor(L.x); x < L.x + L.w; x++) if (png.pixel(x, y).every(v => v > 240)) white++;
  check(white > 50, `label text rendered (${white} white pixels)`);
  const g1 = png.pixel(640 + 64, 600)[0], g2 = png.pixel(640 + 576, 600)[0];
  check(g2 > g1 + 100, `sweep gradient in screenshot (${g1} -> ${g2})`);

  console.log(`timings: server start ${tServer.toFixed(0)} ms, chromium launch ${timings.launch_ms.toFixed(0)} ms, ` +
              `page load ${timings.goto_ms.toFixed(0)} ms, first render (context .. readPixels) ` +
              `${r.firstRenderMs.toFixed(0)} ms, runSmoke ${tEval.toFixed(0)} ms, ` +
              `screenshot ${tShot.toFixed(0)} ms, total incl. close ${tTotal.toFixed(0)} ms`);
  const failed = checks.filter(c => !c.ok);
  for (const c of checks) console.log(`${c.ok ? 'ok  ' : 'FAIL'} ${c.what}`);
  console.log(failed.length ? `smoke: ${failed.length} check(s) failed` : 'smoke: all checks passed');
  return failed.length ? 1 : 0;
}

main().then(code => { process.exitCode = code; }, e => {
  console.error(`run_smoke: ${e.stack ?? e}`);
  process.exitCode = 1;
});
