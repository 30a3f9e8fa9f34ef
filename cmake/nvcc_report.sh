#!/bin/sh
# nvcc_report.sh REPORT NVCC ARGS... - runs nvcc with ptxas's resource report
# (-Xptxas -v) kept in REPORT: registers, stack frame and spills of every
# kernel for every architecture compiled. The cuda_ptx test reads it, so the
# kernels are compiled once per build. Anything but ptxas's info lines (a
# warning, an error) is shown as nvcc would show it.
report=$1
shift
"$@" -Xptxas -v >"$report.tmp" 2>&1
rc=$?
grep -v '^ptxas info\|^    [0-9]* bytes stack frame\|^    Compile time\|^$' "$report.tmp" >&2
[ "$rc" = 0 ] && mv "$report.tmp" "$report" || rm -f "$report.tmp"
exit "$rc"
