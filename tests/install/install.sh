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
grep -qx "prefix=$PK_PREFIX" "$lib/pkgconfig/paprsek.pc" && ok "paprsek.pc: prefix=$PK_PREFIX" \
    || fail "paprsek.pc does not say prefix=$PK_PREFIX: $(head -1 "$lib/pkgconfig/paprsek.pc")"

run_app "bin/paprsek render" "$PK_PREFIX/bin/paprsek" render -o "$work/cornell.png" \
    --width 16 --height 16 --light-samples 2 --threads 2 --quiet
[ -s "$work/cornell.png" ] && ok "bin/paprsek wrote cornell.png" || fail "bin/paprsek wrote no image"
finish
