#!/usr/bin/env bash
# viewer.sh - the README's screenshot of `paprsek view`, docs/viewer.png: the
# page at 1280x800 in headless Chromium, showing the built-in Cornell box at
# 912x684 (the size the page shows it at, so the image is not scaled), the
# camera turned by a drag, once SPP samples per pixel are in (the render
# stops there; the raw image, not denoised).
#
# usage: bash docs/viewer.sh [PAPRSEK [SPP]]   (defaults: build/paprsek, 64)
# needs: Debian's chromium, and playwright-core in the build folder's
#   browser/node_modules (make test puts it there)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
bin=${1:-$repo/build/paprsek}
spp=${2:-64}
modules=$(dirname "$bin")/browser/node_modules
[ -x "$bin" ] || { echo "viewer.sh: $bin is not there: build first (make build)" >&2; exit 1; }
[ -x /usr/bin/chromium ] || { echo "viewer.sh: /usr/bin/chromium is not there (apt-get install chromium)" >&2; exit 1; }
[ -d "$modules/playwright-core" ] || {
  echo "viewer.sh: $modules/playwright-core is not there (npm ci --prefix $(dirname "$modules") after copying tests/browser/package*.json there)" >&2
  exit 1
}
node --input-type=module - "$bin" "$modules" "$spp" "$here/viewer.png" <<'EOF_JS'
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import path from 'node:path';
const [bin, modules, spp, out] = process.argv.slice(2);
const { chromium } = createRequire(path.join(path.resolve(modules), 'index.js'))('playwright-core');
const sleep = (t) => new Promise((r) => setTimeout(r, t));
const server = spawn(bin, ['view', '--port', '0', '--no-open', '--width', '912', '--height', '684', '--spp', spp],
  { stdio: ['ignore', 'pipe', 'inherit'] });
let printed = '';
server.stdout.on('data', (d) => { printed += d; });
let url = null;
for (let i = 0; i < 600 && !url; i++) {
  url = (/http:\/\/\S+/.exec(printed) || [null])[0];
  await sleep(50);
}
if (!url) { server.kill(); throw new Error('paprsek view printed no address'); }
const api = async (p, body) => {
  const r = await fetch(new URL(p, url), body && { method: 'POST', body: JSON.stringify(body),
    headers: { 'Content-Type': 'application/json' } });
  if (!r.ok) throw new Error(`${p}: ${r.status} ${await r.text()}`);
  return r.json();
};
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', headless: true, args: ['--no-sandbox'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(url);
  await page.waitForSelector('#view[data-frame]');
  // turn the camera with a drag
  const view = page.locator('#view');
  const box = await view.boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  for (let i = 1; i <= 10; i++) await page.mouse.move(box.x + box.width / 2 + 6 * i, box.y + box.height / 2 + i);
  await page.mouse.up();
  await sleep(500);
  for (;;) {
    const s = await api('/api/status');
    const shown = await view.evaluate((e) => Number(e.dataset.frame));
    if (s.spp >= Number(spp) && shown >= s.frame) break;
    await sleep(250);
  }
  await page.mouse.move(1, 1);
  await page.screenshot({ path: out });
  console.log(`wrote ${out}`);
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
EOF_JS
