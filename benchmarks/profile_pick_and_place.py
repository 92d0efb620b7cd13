"""Where the pick-and-place run spends its time, per subsystem and per partial transition function.

Not a benchmark (it has no peer and no goal): a profile without a profiler's distortion.
cProfile multiplies the cost of small Python calls, which is most of what a control loop
does; this script times each subsystem's `iterate` and each function call with
`time.perf_counter` around the real calls, in the real interleaved run, so caches are as
cold as they really are.

    .venv/bin/python benchmarks/profile_pick_and_place.py [SECONDS]
"""

from __future__ import annotations

import collections
import sys
import time
from pathlib import Path
from typing import Any

import earl
import earl.runtime.engine as engine_module

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "pick_and_place"


def family(name: str) -> str:
    """`manip/a.motor[3]/re` counts as `manip/a.motor[*]/re`."""
    if "[" not in name:
        return name
    head, _, rest = name.partition("[")
    return f"{head}[*]{rest.partition(']')[2]}"


def main() -> int:
    duration = float(sys.argv[1]) if len(sys.argv) > 1 else 13.0
    sim = earl.simulate(earl.load(EXAMPLE), seed=0)
    clock = time.perf_counter
    spent: collections.Counter[str] = collections.Counter()
    calls: collections.Counter[str] = collections.Counter()

    def timed(label: str, function: Any) -> Any:
        def call(*arguments: Any) -> Any:
            started = clock()
            result = function(*arguments)
            spent[label] += clock() - started
            calls[label] += 1
            return result

        return call

    # every iteration of a subsystem runs the function compiled for its state (and, after a wait
    # for its obligatory buffers, the completion compiled for it): both are timed as the subsystem
    compile_iteration, compile_completion = engine_module.compile_iteration, engine_module.compile_completion

    def timed_iteration(engine: Any, state: Any) -> Any:
        return timed(family(engine.name), compile_iteration(engine, state))

    def timed_completion(engine: Any, state: Any) -> Any:
        return timed(family(engine.name), compile_completion(engine, state))

    engine_module.compile_iteration = timed_iteration  # type: ignore[assignment]
    engine_module.compile_completion = timed_completion  # type: ignore[assignment]
    for engine in sim.network.engines:
        seen: set[int] = set()
        for state in engine.states.values():
            for stage in state.behaviour.stages:
                for function in stage:
                    if id(function) not in seen:
                        seen.add(id(function))
                        function.function = timed(f"{family(engine.name)} {function.name}/pf", function.function)
    scheduler: Any = sim.scheduler
    if scheduler._advance is not None:
        scheduler._advance = timed("physics (environment.advance)", scheduler._advance)
    started = clock()
    sim.advance_to(duration)
    total = clock() - started
    sim.close()
    print(f"{duration:g} s simulated in {total:.2f} s ({duration / total:.1f}x real time)")
    print(f"{'seconds':>8} {'share':>6} {'calls':>8} {'per call':>10}  what")
    for label, seconds in sorted(spent.items(), key=lambda item: -item[1]):
        indent = "    " if label.endswith("/pf") else ""
        share = 100 * seconds / total
        per_call = 1e6 * seconds / calls[label]
        print(f"{seconds:8.3f} {share:5.1f}% {calls[label]:8} {per_call:8.1f} us  {indent}{label}")
    outside = total - sum(v for k, v in spent.items() if not k.endswith("/pf"))
    print(f"{outside:8.3f} {100 * outside / total:5.1f}%                      the scheduler and everything else")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
