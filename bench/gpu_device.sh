#!/usr/bin/env bash
# gpu_device.sh - the GPU measurements of one device session, as one script
# (docs/gpu.md, "What needs a GPU"): run in the project root of the device
# machine after ../shared/tools/device-prep --embree cornell bench here.
#   1. builds with the device's packages for sm_90 (build-dev);
#   2. runs the device tests (ctest -R 'cuda|bvh_gpu');
#   3. builds the textbook kernel (.device/tools/gpuref) and times it in the
#      same interleaved rounds as the traversals of cuda.traversal x
#      cuda.leaf (bench/gpu_variants.sh), hits compared with the CPU's;
#   4. profiles the sorted and the ordered traversal on Sponza diffuse rays
#      with Nsight Compute when ncu is there: lanes busy (thread
#      instructions / 32 x warp instructions), local-memory bytes, issue
#      activity, registers;
#   5. the path tracer's samples/s (bench/gpu_render.sh) when time is left.
# Everything lands in $OUT (default bench/out/device). Steps 3-5 honour
# SIZE (2048), ROUNDS (3), SKIP_RENDER=1.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(dirname "$here")
out=${OUT:-$repo/bench/out/device}
mkdir -p "$out"
cd "$repo"
log() { echo "== $* ($(date +%T))" | tee -a "$out/steps.txt"; }

log build
# shellcheck disable=SC1091
source .device/setup.sh
shared=$repo/.device/shared
cmake -S . -B build-dev $PK_DEVICE_CMAKE_ARGS -DPK_CUDA_ARCHS=90 -DPK_SHARED_DIR="$shared" >"$out/cmake.txt" 2>&1 &&
    cmake --build build-dev -j "$(nproc)" >>"$out/cmake.txt" 2>&1 || { tail -30 "$out/cmake.txt"; exit 1; }
nvidia-smi >"$out/nvidia-smi.txt" 2>&1

log device tests
(cd build-dev && ctest -R 'cuda|bvh_gpu' --output-on-failure) >"$out/ctest.txt" 2>&1
tail -5 "$out/ctest.txt"
cp build-dev/tests/cuda_resources.txt "$out/" 2>/dev/null

log textbook kernel
gpuref=$repo/.device/tools/gpuref/gpuref
nvcc -O3 -arch=sm_90 -o "$gpuref" .device/tools/gpuref/gpuref.cu >"$out/gpuref-build.txt" 2>&1 || gpuref=

log traversal variants
SIZE=${SIZE:-2048} ROUNDS=${ROUNDS:-3} KINDS="primary diffuse diffuse-any" GPUREF=$gpuref \
    bash bench/gpu_variants.sh "$shared" build-dev/paprsek >"$out/variants.md" 2>"$out/variants.err"
cat "$out/variants.md"
cp bench/out/gpu_variants/raw.txt "$out/variants-raw.txt" 2>/dev/null

if command -v ncu >/dev/null; then
    log profile
    rays=$out/sponza-diffuse-1024.rays
    build-dev/paprsek bench gen-rays --workload sponza --shared "$shared" --size 1024 --kind diffuse --seed 1 -o "$rays" &&
        for t in sorted ordered; do
            ncu -k regex:pk_trace_closest -c 1 --metrics \
smsp__inst_executed.sum,smsp__thread_inst_executed.sum,sm__inst_issued.avg.pct_of_peak_sustained_active,\
l1tex__t_bytes_pipe_lsu_mem_local_op_ld.sum,l1tex__t_bytes_pipe_lsu_mem_local_op_st.sum,\
lts__t_bytes.sum,dram__bytes.sum,launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active,\
gpu__time_duration.sum \
                build-dev/paprsek bench rays "$shared/scenes/bench/dabrovic-sponza/sponza.obj" "$rays" --accel cuda \
                --config "cuda.traversal=$t" --reps 1 >"$out/ncu-$t.txt" 2>&1
        done
    rm -f "$rays"
fi

if [ "${SKIP_RENDER:-0}" != 1 ]; then
    log path tracer
    bash bench/gpu_render.sh "$shared" build-dev/paprsek >"$out/render.md" 2>"$out/render.err"
    cat "$out/render.md"
fi
log done
