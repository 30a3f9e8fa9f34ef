#!/usr/bin/env bash
# bench/view.sh [PAPRSEK] [ROUNDS] - how `paprsek view` responds (docs/viewer.md), on the
# built-in Cornell box at 640x360 with 2 threads:
#   1. the time from POST /api/camera to the first frame of the new camera (its event on the
#      stream, then the PNG downloaded), while a full-size pass is being rendered (the pass
#      is cancelled), and
#      while the server has nothing to do (the cheap first pass alone): median and 90th
#      percentile of ROUNDS changes (default 40) each;
#   2. the cancel latency, the difference of the two medians, next to the time of one
#      full pass and of one tile of work (a pass over the tiles, per thread);
#   3. the server's own CPU use over 10 s with no client once the image is finished
#      (utime + stime of /proc/PID/stat).
# Run it on an otherwise idle machine.
set -euo pipefail
PAPRSEK=${1:-build/paprsek}
ROUNDS=${2:-40}
[ -x "$PAPRSEK" ] || { echo "no program at $PAPRSEK (build first, or name it)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "python3 is needed" >&2; exit 1; }
W=640 H=360 THREADS=2

out=$(mktemp)
pid=
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null; rm -f "$out"; }
trap cleanup EXIT

start() { # start SPP: the server in the background; sets pid and url
  "$PAPRSEK" view --width $W --height $H --threads $THREADS --spp "$1" --no-open --quiet >"$out" 2>&1 &
  pid=$!
  for _ in $(seq 100); do grep -q '^paprsek view: http' "$out" && break; sleep 0.1; done
  url=$(sed -n 's/^paprsek view: \(http[^ ]*\).*/\1/p' "$out" | head -n 1)
  [ -n "$url" ] || { echo "the server did not start:" >&2; cat "$out" >&2; exit 1; }
}
stop() { kill "$pid"; wait "$pid" 2>/dev/null || true; pid=; }

echo "paprsek view, Cornell box, ${W}x${H}, $THREADS threads, $(nproc) CPUs ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'))"
start 65536
python3 - "$url" "$ROUNDS" <<'EOF'
import http.client, json, statistics, sys, time, urllib.parse

url, rounds = sys.argv[1], int(sys.argv[2])
u = urllib.parse.urlparse(url)
host, port = u.hostname, u.port

def post(path, body):
    c = http.client.HTTPConnection(host, port, timeout=10)
    c.request("POST", path, json.dumps(body), {"Content-Type": "application/json"})
    r = c.getresponse(); data = r.read(); c.close()
    assert r.status == 200, (r.status, data)
    return json.loads(data)

def png():
    c = http.client.HTTPConnection(host, port, timeout=10)
    c.request("GET", "/api/frame.png"); r = c.getresponse(); d = r.read(); c.close()
    assert r.status == 200 and d[:4] == b"\x89PNG"

def status():
    c = http.client.HTTPConnection(host, port, timeout=10)
    c.request("GET", "/api/status"); r = c.getresponse(); d = json.loads(r.read()); c.close()
    return d

ev = http.client.HTTPConnection(host, port, timeout=30)
ev.request("GET", "/api/events")
stream = ev.getresponse()

def next_event():
    data = None
    while True:
        line = stream.fp.readline().decode()
        if line.startswith("data: "): data = json.loads(line[6:])
        elif line == "\n" and data is not None: return data

def wait_camera(look_from):
    while True:
        e = next_event()
        if [round(v, 4) for v in e["camera"]["look_from"]] == look_from: return e

first = status()
base = first["camera"]["look_from"]

def rounds_of(busy):
    lat = []
    for i in range(rounds):
        if busy:
            time.sleep(0.15)  # a full-size pass is under way
        else:
            while status()["rendering"]: time.sleep(0.02)
        lf = [round(base[0] + 0.02 * ((i % 7) - 3), 4), base[1], base[2]]
        t0 = time.perf_counter()
        post("/api/camera", {"look_from": lf})
        wait_camera(lf)
        png()
        lat.append(time.perf_counter() - t0)
    lat.sort()
    return statistics.median(lat), lat[int(0.9 * (len(lat) - 1))]

busy_med, busy_p90 = rounds_of(True)
# passes: how long one full pass takes, once the first frames are out
post("/api/camera", {"reset": True})
time.sleep(0.5); s0 = status(); time.sleep(3); s1 = status()
pass_s = (s1["elapsed_s"] - s0["elapsed_s"]) / max(1, s1["passes"] - s0["passes"])
print(f"camera change -> first new frame, rendering: median {busy_med*1e3:.1f} ms, p90 {busy_p90*1e3:.1f} ms ({rounds} changes)")
print(f"one full pass (1 spp at 640x360): {pass_s*1e3:.1f} ms; one tile of work (16x16 pixels, per thread): "
      f"{pass_s / ((640 // 16) * ((360 + 15) // 16)) * 2 * 1e3:.2f} ms")
open("/tmp/paprsek-view-bench.json", "w").write(json.dumps({"busy_med": busy_med, "pass_s": pass_s}))
EOF
stop
# idle rounds: a server whose image is finished (4 spp) between changes
start 4
python3 - "$url" "$ROUNDS" <<'EOF'
import http.client, json, statistics, sys, time, urllib.parse
url, rounds = sys.argv[1], int(sys.argv[2])
u = urllib.parse.urlparse(url); host, port = u.hostname, u.port
def req(m, p, b=None):
    c = http.client.HTTPConnection(host, port, timeout=10)
    c.request(m, p, json.dumps(b) if b is not None else None, {"Content-Type": "application/json"} if b is not None else {})
    r = c.getresponse(); d = json.loads(r.read()); c.close(); return d
ev = http.client.HTTPConnection(host, port, timeout=30); ev.request("GET", "/api/events"); stream = ev.getresponse()
def next_event():
    data = None
    while True:
        line = stream.fp.readline().decode()
        if line.startswith("data: "): data = json.loads(line[6:])
        elif line == "\n" and data is not None: return data
base = req("GET", "/api/status")["camera"]["look_from"]
lat = []
for i in range(rounds):
    while req("GET", "/api/status")["rendering"]: time.sleep(0.02)
    lf = [round(base[0] + 0.02 * ((i % 7) - 3), 4), base[1], base[2]]
    t0 = time.perf_counter()
    req("POST", "/api/camera", {"look_from": lf})
    while [round(v, 4) for v in next_event()["camera"]["look_from"]] != lf: pass
    c = http.client.HTTPConnection(host, port, timeout=10); c.request("GET", "/api/frame.png")
    r = c.getresponse(); assert r.status == 200 and r.read()[:4] == b"\x89PNG"; c.close()
    lat.append(time.perf_counter() - t0)
lat.sort()
med = statistics.median(lat)
prev = json.loads(open("/tmp/paprsek-view-bench.json").read())
print(f"camera change -> first new frame, idle: median {med*1e3:.1f} ms, p90 {lat[int(0.9*(len(lat)-1))]*1e3:.1f} ms")
print(f"cancel latency (rendering - idle medians): {(prev['busy_med'] - med)*1e3:.1f} ms")
EOF
rm -f /tmp/paprsek-view-bench.json
# idle CPU: no client, the image finished
for _ in $(seq 200); do
  python3 -c "import json,sys,urllib.request; sys.exit(0 if not json.load(urllib.request.urlopen('$url'.rstrip('/') + '/api/status'))['rendering'] else 1)" && break
  sleep 0.1
done
tick=$(getconf CLK_TCK)
cpu() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
c0=$(cpu); sleep 10; c1=$(cpu)
echo "idle server, no client, 10 s: $(( c1 - c0 )) ticks of CPU ($tick per second) = $(awk -v d=$(( c1 - c0 )) -v t="$tick" 'BEGIN{printf "%.2f", 100 * d / t / 10}') % of one core"
stop
