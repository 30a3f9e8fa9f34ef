#!/usr/bin/env bash
# same_images.sh - render every scene we have with two builds of paprsek and
# compare the images byte for byte (cmp). Used to show that a restructuring
# changes no image: both integrators, the AOVs, every shared scene that the
# program reads (OBJ, JSON, Mitsuba XML, pbrt-v4, glTF) and the scenes of
# tests/data (media under the volumetric path tracer too).
# Images are linear float PFM, so any change in any bit of any pixel shows.
#
# usage: bench/same_images.sh OLD_PAPRSEK NEW_PAPRSEK [SHARED_DIR]
# environment: OUT (images, default bench/out/same), SIZE (64), SPP (4),
# THREADS (2), INTEGRATORS ("path whitted"), EXTRA (more options, such as
# "--device cuda" on a machine with a GPU), OLD_CACHE (below)
# exit status: 0 every image is the same, 1 some differ or failed
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
old=${1:?usage: same_images.sh OLD_PAPRSEK NEW_PAPRSEK [SHARED_DIR]}
new=${2:?usage: same_images.sh OLD_PAPRSEK NEW_PAPRSEK [SHARED_DIR]}
shared=${3:-$repo/../shared}
out=${OUT:-$here/out/same}
size=${SIZE:-64}; spp=${SPP:-4}; threads=${THREADS:-2}
integrators=${INTEGRATORS:-path whitted}
extra=${EXTRA:-}
rm -rf "$out"; mkdir -p "$out/old" "$out/new"
# OLD_CACHE=DIR keeps the old build's renders there and reuses them while
# the old program is the same file (by its SHA-256), so that a series of
# comparisons against one base renders the base once.
cache=${OLD_CACHE:-}
if [ -n "$cache" ]; then
    mkdir -p "$cache"
    sum=$(sha256sum "$old" | cut -d' ' -f1)
    [ "$(cat "$cache/PROGRAM" 2>/dev/null)" = "$sum $size $spp $threads $extra" ] ||
        { rm -f "$cache"/*; echo "$sum $size $spp $threads $extra" >"$cache/PROGRAM"; }
fi

# name | scene ("-": the built-in Cornell box) | options | integrators beyond INTEGRATORS
cases() {
    local cam="--look-from 0,1,3.9 --look-at 0,1,0 --fov 39.3"
    echo "builtin|-|"
    echo "builtin-env|-|--env 0.2,0.3,0.4 --max-depth 5"
    echo "builtin-fresnel-off|-|--fresnel off --light-samples 3"
    echo "builtin-envmap|-|--env $repo/tests/data/tex_checker.png --max-depth 3"
    echo "materials-json|$here/scenes/materials.json|"
    echo "materials-xml|$here/scenes/materials.xml|"
    local d=$shared/scenes/cornell f
    if [ -d "$d" ]; then
        for f in "$d"/*.obj; do
            case $f in */water.obj) continue ;; esac
            echo "$(basename "$f" .obj)|$f|$cam"
        done
    fi
    [ -f "$shared/scenes/bench/stanford-bunny.obj" ] &&
        echo "bunny|$shared/scenes/bench/stanford-bunny.obj|"
    [ -f "$here/sponza-area-light.json" ] && [ -d "$shared/scenes/bench/dabrovic-sponza" ] &&
        echo "sponza-area-light|$here/sponza-area-light.json|" &&
        echo "sponza-light|$here/sponza-light.json|"
    for f in bitterli/cornell-box/scene_v3.xml \
             bitterli/veach-mis/scene.xml bitterli/classroom/scene_v0.6.xml \
             mitsuba/veach-door/scene.xml; do
        [ -f "$shared/scenes/$f" ] && echo "$(echo "$f" | tr '/' '_')|$shared/scenes/$f|"
    done
    for f in pbrt-v4/cornell-box/scene-v4.pbrt pbrt-v4/material-testball/scene-v4.pbrt; do
        [ -f "$shared/scenes/$f" ] && echo "$(echo "$f" | tr '/' '_')|$shared/scenes/$f|"
    done
    if [ -d "$shared/scenes/gltf" ]; then
        for f in "$shared"/scenes/gltf/*/*.gltf "$shared"/scenes/gltf/*/*.glb; do
            [ -f "$f" ] && echo "gltf_$(basename "$f")|$f|"
        done
    fi
    for f in conformance/box.gltf conformance/box.json conformance/box_mr.json conformance/box.obj \
             conformance/box_nomtl.obj conformance/box.pbrt conformance/box.xml \
             pbrt/plymesh.pbrt pbrt/include_main.pbrt gltf/instanced.gltf gltf/cube.glb \
             gltf/external.gltf; do
        [ -f "$repo/tests/data/$f" ] && echo "data_$(echo "$f" | tr '/' '_')|$repo/tests/data/$f|"
    done
    # participating media: the volumetric path tracer as well
    for f in media/fog.json media/fog.pbrt media/fog.xml; do
        [ -f "$repo/tests/data/$f" ] && echo "data_$(echo "$f" | tr '/' '_')|$repo/tests/data/$f||volpath"
    done
    for f in json_example.json tex_json.json fuzz_seed_full.json fuzz_seed_env.json \
             fuzz_seed_sphere.json fuzz_seed_objmaterials.json \
             fuzz_seed_full.xml tex_scene.obj \
             tex_quad.obj obj_mat.obj; do
        [ -f "$repo/tests/data/$f" ] && echo "data_$f|$repo/tests/data/$f|"
    done
}

render() { # bin dir name scene integrator options...
    local bin=$1 dir=$2 name=$3 scene=$4 integ=$5; shift 5
    local args=(render)
    [ "$scene" != - ] && args+=("$scene")
    # shellcheck disable=SC2086
    "$bin" "${args[@]}" -o "$dir/$name.$integ.pfm" --width "$size" --height "$size" \
        --spp "$spp" --threads "$threads" --integrator "$integ" \
        --aov albedo,normal,depth,heatmap -q "$@" $extra >"$dir/$name.$integ.log" 2>&1
    echo "exit $?" >>"$dir/$name.$integ.log"
}

n=0; bad=0
while IFS='|' read -r name scene opts more; do
    for integ in $integrators $more; do
        if [ -n "$cache" ] && [ -f "$cache/$name.$integ.log" ]; then
            cp "$cache/$name.$integ".* "$out/old/"
        else
            # shellcheck disable=SC2086
            render "$old" "$out/old" "$name" "$scene" "$integ" $opts
            [ -n "$cache" ] && cp "$out/old/$name.$integ".* "$cache/"
        fi
        # shellcheck disable=SC2086
        render "$new" "$out/new" "$name" "$scene" "$integ" $opts
        n=$((n + 1))
        if ! tail -n 1 "$out/old/$name.$integ.log" | grep -qx 'exit 0'; then
            echo "FAIL $name $integ: the old build failed ($(head -n 1 "$out/old/$name.$integ.log"))"
            bad=$((bad + 1)); continue
        fi
        same=1
        for f in "$out/old/$name.$integ".*; do
            g=$out/new/$(basename "$f")
            case $f in *.log) cmp -s <(grep -v '^exit' "$f") <(grep -v '^exit' "$g" 2>/dev/null) ;;
                       *) cmp -s "$f" "$g" ;; esac || { same=0; echo "DIFF $name $integ: $(basename "$f")"; }
        done
        [ "$same" = 1 ] && echo "same $name $integ" || bad=$((bad + 1))
    done
done < <(cases)
echo "$((n - bad)) of $n renders byte-identical (images, AOVs and messages) in $out"
[ "$bad" = 0 ]
