#!/usr/bin/env bash
# cmake.sh - tests/install/consumer, a CMake project that uses
# find_package(paprsek) with CMAKE_PREFIX_PATH set to the prefix and links
# app.c with paprsek::paprsek (shared) and paprsek::paprsek_static.
. "$(dirname "$0")/common.sh"
need readelf "${PK_CC%% *}"
workdir cmake
echo "+ cmake -S $here/consumer -B $work -DCMAKE_PREFIX_PATH=$PK_PREFIX"
if ! "$PK_CMAKE" -S "$here/consumer" -B "$work" -DCMAKE_PREFIX_PATH="$PK_PREFIX" \
    -DCMAKE_C_COMPILER="$PK_CC" -DCMAKE_C_FLAGS="$PK_CFLAGS" -DCMAKE_EXE_LINKER_FLAGS="$PK_CFLAGS" \
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >"$work/configure.log" 2>&1; then
    fail "the consumer project does not configure:"
    cat "$work/configure.log"
    finish
fi
dir=$(sed -n 's/^paprsek_DIR:PATH=//p' "$work/CMakeCache.txt")
case "$dir" in "$PK_PREFIX"/*) ok "find_package(paprsek): $dir" ;; *) fail "find_package found paprsek in '$dir'" ;; esac
build "the consumer project" "$PK_CMAKE" --build "$work" -j 2 || finish

needed "$work/app_shared" | grep -qx libpaprsek.so.0 && ok "app_shared needs libpaprsek.so.0" \
    || fail "app_shared does not need libpaprsek.so.0"
run_app "app_shared (paprsek::paprsek)" "$work/app_shared"
check_embree app_shared "$work/app_shared"
needed "$work/app_static" | grep -q paprsek && fail "app_static needs a shared libpaprsek" \
    || ok "app_static needs no shared libpaprsek"
run_app "app_static (paprsek::paprsek_static)" "$work/app_static"
finish
