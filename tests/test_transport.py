"""The pieces of the distributed runtime that need no second process: the wire codec and its
type fingerprints, the key expressions, the deployment file (docs/distributed.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import msgpack  # type: ignore[import-untyped]
import pytest

import earl
from earl.model.expand import expand
from earl.model.types import TypeReference
from earl.runtime.values import Record, TypeSystem
from earl.transport.codec import FingerprintMismatch, LinkCodec, MalformedMessage, describe, fingerprint
from earl.transport.deployment import DeploymentError, read_deployment
from earl.transport.keys import alive_key, escape, link_key, unescape

PINGPONG = Path(__file__).parent / "distributed_specs" / "pingpong"
PICK_AND_PLACE = Path(__file__).parent.parent / "examples" / "pick_and_place"

TYPES = """
system wire
param N: int = 3
type JointPosition = double[N]
struct Pose { position: double[3]  orientation: double[4] }
struct Command { joints: JointPosition?  pose: Pose?  stop: boolean  label: string  raw: bytes  counts: int[] }
"""


COMMAND = TypeReference("Command")


def type_system(text: str = TYPES, parameters: dict[str, int] | None = None) -> TypeSystem:
    return TypeSystem(expand(earl.loads(text + "\nx/a { cs { period 1 ms } }\n"), parameters or {}))


def test_a_message_round_trips_as_records_and_tuples() -> None:
    types = type_system()
    codec = LinkCodec(types, COMMAND, "a test")
    value = types.coerce(
        {
            "joints": [0.1, 0.2, 0.3],
            "pose": {"position": [1.0, 2.0, 3.0], "orientation": [1.0, 0.0, 0.0, 0.0]},
            "stop": False,
            "label": "zażółć",
            "raw": b"\x00\xff",
            "counts": [1, 2, 3],
        },
        COMMAND,
    )
    decoded = codec.decode(codec.encode(value))
    assert decoded == value
    assert isinstance(decoded, Record) and isinstance(decoded.pose, Record)
    assert type(decoded.joints) is tuple and type(decoded.counts) is tuple
    assert decoded.raw == b"\x00\xff" and decoded.label == "zażółć"
    absent = types.coerce({**value, "joints": None, "pose": None}, COMMAND)
    assert codec.decode(codec.encode(absent)).joints is None


def test_the_fingerprint_follows_the_structure_not_the_spelling_of_aliases() -> None:
    types = type_system()
    text = describe(types, COMMAND)
    # the alias JointPosition is followed to its structure, with N expanded
    assert text.startswith("struct Command{joints:double[3]?,pose:struct Pose{position:double[3],")
    assert "counts:int[]" in text
    other = type_system(parameters={"N": 4})
    assert fingerprint(describe(other, COMMAND)) != fingerprint(text)
    renamed = type_system(TYPES.replace("stop: boolean", "halt: boolean"))
    assert fingerprint(describe(renamed, COMMAND)) != fingerprint(text)
    required = type_system(TYPES.replace("pose: Pose?", "pose: Pose"))
    assert fingerprint(describe(required, COMMAND)) != fingerprint(text)
    assert len(fingerprint(text)) == 8


def test_another_types_fingerprint_is_refused_and_bad_bytes_are_malformed() -> None:
    types = type_system()
    codec = LinkCodec(types, COMMAND, "a test")
    other = type_system(parameters={"N": 4})
    stranger = LinkCodec(other, COMMAND, "a test")
    value = other.coerce(
        {"joints": [0.0] * 4, "stop": True, "label": "", "raw": b"", "counts": []},
        COMMAND,
    )
    with pytest.raises(FingerprintMismatch) as refused:
        codec.decode(stranger.encode(value))
    assert refused.value.received == stranger.fingerprint
    bad = [
        b"",
        b"12345678",  # a fingerprint's length and nothing after it
        codec.fingerprint + b"\xc1",  # 0xc1 is never valid msgpack
        codec.fingerprint + msgpack.packb({"joints": "no", "stop": 1}),  # msgpack, but not a Command
        codec.fingerprint + msgpack.packb([1, 2, 3]),
        codec.fingerprint + msgpack.packb({"stop": True}) + b"trailing",
    ]
    for payload in bad:
        with pytest.raises(MalformedMessage):
            codec.decode(payload)


def test_link_names_become_single_key_chunks_that_read_back() -> None:
    assert link_key("pickAndPlace", "task,manip") == "earl/pickAndPlace/task,manip"
    key = link_key("pickAndPlace", "manip/a:cs,motorController[3]")
    assert key == "earl/pickAndPlace/manip%2Fa:cs,motorController[3]"
    assert key.count("/") == 2
    for text in ["task/a", "a b*c$d?e#f@g%h", "zażółć/a", ""]:
        chunk = escape(text)
        assert "/" not in chunk and not set(chunk) & set("*$?#@ ")
        if text:
            assert unescape(chunk) == text
    assert alive_key("pickAndPlace", "task/a") == "earl/pickAndPlace/alive/task%2Fa"


def test_the_examples_deployment_puts_every_agent_in_one_process() -> None:
    deployment = read_deployment(PICK_AND_PLACE / "deploy.toml")
    deployment.check_agents(["task/a", "manip/a", "grip/a"])
    robot = deployment.group_of(["grip", "manip/a"])
    assert robot.environment and robot.is_local
    assert deployment.connect_for(robot) == [deployment.group_of(["task/a"]).listen]


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("", "no `[[process]]` table"),
        ("[[process]]\nagents = []\nlisten = 'tcp/127.0.0.1:1'\n", "`agents` must be a list"),
        ("[[process]]\nagents = ['a']\n", "`listen` must be a Zenoh endpoint"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nspeed = 3\n", "unknown key `speed`"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n[[process]]\nagents = ['a/a']\nlisten = 'tcp/x:2'\n",
            "`a/a` already runs in process 1",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n[[process]]\nagents = ['b']\nlisten = 'tcp/127.0.0.1:1'\n",
            "already process 1's endpoint",
        ),
        ("[[process]\n", "not valid TOML"),
        ("mode = 'peer'\n", "unknown setting `mode`"),
    ],
)
def test_a_bad_deployment_file_is_one_located_sentence(tmp_path: Path, text: str, fragment: str) -> None:
    path = tmp_path / "deploy.toml"
    path.write_text(text)
    with pytest.raises(DeploymentError) as error:
        read_deployment(path)
    assert str(error.value).startswith(str(path))
    assert fragment in str(error.value)


def test_a_deployment_must_cover_the_agents_of_the_system(tmp_path: Path) -> None:
    path = tmp_path / "deploy.toml"
    path.write_text("[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n")
    deployment = read_deployment(path)
    with pytest.raises(DeploymentError, match="the agent `receiver/a` runs in no process"):
        deployment.check_agents(["sender/a", "receiver/a"])
    with pytest.raises(DeploymentError, match="`sender/a` is not an agent of this system"):
        deployment.check_agents(["receiver/a"])
    with pytest.raises(DeploymentError, match="no process runs exactly the agents receiver/a"):
        deployment.group_of(["receiver/a"])


@pytest.mark.parametrize("size", [0, 1, 6, 454])
def test_arrays_of_doubles_are_written_exactly_as_msgpack_writes_them(size: int) -> None:
    types = type_system(f"system wire\ntype Joints = double[{size}]\n")
    codec = LinkCodec(types, TypeReference("Joints"), "a test")
    value = tuple(float(i) * -1.5 for i in range(size))
    payload = codec.encode(value)
    assert payload == codec.fingerprint + msgpack.packb(value)
    decoded = codec.decode(payload)
    assert decoded == value and type(decoded) is tuple
    # the general path reads what another msgpack writer sends: ints where doubles are declared
    assert codec.decode(codec.fingerprint + msgpack.packb(list(range(size)))) == tuple(float(i) for i in range(size))
    if size:
        with pytest.raises(MalformedMessage, match="NaN"):
            codec.decode(codec.fingerprint + msgpack.packb([float("nan")] * size))
        with pytest.raises(MalformedMessage):
            codec.decode(codec.fingerprint + msgpack.packb(["x"] * size))


@pytest.mark.parametrize(
    ("arguments", "fragment"),
    [
        (["--transport", "zenoh"], "--transport zenoh needs --agents"),
        (["--transport", "zenoh", "--agents", "nobody"], "`nobody/a` is not an agent of this system"),
        (["--transport", "zenoh", "--agents", "sender/a"], "deploy.toml"),
        (["--agents", "sender/a", "--zenoh-config", "z.json5"], "go with --transport zenoh"),
        (["--agents", "sender/a,nobody"], "`nobody/a` is not an agent of this system"),
        (["--transport", "zenoh", "--agents", "sender/a", "--wait-for-peers", "soon"], "is not a duration"),
        (["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", "/no/such.json5"], "no such file"),
        (["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", __file__], "cannot use the Zenoh"),
    ],
)
def test_distributed_usage_errors_exit_2_with_one_line(
    arguments: list[str], fragment: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from earl.cli.main import main

    assert main(["run", str(PINGPONG), *arguments]) == 2
    error = capsys.readouterr().err
    assert fragment in error and "Traceback" not in error


def test_a_deployment_that_does_not_cover_the_system_stops_earl_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from earl.cli.main import main

    deploy = tmp_path / "deploy.toml"
    deploy.write_text("[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n")
    arguments = ["run", str(PINGPONG), "--transport", "zenoh", "--agents", "sender", "--deployment", str(deploy)]
    assert main(arguments) == 2
    assert "the agent `receiver/a` runs in no process" in capsys.readouterr().err


class RecordingLinks:
    """A transport that records what the builder asks of it."""

    def __init__(self) -> None:
        self.out: list[tuple[str, str, str, str]] = []
        self.into: list[tuple[str, str, str, str, str]] = []
        self.delivered: list[object] = []

    def outgoing(self, link: str, data_type: object, types: TypeSystem, source: str, destination_agent: str) -> Any:
        self.out.append((link, str(getattr(data_type, "name", data_type)), source, destination_agent))
        return self

    def deliver(self, value: object) -> None:
        self.delivered.append(value)

    def incoming(
        self, link: str, data_type: object, types: TypeSystem, engine: Any, buffer: str, source_agent: str
    ) -> None:
        self.into.append((link, str(getattr(data_type, "name", data_type)), engine.name, buffer, source_agent))


def test_the_builder_hands_the_links_with_one_end_elsewhere_to_the_transport() -> None:
    from earl.runtime.builder import build_network
    from earl.runtime.events import Recorder

    system = earl.load(PINGPONG / "system.earl")
    links = RecordingLinks()
    network = build_network(
        expand(system, {}), recorder=Recorder(), agents={"receiver/a"}, remote=links, code_directories=[PINGPONG]
    )
    assert [engine.name for engine in network.engines] == ["receiver/a.cs"]
    assert links.out == [("receiver,sender", "Ping", "receiver/a.cs", "sender/a")]
    assert links.into == [("sender,receiver", "Ping", "receiver/a.cs", "ping", "sender/a")]
    # the sender's end of the remote link is an ordinary destination without a local engine
    (destination,) = network.by_name["receiver/a.cs"].destinations["echo"]
    assert destination.engine is None and destination.channel is links
    assert network.link_types["receiver,sender"].name == "Ping"  # type: ignore[union-attr]


def test_a_stale_input_reads_as_timed_out_until_its_sender_returns() -> None:
    simulation = earl.simulate(earl.load(Path(__file__).parent / "runtime_specs" / "counter"), seed=1)
    engine = simulation.network.by_name["counter/a.cs"]
    simulation.advance_to(0.02)
    assert simulation.state_of("counter/a.cs").timed_out["echo"] is False  # echo/ib is not obligatory
    engine.stale.add("echo")  # what the transport does when the echo's sender disappears
    simulation.advance_to(0.04)
    assert simulation.state_of("counter/a.cs").timed_out["echo"] is True
    engine.stale.discard("echo")  # it is back
    simulation.advance_to(0.06)
    assert simulation.state_of("counter/a.cs").timed_out["echo"] is False
    simulation.close()


@pytest.mark.parametrize(
    ("deployment", "code", "fragment"),
    [
        (None, 2, "no deployment file"),
        ("[[process]\n", 1, "not valid TOML"),
        (
            "[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n",
            1,
            "the agent `receiver/a` runs in no process",
        ),
        (
            "[[process]]\nagents = ['sender', 'receiver']\nlisten = 'tcp/192.0.2.1:1'\nhost = 'elsewhere.invalid'\n",
            1,
            "has no process for this host",
        ),
    ],
)
def test_launch_refuses_a_deployment_it_cannot_run_before_starting_anything(
    tmp_path: Path, deployment: str | None, code: int, fragment: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from earl.cli.main import main

    arguments = ["launch", str(PINGPONG)]
    if deployment is not None:
        path = tmp_path / "deploy.toml"
        path.write_text(deployment)
        arguments += ["--deployment", str(path)]
    assert main(arguments) == code
    captured = capsys.readouterr()
    assert fragment in captured.err and "started" not in captured.out
