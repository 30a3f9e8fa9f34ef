#!/usr/bin/env bash
# pkgconfig.sh - app.c built with `cc app.c $(pkg-config --cflags --libs
# paprsek)` against the installed shared library, and with `pkg-config
# --static` against libpaprsek.a; both run (and with Embree, or without it).
. "$(dirname "$0")/common.sh"
need pkg-config readelf nm "${PK_CC%% *}"
workdir pkgconfig
lib="$PK_PREFIX/$PK_LIBDIR"
export PKG_CONFIG_PATH="$lib/pkgconfig"

v=$(pkg-config --modversion paprsek) && [ "$v" = 0.1.0 ] && ok "pkg-config --modversion: $v" \
    || fail "pkg-config --modversion paprsek: '$v'"
cflags=$(pkg-config --cflags paprsek) || fail "pkg-config --cflags"
libs=$(pkg-config --libs paprsek) || fail "pkg-config --libs"
slibs=$(pkg-config --static --libs paprsek) || fail "pkg-config --static --libs"
echo "cflags: $cflags"
echo "libs: $libs"
echo "static libs: $slibs"
case " $slibs " in *" -fopenmp"*) ok "--static lists -fopenmp" ;; *) fail "--static lacks -fopenmp" ;; esac
case " $slibs " in *" -lm "*) ok "--static lists -lm" ;; *) fail "--static lacks -lm" ;; esac
case " $slibs " in *" -lcjson "*) ok "--static lists -lcjson" ;; *) fail "--static lacks -lcjson" ;; esac
case " $slibs " in *" -lpng"*) ok "--static lists libpng" ;; *) fail "--static lacks libpng" ;; esac
case " $libs $slibs " in *" -lembree"*) fail "pkg-config links Embree" ;; *) ok "pkg-config does not link Embree" ;; esac

# shared: found at run time through the rpath
if build "app (shared)" $PK_CC $PK_CFLAGS -std=c11 -Wall -Wextra -Werror "$here/app.c" -o "$work/app_shared" \
    $cflags $libs -Wl,-rpath,"$lib"; then
    needed "$work/app_shared" | grep -qx libpaprsek.so.0 && ok "app_shared needs libpaprsek.so.0" \
        || fail "app_shared does not need libpaprsek.so.0: $(needed "$work/app_shared" | tr '\n' ' ')"
    run_app "app_shared" "$work/app_shared"
    check_embree app_shared "$work/app_shared"
fi

# static: the linker prefers libpaprsek.so to libpaprsek.a for -lpaprsek, so
# the archive is asked for by name (-l:libpaprsek.a, GNU ld and lld)
slibs_a=$(echo " $slibs " | sed 's/ -lpaprsek / -l:libpaprsek.a /')
if build "app (static)" $PK_CC $PK_CFLAGS -std=c11 -Wall -Wextra -Werror "$here/app.c" -o "$work/app_static" \
    $cflags $slibs_a; then
    needed "$work/app_static" | grep -q paprsek && fail "app_static needs a shared libpaprsek" \
        || ok "app_static needs no shared libpaprsek"
    nm "$work/app_static" | grep -q ' T pk_render$' && ok "app_static holds pk_render" \
        || fail "app_static does not hold pk_render"
    run_app "app_static" "$work/app_static"
    check_embree app_static "$work/app_static"
fi
finish
