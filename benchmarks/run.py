"""Run every benchmark (`benchmarks/bench_*.py`) and collect their figures.

Each benchmark is a standalone script: it measures, compares against its named peer in
the same run, prints a short table and writes `benchmarks/results/<name>.json`.  This
driver runs them one after another in fresh interpreters (so one cannot warm another's
caches) and prints where the results went.

    make benchmark                       # all of them
    .venv/bin/python benchmarks/run.py parse check   # only those whose name contains a word
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    scripts = sorted(HERE.glob("bench_*.py"))
    if argv:
        scripts = [s for s in scripts if any(word in s.stem for word in argv)]
    if not scripts:
        print("benchmarks: nothing to run", file=sys.stderr)
        return 2
    failed = []
    for script in scripts:
        print(f"== {script.stem}", flush=True)
        result = subprocess.run([sys.executable, str(script)], check=False)
        if result.returncode != 0:
            failed.append(script.stem)
    print(f"results: {HERE / 'results'}")
    if failed:
        print(f"benchmarks that failed to run: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
