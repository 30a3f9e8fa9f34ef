#!/usr/bin/env bash
# The viewer's page in a real browser: tests/browser/view.mjs drives Debian's
# Chromium through the npm package playwright-core (installed by `make test`
# into the build folder's browser/node_modules) against `paprsek view` on the
# built-in Cornell box: first frame, orbit, exposure, focus, save, SIGTERM;
# then again with --bind on this machine's network address (with a token).
# Skipped (77) where Chromium, Node.js or playwright-core is missing.
# usage: test_view_browser.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
script=$here/../browser/view.mjs
# PAPRSEK_BROWSER_MODULES: another node_modules holding playwright-core
modules=${PAPRSEK_BROWSER_MODULES:-$(dirname "$bin")/browser/node_modules}
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
chromium=${PAPRSEK_CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || { echo "SKIP: $chromium is not there (Debian package chromium; make test installs it)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node is not there (Debian package nodejs)"; exit 77; }
[ -f "$modules/playwright-core/package.json" ] || {
  echo "SKIP: $modules/playwright-core is not there (make test installs it: npm ci --prefix $(dirname "$modules"))"
  exit 77
}
"$bin" view --help >/dev/null 2>&1 || { echo "FAIL: $bin view --help failed"; exit 1; }
timeout 180 node "$script" "$bin" "$modules" || exit 1
# again on an address other than loopback, where every request needs the
# token of the printed address: the page must pass it on (images, updates,
# picks, downloads)
addr=$(hostname -I 2>/dev/null | tr ' ' '\n' | grep -E '^[0-9]+(\.[0-9]+){3}$' | grep -v '^127\.' | head -n 1)
if [ -z "$addr" ]; then
  echo "the run with a token is skipped: this machine has no IPv4 address but loopback"
  exit 0
fi
echo "--- with --bind $addr (a token on every request)"
timeout 180 node "$script" "$bin" "$modules" '' -- --bind "$addr" || exit 1
