#!/usr/bin/env bash
# symbols.sh - what the installed libraries define: exactly the pk_*
# functions that paprsek.h declares, in libpaprsek.a (nm -g --defined-only)
# and libpaprsek.so (nm -D --defined-only); nothing else is global. The
# shared library's soname is libpaprsek.so.0 and it does not need Embree
# (readelf -d), nor do paprsek.pc or the CMake files name it.
. "$(dirname "$0")/common.sh"
need nm readelf
workdir symbols
lib="$PK_PREFIX/$PK_LIBDIR"

# The public functions: every PK_API declaration of the installed header.
grep -E '^PK_API ' "$PK_PREFIX/include/paprsek.h" | grep -oE '\bpk_[a-z0-9_]+\(' | tr -d '(' |
    sort -u >"$work/api.txt"
n=$(wc -l <"$work/api.txt")
[ "$n" -gt 20 ] && ok "paprsek.h declares $n functions" || fail "paprsek.h: only $n functions found"

# Global names allowed besides the API: none. (A toolchain symbol that must
# stay global would be listed here, with the reason.)
allowed='^$'

# check_defined WHAT FILE: the defined global symbols (name list in FILE)
# must be the API, all of it and nothing more.
check_defined() {
    local what=$1 list=$2
    sort -u "$list" -o "$list"
    local extra missing
    extra=$(comm -13 "$work/api.txt" "$list" | grep -Ev "$allowed")
    missing=$(comm -23 "$work/api.txt" "$list" | comm -12 - "$work/implemented.txt")
    echo "$what: $(wc -l <"$list") global symbols defined"
    [ -z "$extra" ] && ok "$what defines no global symbol outside the API" \
        || fail "$what defines global symbols outside the API: $(echo $extra)"
    [ -z "$missing" ] && ok "$what defines every API function" \
        || fail "$what does not export API functions that the library defines: $(echo $missing)"
}

# The API functions the library implements: those its objects define (the
# in-tree archive of the tests, hidden symbols included). One that the
# installed libraries lack has lost its PK_API; one that is declared and not
# implemented at all is reported, as the library's business, not the export's.
nm -g --defined-only "$PK_BUILD/libpaprsek_internal.a" | awk 'NF == 3 && $3 ~ /^pk_/ { print $3 }' |
    sort -u >"$work/implemented.txt" || fail "nm libpaprsek_internal.a"
unimplemented=$(comm -23 "$work/api.txt" "$work/implemented.txt")
[ -z "$unimplemented" ] || echo "note: paprsek.h declares functions that the library does not define: $(echo $unimplemented)"

nm -g --defined-only "$lib/libpaprsek.a" | awk 'NF == 3 { print $3 }' >"$work/static.txt" ||
    fail "nm libpaprsek.a"
check_defined libpaprsek.a "$work/static.txt"
nm -D --defined-only "$lib/libpaprsek.so" | awk 'NF == 3 { print $3 }' >"$work/shared.txt" ||
    fail "nm -D libpaprsek.so"
check_defined libpaprsek.so "$work/shared.txt"

readelf -d "$lib/libpaprsek.so" >"$work/dynamic.txt" || fail "readelf -d libpaprsek.so"
grep -q 'Library soname: \[libpaprsek.so.0\]' "$work/dynamic.txt" && ok "soname libpaprsek.so.0" \
    || fail "the soname is not libpaprsek.so.0: $(grep SONAME "$work/dynamic.txt")"
echo "libpaprsek.so needs: $(needed "$lib/libpaprsek.so" | tr '\n' ' ')"
needed "$lib/libpaprsek.so" | grep -qi embree && fail "libpaprsek.so needs Embree" \
    || ok "libpaprsek.so does not need Embree"
# nor what the modules load (OpenVDB and with it Boost, TBB and the C++
# runtime; the CUDA driver) nor oneDNN: all are loaded at run time, when asked for
# (A sanitizer build's program loads oneDNN, Embree and the OpenVDB module
# at start on purpose, for LeakSanitizer: CMakeLists.txt; its library not.)
for dep in openvdb stdc++ boost tbb cuda dnnl; do
    needed "$lib/libpaprsek.so" | grep -qi "$dep" && fail "libpaprsek.so needs $dep" \
        || ok "libpaprsek.so does not need $dep"
    if [ "${PK_SANITIZE:-0}" = 1 ]; then continue; fi
    needed "$PK_PREFIX/bin/paprsek" | grep -qi "$dep" && fail "bin/paprsek needs $dep" \
        || ok "bin/paprsek does not need $dep"
done
# (the fields only: the prefix is a path that may hold any word)
grep -E '^(Requires|Libs)' "$lib/pkgconfig/paprsek.pc" | grep -qi embree && fail "paprsek.pc names Embree" \
    || ok "paprsek.pc does not name Embree"
grep -hE 'INTERFACE_LINK|find_package|find_dependency' "$lib"/cmake/paprsek/*.cmake | grep -qi embree &&
    fail "the CMake package names Embree" || ok "the CMake package does not name Embree"
finish
