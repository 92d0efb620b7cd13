"""Runtime benchmarks (issue: `earl run`), each against its named peer in the same run.

1. engine overhead: the runtime against a hand-written Python loop that calls the same
   partial transition functions in the same order (goal: at most 1.5x its time);
2. iterations per second of a subsystem with a trivial behaviour, on one core (goal: >= 300,000);
3. a transition-heavy FSM against the same FSM in `transitions` and `python-statemachine`
   (goal: faster than both);
4. a 1 kHz real-time loop: start lateness p50 / p99 against a bare Python periodic loop
   (goal: p99 at most 1.2x the bare loop's).

    .venv/bin/python benchmarks/bench_runtime.py          # writes benchmarks/results/runtime.json

Times are medians of the process's CPU time (the goals are "on one core", and the machine may
be shared); the real-time figures are wall-clock lateness, as they must be.
"""

from __future__ import annotations

import contextlib
import gc
import json
import platform
import statistics
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import earl

HERE = Path(__file__).resolve().parent
REPEATS = 5
#: engine and hand-loop runs, alternating (see engine_against_hand_loop)
PAIRS = 11

WORKLOAD_SPEC = """\
system workload

param N: int = 6

loop/a {
    cs {
        period 1 ms

        position/m: double[N] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        target/m: double[N] = [1.0, 0.5, -0.5, 0.25, 0.0, -1.0]
        current/m: double[N] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        integral/m: double[N] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        done/m: boolean = false

        false/pp = false

        regulate/pf(position/mi, target/mi, integral/mi -> current/mo, integral/mo) = python "workload:regulate"
        integrate/pf(position/mi, current/mi -> position/mo) = python "workload:integrate"
        finish/pf(position/mi, target/mi -> done/mo) = python "workload:finish"

        run/bb {
            tf = {regulate/pf, finish/pf} then {integrate/pf}
            tc = false/pp
        }

        fsm {
            initial run
            state run: run/bb
        }
    }
}

r/r {
    loop/a
}
"""

WORKLOAD_CODE = """\
def regulate(inputs, outputs, context):
    # the PI law of Eq. (2)-(3) per joint, in plain Python
    currents = []
    integrals = []
    for position, target, integral in zip(inputs.position, inputs.target, inputs.integral):
        error = target - position
        integral = integral + error * 0.001
        integrals.append(integral)
        currents.append(2.0 * error + 0.5 * integral)
    outputs.current = currents
    outputs.integral = integrals


def integrate(inputs, outputs, context):
    outputs.position = [p + 0.001 * c for p, c in zip(inputs.position, inputs.current)]


def finish(inputs, outputs, context):
    outputs.done = all(abs(t - p) < 1e-3 for p, t in zip(inputs.position, inputs.target))
"""

NUMERIC_CODE = """\
import numpy as np

# a fixed 6x6 map standing in for a manipulator Jacobian: the work real controllers do per period
_JACOBIAN = np.random.default_rng(0).normal(size=(6, 6))


def regulate(inputs, outputs, context):
    error = _JACOBIAN.T @ (np.array(inputs.target) - np.array(inputs.position))
    integral = np.array(inputs.integral) + error * 0.001
    outputs.current = 2.0 * error + 0.5 * integral
    outputs.integral = integral


def integrate(inputs, outputs, context):
    outputs.position = np.array(inputs.position) + 0.001 * np.array(inputs.current)


def finish(inputs, outputs, context):
    outputs.done = bool(np.all(np.abs(np.array(inputs.target) - np.array(inputs.position)) < 1e-3))
"""

TRIVIAL_SPEC = """\
system trivial

spin/a {
    cs {
        period 1 us

        n/m: int = 0

        false/pp = false

        step/pf(n/mi -> n/mo) = python "trivial:step"

        run/bb {
            tf = {step/pf}
            tc = false/pp
        }

        fsm {
            initial run
            state run: run/bb
        }
    }
}

r/r {
    spin/a
}
"""

TRIVIAL_CODE = "def step(inputs, outputs, context):\n    outputs.n = inputs.n + 1\n"

STATES = 8


def fsm_spec() -> str:
    """A ring of STATES states: every behaviour ends after one iteration and the FSM moves on."""
    behaviours = "\n".join(
        f"        s{i}/bb {{\n            tf = {{}}\n            tc = true/pp\n        }}\n" for i in range(STATES)
    )
    states = "\n".join(f"            state s{i}: s{i}/bb" for i in range(STATES))
    transitions = "\n".join(f"            s{i} -> s{(i + 1) % STATES} when true/pp" for i in range(STATES))
    return f"""\
system ring

ring/a {{
    cs {{
        period 1 us

        true/pp = true

{behaviours}
        fsm {{
            initial s0
{states}

{transitions}
        }}
    }}
}}

r/r {{
    ring/a
}}
"""


def write_spec(directory: Path, name: str, spec: str, code: str | None) -> Path:
    folder = directory / name
    folder.mkdir()
    (folder / "system.earl").write_text(spec)
    if code is not None:
        (folder / f"{name}.py").write_text(code)
    return folder / "system.earl"


def median_time(function: Any, repeats: int = REPEATS) -> float:
    """Median CPU time of this process: the figures are "on one core", and the machine may be shared."""
    times = []
    for _ in range(repeats):
        with quiet_collector():
            started = time.process_time()
            function()
            times.append(time.process_time() - started)
    return statistics.median(times)


@contextlib.contextmanager
def quiet_collector() -> Iterator[None]:
    """Collect first, then pause the garbage collector while timing (for earl and its peers alike).

    A full collection scans every live object, and this process holds many (Lark's tables,
    NumPy, earlier runs): it would add a cost to whichever run it happens to land in.
    """
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


# ---------------------------------------------------------------------- 1. engine overhead
def engine_against_hand_loop(directory: Path, code: str, iterations: int = 20_000) -> dict[str, Any]:
    folder = directory / f"workload_{abs(hash(code))}"
    folder.mkdir()
    spec = write_spec(folder, "workload", WORKLOAD_SPEC, code)
    system = earl.load(spec)

    def engine_time() -> float:
        sim = earl.simulate(system, check=False)  # building the engines is not part of the loop
        with quiet_collector():
            started = time.process_time()
            sim.advance_to((iterations - 1) * 1e-3)
            elapsed = time.process_time() - started
        assert sim.state_of("loop/a.cs").iterations == iterations
        return elapsed

    import importlib.util

    module_spec = importlib.util.spec_from_file_location("workload_functions", spec.parent / "workload.py")
    assert module_spec is not None and module_spec.loader is not None
    workload = importlib.util.module_from_spec(module_spec)
    module_spec.loader.exec_module(workload)

    def as_tuple(value: Any) -> tuple[Any, ...]:
        return tuple(value.tolist() if hasattr(value, "tolist") else value)

    def hand_loop() -> None:
        # what a person writes by hand: the same functions, the same order, stage snapshots kept
        memory = {
            "position": (0.0,) * 6,
            "target": (1.0, 0.5, -0.5, 0.25, 0.0, -1.0),
            "current": (0.0,) * 6,
            "integral": (0.0,) * 6,
            "done": False,
        }
        context = SimpleNamespace(time=0.0, iteration=0)
        for _ in range(iterations):
            first = SimpleNamespace(**memory)
            out_regulate, out_finish = SimpleNamespace(), SimpleNamespace()
            workload.regulate(first, out_regulate, context)
            workload.finish(first, out_finish, context)
            memory["current"] = as_tuple(out_regulate.current)
            memory["integral"] = as_tuple(out_regulate.integral)
            memory["done"] = bool(out_finish.done)
            second = SimpleNamespace(**memory)
            out_integrate = SimpleNamespace()
            workload.integrate(second, out_integrate, context)
            memory["position"] = as_tuple(out_integrate.position)
            context.iteration += 1

    def hand_time() -> float:
        with quiet_collector():
            started = time.process_time()
            hand_loop()
            return time.process_time() - started

    # Interleaved pairs, the ratio taken within each pair: this machine's speed drifts over
    # seconds (a shared virtual machine), and a drift would otherwise favour whichever ran first.
    pairs = [(engine_time(), hand_time()) for _ in range(PAIRS)]
    ratio = statistics.median(engine / hand for engine, hand in pairs)
    return {
        "iterations": iterations,
        "pairs": PAIRS,
        "engine_s": statistics.median(engine for engine, _ in pairs),
        "hand_loop_s": statistics.median(hand for _, hand in pairs),
        "ratio": ratio,
        "ratio_spread": [min(e / h for e, h in pairs), max(e / h for e, h in pairs)],
        "goal": "ratio <= 1.5",
        "met": ratio <= 1.5,
    }


# ---------------------------------------------------------------------- 2. trivial behaviour
def trivial_iterations(directory: Path, iterations: int = 200_000) -> dict[str, Any]:
    spec = write_spec(directory, "trivial", TRIVIAL_SPEC, TRIVIAL_CODE)
    system = earl.load(spec)
    rates = []
    for _ in range(REPEATS):
        sim = earl.simulate(system, check=False)
        with quiet_collector():
            started = time.process_time()
            sim.advance_to((iterations - 1) * 1e-6)
            elapsed = time.process_time() - started
        rates.append(sim.state_of("spin/a.cs").iterations / elapsed)
    rate = statistics.median(rates)
    return {"iterations": iterations, "per_second": rate, "goal": ">= 300000", "met": rate >= 300_000}


# ---------------------------------------------------------------------- 3. FSM against libraries
def fsm_against_libraries(directory: Path, transitions_count: int = 50_000) -> dict[str, Any]:
    spec = write_spec(directory, "ring", fsm_spec(), None)
    system = earl.load(spec)

    def earl_fsm() -> None:
        sim = earl.simulate(system, check=False)
        sim.advance_to((transitions_count - 1) * 1e-6)
        assert sim.statistics.subsystems["ring/a.cs"].transitions  # the ring turned

    from statemachine import State, StateMachine
    from transitions import Machine

    names = [f"s{i}" for i in range(STATES)]

    def transitions_library() -> None:
        model = SimpleNamespace()
        machine = Machine(
            model=model,
            states=names,
            transitions=[
                {"trigger": "step", "source": names[i], "dest": names[(i + 1) % STATES], "conditions": lambda: True}
                for i in range(STATES)
            ],
            initial=names[0],
            auto_transitions=False,
        )
        assert machine is not None
        for _ in range(transitions_count):
            model.step()

    attributes: dict[str, Any] = {name: State(name, initial=(name == "s0")) for name in names}
    step = None
    for i in range(STATES):
        link = attributes[names[i]].to(attributes[names[(i + 1) % STATES]], cond=lambda: True)
        step = link if step is None else step | link
    attributes["step"] = step
    Ring = type("Ring", (StateMachine,), attributes)

    def statemachine_library() -> None:
        machine = Ring()
        for _ in range(transitions_count):
            machine.step()

    earl_time = median_time(earl_fsm, 3)
    transitions_time = median_time(transitions_library, 3)
    statemachine_time = median_time(statemachine_library, 3)
    return {
        "transitions": transitions_count,
        "earl_s": earl_time,
        "transitions_s": transitions_time,
        "python_statemachine_s": statemachine_time,
        "speedup_vs_transitions": transitions_time / earl_time,
        "speedup_vs_python_statemachine": statemachine_time / earl_time,
        "goal": "faster than both",
        "met": earl_time < transitions_time and earl_time < statemachine_time,
    }


# ---------------------------------------------------------------------- 4. real-time jitter
def percentile(samples: list[int], fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))] / 1e3


def realtime_jitter(directory: Path, iterations: int = 3_000) -> dict[str, Any]:
    spec = write_spec(directory, "periodic", TRIVIAL_SPEC.replace("period 1 us", "period 1 ms"), TRIVIAL_CODE)
    spec.parent.joinpath("trivial.py").write_text(TRIVIAL_CODE)
    system = earl.load(spec)
    sim = earl.simulate(system, check=False, realtime=True)
    sim.advance_to((iterations - 1) * 1e-3)
    earl_samples = sim.scheduler.lateness["spin/a.cs"].samples
    sim.close()

    # the bare loop a person writes: compute the next deadline, sleep until it, do the work
    period = 1_000_000
    bare_samples = []
    start = time.perf_counter_ns()
    for k in range(iterations):
        due = start + k * period
        remaining = due - time.perf_counter_ns()
        if remaining > 0:
            time.sleep(remaining / 1e9)
        bare_samples.append(time.perf_counter_ns() - due)
    return {
        "iterations": iterations,
        "earl_p50_us": percentile(earl_samples, 0.5),
        "earl_p99_us": percentile(earl_samples, 0.99),
        "bare_p50_us": percentile(bare_samples, 0.5),
        "bare_p99_us": percentile(bare_samples, 0.99),
        "p99_ratio": percentile(earl_samples, 0.99) / max(percentile(bare_samples, 0.99), 1e-9),
        "goal": "p99 <= 1.2x the bare loop",
        "met": percentile(earl_samples, 0.99) <= 1.2 * percentile(bare_samples, 0.99),
    }


def main() -> int:
    results: dict[str, Any] = {
        "machine": {"python": platform.python_version(), "processor": platform.machine(), "cores": 2},
        "when": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    with tempfile.TemporaryDirectory() as folder:
        directory = Path(folder)
        # light: pure-Python functions over six numbers, the harshest case for the engine's overhead;
        # numeric: NumPy functions doing what a controller does each period
        results["engine_vs_hand_loop"] = engine_against_hand_loop(directory, WORKLOAD_CODE)
        results["engine_vs_hand_loop_numeric"] = engine_against_hand_loop(directory, NUMERIC_CODE)
        results["trivial_behaviour"] = trivial_iterations(directory)
        results["fsm_vs_libraries"] = fsm_against_libraries(directory)
        results["realtime_1khz"] = realtime_jitter(directory)
    out = HERE / "results" / "runtime.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(results, indent=2) + "\n")
    n = results["engine_vs_hand_loop_numeric"]
    e, t, f, r = (
        results["engine_vs_hand_loop"],
        results["trivial_behaviour"],
        results["fsm_vs_libraries"],
        results["realtime_1khz"],
    )
    print(f"{'benchmark':34} {'earl':>14} {'peer':>14} {'ratio':>8}  goal")
    print(
        f"{'engine vs hand loop, light (s)':34} {e['engine_s']:14.3f} {e['hand_loop_s']:14.3f} {e['ratio']:8.2f}  {e['goal']} {'met' if e['met'] else 'NOT met'}"
    )
    print(
        f"{'engine vs hand loop, NumPy (s)':34} {n['engine_s']:14.3f} {n['hand_loop_s']:14.3f} {n['ratio']:8.2f}"
        f"  {n['goal']} {'met' if n['met'] else 'NOT met'}"
    )
    print(
        f"{'trivial behaviour (iter/s)':34} {t['per_second']:14,.0f} {'':>14} {'':>8}  {t['goal']} {'met' if t['met'] else 'NOT met'}"
    )
    print(
        f"{'FSM ring vs transitions (s)':34} {f['earl_s']:14.3f} {f['transitions_s']:14.3f} {f['speedup_vs_transitions']:7.1f}x  faster"
    )
    print(
        f"{'FSM ring vs python-statemachine':34} {f['earl_s']:14.3f} {f['python_statemachine_s']:14.3f} {f['speedup_vs_python_statemachine']:7.1f}x  faster"
    )
    print(f"{'1 kHz lateness p50 (us)':34} {r['earl_p50_us']:14.1f} {r['bare_p50_us']:14.1f}")
    print(
        f"{'1 kHz lateness p99 (us)':34} {r['earl_p99_us']:14.1f} {r['bare_p99_us']:14.1f} {r['p99_ratio']:8.2f}  {r['goal']} {'met' if r['met'] else 'NOT met'}"
    )
    print(f"results: {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
