"""A link between two processes: earl's Zenoh transport against raw Zenoh pub/sub, same payloads.

    .venv/bin/python benchmarks/bench_zenoh.py

Two OS processes on 127.0.0.1 (this one, the sender, and a receiver child), peer mode,
explicit endpoints.  For 64 B and 4 KiB messages (a `double[7]` and a `double[511]`: 67 B
and 4100 B on the wire with earl's 8-byte type fingerprint and msgpack ext header; raw
Zenoh sends byte strings of exactly the length earl's codec writes):

- **latency**, one way: the sender stamps each message with the clock (`time.perf_counter`
  is CLOCK_MONOTONIC, one clock for every process of a host) just before handing it to
  the link, and the receiver's own code takes the clock as it first reads it; p50 and p99
  over the samples.  A message goes every PACE seconds, as a control loop sends, so none
  waits behind another.  Each figure is the median of REPEATS runs; every repeat runs earl
  and its two peers interleaved in blocks, in an order rotated from one repeat to the next
  (the spread over the repeats is in the results too);
- **throughput**: the sender publishes as fast as it can for a fixed time; the receiver
  counts what it received and for how long (messages per second at the receiver).

The earl receiver is a real earl process: the Python API's `Simulation` in real time over
the Zenoh transport, as `earl run --transport zenoh --agents echo/a` runs it.  Its
subsystem waits for `in/ib` (obligatory) and its partial transition function `take/pf`
reads the stamp, so earl's figure covers the codec on both sides, the transport, the
scheduler and the engine up to the user's code.  The sender is earl's transport serving
the link built by the real builder (encode and publish), driven from this process.  The
raw receiver is the least a Python program can do: it reads the stamp in the subscriber
callback.  "raw + handover" reads it in the main thread after a hand-over from the callback,
as a control loop in its own thread must.  Results go to benchmarks/results/zenoh.json.
Goals (issue 7): earl latency <= 1.2x raw, throughput >= 0.8x raw.
"""

from __future__ import annotations

import json
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections import deque
from pathlib import Path
from typing import Any

import zenoh

import earl
from earl.model.expand import expand
from earl.model.types import TypeReference
from earl.runtime.builder import build_network
from earl.runtime.engine import Destination, SubsystemEngine
from earl.runtime.events import Recorder
from earl.runtime.simulation import Simulation
from earl.runtime.values import TypeSystem
from earl.transport.codec import LinkCodec
from earl.transport.zenoh_transport import ZenohTransport, default_config

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results" / "zenoh.json"
SIZES = {"64 B": 7, "4 KiB": 511}  # doubles per message: 8 + 3 + 8*7 = 67 B, 8 + 4 + 8*511 = 4100 B
#: stamped messages per peer and repeat
MESSAGES = 1000
#: seconds between two stamped messages: a 1 kHz control loop's pace
PACE = 0.001
#: each measurement is repeated, rotating the order of earl and its peers, and the median of each figure kept
REPEATS = 5
WARM_UP = 100
#: messages of one peer in a row before the next peer's: short enough to share the machine's moods
BLOCK = 50
THROUGHPUT_SECONDS = 1.5
# The first element of a message says what it is: a stamp (> 0, seconds of time.perf_counter),
# or one of these.
COUNT, END_COUNT, QUIT, REPORT = -1.0, -2.0, -3.0, -5.0

SPEC = """\
system bench
param K: int = 6
ping/a {
    cs {
        period 1 ms
        back/ib: double[K]
        out/ob: double[K]
        last/m: double[K]
        false/pp = false
        copy/pf(back/ib -> last/mo) = python "benchcode:copy"
        send/pf(last/mi -> out/ob) = python "benchcode:send"
        run/bb {
            tf = {copy/pf} then {send/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb
        }
    }
}
echo/a {
    cs {
        in/ib: double[K] fifo 1000000
        back/ob: double[K]
        last/m: double[K]
        false/pp = false
        take/pf(in/ib -> last/mo) = python "benchcode:take"
        answer/pf(last/mi -> back/ob) = python "benchcode:answer"
        run/bb {
            tf = {take/pf} then {answer/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb { obligatory in/ib }
        }
    }
}
link ping,echo: ping/a.cs.out -> echo/a.cs.in
link echo,ping: echo/a.cs.back -> ping/a.cs.back
benchRobot/r {
    ping/a
    echo/a
    link ping,echo
    link echo,ping
}
"""

CODE = """\
import time

COUNT, END_COUNT, QUIT, REPORT = -1.0, -2.0, -3.0, -5.0
done = False
#: one-way latencies, seconds
latencies = []
_count, _first, _last = 0, 0.0, 0.0


def copy(i, o, c): o.last = i.back
def send(i, o, c): o.out = i.last


def take(i, o, c):
    global done, _count, _first, _last
    value = i["in/ib"]
    head = value[0]
    if head > 0.0:  # stamped when it was sent
        latencies.append(time.perf_counter() - head)
    elif head == COUNT:  # the throughput phase: count
        _last = time.perf_counter()
        if _count == 0:
            _first = _last
        _count += 1
    elif head == END_COUNT:  # its end: answer with the count and how long it took
        value = (REPORT, float(_count), _last - _first) + value[3:]
        _count = 0
    elif head == QUIT:
        done = True
    o.last = value


def answer(i, o, c):
    if i.last[0] == REPORT:
        o.back = i.last
"""


# ---------------------------------------------------------------- earl side
class EarlEnd:
    """One agent of the bench spec in this process: its input channel and its output's sink."""

    def __init__(self, directory: Path, agent: str, doubles: int, listen: str, connect: str) -> None:
        system = earl.load(directory / "system.earl")
        expanded = expand(system, {"K": doubles})
        self.transport = ZenohTransport("bench", [agent], default_config([listen], [connect]), lambda _: None)
        network = build_network(
            expanded, recorder=Recorder(), agents={agent}, remote=self.transport, code_directories=[directory]
        )
        engine: SubsystemEngine = network.engines[0]
        self.channel = next(iter(engine.channels.values()))
        destination: Destination = next(iter(engine.destinations.values()))[0]
        self.sink = destination.channel
        self.transport.start()
        self.inbox = self.transport.inbox

    def receive(self, timeout: float) -> Any:
        """The next message in the input buffer's channel, as the scheduler would deliver it."""
        deadline = time.perf_counter() + timeout
        queue = self.channel.queue
        while not queue:
            remaining = deadline - time.perf_counter()
            if remaining <= 0:
                raise TimeoutError("no message")
            self.inbox.wait(remaining)
            self.inbox.drain(0)
        return queue.popleft()

    def close(self) -> None:
        self.transport.close()


def earl_receiver(directory: Path, doubles: int, listen: str, connect: str, out: Path) -> None:
    """echo/a as `earl run --realtime --transport zenoh --agents echo/a` runs it, through the Python API;
    the latencies its `take/pf` measured go to `out` (JSON) when the sender says QUIT."""
    transport = ZenohTransport("bench", ["echo/a"], default_config([listen], [connect]), lambda _: None)
    try:
        simulation = Simulation(
            earl.load(directory / "system.earl"),
            parameters={"K": doubles},
            environment=None,
            realtime=True,
            agents=["echo/a"],
            transport=transport,
        )
    except BaseException:
        transport.close()  # else Zenoh's threads keep the process alive
        raise
    import benchcode  # type: ignore[import-not-found]  # bound by the Simulation: the module its functions live in

    print("ready", flush=True)
    try:
        deadline = 300.0  # seconds of run time: the sender ends it long before
        while not benchcode.done and simulation.time < deadline:
            simulation.advance_to(simulation.time + 0.5, lambda: bool(benchcode.done))
    finally:
        simulation.close()
        out.write_text(json.dumps(benchcode.latencies))


# ---------------------------------------------------------------- raw side
_HEAD = struct.Struct("<d")


class RawEnd:
    def __init__(self, listen: str, connect: str, subscribe: str, publish: str) -> None:
        self.session = zenoh.open(default_config([listen], [connect]))
        self.publisher = self.session.declare_publisher(publish, express=True)
        self.received: deque[bytes] = deque()
        self.event = threading.Event()
        self.subscriber = self.session.declare_subscriber(subscribe, self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        self.received.append(sample.payload.to_bytes())
        self.event.set()

    def receive(self, timeout: float) -> bytes:
        deadline = time.perf_counter() + timeout
        while not self.received:
            remaining = deadline - time.perf_counter()
            if remaining <= 0:
                raise TimeoutError("no message")
            self.event.wait(remaining)
            self.event.clear()
        return self.received.popleft()


def raw_receiver(listen: str, connect: str, handover: bool, out: Path) -> None:
    """Read each message's stamp in the subscriber callback, or (`handover`) in the main thread after a
    hand-over, as a control loop must; the latencies go to `out` (JSON) at QUIT."""
    session = zenoh.open(default_config([listen], [connect]))
    publisher = session.declare_publisher("raw/back", express=True)
    state: dict[str, Any] = {"count": 0, "first": 0.0, "last": 0.0}
    latencies: list[float] = []
    done = threading.Event()
    arrived: deque[bytes] = deque()
    wake = threading.Event()
    clock = time.perf_counter
    head_of = _HEAD.unpack_from

    def on_sample(sample: zenoh.Sample) -> None:
        if handover:
            idle = not arrived
            arrived.append(sample.payload.to_bytes())
            if idle:
                wake.set()
        else:
            handle(sample.payload.to_bytes())

    def handle(payload: bytes) -> None:
        head = head_of(payload)[0]
        if head > 0.0:
            latencies.append(clock() - head)
        elif head == COUNT:
            state["last"] = clock()
            if state["count"] == 0:
                state["first"] = state["last"]
            state["count"] += 1
        elif head == END_COUNT:
            report = json.dumps({"count": state["count"], "seconds": state["last"] - state["first"]}).encode()
            publisher.put(report)
            state["count"] = 0
        elif head == QUIT:
            done.set()

    subscriber = session.declare_subscriber("raw/out", on_sample)
    print("ready", flush=True)
    deadline = time.monotonic() + 300
    while handover and not done.is_set() and time.monotonic() < deadline:
        if not arrived:
            wake.wait(1.0)
        wake.clear()
        while arrived:
            handle(arrived.popleft())
    done.wait(max(0.0, deadline - time.monotonic()))
    del subscriber
    session.close()  # type: ignore[no-untyped-call]
    out.write_text(json.dumps(latencies))


# ---------------------------------------------------------------- the measuring side
def free_ports(count: int) -> list[int]:
    sockets = [socket.socket() for _ in range(count)]
    for s in sockets:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in sockets]
    for s in sockets:
        s.close()
    return ports


def child(arguments: list[str]) -> subprocess.Popen[str]:
    process = subprocess.Popen(
        [sys.executable, __file__, *arguments], stdout=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True
    )
    assert process.stdout is not None
    if process.stdout.readline().strip() != "ready":
        process.kill()
        raise RuntimeError(f"the echo process did not start: {arguments}")
    return process


def percentile(samples: list[float], fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


class EarlPeer:
    """earl's link: this process sends from ping/a, an echo/a child receives."""

    def __init__(self, directory: Path, doubles: int, scratch: Path) -> None:
        mine, theirs = free_ports(2)
        listen, connect = f"tcp/127.0.0.1:{mine}", f"tcp/127.0.0.1:{theirs}"
        self.out = scratch / f"earl-{mine}.json"
        self.receiver = child(["earl-receiver", str(directory), str(doubles), connect, listen, str(self.out)])
        self.end = EarlEnd(directory, "ping/a", doubles, listen, connect)
        self.end.transport.wait_for_peers(10)
        self.rest = tuple(float(i + 1) for i in range(doubles - 1))

    def send_stamped(self) -> None:
        self.end.sink.deliver((time.perf_counter(), *self.rest))

    def throughput(self) -> tuple[float, float, int]:
        """(messages the receiver counted, over how many seconds, messages sent)."""
        end, marker = self.end, (COUNT, *self.rest)
        stop_at = time.perf_counter() + THROUGHPUT_SECONDS
        sent = 0
        while time.perf_counter() < stop_at:
            end.sink.deliver(marker)
            sent += 1
        time.sleep(0.3)  # as for raw Zenoh: the end marker is not lost in a full queue
        end.sink.deliver((END_COUNT, *self.rest))
        report = end.receive(15.0)
        return report[1], report[2], sent

    def close(self) -> list[float]:
        """The latencies the receiver measured."""
        self.end.sink.deliver((QUIT, *self.rest))
        self.receiver.wait(20)
        self.end.close()
        return list(json.loads(self.out.read_text()))


class RawPeer:
    """Raw Zenoh pub/sub of byte strings as long as earl's messages, to a receiver child."""

    def __init__(self, size: int, handover: bool, scratch: Path) -> None:
        mine, theirs = free_ports(2)
        listen, connect = f"tcp/127.0.0.1:{mine}", f"tcp/127.0.0.1:{theirs}"
        self.out = scratch / f"raw-{mine}.json"
        mode = "handover" if handover else "callback"
        self.receiver = child(["raw-receiver", connect, listen, mode, str(self.out)])
        self.end = RawEnd(listen, connect, "raw/back", "raw/out")
        self.rest = bytes(size - _HEAD.size)

    def send_stamped(self) -> None:
        self.end.publisher.put(_HEAD.pack(time.perf_counter()) + self.rest)

    def throughput(self) -> tuple[float, float, int]:
        end = self.end
        marker = _HEAD.pack(COUNT) + self.rest
        stop_at = time.perf_counter() + THROUGHPUT_SECONDS
        sent = 0
        while time.perf_counter() < stop_at:
            end.publisher.put(marker)
            sent += 1
        time.sleep(0.3)
        end.publisher.put(_HEAD.pack(END_COUNT) + self.rest)
        report = json.loads(end.receive(15.0))
        return report["count"], report["seconds"], sent

    def close(self) -> list[float]:
        self.end.publisher.put(_HEAD.pack(QUIT) + self.rest)
        self.receiver.wait(20)
        self.end.session.close()  # type: ignore[no-untyped-call]
        return list(json.loads(self.out.read_text()))


Peer = EarlPeer | RawPeer


def measure_together(peers: dict[str, Peer], order: list[str]) -> dict[str, tuple[float, float, int]]:
    """One repeat: the peers' stamped messages interleaved in blocks, so that all of them meet the same
    moments of a noisy machine; then each one's throughput, in `order`.  The latencies are with the
    receivers, read when they close."""
    time.sleep(0.5)  # the links settle
    pause = time.sleep
    for name in order:
        for _ in range(WARM_UP):
            peers[name].send_stamped()
            pause(PACE)
    for block in range(MESSAGES // BLOCK):
        for name in order[block % len(order) :] + order[: block % len(order)]:
            send = peers[name].send_stamped
            for _ in range(BLOCK):
                send()
                pause(PACE)
    return {name: peers[name].throughput() for name in order}


def _figures(samples: list[float], count: float, seconds: float, sent: int) -> dict[str, float]:
    return {
        "latency_p50_us": statistics.median(samples) * 1e6,
        "latency_p99_us": percentile(samples, 0.99) * 1e6,
        "throughput_msgs_per_s": count / seconds if seconds > 0 else 0.0,
        "delivered_fraction": count / sent if sent else 0.0,
    }


def wire_size(doubles: int) -> int:
    """The length of a `double[doubles]` message as earl's codec writes it."""
    types = TypeSystem(
        expand(earl.loads(f"system size\ntype M = double[{doubles}]\nx/a {{ cs {{ period 1 ms }} }}\n"), {})
    )
    return len(LinkCodec(types, TypeReference("M"), "the bench").encode((0.0,) * doubles))


def _medians(runs: list[dict[str, float]]) -> dict[str, float]:
    return {key: statistics.median(run[key] for run in runs) for key in runs[0]}


def main() -> int:
    results: dict[str, Any] = {
        "messages": MESSAGES,
        "pace_s": PACE,
        "latency": "one way: from the sender's call that sends to the receiver's code that reads",
        "throughput_seconds": THROUGHPUT_SECONDS,
        "repeats": REPEATS,
        "sizes": {},
    }
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        directory = Path(scratch)
        (directory / "system.earl").write_text(SPEC)
        (directory / "benchcode.py").write_text(CODE)
        for label, doubles in SIZES.items():
            size = wire_size(doubles)
            runs: dict[str, list[dict[str, float]]] = {"raw": [], "handed": [], "earl": []}
            names = list(runs)
            for repeat in range(REPEATS):
                order = names[repeat % 3 :] + names[: repeat % 3]
                peers: dict[str, Peer] = {}
                latencies: dict[str, list[float]] = {}
                try:
                    for name in order:
                        peers[name] = (
                            EarlPeer(directory, doubles, directory)
                            if name == "earl"
                            else RawPeer(size, name == "handed", directory)
                        )
                    throughputs = measure_together(peers, order)
                finally:
                    for name, peer in peers.items():
                        latencies[name] = peer.close()[WARM_UP:]
                for name in order:
                    runs[name].append(_figures(latencies[name], *throughputs[name]))
            raw, handed, mine = (_medians(runs[name]) for name in ("raw", "handed", "earl"))
            latency_ratio = mine["latency_p50_us"] / raw["latency_p50_us"]
            p99_ratio = mine["latency_p99_us"] / raw["latency_p99_us"]
            throughput_ratio = mine["throughput_msgs_per_s"] / raw["throughput_msgs_per_s"]
            results["sizes"][label] = {
                "bytes": size,
                "earl": mine,
                "raw_zenoh": raw,
                "raw_zenoh_with_handover": handed,
                "earl_latency_p50_ratio_per_repeat": [
                    e["latency_p50_us"] / r["latency_p50_us"] for e, r in zip(runs["earl"], runs["raw"], strict=True)
                ],
                "runs": runs,
                "latency_p50_ratio": latency_ratio,
                "latency_p99_ratio": p99_ratio,
                "throughput_ratio": throughput_ratio,
                "latency_goal_met": latency_ratio <= 1.2,
                "throughput_goal_met": throughput_ratio >= 0.8,
            }
            for name, key, ratio, goal in [
                (f"{label} latency p50 (us)", "latency_p50_us", latency_ratio, 1.2),
                (f"{label} latency p99 (us)", "latency_p99_us", p99_ratio, 1.2),
                (f"{label} throughput (msg/s)", "throughput_msgs_per_s", throughput_ratio, 0.8),
            ]:
                rows.append((name, mine[key], raw[key], handed[key], ratio, goal))
    print(f"{'benchmark':30} {'earl':>10} {'raw zenoh':>10} {'raw+handover':>13} {'ratio':>6}  goal (earl/raw)")
    for name, mine_value, raw_value, handed_value, ratio, goal in rows:
        if "throughput" in name:
            verdict = f"ratio >= {goal} {'met' if ratio >= goal else 'NOT met'}"
        else:
            verdict = f"ratio <= {goal} {'met' if ratio <= goal else 'NOT met'}"
        print(f"{name:30} {mine_value:10,.1f} {raw_value:10,.1f} {handed_value:13,.1f} {ratio:6.2f}  {verdict}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")
    print(f"results: {RESULTS}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "earl-receiver":
        earl_receiver(Path(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5], Path(sys.argv[6]))
    elif len(sys.argv) > 1 and sys.argv[1] == "raw-receiver":
        raw_receiver(sys.argv[2], sys.argv[3], sys.argv[4] == "handover", Path(sys.argv[5]))
    else:
        raise SystemExit(main())
