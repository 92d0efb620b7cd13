"""A link between two processes: earl's Zenoh transport against raw Zenoh pub/sub, same payloads.

    .venv/bin/python benchmarks/bench_zenoh.py

Two OS processes on 127.0.0.1 (this one and an echo child), peer mode, explicit endpoints.
For 64 B and 4 KiB messages (a `double[7]` and a `double[511]`: 67 B and 4100 B on the wire
with earl's 8-byte type fingerprint and msgpack ext header; raw Zenoh sends byte strings of
exactly the length earl's codec writes):

- latency: ping-pong; one-way latency = round trip / 2; p50 and p99 over the samples;
  each figure is the median of REPEATS runs; every repeat runs earl and its two peers, in an
  order rotated from one repeat to the next so that none always runs first or last (the
  spread over the repeats is in the results too);
- throughput: the sender publishes as fast as it can for a fixed time; the receiver counts
  what it received and for how long (messages per second at the receiver).

The earl side is the real transport (earl.transport.zenoh_transport) serving links built
by the real builder: the sender's output goes through the codec and a publisher; the
receiver decodes and type-checks on Zenoh's thread, hands over through the inbox and
delivers into the input buffer's channel in its main thread, which is where a subsystem
would read it (the echo's buffer is a FIFO, so that every delivery is counted: a
latest-value buffer keeps only the newest).  The raw peer is the least a Python program can do: the echo publishes
from the subscriber callback, and the pinger wakes on a threading.Event.  Results go to
benchmarks/results/zenoh.json.  Goals (issue 7): earl latency <= 1.2x raw, throughput >= 0.8x raw.
"""

from __future__ import annotations

import json
import socket
import statistics
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
from earl.runtime.values import TypeSystem
from earl.transport.codec import LinkCodec
from earl.transport.zenoh_transport import ZenohTransport, default_config

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results" / "zenoh.json"
SIZES = {"64 B": 7, "4 KiB": 511}  # doubles per message: 8 + 3 + 8*7 = 67 B, 8 + 4 + 8*511 = 4100 B
ROUND_TRIPS = 1000
#: each measurement is repeated, rotating the order of earl and its peers, and the median of each figure kept
REPEATS = 5
WARM_UP = 200
#: round trips of one peer in a row before the next peer's: short enough to share the machine's moods
BLOCK = 50
THROUGHPUT_SECONDS = 1.5
#: the first element of the message that ends an earl echo (-1.0 and -2.0 mark the throughput phase)
QUIT = -3.0

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
        period 1 ms
        in/ib: double[K] fifo 1000000
        back/ob: double[K]
        last/m: double[K]
        false/pp = false
        copy/pf(in/ib -> last/mo) = python "benchcode:copy_in"
        send/pf(last/mi -> back/ob) = python "benchcode:send_back"
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
def copy(i, o, c): o.last = i.back
def send(i, o, c): o.out = i.last
def copy_in(i, o, c): o.last = i["in/ib"]
def send_back(i, o, c): o.back = i.last
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


def earl_echo(directory: Path, doubles: int, listen: str, connect: str) -> None:
    end = EarlEnd(directory, "echo/a", doubles, listen, connect)
    print("ready", flush=True)
    try:
        while True:
            try:
                value = end.receive(10.0)
            except TimeoutError:
                return
            if value and value[0] == QUIT:
                return
            if value and value[0] < 0:  # the throughput phase: count, do not answer
                _count_throughput(end, value)
                continue
            end.sink.deliver(value)
    finally:
        end.close()


def _count_throughput(end: EarlEnd, first: Any) -> None:
    count, started, last = 1, time.perf_counter(), time.perf_counter()
    while True:
        try:
            value = end.receive(1.0)
        except TimeoutError:
            break
        if value[0] == -2.0:  # end marker
            break
        count += 1
        last = time.perf_counter()
    end.sink.deliver((float(count), last - started) + (0.0,) * (len(first) - 2))


# ---------------------------------------------------------------- raw side
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


def raw_echo(size: int, listen: str, connect: str, handover: bool) -> None:
    """Echo raw bytes; with `handover`, from the main thread (as a control loop must), else from the callback."""
    session = zenoh.open(default_config([listen], [connect]))
    publisher = session.declare_publisher("raw/back", express=True)
    state: dict[str, Any] = {"count": 0, "first": 0.0, "last": 0.0}
    done = threading.Event()
    arrived: deque[bytes] = deque()
    wake = threading.Event()

    def on_sample(sample: zenoh.Sample) -> None:
        if handover:
            idle = not arrived
            arrived.append(sample.payload.to_bytes())
            if idle:
                wake.set()
        else:
            handle(sample.payload.to_bytes())

    def handle(payload: bytes) -> None:
        if payload[:1] == b"T":  # throughput phase
            if state["count"] == 0:
                state["first"] = time.perf_counter()
            state["count"] += 1
            state["last"] = time.perf_counter()
            return
        if payload[:1] == b"E":  # end of the throughput phase
            report = json.dumps({"count": state["count"], "seconds": state["last"] - state["first"]}).encode()
            publisher.put(b"R" + report)
            state["count"] = 0
            return
        if payload[:1] == b"Q":
            done.set()
            return
        publisher.put(payload)  # echo straight from the callback: the least work possible

    subscriber = session.declare_subscriber("raw/out", on_sample)
    print("ready", flush=True)
    deadline = time.monotonic() + 120
    while handover and not done.is_set() and time.monotonic() < deadline:
        if not arrived:
            wake.wait(1.0)
        wake.clear()
        while arrived:
            handle(arrived.popleft())
    done.wait(max(0.0, deadline - time.monotonic()))
    del subscriber
    session.close()  # type: ignore[no-untyped-call]


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
    """earl's link, both ways: this process's ping/a and an echo/a child."""

    def __init__(self, directory: Path, doubles: int) -> None:
        mine, theirs = free_ports(2)
        listen, connect = f"tcp/127.0.0.1:{mine}", f"tcp/127.0.0.1:{theirs}"
        self.echo = child(["earl-echo", str(directory), str(doubles), connect, listen])
        self.end = EarlEnd(directory, "ping/a", doubles, listen, connect)
        self.end.transport.wait_for_peers(10)
        self.value = tuple(float(i) for i in range(doubles))

    def round_trip(self) -> None:
        self.end.sink.deliver(self.value)
        self.end.receive(5.0)

    def throughput(self) -> tuple[float, float, int]:
        """(messages the echo counted, over how many seconds, messages sent)."""
        end, value = self.end, self.value
        marker = (-1.0, *value[1:])
        stop_at = time.perf_counter() + THROUGHPUT_SECONDS
        sent = 0
        while time.perf_counter() < stop_at:
            end.sink.deliver(marker)
            sent += 1
        end.sink.deliver((-2.0, *value[1:]))
        report = end.receive(15.0)
        return report[0], report[1], sent

    def close(self) -> None:
        self.end.sink.deliver((QUIT, *self.value[1:]))
        self.echo.wait(20)
        self.end.close()


class RawPeer:
    """Raw Zenoh pub/sub of byte strings as long as earl's messages, to an echo child."""

    def __init__(self, size: int, handover: bool) -> None:
        mine, theirs = free_ports(2)
        listen, connect = f"tcp/127.0.0.1:{mine}", f"tcp/127.0.0.1:{theirs}"
        self.echo = child(["raw-echo", str(size), connect, listen, "handover" if handover else "callback"])
        self.end = RawEnd(listen, connect, "raw/back", "raw/out")
        self.size = size
        self.payload = bytes(size)

    def round_trip(self) -> None:
        self.end.publisher.put(self.payload)
        self.end.receive(5.0)

    def throughput(self) -> tuple[float, float, int]:
        end = self.end
        marker = b"T" + bytes(self.size - 1)
        stop_at = time.perf_counter() + THROUGHPUT_SECONDS
        sent = 0
        while time.perf_counter() < stop_at:
            end.publisher.put(marker)
            sent += 1
        time.sleep(0.3)
        end.publisher.put(b"E")
        report = json.loads(end.receive(15.0)[1:])
        return report["count"], report["seconds"], sent

    def close(self) -> None:
        self.end.publisher.put(b"Q")
        self.end.session.close()  # type: ignore[no-untyped-call]
        self.echo.wait(20)


Peer = EarlPeer | RawPeer


def measure_together(peers: dict[str, Peer], order: list[str]) -> dict[str, dict[str, float]]:
    """One repeat: the peers' round trips interleaved in blocks, so that all of them meet the same
    moments of a noisy machine; then each one's throughput, in `order`."""
    time.sleep(0.5)  # the links settle
    for name in order:
        for _ in range(WARM_UP):
            peers[name].round_trip()
    samples: dict[str, list[float]] = {name: [] for name in peers}
    clock = time.perf_counter
    for block in range(ROUND_TRIPS // BLOCK):
        for name in order[block % len(order) :] + order[: block % len(order)]:
            round_trip, taken = peers[name].round_trip, samples[name]
            for _ in range(BLOCK):
                started = clock()
                round_trip()
                taken.append((clock() - started) / 2)
    return {name: _figures(samples[name], *peers[name].throughput()) for name in order}


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
        "round_trips": ROUND_TRIPS,
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
                try:
                    for name in order:
                        peers[name] = (
                            EarlPeer(directory, doubles) if name == "earl" else RawPeer(size, handover=name == "handed")
                        )
                    for name, figures in measure_together(peers, order).items():
                        runs[name].append(figures)
                finally:
                    for peer in peers.values():
                        peer.close()
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
    if len(sys.argv) > 1 and sys.argv[1] == "earl-echo":
        earl_echo(Path(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5])
    elif len(sys.argv) > 1 and sys.argv[1] == "raw-echo":
        raw_echo(int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[5] == "handover")
    else:
        raise SystemExit(main())
