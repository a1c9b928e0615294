#!/usr/bin/env bash
# The prepared run for a lent many-core machine (issues 31 and 32), one call:
#   1. batch scaling: 10,000 generated hearts through --jobs 1, 2, 4, 8, 16 and a
#      16-worker dask LocalCluster (bench/scaling.py), one round;
#   2. memory at 100,000 paths: one --jobs 16 run, the parent's resident size sampled;
#   3. the fuzz campaign (bench/fuzz_campaign.py) on 15 workers until 100,000 cases or
#      FUZZ_SECONDS (at most what is left of WITHIN seconds), whichever comes first.
# Results go to $OUT (scaling-16.json, memory-100k.json, fuzz-summary.json,
# fuzz-failures.jsonl, log).  The machine has no network: python-flint, dask and their
# needs travel as wheels in .whl/ (see docs/speed.md); SymPy, mpmath, click, PyYAML, rich,
# pytest and psutil are the image's.
set -u
export PYTHONUNBUFFERED=1
OUT=${OUT:-/tmp/many-cores}
mkdir -p "$OUT"
FUZZ_SECONDS=${FUZZ_SECONDS:-300}
DEADLINE=$(( $(date +%s) + ${WITHIN:-560} ))  # the whole run ends by then
PATHS=${PATHS:-10000}
MEMORY_PATHS=${MEMORY_PATHS:-10000,100000}
JOBS=${JOBS:-1,2,4,8,16}
if [ -d .whl ]; then
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
        --target /tmp/site .whl/*.whl || exit 1
    export PYTHONPATH=/tmp/site:$PWD
fi
{
    echo "cores: $(nproc); $(python3 --version)"
    python3 -c "import flint, distributed, sympy, hypothesis; print('flint', flint.__version__, 'distributed', distributed.__version__, 'sympy', sympy.__version__, 'hypothesis', hypothesis.__version__)"
    python3 -m singcheck run robots/orthoglide.yaml trajectories/heart1.yaml --backend flint -q --format json | head -c 300; echo
    date -u +%T; timeout 240 python3 bench/scaling.py "$PATHS" 1 "$JOBS" --json "$OUT/scaling-16.json"
    date -u +%T; timeout 150 python3 - "$OUT/memory-100k.json" "$MEMORY_PATHS" "${JOBS##*,}" <<'PY'
import json, sys, tempfile
from pathlib import Path
sys.path.insert(0, "bench")
import scaling
from generate import write_stream
with tempfile.TemporaryDirectory() as tmp:
    env = {**scaling.os.environ, "SINGCHECK_CACHE_DIR": tmp}
    exe = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", "-", "-q",
           "--format", "jsonl", "--no-regions", "--backend", "flint", "--jobs", sys.argv[3]]
    rows = {}
    for n in map(int, sys.argv[2].split(",")):
        rows[n] = scaling._run(exe, write_stream(Path(tmp) / f"s{n}.yaml", n), env)
        print(n, "paths:", {k: round(v, 2) if isinstance(v, float) else v for k, v in rows[n].items()})
    Path(sys.argv[1]).write_text(json.dumps(rows, indent=1))
PY
    left=$(( DEADLINE - $(date +%s) - 40 ))
    [ "$left" -lt "$FUZZ_SECONDS" ] && FUZZ_SECONDS=$left
    date -u +%T; echo "fuzzing for $FUZZ_SECONDS s"
    timeout $((FUZZ_SECONDS + 35)) python3 bench/fuzz_campaign.py --jobs $(($(nproc) - 1)) \
        --examples 2000 --budget 1 --minutes "$(python3 -c "print($FUZZ_SECONDS / 60)")" --cases 100000 --out /tmp/fuzz \
        | tail -40
    cp /tmp/fuzz/summary.json "$OUT/fuzz-summary.json"
    cat /tmp/fuzz/*.failures > "$OUT/fuzz-failures.jsonl" 2>/dev/null
    date -u +%T
} 2>&1 | tee "$OUT/log"
