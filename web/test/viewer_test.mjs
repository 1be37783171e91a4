// The browser viewer in a real browser (issue 23): Debian's Chromium, headless, through
// playwright-core, against `daylit replay --serve` of a recording held at a clear frame and at a
// frame under a cloud. Checks, per frame:
//  - /lighting is the replay's own estimates.csv row for that frame;
//  - the sphere is where the scene's camera projects it (its pixels' centroid, and its disc);
//  - its sunlit side has the radiance the message predicts, ρ/π·(E_sun·n·s + E_SH(n))·k, and
//    between the two frames it darkens by the messages' ratio.
// Usage: node viewer_test.mjs DAYLIT RECORDING CACHE WORKDIR CLEAR_FRAMES CLOUD_FRAMES
import { spawn } from 'node:child_process';
import { mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { PNG } from 'pngjs';
import { shIrradiance } from '../viewer/sh.mjs';

const [daylit, recording, cache, work, clearFrames, cloudFrames] = process.argv.slice(2);
let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
}
const figures = {};

// A replay of the first `frames` frames that keeps serving the last one; resolves to its port.
function startReplay(frames, dir) {
  rmSync(dir, { recursive: true, force: true });
  mkdirSync(dir, { recursive: true });
  const child = spawn(daylit, ['replay', recording, '--cache', cache, '--frames', String(frames), '--out',
                               join(dir, 'replay.mp4'), '--serve', '0', '--hold'], { stdio: ['ignore', 'ignore', 'pipe'] });
  let log = '';
  const ready = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no "still serving" within 300 s:\n${log}`)), 300000);
    child.stderr.on('data', (chunk) => {
      log += chunk;
      const held = /--hold: still serving frame (-?\d+) on port (\d+)/.exec(log);
      if (held) {
        clearTimeout(timer);
        resolve({ frame: Number(held[1]), port: Number(held[2]) });
      }
    });
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`daylit replay exited ${code}:\n${log}`)); });
  });
  return { child, ready };
}

function csvRow(file, frame) {
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  const names = lines[0].split(',');
  for (const line of lines.slice(1)) {
    const cells = line.split(',');
    if (Number(cells[0]) === frame) return Object.fromEntries(names.map((n, i) => [n, cells[i]]));
  }
  return null;
}

// Scene point → pixel (OpenCV: x_cam = R x + t).
function project(cam, p) {
  const r = cam.world_to_camera.rotation, t = cam.world_to_camera.translation;
  const x = [0, 1, 2].map((i) => r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + t[i]);
  return [cam.fx * x[0] / x[2] + cam.cx, cam.fy * x[1] / x[2] + cam.cy, x[2]];
}
const srgbToLinear = (v) => (v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4));
const norm = (v) => { const l = Math.hypot(...v); return v.map((x) => x / l); };
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

async function measure(browser, frames, name) {
  const dir = join(work, name);
  const { child, ready } = startReplay(frames, dir);
  try {
    const { frame, port } = await ready;
    const base = `http://127.0.0.1:${port}`;
    const message = await (await fetch(`${base}/lighting`)).json();
    const scene = await (await fetch(`${base}/scene`)).json();
    const row = csvRow(join(dir, 'estimates.csv'), frame);
    check(message.frame === frame && row !== null, `${name}: /lighting is frame ${frame}, the replay's last`);
    if (row) {
      const pairs = [['sun_r', message.primaryLightIntensity.x], ['sun_g', message.primaryLightIntensity.y],
                     ['sun_b', message.primaryLightIntensity.z], ['sky_r', message.skyIrradiance.x],
                     ['sky_g', message.skyIrradiance.y], ['sky_b', message.skyIrradiance.z],
                     ['sun_elevation_deg', message.sunElevationDeg]];
      // estimates.csv keeps 6 significant digits (a relative rounding of at most 5e-6) and the
      // confidence 4 decimals (an absolute one of 5e-5: relative, it grows as the confidence falls).
      const worst = Math.max(...pairs.map(([k, v]) => Math.abs(v - Number(row[k])) / Math.max(Math.abs(Number(row[k])), 1e-3)));
      const confidence = Math.abs(message.confidence - Number(row.confidence));
      check(worst < 1e-5 && confidence <= 5.1e-5, `${name}: /lighting matches estimates.csv's row (worst relative difference ` +
            `${worst.toExponential(2)}, the confidence ${confidence.toExponential(2)} off)`);
    }

    const page = await browser.newPage({ viewport: { width: scene.camera.width, height: scene.camera.height + 40 } });
    const logs = [];
    page.on('console', (m) => logs.push(m.text()));
    page.on('pageerror', (e) => logs.push(String(e)));
    await page.goto(`${base}/`);
    await page.waitForFunction((f) => window.daylit && window.daylit.renderedFrame === f &&
      document.getElementById('background').naturalWidth > 0, frame, { timeout: 60000 })
      .catch((e) => { throw new Error(`${e}\nbrowser log:\n${logs.join('\n')}`); });
    // A second frame drawn after the background arrived: then the picture is whole.
    await page.waitForTimeout(500);
    const shot = PNG.sync.read(await page.screenshot({ clip: { x: 0, y: 0, width: scene.camera.width, height: scene.camera.height } }));
    writeFileSync(join(dir, 'viewer.png'), PNG.sync.write(shot));
    // The objects' own pixels: the WebGL canvas's alpha (opaque objects 255, shadows less).
    const alpha = await page.evaluate(() => {
      const gl = document.querySelector('#view canvas');
      const c = document.createElement('canvas');
      c.width = gl.width, c.height = gl.height;
      const g = c.getContext('2d');
      g.drawImage(gl, 0, 0);
      const d = g.getImageData(0, 0, c.width, c.height).data;
      const a = new Array(c.width * c.height);
      for (let i = 0; i < a.length; ++i) a[i] = d[4 * i + 3];
      return a;
    });
    await page.close();
    return { frame, message, scene, shot, alpha };
  } finally {
    child.kill('SIGTERM');
  }
}

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const results = [];
try {
  for (const [frames, name] of [[clearFrames, 'clear'], [cloudFrames, 'cloud']]) results.push(await measure(browser, Number(frames), name));
} finally {
  await browser.close();
}

const lit = [];
for (const [i, r] of results.entries()) {
  const name = i === 0 ? 'clear' : 'cloud';
  const cam = r.scene.camera, w = cam.width, h = cam.height;
  const sphere = r.scene.objects.find((o) => o.mesh === 'sphere');
  const [u, v, depth] = project(cam, sphere.position);
  const rPx = cam.fx * sphere.radius / depth;
  // The sphere's pixels: opaque ones within 1.5 disc radii of its projected centre, against the
  // pixels whose centre's camera ray meets the sphere (ray cast here, exactly).
  const R = cam.world_to_camera.rotation, c = cam.center, p0 = sphere.position;
  // The sphere's unit normal where pixel (x, y)'s centre ray meets it, or null.
  const normalAt = (x, y) => {
    const dc = [(x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1];
    const d = norm([0, 1, 2].map((k) => R[0][k] * dc[0] + R[1][k] * dc[1] + R[2][k] * dc[2]));
    const oc = [0, 1, 2].map((k) => c[k] - p0[k]);
    const b = dot(oc, d), disc = b * b - (dot(oc, oc) - sphere.radius * sphere.radius);
    if (disc <= 0) return null;
    const t = -b - Math.sqrt(disc);
    return [0, 1, 2].map((k) => (oc[k] + t * d[k]) / sphere.radius);
  };
  const hits = (x, y) => normalAt(x, y) !== null;
  let n = 0, su = 0, sv = 0, nt = 0, tu = 0, tv = 0, differ = 0;
  for (let y = Math.floor(v - 1.5 * rPx); y <= v + 1.5 * rPx; ++y) for (let x = Math.floor(u - 1.5 * rPx); x <= u + 1.5 * rPx; ++x) {
    const opaque = r.alpha[y * w + x] === 255, truth = hits(x, y);
    if (opaque) { n += 1; su += x; sv += y; }
    if (truth) { nt += 1; tu += x; tv += y; }
    if (opaque !== truth) differ += 1;
  }
  const off = Math.hypot(su / n - tu / nt, sv / n - tv / nt);
  check(off < 0.25, `${name}: the sphere's pixels centre ${off.toFixed(3)} px from the ray-cast disc's (bar 0.25 px; ` +
        `${Math.hypot(tu / nt - u, tv / nt - v).toFixed(2)} px from the projected centre, by perspective)`);
  // Only the rim may differ: antialiased pixels there are not opaque.
  const rim = 2 * Math.PI * rPx;
  check(differ < 1.5 * rim, `${name}: ${differ} pixels differ from the ray-cast disc of ${nt} (bar 1.5 × its ${rim.toFixed(0)} rim pixels)`);
  figures[`${name}/centroid_px`] = off;

  // The sunlit side: of the sphere's points the camera sees squarely (not within 3 px of the
  // rim), the one the sun lights most steeply whose clear-frame pixel stays below 0.8 (a low sun
  // full on the sphere clips the camera, as it does the recording's), chosen on the clear frame.
  const m = r.message, s = [m.primaryLightDirection.x, m.primaryLightDirection.y, m.primaryLightDirection.z];
  const toCam = norm([c[0] - p0[0], c[1] - p0[1], c[2] - p0[2]]);
  const sunE = [m.primaryLightIntensity.x, m.primaryLightIntensity.y, m.primaryLightIntensity.z];
  const predict = (n) => {
    const e = shIrradiance(m.sphericalHarmonicsCoefficients, n);
    return [0, 1, 2].map((k) => m.exposure * sphere.albedo[k] / Math.PI * (sunE[k] * Math.max(dot(n, s), 0) + e[k]));
  };
  if (i === 0) {
    let best = null;
    for (let a = 0; a < 180; ++a) for (let b = 0; b < 360; ++b) {
      const t = (a + 0.5) * Math.PI / 180, f = b * Math.PI / 180;
      const n = [Math.sin(t) * Math.cos(f), Math.sin(t) * Math.sin(f), Math.cos(t)];
      if (dot(n, toCam) < Math.sqrt(1 - Math.pow((rPx - 3) / rPx, 2)) || dot(n, s) < 0.1) continue;
      if (Math.max(...predict(n)) > 0.8) continue;
      if (best === null || dot(n, s) > dot(best, s)) best = n;
    }
    lit.normal = best;
  }
  const normal = lit.normal;
  check(normal !== undefined && normal !== null, `${name}: a sunlit point of the sphere below clipping exists`);
  const p = p0.map((x, k) => x + sphere.radius * normal[k]);
  const [pu, pv] = project(cam, p);
  // The 5 × 5 pixels around it, each against the prediction at its own centre's normal.
  const seen = [0, 0, 0], expected = [0, 0, 0];
  let count = 0;
  for (let y = Math.round(pv) - 2; y <= Math.round(pv) + 2; ++y) for (let x = Math.round(pu) - 2; x <= Math.round(pu) + 2; ++x) {
    const at = predict(normalAt(x, y));
    for (let k = 0; k < 3; ++k) seen[k] += srgbToLinear(r.shot.data[4 * (y * w + x) + k] / 255), expected[k] += at[k];
    count += 1;
  }
  for (let k = 0; k < 3; ++k) seen[k] /= count, expected[k] /= count;
  const worst = Math.max(...[0, 1, 2].map((k) => Math.abs(seen[k] / expected[k] - 1)));
  check(worst < 0.015, `${name}: the sunlit side (n·s ${dot(normal, s).toFixed(2)}) at (${pu.toFixed(0)}, ${pv.toFixed(0)}) reads ${seen.map((x) => x.toFixed(4)).join(' ')}, ` +
        `the message predicts ${expected.map((x) => x.toFixed(4)).join(' ')} (worst ${(100 * worst).toFixed(2)}%, bar 1.5%)`);
  figures[`${name}/sunlit_error`] = worst;
  lit.push({ seen, expected });
}
const ratioSeen = [0, 1, 2].map((k) => lit[1].seen[k] / lit[0].seen[k]);
const ratioExpected = [0, 1, 2].map((k) => lit[1].expected[k] / lit[0].expected[k]);
const ratioError = Math.max(...[0, 1, 2].map((k) => Math.abs(ratioSeen[k] / ratioExpected[k] - 1)));
check(ratioExpected[1] < 0.7, `the cloud frame is darker: predicted ratio ${ratioExpected.map((x) => x.toFixed(3)).join(' ')}`);
check(ratioError < 0.015, `the sunlit side darkens by ${ratioSeen.map((x) => x.toFixed(3)).join(' ')} under the cloud, the estimates by ` +
      `${ratioExpected.map((x) => x.toFixed(3)).join(' ')} (worst ${(100 * ratioError).toFixed(2)}%, bar 1.5%)`);
figures.darkening_error = ratioError;
writeFileSync(join(work, 'viewer_figures.json'), JSON.stringify(figures, null, 1));
process.exit(failures === 0 ? 0 : 1);
