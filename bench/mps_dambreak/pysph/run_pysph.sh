#!/bin/sh
# PySPH side of bench/mps_dambreak: PySPH's dam_break_2d (WCSPH) at dx = 0.015 m to t = 0.6 s,
# one thread, timed, fronts at 0.4 and 0.6 s. Needs Debian's python3-pysph
# (apt-get install -y python3-pysph); uses /usr/bin/python3 because the package installs for the
# system interpreter, not for a pyenv or virtualenv one that may come first in PATH.
# Usage: run_pysph.sh [--stock] [--dx DX] [--tf TF] [--out DIR]   (run_pysph.py --help)
set -e
here=$(cd "$(dirname "$0")" && pwd)
if ! /usr/bin/python3 -c 'import pysph' 2>/dev/null; then
    echo "python3-pysph is missing: apt-get install -y python3-pysph" >&2
    exit 1
fi
export OMP_NUM_THREADS=1
exec /usr/bin/python3 "$here/run_pysph.py" "$@"
