#!/bin/bash
# test_oracle.sh DUMP WEIGHTS ORACLE: the C denoiser's dump checked by the
# NumPy oracle. Skips (77) when the weights, oneDNN or NumPy are missing.
set -u
dump=$1 weights=$2 oracle=$3
py=/usr/bin/python3
if ! "$py" -c 'import numpy' 2>/dev/null; then
    echo "SKIP: NumPy for $py is missing (Debian: apt-get install python3-numpy)"; exit 77
fi
if [ ! -f "$weights" ]; then echo "SKIP: no weights at $weights (make weights)"; exit 77; fi
dir=$(mktemp -d) || exit 1
trap 'rm -rf "$dir"' EXIT
"$dump" "$weights" "$dir"
rc=$?
[ $rc -eq 0 ] || exit $rc
"$py" "$oracle" "$weights" "$dir"
