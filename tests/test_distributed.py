"""Agents split over real OS processes on 127.0.0.1, linked by Zenoh (docs/distributed.md).

Every wait here is bounded: a process that does not print what is expected within
its deadline fails the test, and every process a test starts is killed at its end.
The pick-and-place test runs the MuJoCo example in real time and takes about half
a minute; the others a few seconds each.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

SPECS = Path(__file__).parent / "distributed_specs"
PINGPONG = SPECS / "pingpong"
PICK_AND_PLACE = Path(__file__).parent.parent / "examples" / "pick_and_place"
MOBILE_ROBOT = Path(__file__).parent.parent / "examples" / "mobile_robot"
PING = "struct Ping{count:int,stamp:double[2],note:string?}"
EARL_RUN = [sys.executable, "-m", "earl.cli.main", "run"]


def free_ports(count: int) -> list[int]:
    sockets = [socket.socket() for _ in range(count)]
    try:
        for s in sockets:
            s.bind(("127.0.0.1", 0))
        return [s.getsockname()[1] for s in sockets]
    finally:
        for s in sockets:
            s.close()


def deployment(tmp_path: Path, groups: list[tuple[list[str], bool]]) -> Path:
    path = tmp_path / "deploy.toml"
    lines = []
    for (agents, environment), port in zip(groups, free_ports(len(groups)), strict=True):
        names = ", ".join(f'"{a}"' for a in agents)
        lines += ["[[process]]", f"agents = [{names}]", f'listen = "tcp/127.0.0.1:{port}"']
        lines += [f"environment = {'true' if environment else 'false'}", ""]
    path.write_text("\n".join(lines))
    return path


class Process:
    """One `earl run` child whose output goes to a file the test reads while it runs."""

    def __init__(self, log: Path, arguments: list[str], command: str = "run") -> None:
        self.log = log
        self.stream = open(log, "wb")  # noqa: SIM115 — closed in stop()
        tail = ["--no-progress"] if command == "run" else []
        self.child = subprocess.Popen(
            [sys.executable, "-m", "earl.cli.main", command, *arguments, *tail],
            stdout=self.stream,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1", "COLUMNS": "200"},
        )

    @property
    def output(self) -> str:
        return self.log.read_text(encoding="utf-8", errors="replace")

    def wait_for(self, text: str, seconds: float, after: int = 0) -> int:
        """Where `text` first appears in the output after position `after`; fails after `seconds`."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            found = self.output.find(text, after)
            if found >= 0:
                return found
            if self.child.poll() is not None:
                found = self.output.find(text, after)
                if found >= 0:
                    return found
                pytest.fail(f"the process exited ({self.child.returncode}) before printing {text!r}:\n{self.output}")
            time.sleep(0.05)
        pytest.fail(f"no {text!r} within {seconds} s:\n{self.output}")

    def finish(self, seconds: float) -> int:
        try:
            return self.child.wait(timeout=seconds)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the process did not end within {seconds} s:\n{self.output}")

    def stop(self) -> None:
        if self.child.poll() is None:
            self.child.kill()
            self.child.wait(timeout=10)
        self.stream.close()


@pytest.fixture
def processes() -> Iterator[list[Process]]:
    started: list[Process] = []
    yield started
    for process in started:
        process.stop()


def run(processes: list[Process], log: Path, arguments: list[str]) -> Process:
    process = Process(log, arguments)
    processes.append(process)
    return process


def trace(path: Path) -> list[tuple[str, int, dict[str, Any]]]:
    with open(path, "rb") as stream:
        return [
            (channel.topic, message.log_time, json.loads(bytes(message.data)))
            for _, channel, message in make_reader(stream).iter_messages(log_time_order=True)
        ]


def endpoints(deploy: Path) -> list[str]:
    """The `listen` endpoints of a deployment file, in order."""
    return [line.split('"')[1] for line in deploy.read_text().splitlines() if line.startswith("listen = ")]


def received(output: str, link: str) -> int:
    """The count in a closing line `link LINK (KEY): N received, …`."""
    for line in output.splitlines():
        if line.startswith(f"link {link} (") and " received" in line:
            return int(line.split("): ", 1)[1].split(" ", 1)[0])
    raise AssertionError(f"no closing line for the link {link}:\n{output}")


def test_two_processes_exchange_messages_and_a_remote_message_wakes_a_waiting_subsystem(
    tmp_path: Path, processes: list[Process]
) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    sender_endpoint, receiver_endpoint = endpoints(deploy)
    # the sender passes its own Zenoh configuration (JSON5) instead of the deployment's endpoints
    config = tmp_path / "sender.json5"
    config.write_text(
        "// a user's own configuration, used unchanged\n{\n  mode: 'peer',\n"
        f"  listen: {{ endpoints: ['{sender_endpoint}'] }},\n  connect: {{ endpoints: ['{receiver_endpoint}'] }},\n"
        "  scouting: { multicast: { enabled: false } },\n}\n"
    )
    common = [str(PINGPONG), "--transport", "zenoh", "--duration", "2s"]
    receiver = run(
        processes,
        tmp_path / "receiver.log",
        [
            *common,
            "--agents",
            "receiver/a",
            "--deployment",
            str(deploy),
            "--trace",
            str(tmp_path / "r.mcap"),
            "--record-memory",
            "receiver/a.cs",
        ],
    )
    sender = run(processes, tmp_path / "sender.log", [*common, "--agents", "sender", "--zenoh-config", str(config)])
    assert sender.finish(60) == 0, sender.output
    assert receiver.finish(60) == 0, receiver.output
    # the receiver has no period: each of its iterations was started by a ping from the other process
    pings = received(receiver.output, "sender,receiver")
    echoes = received(sender.output, "receiver,sender")
    assert pings > 100 and echoes > 100, (receiver.output, sender.output)
    events = trace(tmp_path / "r.mcap")
    faults = [data for topic, _, data in events if topic == "/earl/faults"]
    # a ping whose arrays were not tuples, or not a Record, would be an exception fault of answer/pf
    assert not [f for f in faults if f["kind"] in ("exception", "type")], faults
    memory = [data for topic, _, data in events if topic == "/receiver/a.cs/memory"]
    # one iteration per ping (two pings between receives leave one: a latest-value buffer)
    assert 100 < memory[-1]["received"] <= pings, (memory[-1], pings)
    assert memory[-1]["lastPing"]["stamp"][1] == float(memory[-1]["lastPing"]["count"])
    assert "Traceback" not in receiver.output + sender.output


def test_a_killed_sender_leaves_its_receiver_holding_and_a_restarted_one_resumes_the_flow(
    tmp_path: Path, processes: list[Process]
) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    common = [str(PINGPONG), "--transport", "zenoh", "--deployment", str(deploy)]
    receiver = run(
        processes,
        tmp_path / "receiver.log",
        [*common, "--agents", "receiver/a", "--duration", "60s", "--trace", str(tmp_path / "r.mcap")],
    )
    first = run(processes, tmp_path / "first.log", [*common, "--agents", "sender/a", "--duration", "60s"])
    receiver.wait_for("sender/a is alive", 30)
    first.wait_for("starting", 30)
    time.sleep(1.0)
    os.kill(first.child.pid, signal.SIGKILL)
    lost = receiver.wait_for("sender/a disappeared: ping/ib are stale", 20)
    time.sleep(1.0)
    second = run(processes, tmp_path / "second.log", [*common, "--agents", "sender/a", "--duration", "2s"])
    receiver.wait_for("sender/a is alive: receiver/a.cs ping/ib receive again from it", 30, after=lost)
    assert second.finish(60) == 0, second.output
    receiver.child.send_signal(signal.SIGTERM)
    assert receiver.finish(30) == 130, receiver.output  # stopped by us: the trace is closed
    assert "Traceback" not in receiver.output
    events = trace(tmp_path / "r.mcap")
    stale = [t for topic, t, data in events if topic == "/earl/faults" and data["kind"] == "stale"]
    assert len(stale) >= 1
    changes = [(t, data["to"]) for topic, t, data in events if topic == "/receiver/a.cs/fsm"]
    # stale input: stale(ping/ib) holds, the receiver waits in `gone`; the restarted sender's pings bring it back
    assert any(t >= stale[0] and state == "gone" for t, state in changes), changes
    back = [t for t, state in changes if state == "listen" and t > stale[0]]
    assert back, changes
    assert received(second.output, "receiver,sender") > 50, second.output


def test_a_peer_with_another_data_type_is_refused_with_both_types_named(
    tmp_path: Path, processes: list[Process]
) -> None:
    other = tmp_path / "other"
    shutil.copytree(PINGPONG, other)
    spec = other / "system.earl"
    spec.write_text(spec.read_text().replace("stamp: double[2]", "stamp: double[3]"))
    (other / "pingpong" / "sender.py").write_text(
        (other / "pingpong" / "sender.py")
        .read_text()
        .replace("(context.time, float(count))", "(context.time, 0.0, 1.0)")
    )
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    common = ["--transport", "zenoh", "--deployment", str(deploy), "--duration", "2s"]
    receiver = run(processes, tmp_path / "receiver.log", [str(PINGPONG), *common, "--agents", "receiver/a"])
    sender = run(processes, tmp_path / "sender.log", [str(other), *common, "--agents", "sender/a"])
    # the run goes on, and fails at its end: the link's messages were lost (the sender is told by the receiver)
    assert sender.finish(60) == 1, sender.output
    assert receiver.finish(60) == 1, receiver.output
    theirs = PING.replace("double[2]", "double[3]")
    output = receiver.output
    assert f"refused a message of `{theirs}` from sender/a; receiver/a.cs ping/ib expects `{PING}`" in output
    # reported once (and shown again as the run's first fault), then counted
    assert output.count("earl run: receiver/a.cs: link sender,receiver") == 1
    line = next(line for line in output.splitlines() if line.startswith("link sender,receiver ("))
    refused = int(line.split(", ")[-1].split(" ")[0])
    assert refused > 50, line
    assert received(output, "sender,receiver") == 0
    # the sender, whose messages are lost, says it too (it counted them as sent)
    assert (
        f"earl run: link sender,receiver: receiver/a.cs refuses this process's messages of `{theirs}`: its ping/ib "
        f"expects `{PING}`" in sender.output
    ), sender.output
    # each names the lost links as it ends (the receiver's echo of its first iteration is refused too)
    for said, lost in ((output, f"sender,receiver ({refused} refused here)"), (sender.output, SENDER_TOLD)):
        last = said.splitlines()[-1]
        assert last.startswith("earl run: the link") and lost in last, said
        assert last.endswith(
            " lost messages of another data type: the processes run different specifications (exit code 1)"
        )


#: how a sender whose receiver refused its pings names the link, told by the receiver
SENDER_TOLD = "sender,receiver (receiver/a.cs refused this process's)"


def test_a_launch_whose_processes_disagree_on_a_data_type_reports_both_failed(tmp_path: Path) -> None:
    """A process given `--param N=3` in its `args` sends pings of `double[3]` where the other expects
    `double[2]`: both run to their end, name the lost link, and `earl launch` reports them failed, exit 1."""
    spec = tmp_path / "pingpong"
    shutil.copytree(PINGPONG, spec)
    system = spec / "system.earl"
    system.write_text(
        system.read_text()
        .replace("system pingPong\n", "system pingPong\n\nparam N: int = 2\n")
        .replace("stamp: double[2]", "stamp: double[N]")
    )
    sender = spec / "pingpong" / "sender.py"
    sender.write_text(
        sender.read_text().replace(
            "(context.time, float(count))", "(context.time, float(count)) + (0.0,) * (context.parameters['N'] - 2)"
        )
    )
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    deploy.write_text(
        deploy.read_text().replace("environment = false\n", 'environment = false\nargs = ["--param", "N=3"]\n', 1)
    )
    command = [sys.executable, "-m", "earl.cli.main", "launch", str(spec), "--deployment", str(deploy)]
    result = subprocess.run([*command, "--duration", "2s"], capture_output=True, text=True, timeout=120, check=False)
    output = result.stdout
    assert result.returncode == 1, output + result.stderr
    lost = {line[:12]: line for line in output.splitlines() if "lost messages of another data type" in line}
    assert "sender,receiver (" in lost["[receiver/a]"] and SENDER_TOLD in lost["[sender/a  ]"], output
    assert "[receiver/a] failed with exit code 1" in output and "[sender/a  ] failed with exit code 1" in output
    assert "Traceback" not in output + result.stderr


def test_peers_that_run_different_specifications_say_so_and_their_links_still_carry_messages(
    tmp_path: Path, processes: list[Process]
) -> None:
    # a timeout of the receiver changed in one copy: no link's data type shows it, so every message is accepted
    other = tmp_path / "other"
    shutil.copytree(PINGPONG, other)
    spec = other / "system.earl"
    spec.write_text(
        spec.read_text().replace(
            "state gone: gone/bb { obligatory ping/ib  timeout 200 ms }",
            "state gone: gone/bb { obligatory ping/ib  timeout 300 ms }",
        )
    )
    assert spec.read_text() != (PINGPONG / "system.earl").read_text()
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    common = ["--transport", "zenoh", "--deployment", str(deploy), "--duration", "2s"]
    receiver = run(processes, tmp_path / "receiver.log", [str(PINGPONG), *common, "--agents", "receiver/a"])
    sender = run(processes, tmp_path / "sender.log", [str(other), *common, "--agents", "sender/a"])
    assert sender.finish(60) == 0, sender.output
    assert receiver.finish(60) == 0, receiver.output
    said = "runs another specification than this process (digest "
    assert receiver.output.count(f"earl run: sender/a {said}") == 1, receiver.output
    assert sender.output.count(f"earl run: receiver/a {said}") == 1, sender.output
    assert "the spec, its imports or the --param values differ" in receiver.output
    assert received(receiver.output, "sender,receiver") > 50, receiver.output
    # the same spec read from another directory, with its comments changed, is the same system
    again = tmp_path / "again"
    shutil.copytree(PINGPONG, again)
    (again / "system.earl").write_text("// another copy\n" + (PINGPONG / "system.earl").read_text())
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    common = ["--transport", "zenoh", "--deployment", str(deploy), "--duration", "1s"]
    receiver = run(processes, tmp_path / "receiver2.log", [str(PINGPONG), *common, "--agents", "receiver/a"])
    sender = run(processes, tmp_path / "sender2.log", [str(again), *common, "--agents", "sender/a"])
    assert sender.finish(60) == 0, sender.output
    assert receiver.finish(60) == 0, receiver.output
    assert said not in receiver.output + sender.output, (receiver.output, sender.output)


def test_a_peer_whose_token_names_no_specification_is_alive_and_not_compared(
    tmp_path: Path, processes: list[Process]
) -> None:
    # an earlier earl's token is `alive/<agent>/<process>`, without the digest: it is a peer all the same
    import zenoh

    from earl.transport.zenoh_transport import default_config

    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    sender_endpoint, receiver_endpoint = endpoints(deploy)
    receiver = run(
        processes,
        tmp_path / "receiver.log",
        [
            *(str(PINGPONG), "--transport", "zenoh", "--deployment", str(deploy), "--duration", "1s"),
            *("--agents", "receiver/a", "--wait-for-peers", "20s"),
        ],
    )
    receiver.wait_for("waiting up to 20 s for sender/a", 30)
    session = zenoh.open(default_config([sender_endpoint], [receiver_endpoint]))
    try:
        token = session.liveliness().declare_token("earl/pingPong/alive/sender%2Fa/0123456789ab")
        receiver.wait_for("peers sender/a are alive; starting", 30)
        assert receiver.finish(60) == 0, receiver.output
        token.undeclare()  # type: ignore[no-untyped-call]
    finally:
        session.close()  # type: ignore[no-untyped-call]
    assert "another specification" not in receiver.output


def test_malformed_bytes_injected_on_a_link_key_are_counted_and_dropped(
    tmp_path: Path, processes: list[Process]
) -> None:
    import msgpack  # type: ignore[import-untyped]
    import zenoh

    from earl.transport.codec import fingerprint
    from earl.transport.zenoh_transport import default_config

    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    sender_endpoint, receiver_endpoint = endpoints(deploy)
    receiver = run(
        processes,
        tmp_path / "receiver.log",
        [
            *(str(PINGPONG), "--transport", "zenoh", "--deployment", str(deploy), "--duration", "4s"),
            *("--agents", "receiver/a", "--wait-for-peers", "0.5s"),
        ],
    )
    receiver.wait_for("starting without sender/a", 30)
    # the test plays a broken sender/a, listening where sender/a would
    session = zenoh.open(default_config([sender_endpoint], [receiver_endpoint]))
    try:
        publisher = session.declare_publisher("earl/pingPong/sender,receiver")
        ours = fingerprint(PING)
        garbage = [
            b"",
            b"\x01\x02",
            ours + b"\xc1",  # never valid msgpack
            ours + msgpack.packb({"count": "three", "stamp": [0.0, 0.0]}),
            ours + msgpack.packb([1, 2]),
            b"\xde\xad\xbe\xef" * 8,  # another fingerprint: refused, not malformed
        ]
        time.sleep(1.0)  # let the sessions meet
        for payload in garbage:
            publisher.put(payload)
        valid = ours + msgpack.packb({"count": 7, "stamp": [0.5, 7.0], "note": None})
        publisher.put(valid)
        assert receiver.finish(60) == 1, receiver.output  # a message refused is a message lost
    finally:
        session.close()  # type: ignore[no-untyped-call]
    output = receiver.output
    reported = "earl run: receiver/a.cs: link sender,receiver (earl/pingPong/sender,receiver): dropped malformed bytes"
    assert output.count(reported) == 1  # the first is reported, the others counted
    assert "refused a message of an unknown type (fingerprint deadbeefdeadbeef" in output
    assert (
        "link sender,receiver (earl/pingPong/sender,receiver): 1 received, 5 malformed (dropped), 1 refused" in output
    )
    assert "earl run: the link sender,receiver (1 refused here) lost messages of another data type" in output
    assert "Traceback" not in output


def test_a_peer_that_finishes_its_run_is_no_fault_but_one_killed_is(tmp_path: Path, processes: list[Process]) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    common = [str(PINGPONG), "--transport", "zenoh", "--deployment", str(deploy)]
    receiver = run(
        processes,
        tmp_path / "receiver.log",
        # long enough for the second sender to start, be seen and be killed on a busy machine
        [*common, "--agents", "receiver/a", "--duration", "12s", "--trace", str(tmp_path / "r.mcap")],
    )
    sender = run(processes, tmp_path / "sender.log", [*common, "--agents", "sender/a", "--duration", "2s"])
    assert sender.finish(60) == 0, sender.output
    finished = receiver.wait_for("sender/a finished its run: ", 30)
    again = run(processes, tmp_path / "again.log", [*common, "--agents", "sender/a", "--duration", "60s"])
    back = receiver.wait_for("sender/a is alive: receiver/a.cs ", 30, after=finished)
    time.sleep(0.5)
    os.kill(again.child.pid, signal.SIGKILL)
    receiver.wait_for("sender/a disappeared", 30, after=back)
    assert receiver.finish(60) == 0, receiver.output
    faults = [data for topic, _, data in trace(tmp_path / "r.mcap") if topic == "/earl/faults"]
    assert [f["kind"] for f in faults if f["kind"] == "stale"] == ["stale"], faults  # the kill alone


def test_an_agent_started_in_two_processes_is_reported(tmp_path: Path, processes: list[Process]) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    _, receiver_endpoint = endpoints(deploy)
    common = [str(PINGPONG), "--transport", "zenoh", "--duration", "20s"]
    receiver = run(processes, tmp_path / "receiver.log", [*common, "--deployment", str(deploy), "--agents", "receiver"])
    run(processes, tmp_path / "first.log", [*common, "--deployment", str(deploy), "--agents", "sender"])
    receiver.wait_for("sender/a is alive", 30)
    # the same agent once more, on an endpoint of its own (its own Zenoh configuration)
    [port] = free_ports(1)
    config = tmp_path / "again.json5"
    config.write_text(
        f"{{ mode: 'peer', listen: {{ endpoints: ['tcp/127.0.0.1:{port}'] }}, "
        f"connect: {{ endpoints: ['{receiver_endpoint}'] }}, scouting: {{ multicast: {{ enabled: false }} }} }}\n"
    )
    again = run(processes, tmp_path / "again.log", [*common, "--zenoh-config", str(config), "--agents", "sender"])
    receiver.wait_for("sender/a runs in 2 processes: the messages of its links mix", 30)
    again.wait_for("sender/a runs here and in another process", 30)


def pingpong_launched(tmp_path: Path, processes: list[Process]) -> Process:
    """`earl launch` of the ping-pong example in two processes for a minute, once both run."""
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    launch = Process(
        tmp_path / "launch.log", [str(PINGPONG), "--deployment", str(deploy), "--duration", "60s"], "launch"
    )
    processes.append(launch)
    # the labels are padded to the longest, so the columns line up
    launch.wait_for("[receiver/a] earl run: peers sender/a are alive; starting", 60)
    launch.wait_for("[sender/a  ] earl run: peers receiver/a are alive; starting", 60)
    return launch


def test_launch_starts_each_process_prefixes_its_output_and_stops_them_all_on_ctrl_c(
    tmp_path: Path, processes: list[Process]
) -> None:
    launch = pingpong_launched(tmp_path, processes)
    time.sleep(0.5)
    launch.child.send_signal(signal.SIGINT)  # what Ctrl-C sends
    assert launch.finish(30) == 130, launch.output
    output = launch.output
    pids = [int(line.split("(pid ")[1].split(")")[0]) for line in output.splitlines() if "] started (pid " in line]
    assert len(pids) == 2
    for pid in pids:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
    for label in ("[receiver/a]", "[sender/a  ]"):
        assert f"{label} stopping" in output
        assert f"{label} earl run: interrupted at" in output  # each closed its run (and trace) itself
    assert "Traceback" not in output


def _started_pids(output: str) -> list[int]:
    return [int(line.split("(pid ")[1].split(")")[0]) for line in output.splitlines() if "] started (pid " in line]


def _gone(pid: int, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGHUP])
def test_a_stop_signal_while_launch_starts_its_processes_leaves_none_running(
    tmp_path: Path, processes: list[Process], stop: int
) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    launch = Process(
        tmp_path / "launch.log", [str(PINGPONG), "--deployment", str(deploy), "--duration", "60s"], "launch"
    )
    processes.append(launch)
    launch.wait_for("] started (pid ", 60)
    launch.child.send_signal(stop)  # at once: the second process may be starting
    assert launch.finish(30) == 130, launch.output
    pids = _started_pids(launch.output)
    assert pids
    assert all(_gone(pid) for pid in pids), launch.output
    assert "Traceback" not in launch.output


def launch_command(deploy: Path, duration: str) -> list[str]:
    """`earl launch` of the ping-pong spec over `deploy`, each process running `duration`."""
    program = [sys.executable, "-m", "earl.cli.main", "launch"]
    return [*program, str(PINGPONG), "--deployment", str(deploy), "--duration", duration]


def test_processes_listening_on_one_port_of_ipv4_and_ipv6_loopback_exchange_messages(tmp_path: Path) -> None:
    """`tcp/127.0.0.1:P` and `tcp/[::1]:P` are two sockets: the deployment was refused as naming one endpoint."""
    with socket.socket(socket.AF_INET6) as probe:
        try:
            probe.bind(("::1", 0))
        except OSError:
            pytest.skip("this host has no IPv6 loopback")
    for _ in range(5):  # a port free on both loopbacks
        port = free_ports(1)[0]
        with socket.socket(socket.AF_INET6) as probe, contextlib.suppress(OSError):
            probe.bind(("::1", port))
            break
    deploy = tmp_path / "deploy.toml"
    deploy.write_text(
        f'[[process]]\nagents = ["sender/a"]\nlisten = "tcp/127.0.0.1:{port}"\n\n'
        f'[[process]]\nagents = ["receiver/a"]\nlisten = "tcp/[::1]:{port}"\n'
    )
    result = subprocess.run(launch_command(deploy, "1s"), capture_output=True, text=True, timeout=120, check=False)
    output = result.stdout
    assert result.returncode == 0, output + result.stderr
    for label, link in (("[receiver/a]", "sender,receiver"), ("[sender/a  ]", "receiver,sender")):
        closing = next(line for line in output.splitlines() if line.startswith(f"{label} link {link} ("))
        assert int(closing.split("): ", 1)[1].split(" ", 1)[0]) > 50, output


def test_launch_whose_reader_goes_away_stops_every_process(tmp_path: Path) -> None:
    """`earl launch … | head -1`: the output is closed, so the processes are stopped, not left to block."""
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    launch = subprocess.Popen(
        launch_command(deploy, "60s"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
    )
    try:
        assert launch.stdout is not None and launch.stderr is not None
        first = launch.stdout.readline().decode()
        assert "started (pid" in first
        time.sleep(1.0)
        launch.stdout.close()
        assert launch.wait(timeout=30) == 1
        assert "the output was closed; every process was stopped" in launch.stderr.read().decode()
    finally:
        launch.kill()
        launch.wait()
    assert all(_gone(pid) for pid in _started_pids(first))


def test_a_zenoh_run_whose_output_is_closed_still_ends(tmp_path: Path) -> None:
    """`earl run … --transport zenoh 2>&1 | true`: printing fails, and the Zenoh session must still close,
    or its threads keep the process alive for ever."""
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    run = subprocess.Popen(
        [
            *(sys.executable, "-m", "earl.cli.main", "run", str(PINGPONG), "--transport", "zenoh"),
            "--deployment",
            str(deploy),
            "--agents",
            "receiver/a",
            "--duration",
            "1s",
            "--wait-for-peers",
            "1s",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
    )
    assert run.stdout is not None
    run.stdout.close()  # the reader is gone before anything is printed
    try:
        run.wait(timeout=40)
    finally:
        run.kill()
        run.wait()


def test_launch_checks_the_duration_and_names_processes_of_other_hosts_before_starting(tmp_path: Path) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    for duration, said in (("abc", "--duration: `abc` is not a duration"), ("", "--duration: the duration is empty")):
        result = subprocess.run(
            launch_command(deploy, duration),
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert result.returncode == 2 and said in result.stderr, result.stderr
        assert "started" not in result.stdout
    deploy.write_text(
        deploy.read_text().replace("environment = false\n", 'environment = false\nhost = "locahost"\n', 1)
    )
    result = subprocess.run(
        launch_command(deploy, "1s"),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert "[sender/a  ] runs on host `locahost`, not started here" in result.stdout, result.stdout


def test_launch_help_says_every_exit_code_and_stop_signal_the_docs_say() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "launch", "--help"], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    text = " ".join(result.stdout.split())
    exit_codes = text.split("exit codes:", 1)[1]
    assert "1 a process failed (or ended before its run started" in exit_codes
    assert "or the output was closed" in exit_codes
    assert "130 interrupted by Ctrl-C, SIGTERM or SIGHUP" in exit_codes
    assert "Ctrl-C, SIGTERM or SIGHUP (a closed terminal) stops every process" in text
    docs = " ".join((Path(__file__).parent.parent / "docs" / "distributed.md").read_text().split())
    assert "Ctrl-C, SIGTERM or SIGHUP (a closed terminal) stops them all" in docs
    assert "1 one failed (or ended before its run started" in docs and "or the output was closed, 2" in docs


def test_launch_refuses_to_split_the_robots_effectors_from_their_environment(tmp_path: Path) -> None:
    """manip/a and grip/a drive MuJoCo's actuators: in two processes each would simulate a world of its own."""
    deploy = deployment(tmp_path, [(["task/a"], False), (["manip/a"], True), (["grip/a"], False)])
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "launch", str(PICK_AND_PLACE), "--deployment", str(deploy)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 1, result.stderr
    assert (
        f"earl launch: {deploy}:12: process 3 runs `grip/a`, whose Real Effectors or Receptors act on the environment"
        in result.stderr
    ), result.stderr
    assert result.stderr.count("\n") == 1, result.stderr
    assert "started" not in result.stdout and "Traceback" not in result.stderr


def test_pick_and_place_split_over_two_processes_survives_a_killed_task_agent_and_completes(
    tmp_path: Path, processes: list[Process]
) -> None:
    """The example in real time: manip/a and grip/a with the MuJoCo workcell in one process, task/a in
    another.  task/a is killed (SIGKILL) during its approach: the manipulator finishes the motion it was
    given and holds still with stale inputs; a new task/a process starts the task over and completes it."""
    deploy = deployment(tmp_path, [(["manip/a", "grip/a"], True), (["task/a"], False)])
    common = [str(PICK_AND_PLACE), "--transport", "zenoh", "--deployment", str(deploy), "--param", "N=3"]
    robot = run(
        processes,
        tmp_path / "robot.log",
        [*common, "--agents", "manip/a,grip/a", "--duration", "120s", "--trace", str(tmp_path / "robot.mcap")],
    )
    task_arguments = [*common, "--agents", "task/a", "--environment", "none"]
    first = run(processes, tmp_path / "first.log", [*task_arguments, "--duration", "120s"])
    robot.wait_for("task/a is alive", 60)
    time.sleep(1.5)  # task/a is in its approach: manip/a moves
    os.kill(first.child.pid, signal.SIGKILL)
    lost = robot.wait_for("task/a disappeared", 20)
    time.sleep(2.0)  # manip/a finishes its motion and holds
    second = run(
        processes,
        tmp_path / "second.log",
        [*task_arguments, "--duration", "18s", "--trace", str(tmp_path / "task.mcap")],
    )
    robot.wait_for("task/a is alive: manip/a.cs manipulatorCommand/ib receive again from it", 60, after=lost)
    assert second.finish(90) == 0, second.output
    robot.child.send_signal(signal.SIGTERM)
    assert robot.finish(60) == 130, robot.output
    output = robot.output
    assert "Traceback" not in output + second.output
    assert "pick-and-place: placed=true" in output, output
    task_states = [data["to"] for topic, _, data in trace(tmp_path / "task.mcap") if topic == "/task/a.cs/fsm"]
    assert task_states[-1] == "done", task_states

    events = trace(tmp_path / "robot.mcap")
    stale = [
        t
        for topic, t, data in events
        if topic == "/earl/faults" and data["kind"] == "stale" and data["subsystem"] == "manip/a.cs"
    ]
    assert stale, "manip/a.cs never saw task/a go"
    changes = [(t, data["to"]) for topic, t, data in events if topic == "/manip/a.cs/fsm"]
    resumed = next(t for t, state in changes if t > stale[0] and state != "idle")
    idle = max(t for t, state in changes if t < resumed and state == "idle")
    assert idle > stale[0] - 5_000_000_000  # it was idle, holding, when the new task/a began
    holding = [
        data["currentJointPos"]
        for topic, t, data in events
        if topic == "/manip/a.cs/memory" and idle + 500_000_000 <= t < resumed
    ]
    assert len(holding) > 100, "manip/a.cs held for less than the outage"
    for joint in range(3):
        positions = [q[joint] for q in holding]
        assert max(positions) - min(positions) < 2e-3, f"joint {joint + 1} moved while task/a was gone"


def test_with_a_zenoh_config_the_environment_runs_only_with_every_agent_acting_on_it(tmp_path: Path) -> None:
    """No deployment file says where run.toml's environment lives: the task agent's process runs no
    world of its own (it printed a pick-and-place report of a world without an arm), and a process with
    only some of the acting agents is refused before Zenoh starts."""
    (port,) = free_ports(1)
    config = tmp_path / "zenoh.json5"
    config.write_text(
        '{mode: "peer", scouting: {multicast: {enabled: false}}, '
        f'listen: {{endpoints: ["tcp/127.0.0.1:{port}"]}}, connect: {{endpoints: []}}}}'
    )
    command = [sys.executable, "-m", "earl.cli.main", "run", str(PICK_AND_PLACE), "--transport", "zenoh"]
    common = ["--zenoh-config", str(config), "--no-progress"]
    alone = subprocess.run([*command, "--agents", "manip", *common], capture_output=True, text=True, timeout=120)
    assert alone.returncode == 2, alone.stdout + alone.stderr
    assert "this process runs manip/a alone" in " ".join(alone.stderr.split())
    task = subprocess.run(
        [*command, "--agents", "task", *common, "--wait-for-peers", "0.2s", "--duration", "0.2s"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert task.returncode == 0, task.stdout + task.stderr
    assert "pick-and-place:" not in task.stdout + task.stderr


def _ended(pid: int, seconds: float) -> bool:
    """The process is gone, or a zombie nobody reaps yet (its parent, the supervisor, was killed)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError, IndexError):
            return True
        if state in ("Z", "X"):
            return True
        time.sleep(0.1)
    return False


def test_processes_of_a_launch_killed_with_sigkill_stop_themselves(tmp_path: Path, processes: list[Process]) -> None:
    """SIGKILL cannot be caught: the supervisor cannot stop its children. Each notices it is orphaned and
    stops itself as on SIGTERM, instead of running on unsupervised, holding its ports."""
    launch = pingpong_launched(tmp_path, processes)
    pids = _started_pids(launch.output)
    assert len(pids) == 2
    launch.child.kill()
    launch.child.wait(timeout=10)
    try:
        assert all(_ended(pid, 15) for pid in pids), launch.output
    finally:
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("failure", ["code that does not compile", "a missing module", "a port held by another"])
def test_a_process_that_fails_before_its_run_starts_stops_the_launch_at_once(
    tmp_path: Path, processes: list[Process], failure: str
) -> None:
    """The sender cannot start: the receiver would wait for it (--wait-for-peers, 30 s), then run without
    it. The failure is said as it happens, the receiver is stopped, and the launch ends with exit 1; the
    sender's spec errors come before it opens its Zenoh session, not after it has shown itself."""
    spec = tmp_path / "pingpong"
    shutil.copytree(PINGPONG, spec)
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    holder = socket.socket()
    try:
        if failure == "code that does not compile":
            (spec / "pingpong" / "sender.py").write_text("def broken(:\n")
        elif failure == "a missing module":
            (spec / "pingpong" / "sender.py").unlink()
        else:
            port = int(endpoints(deploy)[0].rsplit(":", 1)[1])
            holder.bind(("127.0.0.1", port))
            holder.listen()
        started = time.monotonic()
        launch = Process(
            tmp_path / "launch.log", [str(spec), "--deployment", str(deploy), "--duration", "60s"], "launch"
        )
        processes.append(launch)
        assert launch.finish(25) == 1, launch.output
        assert time.monotonic() - started < 25  # not the receiver's 30 s wait, nor its 60 s run
    finally:
        holder.close()
    output = launch.output
    assert "[sender/a  ] ended with exit code 1 before its run started; the others cannot run" in output, output
    assert "[receiver/a] stopping" in output
    assert "earl launch: sender/a ended before its run started; every process was stopped" in output
    assert "[sender/a  ] earl run: sender/a over Zenoh" not in output  # its errors came first
    if failure == "a port held by another":
        assert "Address already in use" in output
        # the receiver, connecting to that port, which never answers, stops itself in order and in time: its
        # Zenoh session waited 10 s for the connection under way, and the launch killed it after 5 s
        assert "[receiver/a] earl run: interrupted before the run started" in output
        assert "did not stop within" not in output
    else:
        assert "EARL-X00" in output
    assert "Traceback" not in output
    assert all(_gone(pid) for pid in _started_pids(output)), output


def test_a_process_that_fails_in_the_middle_of_its_run_leaves_the_others_running(
    tmp_path: Path, processes: list[Process]
) -> None:
    """Once its run started, a process that fails is a lost peer: it is said at once and the others go on."""
    launch = pingpong_launched(tmp_path, processes)
    sender = next(
        int(line.split("(pid ")[1].split(")")[0])
        for line in launch.output.splitlines()
        if "[sender/a  ] started" in line
    )
    os.kill(sender, signal.SIGKILL)
    launch.wait_for("[sender/a  ] failed with signal 9 (SIGKILL)", 25)
    launch.wait_for("[receiver/a] earl run: receiver/a.cs: sender/a disappeared", 25)
    time.sleep(1.0)
    assert launch.child.poll() is None, launch.output  # the receiver runs on, holding its stale input
    assert "[receiver/a] stopping" not in launch.output
    launch.child.send_signal(signal.SIGINT)
    assert launch.finish(30) == 130, launch.output


@pytest.mark.parametrize(
    ("args", "said"),
    [
        ('["--trace", "/nonexistent/dir/s.mcap"]', "cannot write the trace /nonexistent/dir/s.mcap: the directory"),
        ('["--duration", "soon"]', "--duration: `soon` is not a duration"),
        ('["--duration="]', "--duration: the duration is empty"),
        ('["--plot", "/nonexistent/dir/s.png", "--signal", "sender/a.cs.count"]', "--plot '/nonexistent/dir/s.png'"),
        ('["--wait-for-peers", "soon"]', "--wait-for-peers: `soon` is not a duration"),
        ('["--signal", "sender/a.cs.count"]', "--signal needs --plot FILE.png"),  # a plot of nothing
        ('["--record-links", ""]', "--record-links names no link pattern"),
        ('["--seed", "x"]', "argument --seed: `x` is not a whole number"),
        ('["--bogus"]', "unrecognized arguments: --bogus"),
        ('["--help"]', "it asks for help"),
    ],
)
def test_launch_checks_each_processs_args_before_starting_any(tmp_path: Path, args: str, said: str) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    deploy.write_text(deploy.read_text().replace("environment = false\n", f"environment = false\nargs = {args}\n", 1))
    result = subprocess.run(launch_command(deploy, "1s"), capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 1, result.stdout + result.stderr
    # at the line of its `args`
    assert f"{deploy}:5: process 1 (sender/a) cannot run with its `args`: {said}" in result.stderr, result.stderr
    assert "nothing was started" in result.stderr
    assert "started" not in result.stdout and "Traceback" not in result.stderr


def test_wait_for_peers_0_starts_at_once_and_a_missing_deployment_file_is_a_usage_error(tmp_path: Path) -> None:
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    command = [
        sys.executable,
        "-m",
        "earl.cli.main",
        "run",
        str(PINGPONG),
        "--transport",
        "zenoh",
        "--agents",
        "sender",
    ]
    alone = subprocess.run(
        [*command, "--deployment", str(deploy), "--wait-for-peers", "0", "--duration", "0.2s", "--no-progress"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert alone.returncode == 0, alone.stderr
    assert "waiting up to" not in alone.stderr and "starting without receiver/a" in alone.stderr
    missing = subprocess.run(
        [*command, "--deployment", str(tmp_path / "none.toml")], capture_output=True, text=True, timeout=120
    )
    assert missing.returncode == 2 and "none.toml does not exist" in missing.stderr


def test_a_session_that_waits_to_close_for_a_connection_that_never_answers_says_so(tmp_path: Path) -> None:
    """With the user's Zenoh configuration (its own open_timeout), a connect endpoint held by a program that
    never speaks Zenoh keeps the session from closing until the connection times out: the process says why
    it waits, then ends in order."""
    held, listen = free_ports(2)
    config = tmp_path / "zenoh.json5"
    config.write_text(
        json.dumps(
            {
                "mode": "peer",
                "scouting": {"multicast": {"enabled": False}},
                "listen": {"endpoints": [f"tcp/127.0.0.1:{listen}"]},
                "connect": {"endpoints": [f"tcp/127.0.0.1:{held}"]},
                "transport": {"unicast": {"open_timeout": 4000}},
            }
        )
    )
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", held))
        holder.listen()  # connections are accepted by the system, and never answered
        started = time.monotonic()
        options = ["--agents", "receiver", "--duration", "0.2s", "--wait-for-peers", "0", "--no-progress"]
        result = subprocess.run(
            [*EARL_RUN, str(PINGPONG), "--transport", "zenoh", "--zenoh-config", str(config), *options],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "earl run: the Zenoh session is still closing: it waits for a connection it is opening" in result.stderr
    assert time.monotonic() - started < 20


def test_a_deployment_named_with_a_zenoh_config_is_read_and_checked(tmp_path: Path) -> None:
    """--zenoh-config replaces the deployment's endpoints, not what it says of the agents and the environment."""
    (port,) = free_ports(1)
    config = tmp_path / "zenoh.json5"
    config.write_text(
        '{mode: "peer", scouting: {multicast: {enabled: false}}, '
        f'listen: {{endpoints: ["tcp/127.0.0.1:{port}"]}}, connect: {{endpoints: []}}}}'
    )
    command = [sys.executable, "-m", "earl.cli.main", "run", "--transport", "zenoh", "--zenoh-config", str(config)]
    broken = tmp_path / "broken.toml"
    broken.write_text('[[process]\nagents = ["sender/a"]\n')
    result = subprocess.run(
        [*command, str(PINGPONG), "--agents", "sender", "--deployment", str(broken)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1 and f"earl run: {broken}:1:10: not valid TOML" in result.stderr, result.stderr
    assert result.stderr.count("\n") == 1, result.stderr
    # the environment with the task agent, apart from the agents acting on it
    misplaced = deployment(tmp_path, [(["manip/a", "grip/a"], False), (["task/a"], True)])
    result = subprocess.run(
        [*command, str(PICK_AND_PLACE), "--agents", "manip,grip", "--deployment", str(misplaced)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"earl run: {misplaced}:2: process 1 runs `manip/a`" in result.stderr, result.stderr
    assert "but the environment lives in process 2 (task/a)" in result.stderr
    assert "over Zenoh" not in result.stderr  # refused before Zenoh starts


def test_an_interrupt_while_waiting_for_peers_leaves_no_trace(tmp_path: Path, processes: list[Process]) -> None:
    """No iteration ran: as for an interrupt one step earlier, the trace this command created is removed."""
    deploy = deployment(tmp_path, [(["sender/a"], False), (["receiver/a"], False)])
    trace_file = tmp_path / "w.mcap"
    sender = run(
        processes,
        tmp_path / "sender.log",
        [
            str(PINGPONG),
            "--transport",
            "zenoh",
            "--deployment",
            str(deploy),
            "--agents",
            "sender",
            "--trace",
            str(trace_file),
            "--duration",
            "1s",
        ],
    )
    sender.wait_for("waiting up to 30 s for receiver/a", 60)
    sender.child.send_signal(signal.SIGINT)
    assert sender.finish(30) == 130, sender.output
    said = " ".join(sender.output.split())
    assert (
        f"interrupted while waiting for the other processes; nothing was executed; no trace was written to {trace_file}"
        in said
    ), said
    assert not trace_file.exists()


def test_the_mobile_robot_split_as_its_deploy_toml_says_runs_and_its_base_reports_without_the_coordinator(
    tmp_path: Path, processes: list[Process]
) -> None:
    """examples/mobile_robot/deploy.toml, on free ports: the base with its world in one process, the
    coordinator in another, for 2 s. The goal and the statuses cross, and the base's process, which runs
    the world and so the report, says what it can of the patrol without the coordinator's state."""
    shipped = (MOBILE_ROBOT / "deploy.toml").read_text()
    first, second = free_ports(2)
    assert shipped.count('listen = "tcp/127.0.0.1:7461"') == 1 and shipped.count('listen = "tcp/127.0.0.1:7462"') == 1
    deploy = tmp_path / "deploy.toml"
    deploy.write_text(shipped.replace(":7461", f":{first}").replace(":7462", f":{second}"))
    launch = Process(
        tmp_path / "launch.log", [str(MOBILE_ROBOT), "--deployment", str(deploy), "--duration", "2s"], "launch"
    )
    processes.append(launch)
    assert launch.finish(150) == 0, launch.output
    output = launch.output
    assert "Traceback" not in output and "earl run: the report" not in output, output
    lines = [" ".join(line.split()) for line in output.splitlines()]
    assert "[base/a ] coordinator/a runs in another process: its summary says whether the patrol is done" in lines
    assert any(
        line.startswith("[base/a ] mobile-robot: patrolled=unknown coordinator=elsewhere least_clearance_m=")
        for line in lines
    ), output
    assert not any(line.startswith("[coordinator/a] mobile-robot:") for line in lines)  # no world there

    def count(label: str, link: str) -> int:
        prefix = f"{label} link {link} ("
        line = next(line for line in lines if line.startswith(prefix) and " received" in line)
        return int(line.split("): ", 1)[1].split(" ", 1)[0])

    assert count("[base/a ]", "coordinator,base") >= 1 and count("[coordinator/a]", "base,coordinator") > 10, output
