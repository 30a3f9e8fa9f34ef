#!/usr/bin/env bash
# cxx.sh - app.cpp: paprsek.h compiled as C++ by g++ (-pedantic, warnings as
# errors), linked with the installed shared and static libraries. (clang++
# when clang built the library: the sanitizer and OpenMP flags are clang's.)
. "$(dirname "$0")/common.sh"
cxx=${PK_CXX:-g++}
need "$cxx" pkg-config
workdir cxx
lib="$PK_PREFIX/$PK_LIBDIR"
export PKG_CONFIG_PATH="$lib/pkgconfig"
cflags=$(pkg-config --cflags paprsek) && libs=$(pkg-config --libs paprsek) &&
    slibs=$(pkg-config --static --libs paprsek) || { echo "FAIL: pkg-config paprsek"; exit 1; }
slibs_a=$(echo " $slibs " | sed 's/ -lpaprsek / -l:libpaprsek.a /')
for std in c++11 c++17; do
    build "app.cpp (-std=$std, shared)" "$cxx" $PK_CFLAGS -std=$std -Wall -Wextra -pedantic -Werror \
        "$here/app.cpp" -o "$work/app_$std" $cflags $libs -Wl,-rpath,"$lib" &&
        run_app "app.cpp (-std=$std, shared)" "$work/app_$std"
done
build "app.cpp (static)" "$cxx" $PK_CFLAGS -std=c++17 -Wall -Wextra -pedantic -Werror \
    "$here/app.cpp" -o "$work/app_static" $cflags $slibs_a &&
    run_app "app.cpp (static)" "$work/app_static"
finish
