// The page of `paprsek view` in a real browser (Chromium, headless, driven by
// playwright-core): it starts the viewer on a free port with the built-in
// Cornell box, opens the printed address, waits for the first frame, orbits
// the camera with a drag and waits for a different image, changes the
// exposure and waits for a brighter image, focuses with a ctrl-click, saves a
// PNG, and stops the server with SIGTERM (exit status 0 within 2 s). Any
// error in the page fails the test. Timings go to standard output.
//
// usage: node view.mjs PAPRSEK NODE_MODULES_DIR [SCREENSHOT_DIR] [-- VIEW_OPTIONS...]
//   NODE_MODULES_DIR holds playwright-core; SCREENSHOT_DIR (or ''), when
//   given, gets the page's screenshots (first.png, orbit.png, exposure.png);
//   VIEW_OPTIONS go to paprsek view after its own (e.g. --bind ADDR, which
//   makes the page work with a token).
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

const argv = process.argv.slice(2);
const dash = argv.indexOf('--');
const extra = dash >= 0 ? argv.splice(dash).slice(1) : [];
const [bin, modules, shots] = argv;
if (!bin || !modules) {
  console.error('usage: node view.mjs PAPRSEK NODE_MODULES_DIR [SCREENSHOT_DIR] [-- VIEW_OPTIONS...]');
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(modules), 'index.js'));
const { chromium } = require('playwright-core');

const t0 = performance.now();
const ms = (t) => `${Math.round(performance.now() - t)} ms`;
let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures++;
  return ok;
}
class Fatal extends Error {}
function fatal(what) {
  check(false, what);
  throw new Fatal(what);
}
const sleep = (t) => new Promise((r) => setTimeout(r, t));

// poll(fn, timeout): fn's first truthy result, or null after timeout ms
async function poll(fn, timeout, every = 20) {
  const end = performance.now() + timeout;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (performance.now() > end) return null;
    await sleep(every);
  }
}

// ---- the server ----
const args = ['view', '--port', '0', '--no-open', '--width', '320', '--height', '240', ...extra];
const server = spawn(bin, args, { stdio: ['ignore', 'pipe', 'pipe'] });
let serverOut = '';
let exited = null;
const exitPromise = new Promise((resolve) => {
  server.on('exit', (code, signal) => { exited = { code, signal, at: performance.now() }; resolve(exited); });
});
server.stdout.on('data', (d) => { serverOut += d; });
server.stderr.on('data', (d) => { serverOut += d; });

let browser = null;
let baseUrl = null;
async function api(p) {
  const u = new URL(p, baseUrl);
  const token = new URL(baseUrl).searchParams.get('token');
  if (token) u.searchParams.set('token', token);
  const r = await fetch(u);
  if (!r.ok) throw new Error(`${p}: ${r.status} ${await r.text()}`);
  return r.json();
}

async function main() {
  const found = await poll(() => exited || /http:\/\/\S+/.exec(serverOut), 30000);
  if (!found || exited) fatal(`paprsek ${args.join(' ')} printed no address:\n${serverOut}`);
  baseUrl = found[0];
  const bound = extra.includes('--bind') ? extra[extra.indexOf('--bind') + 1] : '127.0.0.1';
  check(baseUrl.startsWith(`http://${bound}:`), `the address printed: ${baseUrl} (${ms(t0)})`);
  if (!bound.startsWith('127.')) check(/[?&]token=[^&]+/.test(baseUrl), 'away from loopback the address carries a token');

  browser = await chromium.launch({
    executablePath: process.env.PAPRSEK_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox'],
  });
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(`console: ${m.text()}`); });

  // stats(): mean and variance of the luminance of a screenshot of the image,
  // and a 16x16 thumbnail of it to compare images by
  const view = page.locator('#view');
  async function stats(name) {
    const png = await view.screenshot();
    if (shots) fs.writeFileSync(path.join(shots, name), await page.screenshot());
    return page.evaluate(async (b64) => {
      const im = new Image();
      im.src = 'data:image/png;base64,' + b64;
      await im.decode();
      const c = document.createElement('canvas');
      c.width = im.width;
      c.height = im.height;
      const g = c.getContext('2d');
      g.drawImage(im, 0, 0);
      const d = g.getImageData(0, 0, c.width, c.height).data;
      let s = 0, s2 = 0;
      const n = d.length / 4;
      for (let i = 0; i < d.length; i += 4) {
        const y = 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2];
        s += y;
        s2 += y * y;
      }
      const t = document.createElement('canvas');
      t.width = t.height = 16;
      const tg = t.getContext('2d');
      tg.drawImage(im, 0, 0, 16, 16);
      const thumb = Array.from(tg.getImageData(0, 0, 16, 16).data);
      return { mean: s / n, variance: s2 / n - (s / n) ** 2, thumb };
    }, png.toString('base64'));
  }
  const diff = (a, b) => a.thumb.reduce((s, v, i) => s + Math.abs(v - b.thumb[i]), 0) / a.thumb.length;
  const shownFrame = () => view.evaluate((e) => Number(e.dataset.frame ?? -1));

  // ---- the first frame ----
  let t = performance.now();
  await page.goto(baseUrl);
  check(await page.title() === 'Paprsek view', `the page loads (${ms(t)})`);
  const first = await poll(async () => (await shownFrame()) >= 0, 30000);
  if (!first) fatal('no frame shown within 30 s');
  console.log(`     the first frame is shown ${ms(t)} after the page was opened`);
  // let a few passes land so that the image is more than noise
  await poll(async () => (await api('/api/status')).spp >= 2, 10000);
  await sleep(300);
  const before = await stats('first.png');
  check(before.variance > 20, `the image is not blank (luminance mean ${before.mean.toFixed(1)}, variance ${before.variance.toFixed(1)})`);
  const s0 = await api('/api/status');
  check(s0.width === 320 && s0.height === 240, `the status says 320x240 (${s0.width}x${s0.height})`);
  const spp = Number(await page.locator('#spp').textContent());
  check(spp >= 1, `the page shows the samples per pixel (${spp})`);
  const opts = await page.locator('#opts').textContent();
  check(opts.includes('--look-from ' + s0.camera.look_from.map((x) => String(Number(x.toPrecision(6)))).join(',')),
    `the camera as options: ${opts}`);

  // ---- orbit ----
  const box = await view.boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const frameBefore = await shownFrame();
  t = performance.now();
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  for (let i = 1; i <= 10; i++) await page.mouse.move(cx + 12 * i, cy + 3 * i);
  await page.mouse.up();
  const tUp = performance.now();
  const moved = await poll(async () => {
    const s = await api('/api/status');
    return s.camera.look_from.some((v, i) => Math.abs(v - s0.camera.look_from[i]) > 1e-3 * (1 + Math.abs(v))) && s;
  }, 5000);
  if (!check(moved, 'the drag moved the camera (look_from changed on the server)')) return;
  const dist0 = Math.hypot(...s0.camera.look_from.map((v, i) => v - s0.camera.look_at[i]));
  const dist1 = Math.hypot(...moved.camera.look_from.map((v, i) => v - moved.camera.look_at[i]));
  check(Math.abs(dist1 - dist0) < 1e-3 * dist0 && moved.camera.look_at.every((v, i) => Math.abs(v - s0.camera.look_at[i]) < 1e-4 * (1 + Math.abs(v))),
    `an orbit: look_at kept, distance kept (${dist0.toPrecision(6)} -> ${dist1.toPrecision(6)})`);
  const newFrame = await poll(async () => (await shownFrame()) > frameBefore, 10000);
  check(newFrame, `a new frame is shown after the drag (${ms(tUp)} after the button was released, ${ms(t)} after the drag began)`);
  // wait for the server to settle on the final camera and show a frame of it
  const settled = await poll(async () => {
    const s = await api('/api/status');
    return s.spp >= 2 && (await shownFrame()) >= s.frame && s;
  }, 10000);
  if (!check(settled, 'the server renders the new view')) return;
  const orbited = await stats('orbit.png');
  check(orbited.variance > 20, `the image after the orbit is not blank (variance ${orbited.variance.toFixed(1)})`);
  check(diff(before, orbited) > 2, `the image after the orbit differs (mean absolute difference of 16x16 thumbnails ${diff(before, orbited).toFixed(2)})`);

  // ---- exposure: +2 EV with the keyboard ----
  const exposure = page.locator('#exposure');
  await exposure.focus();
  t = performance.now();
  for (let i = 0; i < 20; i++) await exposure.press('ArrowRight');
  const tKeys = performance.now();
  const exposed = await poll(async () => {
    const s = await api('/api/status');
    return Math.abs(s.settings.exposure - 2) < 1e-6 && s;
  }, 5000);
  if (!check(exposed, `the exposure reached the server (${exposed ? exposed.settings.exposure : 'no'})`)) return;
  check(exposed.camera.look_from.every((v, i) => v === settled.camera.look_from[i]), 'the exposure left the camera alone');
  const exposedShown = await poll(async () => (await shownFrame()) >= exposed.frame, 10000);
  check(exposedShown, `a frame with the new exposure is shown (${ms(tKeys)} after the last of 20 key presses, ${ms(t)} after the first)`);
  await sleep(100);
  const bright = await stats('exposure.png');
  check(bright.mean > orbited.mean + 10, `+2 EV is brighter (mean luminance ${orbited.mean.toFixed(1)} -> ${bright.mean.toFixed(1)})`);
  check((await page.locator('#exposure-out').textContent()).includes('+2'), 'the page shows +2 EV');

  // ---- focus: ctrl-click the middle of the image ----
  const px = Math.floor(s0.width / 2), py = Math.floor(s0.height / 2);
  const pick = await api(`/api/pick?x=${px}&y=${py}`);
  check(pick.hit && pick.distance > 0, `something is under the middle of the image (distance ${pick.distance})`);
  await page.keyboard.down('Control');
  await page.mouse.click(box.x + (px + 0.5) * box.width / s0.width, box.y + (py + 0.5) * box.height / s0.height);
  await page.keyboard.up('Control');
  const focused = await poll(async () => {
    const s = await api('/api/status');
    return s.camera.focus_distance > 0 && s;
  }, 5000);
  check(focused && Math.abs(focused.camera.focus_distance - pick.distance) <= 1e-4 * pick.distance,
    `a ctrl-click sets the focus distance to the pick's (${focused ? focused.camera.focus_distance : 'unchanged'}, pick ${pick.distance})`);
  check(focused && focused.camera.look_from.every((v, i) => v === settled.camera.look_from[i]), 'the ctrl-click did not move the camera');
  // the focus restarted the render: save once full passes are in again
  await poll(async () => {
    const s = await api('/api/status');
    return s.spp >= 2 && (await shownFrame()) >= s.frame;
  }, 10000);

  // ---- save a PNG ----
  t = performance.now();
  const [download] = await Promise.all([page.waitForEvent('download'), page.locator('#save-png').click()]);
  const file = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'paprsek-view-')), 'saved.png');
  await download.saveAs(file);
  const bytes = fs.readFileSync(file);
  check(download.suggestedFilename() === 'paprsek.png', `the download is named ${download.suggestedFilename()}`);
  check(bytes.length > 33 && bytes.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a])) &&
    bytes.readUInt32BE(16) === s0.width && bytes.readUInt32BE(20) === s0.height,
  `"Save PNG" downloads a ${s0.width}x${s0.height} PNG (${bytes.length} bytes, ${ms(t)})`);
  fs.rmSync(path.dirname(file), { recursive: true, force: true });

  check(pageErrors.length === 0, `no errors in the page${pageErrors.length ? ':\n  ' + pageErrors.join('\n  ') : ''}`);
}

let crashed = null;
try {
  await main();
} catch (e) {
  crashed = e;
}
if (browser) await browser.close().catch(() => {});
if (crashed && !(crashed instanceof Fatal)) check(false, `the test stopped: ${crashed.stack || crashed}`);
if (!exited) {
  const t = performance.now();
  server.kill('SIGTERM');
  const done = await Promise.race([exitPromise, sleep(5000).then(() => null)]);
  if (!done) {
    server.kill('SIGKILL');
    check(false, 'the server did not exit within 5 s of SIGTERM');
  } else {
    check(done.code === 0 && done.at - t < 2000, `SIGTERM: the server exits with status ${done.code ?? done.signal} after ${Math.round(done.at - t)} ms`);
  }
} else {
  check(false, `the server exited early (${exited.code ?? exited.signal}):\n${serverOut}`);
}
if (failures) console.log(`server output:\n${serverOut}`);
console.log(`${failures ? 'FAILED' : 'passed'}: ${failures} failure(s), ${ms(t0)} in all`);
process.exit(failures ? 1 : 0);
