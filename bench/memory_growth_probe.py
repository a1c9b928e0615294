"""The parent's peak resident memory of a streamed batch at several lengths (issue 32).

    python bench/memory_growth_probe.py 3000,30000 JOBS

Runs ``singcheck run robots/orthoglide.yaml - --format jsonl --no-regions --jobs JOBS``
on N generated hearts on standard input (bench/generate.py), for each N, and prints the
row of :func:`scaling._run`: ``parent_peak_rss_mb`` is the ``singcheck`` process alone,
sampled every 50 ms with psutil.
"""

import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, "bench")
import scaling  # noqa: E402
from generate import write_stream  # noqa: E402

with tempfile.TemporaryDirectory() as tmp:
    env = {**os.environ, "SINGCHECK_CACHE_DIR": tmp}
    exe = [sys.executable, "-m", "singcheck", "run", "robots/orthoglide.yaml", "-", "-q",
           "--format", "jsonl", "--no-regions", "--backend", "flint", "--jobs", sys.argv[2]]
    for n in map(int, sys.argv[1].split(",")):
        row = scaling._run(exe, write_stream(Path(tmp) / f"s{n}.yaml", n), env)
        print(n, "paths:", {k: round(v, 2) if isinstance(v, float) else v
                            for k, v in row.items()}, flush=True)
