#!/usr/bin/env bash
# install.sh - fixture of the install tests: `cmake --install BUILD --prefix
# PREFIX` into an empty prefix, then checks that every file is there and that
# the installed program runs.
. "$(dirname "$0")/common.sh"
workdir install
rm -rf "$PK_PREFIX"
echo "+ $PK_CMAKE --install $PK_BUILD --prefix $PK_PREFIX"
"$PK_CMAKE" --install "$PK_BUILD" --prefix "$PK_PREFIX" || { echo "FAIL: cmake --install"; exit 1; }

lib="$PK_PREFIX/$PK_LIBDIR"
for f in bin/paprsek include/paprsek.h "$PK_LIBDIR/libpaprsek.a" "$PK_LIBDIR/libpaprsek.so.0.1.0" \
    "$PK_LIBDIR/pkgconfig/paprsek.pc" "$PK_LIBDIR/cmake/paprsek/paprsekConfig.cmake" \
    "$PK_LIBDIR/cmake/paprsek/paprsekConfigVersion.cmake" "$PK_LIBDIR/cmake/paprsek/paprsekTargets.cmake"; do
    if [ -f "$PK_PREFIX/$f" ]; then ok "$f"; else fail "$f is not installed"; fi
done
# paprsek-mpi: installed exactly when it was built (MPI found)
if [ "${PK_HAVE_MPI:-0}" = 1 ]; then
    [ -x "$PK_PREFIX/bin/paprsek-mpi" ] && ok "bin/paprsek-mpi" || fail "bin/paprsek-mpi is not installed"
else
    [ -e "$PK_PREFIX/bin/paprsek-mpi" ] && fail "bin/paprsek-mpi is installed without MPI" || ok "no bin/paprsek-mpi (no MPI)"
fi
[ "$(readlink "$lib/libpaprsek.so.0")" = libpaprsek.so.0.1.0 ] && ok "libpaprsek.so.0 -> libpaprsek.so.0.1.0" \
    || fail "libpaprsek.so.0 is not a link to libpaprsek.so.0.1.0"
[ "$(readlink "$lib/libpaprsek.so")" = libpaprsek.so.0 ] && ok "libpaprsek.so -> libpaprsek.so.0" \
    || fail "libpaprsek.so is not a link to libpaprsek.so.0"
# the library's modules (src/device/module.h): in LIBDIR/paprsek exactly when they were built
for m in OPENVDB:paprsek_openvdb.so CUDA:paprsek_cuda.so; do
    var=PK_HAVE_${m%%:*} file=$PK_LIBDIR/paprsek/${m#*:}
    if [ "${!var:-0}" = 1 ]; then
        [ -f "$PK_PREFIX/$file" ] && ok "$file" || fail "$file is not installed"
    else
        [ -e "$PK_PREFIX/$file" ] && fail "$file is installed but was not built" || ok "no $file (not built)"
    fi
done
grep -qx "prefix=$PK_PREFIX" "$lib/pkgconfig/paprsek.pc" && ok "paprsek.pc: prefix=$PK_PREFIX" \
    || fail "paprsek.pc does not say prefix=$PK_PREFIX: $(head -1 "$lib/pkgconfig/paprsek.pc")"

run_app "bin/paprsek render" "$PK_PREFIX/bin/paprsek" render -o "$work/cornell.png" \
    --width 16 --height 16 --light-samples 2 --threads 2 --quiet
[ -s "$work/cornell.png" ] && ok "bin/paprsek wrote cornell.png" || fail "bin/paprsek wrote no image"
# a .vdb medium: the installed program finds the installed OpenVDB module
# (bin/../LIBDIR/paprsek), wherever the prefix is
if [ "${PK_HAVE_OPENVDB:-0}" = 1 ]; then
    cp "$PK_TEST_DATA/media/grid.vdb" "$work/"
    printf '%s\n' '{"spheres": [{"center": [0, 0, 0], "radius": 1}],' \
        ' "media": [{"name": "smoke", "type": "grid", "file": "grid.vdb", "grid": "density", "sigma_t": 0.01}], "medium": "smoke"}' \
        >"$work/smoke.json"
    run_app "bin/paprsek render smoke.json (grid.vdb)" "$PK_PREFIX/bin/paprsek" render "$work/smoke.json" \
        -o "$work/smoke.png" --width 8 --height 8 --spp 1 --quiet
    [ -s "$work/smoke.png" ] && ok "bin/paprsek read grid.vdb through $PK_LIBDIR/paprsek/paprsek_openvdb.so" \
        || fail "bin/paprsek did not render smoke.json"
fi
finish
