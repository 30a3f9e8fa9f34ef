# mpi_common.sh - sourced by the paprsek-mpi tests: checks the programs,
# makes a scratch folder ($tmp) and defines run_mpi.
# The scripts take: PAPRSEK PAPRSEK_MPI MPIEXEC DATA_DIR.
set -u
bin=$1 mpi=$2 mpiexec=$3 data=$4
[ -x "$bin" ] || { echo "SKIP: $bin is not a program"; exit 77; }
if [ -z "$mpi" ] || [ ! -x "$mpi" ] || [ -z "$mpiexec" ]; then
  echo "SKIP: paprsek-mpi is not built (MPI was not found, or -DPK_WITH_MPI=OFF: install libopenmpi-dev openmpi-bin and reconfigure)"
  exit 77
fi
if ! command -v "$mpiexec" >/dev/null 2>&1; then
  echo "SKIP: mpirun ($mpiexec) is missing (install openmpi-bin)"
  exit 77
fi
# Open MPI refuses to start as root without these.
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
# Sanitizer builds: Open MPI leaves some 3000 small allocations of its
# components (dlopen'ed and closed: no names in the stacks) at exit, and none
# of paprsek-mpi's own (checked): leak checking is off for the ranks, the
# other sanitizer checks stay on.
if [ -n "${ASAN_OPTIONS:-}" ]; then export ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0"; fi
# Loopback only, no network probing: quick starts on any machine.
export OMPI_MCA_btl_tcp_if_include=lo OMPI_MCA_oob_tcp_if_include=lo
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
bad() { echo "FAIL $*"; fail=1; }

# The scene lives in $tmp/scene only; the other ranks run in $tmp/empty.
mkdir -p "$tmp/scene" "$tmp/empty"
cp "$data/mpi_room.obj" "$data/mpi_room.mtl" "$data/mpi_tex.obj" "$data/mpi_tex.mtl" "$data/json_example.json" \
   "$data/json_floor.obj" "$data/json_lamp.obj" "$tmp/scene/"
# mpi_tex.mtl's texture: a 2x2 PFM (red, green / blue, white)
{ printf 'PF\n2 2\n-1.0\n'
  printf '\000\000\200\077\000\000\000\076\000\000\000\076\000\000\000\076\000\000\200\077\000\000\000\076'
  printf '\000\000\000\076\000\000\000\076\000\000\200\077\000\000\200\077\000\000\200\077\000\000\200\077'
} >"$tmp/scene/mpi_tex.pfm"

# run_mpi N ARGS...: mpirun with N ranks (1..), rank 0 in $tmp/scene and the
# others in $tmp/empty, each given ARGS (after "render").
run_mpi() {
  local n=$1
  shift
  if [ "$n" -gt 1 ]; then
    timeout 120 "$mpiexec" --oversubscribe -np 1 -wdir "$tmp/scene" "$mpi" render "$@" : \
      -np $((n - 1)) -wdir "$tmp/empty" "$mpi" render "$@"
  else
    timeout 120 "$mpiexec" --oversubscribe -np 1 -wdir "$tmp/scene" "$mpi" render "$@"
  fi
}
