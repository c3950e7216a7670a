#!/bin/bash
# The scale part of the benchmarks (benchmarks/scale.py) before and after a change, on a machine
# with many cores that has neither network nor dask (docs/sweep_performance.md reports it):
#
#     benchmarks/device_scale.sh CARRY CASES [SECONDS] [per-worker]
#
# CARRY holds whl/ (wheels of what the machine lacks: dask, distributed, tornado, zict, tblib,
# locket, partd, fmpy, lark) and two trees, after/ and before/, each with its dist/Pendulum.fmu
# and pendulum_fmu/fmu/_cs_loop.so built (plain C: any Python of the same processor loads them) and
# this branch's benchmarks/scale.py, so that both are measured alike. CASES: 3-s cases per study;
# SECONDS: the most each tree may take; per-worker: CASES per worker, each worker count's study as
# many times larger, and each control process running CASES (both trees carry this branch's
# scale.py, as above). So that
# at 16 workers a study is mostly cases within the machine's minutes: a study costs about 0.3 s
# besides its cases (a row gives its share, target under 5 %), so e.g. 16384 3-s cases per
# worker, 6 to 11 s a study at 1,500 to 2,800 cases/s per worker (12 GB written by the 16-worker
# one, removed after it). Each tree's table goes to
# $OUT/<tree>.txt (OUT defaults to ./device-out) and is printed last, "after" first, as it
# matters more.
set -u
carry=$(cd "$1" && pwd)
cases=$2
limit=${3:-200}
per_worker=$([ "${4:-}" = per-worker ] && echo True || echo False)
out=${OUT:-device-out}
mkdir -p "$out"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target /tmp/site "$carry"/whl/*.whl || exit 1
export PYTHONUNBUFFERED=1
echo "$(nproc) cores, $(python3 --version), load $(cut -d' ' -f1-3 /proc/loadavg)"
measure='
import sys, tempfile
from pathlib import Path
from benchmarks.builds import unzipped
from benchmarks.report import as_text, main_table
from benchmarks.scale import scale_rows
with tempfile.TemporaryDirectory() as scratch:
    fmu = unzipped(Path("dist/Pendulum.fmu").resolve(), Path(scratch))
    print(as_text(main_table(scale_rows(fmu, quick=True, cases=int(sys.argv[1]), per_worker=sys.argv[2] == "True"))))
'
for tree in after before; do
    (cd "$carry/$tree" && PYTHONPATH=".:/tmp/site" timeout "$limit" python3 -c "$measure" "$cases" "$per_worker") \
        >"$out/$tree.txt" 2>&1
    echo "$tree: exit $?"
done
for tree in after before; do
    echo "== $tree"
    cat "$out/$tree.txt"
done
