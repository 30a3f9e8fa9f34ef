#!/usr/bin/env bash
# The command line: --opt=value is --opt value, near-misses get "did you
# mean", `help render` is `render --help`, -v/--version, --stats-json -
# writes to stdout, and every integer render option is accepted at the ends
# of its range and refused (exit 2) one beyond them.
# usage: test_options.sh PAPRSEK SHARED_DIR DATA_DIR
set -u
bin=$1
data=$3
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }
ok() { echo "ok   $*"; }

# run ARGS...: runs paprsek, sets $rc, $out (stdout) and $err (stderr).
run() {
  timeout 120 "$bin" "$@" >"$tmp/stdout" 2>"$tmp/stderr" </dev/null
  rc=$?
  out=$(cat "$tmp/stdout")
  err=$(cat "$tmp/stderr")
}

printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$tmp/tri.obj"

# ---- --opt=value and --opt value give the same image
run render -o "$tmp/a.png" --width 24 --height 16 --spp 2 --light-samples 4 --max-depth 3 --threads 2 \
  --accel midpoint --fresnel off --look-from 0,1,3.9 --look-at 0,1,0 --up 0,1,0 --fov 40 --quiet
[ $rc -eq 0 ] || bad "--opt value: exit $rc: $err"
run render --output="$tmp/b.png" --width=24 --height=16 --spp=2 --light-samples=4 --max-depth=3 --threads=2 \
  --accel=midpoint --fresnel=off --look-from=0,1,3.9 --look-at=0,1,0 --up=0,1,0 --fov=40 --quiet
[ $rc -eq 0 ] || bad "--opt=value: exit $rc: $err"
if cmp -s "$tmp/a.png" "$tmp/b.png"; then ok "--opt=value and --opt value: the same image"; else bad "--opt=value: the images differ"; fi
# a unique beginning of a name is the option (getopt_long)
run render -o "$tmp/c.png" --wid 24 --hei=16 --spp 2 --light-s 4 --max 3 --thr 2 --acc midpoint --fres off \
  --look-f 0,1,3.9 --look-a 0,1,0 --fov 40 -q
if [ $rc -eq 0 ] && cmp -s "$tmp/a.png" "$tmp/c.png"; then ok "abbreviated names: the same image"; else bad "abbreviations: exit $rc: $err"; fi
# the scene may come after the options
run render -o "$tmp/d.png" --width=8 --height=8 --quiet "$tmp/tri.obj"
[ $rc -eq 0 ] && [ -s "$tmp/d.png" ] && ok "scene after the options" || bad "scene after the options: exit $rc: $err"

# ---- near-misses and other usage errors: exit 2, one line
# usage_error NAME MESSAGE ARGS...
usage_error() {
  local name=$1 want="paprsek: $2"
  shift 2
  run "$@"
  if [ $rc -ne 2 ]; then bad "$name: exit $rc, wanted 2; stderr: $err"
  elif [ "$err" != "$want" ]; then bad "$name: stderr is '$err', wanted '$want'"
  else ok "$name: $err"; fi
}
usage_error "near-miss option" "render: unknown option '--spq'; did you mean --spp?" render -o "$tmp/x.png" --spq 4
usage_error "swapped letters" "render: unknown option '--hieght'; did you mean --height?" render -o "$tmp/x.png" --hieght=4
usage_error "underscore for dash" "render: unknown option '--light_samples'; did you mean --light-samples?" \
  render -o "$tmp/x.png" --light_samples 4
usage_error "one dash for two" "render: unknown option '-spp'; did you mean --spp?" render -o "$tmp/x.png" -spp 4
usage_error "nothing near" "render: unknown option '--bogus' (see paprsek render --help)" render -o "$tmp/x.png" --bogus
usage_error "ambiguous beginning" "render: option '--look' is ambiguous: --look-from, --look-at" \
  render -o "$tmp/x.png" --look 1,2,3
usage_error "value for a flag" "--stats takes no value" render -o "$tmp/x.png" --stats=yes
usage_error "missing value at the end" "--spp needs a value" render -o "$tmp/x.png" --spp
usage_error "bad value after =" "--width: 'wide' is not a whole number in 1..16384" render -o "$tmp/x.png" --width=wide
usage_error "near-miss command" "unknown command 'rendr'; did you mean render?" rendr -o "$tmp/x.png"
usage_error "near-miss bench option" "bench rays: unknown option '--rpes'; did you mean --reps?" \
  bench rays "$tmp/tri.obj" "$tmp/x.rays" --rpes=2
usage_error "near-miss bench subcommand" "bench gen-ray: unknown subcommand; did you mean bench gen-rays?" \
  bench gen-ray
ls "$tmp"/x.* >/dev/null 2>&1 && bad "a usage error wrote a file: $(ls "$tmp"/x.*)"

# ---- help
run help render
help_out=$out
if [ $rc -eq 0 ] && [ "${help_out#usage: paprsek render}" != "$help_out" ]; then
  ok "help render prints the render options"
else
  bad "help render: exit $rc, output starts '${out:0:40}'"
fi
run render --help
[ $rc -eq 0 ] && [ "$out" = "$help_out" ] && ok "render --help is help render" || bad "render --help differs from help render"
run render -h
[ $rc -eq 0 ] && [ "$out" = "$help_out" ] || bad "render -h differs from help render"
for word in "exit status" "130" "143" "--stats-json FILE" "--quiet"; do
  grep -qF -- "$word" "$tmp/stdout" || bad "render --help does not mention '$word'"
done
run help bench
bench_help=$out
run bench --help
[ $rc -eq 0 ] && [ "$out" = "$bench_help" ] && [ -n "$out" ] && ok "help bench is bench --help" || bad "help bench"
run help
[ $rc -eq 0 ] && grep -q "exit status" "$tmp/stdout" && ok "help: with the exit statuses" || bad "help: exit $rc"
# texts speak to users, not to the project's history
run render --help
# ("seed" is a word of the path tracer's --seed; "the seed's" was the project's history)
grep -qiE "the seed'?s?\b" "$tmp/stdout" && bad "render --help speaks of the seed: $(grep -iE "the seed'?s?\b" "$tmp/stdout")"

# ---- version
header=$(dirname "$data")/../include/paprsek.h
version=$(sed -n 's/^#define PK_VERSION_STRING "\(.*\)"/\1/p' "$header" 2>/dev/null)
[ -n "$version" ] || version='[0-9]+\.[0-9]+\.[0-9]+'
for flag in -v --version; do
  run $flag
  if [ $rc -eq 0 ] && echo "$out" | grep -Eqx "paprsek $version"; then ok "$flag: $out"; else bad "$flag: exit $rc, '$out'"; fi
done

# ---- --stats-json - writes the JSON to stdout, and nothing else
run render -o "$tmp/s.png" --width 8 --height 8 --stats-json -
if [ $rc -ne 0 ]; then
  bad "--stats-json -: exit $rc: $err"
elif [ "${out:0:1}" != "{" ] || [ "${out: -1}" != "}" ] || ! echo "$out" | grep -q '"rays": [0-9]'; then
  bad "--stats-json -: stdout is not the JSON: $out"
elif [ -e ./- ] || [ -e "$tmp/-" ]; then
  bad "--stats-json -: a file named - was written"
else
  if command -v python3 >/dev/null; then
    echo "$out" | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d["width"] == 8' ||
      bad "--stats-json -: python cannot read the JSON"
  fi
  ok "--stats-json - writes the JSON to stdout"
fi
run render -o "$tmp/s.png" --width 8 --height 8 --stats-json=- --stats
[ $rc -eq 2 ] && ok "--stats-json - with --stats is refused: $err" || bad "--stats-json - --stats: exit $rc"

# ---- the integer options: the library's table (include/paprsek.h PK_MAX_*)
# name min max default
table="width 1 16384 512
height 1 16384 512
spp 1 65536 1
light-samples 0 4096 32
max-depth -1 1024 -1
threads 0 1024 0"
run render --help
flat=$(tr -s ' \n' '  ' <"$tmp/stdout")
while read -r name min max def; do
  echo "$flat" | grep -qF -- "--$name N " && echo "$flat" | grep -qF -- "$min..$max, default $def" ||
    bad "--help does not give --$name N with $min..$max, default $def"
  rm -f "$tmp/r.png"
  for v in $((min - 1)) $((max + 1)); do
    run render -o "$tmp/r.png" --width 2 --height 2 "--$name" "$v"
    want="paprsek: --$name: '$v' is not a whole number in $min..$max"
    if [ $rc -ne 2 ] || [ "$err" != "$want" ]; then bad "--$name $v: exit $rc, '$err'"; fi
    run render -o "$tmp/r.png" --width 2 --height 2 "--$name=$v"
    [ $rc -eq 2 ] || bad "--$name=$v: exit $rc"
  done
  [ -e "$tmp/r.png" ] && bad "--$name: an image was written for a refused value"
  for v in $min $max; do
    # cheap renders at the bounds: one pixel (or one row), no area-light samples
    args=(--width 1 --height 1 --light-samples 0 --max-depth 1)
    [ "$name" = width ] && args=(--height 1 --light-samples 0 --max-depth 1)
    [ "$name" = height ] && args=(--width 1 --light-samples 0 --max-depth 1)
    rm -f "$tmp/r.png"
    run render -o "$tmp/r.png" "${args[@]}" "--$name" "$v" --quiet
    if [ $rc -ne 0 ] || [ ! -s "$tmp/r.png" ]; then bad "--$name $v (a bound): exit $rc, '$err'"; fi
  done
  [ $fail -eq 0 ] && ok "--$name: $min and $max accepted, $((min - 1)) and $((max + 1)) refused"
done <<<"$table"
# ---- one side given: the other follows the scene file's aspect ratio
printf '{"render": {"width": 200, "height": 100, "spp": 1}, "meshes": [{"obj": "tri.obj"}]}' >"$tmp/wide.json"
size_of() { sed -n 's/^settings [^,]*, [0-9]* threads\{0,1\}, \([0-9]*x[0-9]*\),.*/\1/p' "$tmp/stdout"; }
run render -o "$tmp/w.png" --width 50 --quiet --stats "$tmp/wide.json"
[ $rc -eq 0 ] && [ "$(size_of)" = 50x25 ] && ok "--width alone keeps the scene's 2:1" || bad "--width 50 of a 200x100 scene: $(size_of), $err"
run render -o "$tmp/w.png" --height 20 --quiet --stats "$tmp/wide.json"
[ $rc -eq 0 ] && [ "$(size_of)" = 40x20 ] && ok "--height alone keeps the scene's 2:1" || bad "--height 20 of a 200x100 scene: $(size_of), $err"
run render -o "$tmp/w.png" --width 30 --height 30 --quiet --stats "$tmp/wide.json"
[ $rc -eq 0 ] && [ "$(size_of)" = 30x30 ] && ok "both sides given: as given" || bad "--width 30 --height 30: $(size_of), $err"
run render -o "$tmp/w.png" --width 30 --quiet --stats "$tmp/tri.obj"
[ $rc -eq 0 ] && [ "$(size_of)" = 30x512 ] && ok "a scene without a size: the default height" || bad "--width 30 of an OBJ: $(size_of), $err"

run render -o "$tmp/t.png" --width 8 --height 8 --threads 0 --stats
threads=$(sed -n 's/^settings .*, \([0-9]*\) threads\{0,1\},.*/\1/p' "$tmp/stdout")
[ $rc -eq 0 ] && [ "${threads:-0}" -ge 1 ] && ok "--threads 0: all cores ($threads)" || bad "--threads 0: exit $rc, $err"

# ---- bench: --opt=value there too
run bench gen-rays "$tmp/tri.obj" --look-from 0.2,0.2,3 --look-at 0.2,0.2,0 --fov 40 --size 8 -o "$tmp/a.rays"
[ $rc -eq 0 ] || bad "bench gen-rays: exit $rc: $err"
run bench gen-rays "$tmp/tri.obj" --look-from=0.2,0.2,3 --look-at=0.2,0.2,0 --fov=40 --size=8 --output="$tmp/b.rays"
[ $rc -eq 0 ] && cmp -s "$tmp/a.rays" "$tmp/b.rays" && ok "bench gen-rays --opt=value" || bad "bench gen-rays --opt=value: $rc $err"
run bench rays "$tmp/tri.obj" "$tmp/a.rays" --accel bvh --threads 1 --reps 1 --hits "$tmp/a.hits"
[ $rc -eq 0 ] || bad "bench rays: exit $rc: $err"
run bench rays "$tmp/tri.obj" "$tmp/a.rays" --accel=bvh --threads=1 --reps=1 --hits="$tmp/b.hits"
[ $rc -eq 0 ] && cmp -s "$tmp/a.hits" "$tmp/b.hits" && ok "bench rays --opt=value" || bad "bench rays --opt=value: $rc $err"
run bench compare "$tmp/a.hits" "$tmp/b.hits" --rays="$tmp/a.rays"
[ $rc -eq 0 ] && ok "bench compare --rays=FILE" || bad "bench compare --rays=FILE: $rc $err"
run bench rays "$tmp/tri.obj" "$tmp/a.rays" --threads=1025
[ $rc -eq 2 ] && [ "$err" = "paprsek: --threads: '1025' is not a whole number in 0..1024" ] ||
  bad "bench rays --threads=1025: exit $rc, $err"

exit $fail
