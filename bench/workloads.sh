# workloads.sh - sourced by the bench scripts: the standard workloads'
# scenes under $shared (spec/ray-benchmark.md) and the `key=value` reader
# for the lines `paprsek bench rays` prints. The script defines die().

# the scene of a standard workload
scene_of() {
    case $1 in
    cornell-sphere) echo "$shared/scenes/cornell/CornellBox-Sphere.obj" ;;
    bunny) echo "$shared/scenes/bench/stanford-bunny.obj" ;;
    sponza) echo "$shared/scenes/bench/dabrovic-sponza/sponza.obj" ;;
    *) die "unknown workload $1" ;;
    esac
}

# value of key in a `key=value ...` line
field() { awk -v k="$1" '{ for (i = 1; i <= NF; i++) { split($i, kv, "="); if (kv[1] == k) print kv[2] } }'; }
