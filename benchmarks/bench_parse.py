"""Benchmark of reading a spec against the figure of issue 2.

Goal: parse and resolve a generated spec of 1,000 agents (each with a cs, two ve/re pairs
and a vr/rr pair) in under 2 s.  The spec comes from benchmarks/generate.py: every agent
written out in full, complete and valid (`earl check` finds no errors in it).

Each size is read as `earl.load` reads a file, split into its phases: decoding the bytes,
parsing (Lark's LALR parser building the elements as it reduces) and resolving names.  The
named peer is *Lark alone*: the same grammar parsed by Lark the usual way, into a parse tree
with positions and nothing else (no elements, no names resolved), so the table says what the
model costs on top of the parser it is built on.

A third figure splits earl's own time: *the loop alone* is the reader's loop (driver.py: the
same scanners, the same parse table, the same calls) with every rule's callback replaced by
one that builds nothing.  What earl's read costs beyond it is the model: building the
elements as rules reduce, and resolving names.  When that part alone exceeds the goal, no
faster loop (a compiled one included) can meet it; only building the model more cheaply can.

Every figure is the median of several runs, as wall-clock time and as the process's CPU time
(the machine may be shared with other work; CPU time is what an idle machine shows as wall time).
earl's reads and Lark's parses alternate, and the ratio of their CPU times is taken per pair:
this machine's speed drifts by up to 1.5x within minutes.

    .venv/bin/python benchmarks/bench_parse.py            # 100 and 1,000 agents, 3 runs each
    .venv/bin/python benchmarks/bench_parse.py --quick    # 20 agents, one run: a smoke test
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from lark import Lark  # noqa: E402

from earl.collector import paused as collection_paused  # noqa: E402
from earl.diagnostics import SourceMap  # noqa: E402
from earl.lang.driver import Driver  # noqa: E402
from earl.lang.loader import merge  # noqa: E402
from earl.lang.parser import _element_parser, _grammar, decode, parse_text  # noqa: E402
from earl.lang.reductions import PASS_THROUGH  # noqa: E402
from earl.lang.resolver import resolve  # noqa: E402
from earl.model.elements import System  # noqa: E402
from generate import generate  # noqa: E402

RESULTS = HERE / "results" / "parse.json"

TARGET_SECONDS = 2.0
TARGET_AGENTS = 1000


@dataclass(frozen=True)
class Timing:
    wall: float
    cpu: float


def timed(function: Callable[[], Any]) -> tuple[Any, Timing]:
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, Timing(time.perf_counter() - wall, time.process_time() - cpu)


def median(timings: list[Timing]) -> Timing:
    return Timing(statistics.median(t.wall for t in timings), statistics.median(t.cpu for t in timings))


def total(*timings: Timing) -> Timing:
    return Timing(sum(t.wall for t in timings), sum(t.cpu for t in timings))


@dataclass(frozen=True)
class ReadRun:
    decode: Timing
    parse: Timing
    resolve: Timing

    @property
    def total(self) -> Timing:
        return total(self.decode, self.parse, self.resolve)


def read_once(data: bytes) -> tuple[ReadRun, System]:
    """Decode, parse and resolve as `earl.load` does, each phase timed."""
    sources = SourceMap()
    with collection_paused():
        text, decoding = timed(lambda: decode(data, "bench.earl"))
        parsed, parsing = timed(lambda: parse_text(text, "bench.earl", sources))

        def resolve_all() -> System:
            system = merge(parsed, [], sources)
            errors = [d for d in resolve(system, {}) if d.severity.value == "error"]
            if errors:
                raise SystemExit(f"the generated spec does not resolve: {errors[0]}")
            return system

        system, resolving = timed(resolve_all)
    return ReadRun(decoding, parsing, resolving), system


def lark_tree_parser() -> Lark:
    """The peer: the same grammar, parsed the way Lark parses by default, into a tree with positions."""
    return Lark(_grammar(), parser="lalr", propagate_positions=True, maybe_placeholders=False, cache=True)


def _build_nothing(children: list[Any]) -> None:
    return None


def loop_alone() -> Driver:
    """earl's reading loop over the grammar's own tables, its rules building nothing."""
    lark = Lark(
        _grammar(),
        parser="lalr",
        propagate_positions=False,
        maybe_placeholders=False,
        strict=True,
        cache=True,
        lexer_callbacks={"COMMENT": lambda token: token},  # the reader's comment collector, keeping nothing
    )
    callbacks = lark.parser.parser.parser.callbacks
    for rule, callback in list(callbacks.items()):
        if not isinstance(rule, str) and callback is not PASS_THROUGH:  # str keys: terminals' callbacks
            callbacks[rule] = _build_nothing
    return Driver(lark)


def bench(sizes: list[int], runs: int, peer_runs: int) -> list[dict[str, Any]]:
    _element_parser()  # built (or loaded from Lark's cache) once, as in any process that reads specs
    peer = lark_tree_parser()
    loop = loop_alone()
    rows = []
    for agents in sizes:
        data = generate(agents).encode("utf-8")
        text = data.decode("utf-8")
        timings: list[ReadRun] = []
        peer_timings: list[Timing] = []
        loop_timings: list[Timing] = []
        # earl and Lark alternate, so that both meet the same moods of this machine, whose speed
        # drifts by up to 1.5x within minutes; the ratio of each pair is kept too
        for index in range(max(runs, peer_runs)):
            if index < runs:
                run, system = read_once(data)
                subsystems = sum(len(agent.subsystems) for agent in system.agents)
                links = len(system.links) + sum(len(agent.links) for agent in system.agents)
                del system
                gc.collect()  # the previous run's model, before the next is built
                timings.append(run)
                print(f"  {agents} agents: {run.total.wall:.2f} s wall, {run.total.cpu:.2f} s CPU", flush=True)
            if index < peer_runs:
                with collection_paused():
                    tree, timing = timed(lambda text=text: peer.parse(text))  # type: ignore[misc]
                del tree
                gc.collect()
                peer_timings.append(timing)
                print(f"  {agents} agents, Lark's tree parse: {timing.cpu:.2f} s CPU", flush=True)
            if index < runs:
                with collection_paused():
                    _, timing = timed(lambda text=text: loop.read(text))  # type: ignore[misc]
                loop_timings.append(timing)
                print(f"  {agents} agents, earl's loop alone: {timing.cpu:.2f} s CPU", flush=True)
        ratios = [run.total.cpu / timing.cpu for run, timing in zip(timings, peer_timings, strict=False)]
        # what the model costs: earl's whole read less its loop alone, pair by pair
        model = [run.total.cpu - timing.cpu for run, timing in zip(timings, loop_timings, strict=True)]
        tokens = sum(1 for token in peer.lex(text) if token.type not in ("WS", "COMMENT"))
        rows.append(
            {
                "agents": agents,
                "subsystems": subsystems,
                "links": links,
                "text_bytes": len(data),
                "tokens": tokens,
                "runs": runs,
                "decode": asdict(median([t.decode for t in timings])),
                "parse": asdict(median([t.parse for t in timings])),
                "resolve": asdict(median([t.resolve for t in timings])),
                "total": asdict(median([t.total for t in timings])),
                "peer_lark_tree_parse": asdict(median(peer_timings)) if peer_timings else None,
                "earl_over_lark_cpu_per_pair": ratios,
                "earl_over_lark_cpu_median": statistics.median(ratios) if ratios else None,
                "loop_alone": asdict(median(loop_timings)),
                "model_cpu_per_pair": model,
                "model_cpu_median": statistics.median(model),
            }
        )
    return rows


def table(rows: list[dict[str, Any]]) -> str:
    header = (
        f"{'agents':>7} {'MB':>6} {'tokens':>9} {'decode':>7} {'parse':>7} {'resolve':>8} "
        f"{'total':>7} {'total CPU':>9} {'peer: Lark tree':>16} {'peer CPU':>9} {'earl/Lark':>9} {'µs/token':>9}"
        f" {'loop CPU':>9} {'model CPU':>9}"
    )
    lines = [header, "-" * len(header)]
    for row in rows:
        peer = row["peer_lark_tree_parse"]
        peer_text = f"{peer['wall']:.2f}s" if peer else "-"
        peer_cpu = f"{peer['cpu']:.2f}s" if peer else "-"
        ratio = row["earl_over_lark_cpu_median"]
        ratio_text = f"{ratio:.2f}" if ratio is not None else "-"
        lines.append(
            f"{row['agents']:>7} {row['text_bytes'] / 1e6:>6.2f} {row['tokens']:>9} "
            f"{row['decode']['wall']:>6.2f}s {row['parse']['wall']:>6.2f}s {row['resolve']['wall']:>7.2f}s "
            f"{row['total']['wall']:>6.2f}s {row['total']['cpu']:>8.2f}s "
            f"{peer_text:>16} {peer_cpu:>9} {ratio_text:>9} "
            f"{row['total']['cpu'] / row['tokens'] * 1e6:>9.2f} "  # CPU time per token read
            f"{row['loop_alone']['cpu']:>8.2f}s {row['model_cpu_median']:>8.2f}s"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="20 agents, one run: a smoke test")
    parser.add_argument("--runs", type=int, default=3, help="runs per size (default 3)")
    arguments = parser.parse_args(argv)
    if arguments.quick:
        sizes, runs, peer_runs = [20], 1, 1
    else:
        sizes, runs, peer_runs = [100, TARGET_AGENTS], arguments.runs, arguments.runs
    rows = bench(sizes, runs, peer_runs)
    print()
    print(table(rows))
    goal = next((row for row in rows if row["agents"] == TARGET_AGENTS), None)
    verdict: dict[str, Any] = {"target_seconds": TARGET_SECONDS, "target_agents": TARGET_AGENTS}
    if goal is not None:
        verdict["wall_seconds"] = goal["total"]["wall"]
        verdict["cpu_seconds"] = goal["total"]["cpu"]
        verdict["met"] = goal["total"]["wall"] < TARGET_SECONDS
        verdict["model_cpu_seconds"] = goal["model_cpu_median"]
        state = "met" if verdict["met"] else "NOT met"
        print(
            f"\ngoal: {TARGET_AGENTS} agents parsed and resolved in < {TARGET_SECONDS:.0f} s: {state} "
            f"({goal['total']['wall']:.2f} s wall, {goal['total']['cpu']:.2f} s CPU; of which the model, "
            f"beyond the reading loop alone: {goal['model_cpu_median']:.2f} s CPU)"
        )
    if not arguments.quick:
        RESULTS.parent.mkdir(exist_ok=True)
        document = {
            "benchmark": "parse",
            "goal": verdict,
            "machine": {
                "python": platform.python_version(),
                "implementation": platform.python_implementation(),
                "processor": platform.machine(),
                "cpus": os.cpu_count(),
                "load_average_at_end": os.getloadavg(),
            },
            "sizes": rows,
        }
        RESULTS.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
        print(f"results: {RESULTS}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
