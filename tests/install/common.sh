# common.sh - sourced by the install tests (tests/install/*.sh). ctest sets
export LC_ALL=C
# the environment (tests/CMakeLists.txt):
#   PK_CMAKE    the cmake program          PK_BUILD   the build folder
#   PK_PREFIX   the prefix installed into  PK_LIBDIR  its library folder
#   PK_WORK     a folder for this test     PK_CC      the C compiler
#   PK_CXX      the C++ compiler (g++, or clang++ when clang built the library)
#   PK_CFLAGS   extra compile and link flags of every test program (the
#               sanitizers, in a sanitizer build)
#   PK_HAVE_EMBREE  1 when the Embree backend is built in
#   PK_HAVE_OPENVDB, PK_HAVE_CUDA  1 when the OpenVDB module, the CUDA
#               kernels' module are built (and so installed)
#   PK_TEST_DATA  tests/data
set -u
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }

# need TOOL...: exit 77 (ctest: skipped) when a tool is not installed.
need() {
    local t
    for t in "$@"; do
        command -v "$t" >/dev/null 2>&1 || { echo "SKIP: $t is not installed"; exit 77; }
    done
}

# finish: the exit status of the test.
finish() {
    if [ "$fails" -ne 0 ]; then
        echo "$fails check(s) failed"
        exit 1
    fi
    exit 0
}

# workdir NAME: an empty folder for this test, in $work.
workdir() {
    work="$PK_WORK/$1"
    rm -rf "$work" && mkdir -p "$work" || { echo "FAIL: cannot make $work"; exit 1; }
}

# build WHAT CMD...: runs a compile or link command, which must succeed.
build() {
    local what=$1
    shift
    echo "+ $*"
    if "$@" >"$work/build.log" 2>&1; then
        ok "$what builds"
        return 0
    fi
    fail "$what does not build:"
    cat "$work/build.log"
    return 1
}

# run_app WHAT CMD...: runs a test program, which must exit 0 and print
# nothing (the library never prints).
run_app() {
    local what=$1
    shift
    local out rc
    out=$("$@" 2>&1)
    rc=$?
    if [ $rc -ne 0 ]; then
        fail "$what: exit status $rc: $out"
    elif [ -n "$out" ]; then
        fail "$what: printed: $out"
    else
        ok "$what runs"
    fi
}

# needed FILE: the NEEDED entries of an ELF file, one a line.
needed() { readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'; }

# Embree checks of a program built with app.c: with Embree built in and
# libembree3.so.3 installed, it renders through Embree; with the library
# missing (PAPRSEK_EMBREE_LIBRARY naming no file), or without the backend,
# Embree is reported unavailable with a message naming the library and the
# other accelerators work.
check_embree() {
    local what=$1 app=$2
    if [ "${PK_HAVE_EMBREE:-0}" = 1 ]; then
        if /sbin/ldconfig -p 2>/dev/null | grep -q 'libembree3\.so\.3 '; then
            run_app "$what with Embree" "$app" embree
        else
            echo "note: libembree3.so.3 is not installed here: $what is not run with Embree"
        fi
        run_app "$what without libembree3.so.3" \
            env PAPRSEK_EMBREE_LIBRARY="$work/nowhere/libembree3.so.3" "$app" embree-missing libembree3.so.3
    else
        run_app "$what (no Embree backend)" "$app" embree-missing "no Embree"
    fi
}
