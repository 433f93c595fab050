// Runs a plan of measurements on the viewer page in headless Chromium (tests/viewer/browser.mjs)
// and writes what the page returned as JSON: the viewer tests (test_viewer.py) and the benchmark
// (bench/viewer_bench.py) use it.
//
//   node tests/viewer/drive.mjs --url URL --plan plan.json --out result.json [--shots DIR]
//
// plan.json (every key optional):
//   width, height                 the canvas (default 480 x 270)
//   domes: [{name, haziness, cloudiness, sun_zenith_deg: [...], width, height}]
//                                 dome views (lut/dome_view.h) of the weather blend, linear radiance
//   weights: [[h, c], ...]        the page's basis-sky weights for these (haziness, cloudiness)
//   display: [{name, haziness, cloudiness, sun_zenith_deg, width, height, white_cd_m2}]
//                                 one dome through the display pass (OCIO's GLSL): 8-bit codes
//   fog: [{sky, points: [{sun_zenith_deg, view_zenith_deg, relative_azimuth_deg, depth_m, occlusion}]}]
//   screenshots: [{name, state}]  the game view with these state overrides -> DIR/<name>.png, and
//                                 the HDR target's statistics (non-finite texels, max luminance)
//   fetches: [{name, state}]      mean texture fetches per pixel (sky half / ground half of a level view)
//   frame_times: [{name, state, frames}]  mean frame time (ms), each frame waited for (readPixels)
import fs from 'node:fs';
import path from 'node:path';
import {withPage} from './browser.mjs';

function arg(name, fallback) {
  const i = process.argv.indexOf(name);
  return i >= 0 ? process.argv[i + 1] : fallback;
}

const url = arg('--url');
const plan = JSON.parse(fs.readFileSync(arg('--plan'), 'utf8'));
const out = arg('--out');
const shots = arg('--shots');
if (!url || !out) {
  console.error('usage: node tests/viewer/drive.mjs --url URL --plan plan.json --out result.json [--shots DIR]');
  process.exit(2);
}
const width = plan.width || 480, height = plan.height || 270;
const page_url = `${url}?width=${width}&height=${height}`;

const result = await withPage(page_url, async (page, log) => {
  await page.waitForFunction(() => window.skybake && window.skybake.ready, {timeout: 120000});
  const ok = await page.evaluate(() => window.skybake.ready.then(() => true, (e) => String(e)));
  if (ok !== true) throw new Error(`the viewer failed to start: ${ok}`);
  const r = await page.evaluate(() => ({
    names: window.skybake.names, fog_skies: window.skybake.fogSkies, has_clouds: window.skybake.hasClouds,
    renderer: window.skybake.renderer(), luminance_from_rgb: window.skybake.viewer.bake.display.luminance_from_rgb,
  }));
  r.domes = [];
  for (const d of plan.domes || []) {
    const v = await page.evaluate((d) => {
      const w = window.skybake.weatherWeights(d.haziness, d.cloudiness);
      const res = window.skybake.domes(w, d.sun_zenith_deg, d.width, d.height);
      return {name: d.name, weights: w, views: res.views, fetches_per_pixel: res.fetchesPerPixel};
    }, d);
    r.domes.push(v);
  }
  r.display = [];
  for (const d of plan.display || []) {
    r.display.push(await page.evaluate((d) => ({
      name: d.name,
      codes: window.skybake.domeDisplay(window.skybake.weatherWeights(d.haziness, d.cloudiness), d.sun_zenith_deg, d.width,
                                        d.height, d.white_cd_m2),
    }), d));
  }
  r.plan_weights = plan.weights || [];
  r.weights = await page.evaluate((ws) => ws.map(([h, c]) => window.skybake.weatherWeights(h, c)), r.plan_weights);
  r.fog = [];
  for (const f of plan.fog || []) {
    r.fog.push({sky: f.sky, values: await page.evaluate((f) => window.skybake.fogPoints(f.sky, f.points), f)});
  }
  r.hdr = {};
  for (const s of plan.screenshots || []) {
    const stats = await page.evaluate((state) => {
      window.skybake.show(state);
      const v = window.skybake.viewer, gl = v.gl, t = v.hdr;
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, t.fb);
      const px = new Float32Array(t.w * t.h * 4);
      gl.readPixels(0, 0, t.w, t.h, gl.RGBA, gl.FLOAT, px);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
      let bad = 0, max = 0;
      for (let i = 0; i < t.w * t.h; ++i) {
        const c = [px[i * 4], px[i * 4 + 1], px[i * 4 + 2]];
        if (!c.every(Number.isFinite)) { bad++; continue; }
        max = Math.max(max, v.luminance(c));
      }
      return {non_finite: bad, max_luminance: max};
    }, s.state);
    r.hdr[s.name] = stats;
    if (shots) {
      const canvas = await page.$('#view');
      await canvas.screenshot({path: path.join(shots, `${s.name}.png`)});
    }
  }
  r.fetches = {};
  for (const f of plan.fetches || []) r.fetches[f.name] = await page.evaluate((st) => window.skybake.fetchCounts(st), f.state);
  r.frame_times = {};
  for (const f of plan.frame_times || []) {
    r.frame_times[f.name] = await page.evaluate((f) => window.skybake.frameTime(f.state, f.frames || 3), f);
  }
  r.gl_error = await page.evaluate(() => window.skybake.glError());
  r.errors = [...log.errors, ...(await page.evaluate(() => window.skybake.errors))];
  r.timings = log.timings;
  return r;
}, {width: width + 400, height: height + 200, timeoutMs: 1200000, allowErrors: true});

fs.writeFileSync(out, JSON.stringify(result));
