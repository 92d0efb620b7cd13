"""The pieces of the distributed runtime that need no second process: the wire codec and its
type fingerprints, the key expressions, the deployment file (docs/distributed.md)."""

from __future__ import annotations

import struct
import threading
import time
from pathlib import Path
from typing import Any

import msgpack  # type: ignore[import-untyped]
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import earl
from earl.model.expand import expand
from earl.model.types import TypeReference
from earl.runtime.channels import Channel
from earl.runtime.simulation import Simulation
from earl.runtime.values import Reals, Record, TypeSystem
from earl.transport.codec import (
    REAL_ARRAY_EXT,
    FingerprintMismatch,
    LinkCodec,
    MalformedMessage,
    describe,
    fingerprint,
)
from earl.transport.deployment import DeploymentError, read_deployment
from earl.transport.inbox import Inbox
from earl.transport.keys import alive_key, escape, link_key, unescape

BAD_PORT = Path(__file__).parent / "distributed_specs" / "bad_port.json5"
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
    # arrays of reals arrive as Reals, the tuple earl knows it checked; other arrays as tuples
    assert type(decoded.joints) is Reals and type(decoded.counts) is tuple
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
    assert alive_key("pickAndPlace", "task/a", "1f2e", "468ec4426e04f9f7") == (
        "earl/pickAndPlace/alive/task%2Fa/1f2e/468ec4426e04f9f7"
    )
    assert alive_key("pickAndPlace", "task/a", "1f2e") == "earl/pickAndPlace/alive/task%2Fa/1f2e/-"  # says none


def test_the_examples_deployment_puts_every_agent_in_one_process() -> None:
    deployment = read_deployment(PICK_AND_PLACE / "deploy.toml")
    deployment.check_agents(["task/a", "manip/a", "grip/a"])
    robot = deployment.group_of(["grip", "manip/a"])
    assert robot.environment and robot.is_local
    assert deployment.connect_for(robot) == [deployment.group_of(["task/a"]).listen]


def _placed(tmp_path: Path, processes: list[tuple[list[str], str]], acting: list[str]) -> list[bool | None]:
    """Where the environment runs for a deployment of `processes` (agents, extra lines of the table)."""
    lines = []
    for number, (agents, extra) in enumerate(processes):
        names = ", ".join(f'"{a}"' for a in agents)
        lines += ["[[process]]", f"agents = [{names}]", f'listen = "tcp/127.0.0.1:{7500 + number}"', extra, ""]
    (tmp_path / "deploy.toml").write_text("\n".join(lines))
    placed = read_deployment(tmp_path / "deploy.toml").place_environment(acting)
    return [process.environment for process in placed.processes]


ROBOT, TASK = ["manip/a", "grip/a"], ["task/a"]


def test_the_environment_goes_to_the_process_whose_agents_act_on_it_unless_the_file_says(tmp_path: Path) -> None:
    assert _placed(tmp_path, [(TASK, ""), (ROBOT, "")], ROBOT) == [False, True]
    assert _placed(tmp_path, [(TASK, "environment = false"), (ROBOT, "environment = true")], ROBOT) == [False, True]
    assert _placed(tmp_path, [(TASK, "environment = false"), (ROBOT, "")], ROBOT) == [False, True]
    assert _placed(tmp_path, [(TASK, ""), (["b/a"], "")], []) == [True, False]  # nobody acts: the first
    # nobody acts on it: nobody needs it
    assert _placed(tmp_path, [(TASK, "environment = false"), (["b/a"], "environment = false")], []) == [False, False]
    # a process that names its own environment in `args` is left to the user
    args = 'args = ["--environment", "hardware:open"]'
    assert _placed(tmp_path, [(["manip/a"], args), (["grip/a"], "")], ROBOT) == [None, True]


@pytest.mark.parametrize(
    ("processes", "line", "fragment"),
    [
        (  # said at the second process that would hold it
            [(TASK, ""), (["manip/a"], ""), (["grip/a"], "")],
            11,
            "the environment would run in process 2 (manip/a) and in process 3 (grip/a), each simulating a "
            "world of its own",
        ),
        (
            [(TASK, "environment = true"), (ROBOT, "")],
            7,
            "process 2 runs `manip/a`, whose Real Effectors or Receptors act on the environment, but the "
            "environment lives in process 1 (task/a); run `manip/a` in process 1",
        ),
        (
            [(TASK, ""), (ROBOT, "environment = false")],
            9,
            "no process runs the environment, but `manip/a` (process 2) has Real Effectors or Receptors",
        ),
        (
            [(["manip/a"], "environment = true"), (["grip/a", "task/a"], "")],
            7,
            "process 2 runs `grip/a`, whose Real Effectors or Receptors act on the environment, but the "
            "environment lives in process 1 (manip/a)",
        ),
    ],
)
def test_an_environment_that_would_run_twice_or_apart_from_its_effectors_is_refused(
    tmp_path: Path, processes: list[tuple[list[str], str]], line: int, fragment: str
) -> None:
    with pytest.raises(DeploymentError) as raised:
        _placed(tmp_path, processes, ROBOT)
    assert str(raised.value).startswith(f"{tmp_path / 'deploy.toml'}:{line}: "), str(raised.value)
    assert fragment in str(raised.value)


@pytest.mark.parametrize(
    ("text", "line", "fragment"),
    [
        ("", 1, "no `[[process]]` table"),
        ("[[process]]\nagents = []\nlisten = 'tcp/127.0.0.1:1'\n", 2, "`agents` is empty; list the agents it runs"),
        (
            "[[process]]\nagents = 'a'\nlisten = 'tcp/127.0.0.1:1'\n",
            2,
            '`agents` is a list of agent names, e.g. ["manip/a", "grip/a"], not "a"',
        ),
        ("[process]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n", 1, "write `[[process]]`, with two brackets"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--transport', 'inproc']\n",
            4,
            "`args` sets `--transport`, which `earl launch` sets for each process itself (always zenoh)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--agents=b/a']\n",
            4,
            "`args` sets `--agents`, which `earl launch` sets for each process itself",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--agent', 'b/a']\n",
            4,
            "`args` sets `--agents` (as `--agent`)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--trans=inproc']\n",
            4,
            "`args` sets `--transport` (as `--trans`)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--dep', 'x.toml']\n",
            4,
            "`args` sets `--deployment` (as `--dep`)",
        ),
        ("[[process]]\nagents = ['a']\n", 1, "process 1: no `listen` endpoint"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nspeed = 3\n", 4, "unknown key `speed`"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n[[process]]\nagents = ['a/a']\nlisten = 'tcp/x:2'\n",
            5,
            "`a/a` already runs in process 1",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n[[process]]\nagents = ['b']\nlisten = 'tcp/127.0.0.1:1'\n",
            6,
            "the same endpoint as process 1's",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7'\n[[process]]\nagents = ['b']\nlisten = 'tcp/localhost:7'\n",
            6,
            "`tcp/localhost:7` and process 1's `tcp/127.0.0.1:7` cannot both listen on port 7 (`localhost` is "
            "127.0.0.1 or ::1, as this host resolves it)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/[::1]:7'\n[[process]]\nagents = ['b']\nlisten = 'tcp/localhost:7'\n",
            6,
            "`tcp/localhost:7` and process 1's `tcp/[::1]:7` cannot both listen on port 7 (`localhost` is",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7'\n[[process]]\nagents = ['b']\nlisten = 'tcp/0.0.0.0:7'\n",
            6,
            "cannot both listen on port 7 (`0.0.0.0` listens on every IPv4 address of this host)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7'\n[[process]]\nagents = ['b']\nlisten = 'tcp/[::]:7'\n",
            6,
            "cannot both listen on port 7 (`[::]` listens on every address of this host, IPv4 too)",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/[0:0:0:0:0:0:0:1]:7'\n[[process]]\nagents = ['b']\nlisten = 'tcp/[::1]:7'\n",
            6,
            "`tcp/[::1]:7` is the same endpoint as process 1's",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7'\n[[process]]\nagents = ['b']\nlisten = 'tls/127.0.0.1:7'\n",
            6,
            "`tls/127.0.0.1:7` is the same endpoint as process 1's",  # both bind TCP port 7
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7451'\n[[process]]\nagents = ['b']\nlisten = 'tcp/127.0.0.1:07451'\n",
            6,
            "the same endpoint as process 1's",
        ),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tpc/127.0.0.1:7451'\n",
            3,
            "`tpc` is not a protocol of Zenoh; did you mean `tcp`",
        ),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:notaport'\n", 3, "`notaport` is not a port"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:99999'\n", 3, "`99999` is not a port"),
        # digits of other scripts: Zenoh would refuse them only as the process opens, and `int` the superscripts
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:\u0661\u0667\u0664\u0665\u0661'\n", 3, "is not a port"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7\u00b2'\n", 3, "is not a port"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1'\n", 3, "write it as tcp/HOST:PORT"),
        ("[[process]]\nagents = ['a', 'a/a']\nlisten = 'tcp/127.0.0.1:1'\n", 2, "`a/a` is listed twice"),
        ("[[process]\n", 1, "not valid TOML"),
        ("mode = 'peer'\n", 1, "unknown setting `mode`"),
        ("# processes\n\nproces = []\n", 3, "unknown setting `proces`; did you mean `process`?"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nagent = ['b']\n",
            4,
            "process 1: unknown key `agent`; did you mean `agents`? (known: agents, listen, environment, host, args)",
        ),
        ("[[process]]\nlisten = 'tcp/127.0.0.1:1'\n", 1, "process 1: no `agents`; list the agents it runs"),
        (  # an agent named twice: at the second, on its own line of the list
            "[[process]]\nagents = [\n  'a',\n  'b',\n  'a/a',\n]\nlisten = 'tcp/127.0.0.1:1'\n",
            5,
            "process 1: `a/a` is listed twice in its `agents`",
        ),
        ("[[process]]\nagents = [\n  'a',\n  'a',\n]\nlisten = 'tcp/127.0.0.1:1'\n", 4, "`a/a` is listed twice"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\n\n[[process]]\nagents = [\n  'b',\n  'a',\n]\n"
            "listen = 'tcp/127.0.0.1:2'\n",
            8,
            "process 2: `a/a` already runs in process 1",
        ),
        (  # endpoints that clash: at the second, whatever comes between
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:7451'\n# the task\n[[process]]\nagents = ['b']\n"
            "host = 'localhost'\n\nlisten = 'tcp/0.0.0.0:7451'\n",
            9,
            "process 2: `tcp/0.0.0.0:7451` and process 1's `tcp/127.0.0.1:7451` cannot both listen on port 7451",
        ),
        ("[[process]]\nagents = ['a']\nlisten = 7451\n", 3, "`listen` is a Zenoh endpoint such as"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nenvironment = 'yes'\n", 4, 'not "yes"'),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nhost = 1\n", 4, "`host` is a host name"),
        ("[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = '--trace'\n", 4, "`args` is a list"),
        (
            "[[process]]\nagents = ['a']\nlisten = 'tcp/127.0.0.1:1'\nargs = [\n  '--seed', '1',\n  '--agents', 'b'\n]\n",
            6,
            "`args` sets `--agents`",
        ),
        ("process = [1]\n", 1, "process 1 is 1, not a table"),
        (  # written inline, every process is said at the `process` line
            "# two\nprocess = [{agents = ['a'], listen = 'tcp/127.0.0.1:1'}, {agents = ['a'], listen = 'tcp/127.0.0.1:2'}]\n",
            2,
            "process 2: `a/a` already runs in process 1",
        ),
        ("\n\nx = [\n1,,\n]\n", 4, "4:3: not valid TOML: Invalid value"),
    ],
)
def test_a_bad_deployment_file_is_one_located_sentence(tmp_path: Path, text: str, line: int, fragment: str) -> None:
    """`FILE:LINE: …`, the line of the key that is wrong (the second of two that clash), as run.toml's."""
    path = tmp_path / "deploy.toml"
    path.write_text(text)
    with pytest.raises(DeploymentError) as error:
        read_deployment(path)
    assert str(error.value).startswith(f"{path}:{line}:"), str(error.value)
    assert fragment in str(error.value)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("tcp/127.0.0.1:7451", "tcp/[::1]:7451"),  # IPv4 and IPv6 each have their own port 7451
        ("tcp/0.0.0.0:7451", "tcp/[::1]:7451"),
        ("tcp/127.0.0.1:7451", "udp/127.0.0.1:7451"),  # a TCP port and a UDP port
        ("tcp/127.0.0.1:7451", "tcp/127.0.0.2:7451"),
    ],
)
def test_listeners_on_different_sockets_of_one_port_are_two_endpoints(tmp_path: Path, first: str, second: str) -> None:
    path = tmp_path / "deploy.toml"
    path.write_text(
        f"[[process]]\nagents = ['a']\nlisten = '{first}'\n[[process]]\nagents = ['b']\nlisten = '{second}'\n"
    )
    assert [process.listen for process in read_deployment(path).processes] == [first, second]


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("tcp/0.0.0.0:7451", "tcp/192.168.1.20:7451"),  # each computer has its own port 7451
        ("tcp/[::]:7451", "tcp/[::]:7451"),
        ("tcp/127.0.0.1:7451", "tcp/127.0.0.1:7451"),
    ],
)
def test_processes_on_two_hosts_may_listen_on_one_port(tmp_path: Path, first: str, second: str) -> None:
    path = tmp_path / "deploy.toml"
    path.write_text(
        f"[[process]]\nagents = ['a']\nlisten = '{first}'\nhost = 'robot'\n"
        f"[[process]]\nagents = ['b']\nlisten = '{second}'\nhost = 'laptop'\n"
    )
    assert [process.host for process in read_deployment(path).processes] == ["robot", "laptop"]
    # on one host, by its name in another case or by this machine's names, they clash
    for one, other in (("robot", "ROBOT."), ("localhost", "127.0.0.1")):
        path.write_text(
            f"[[process]]\nagents = ['a']\nlisten = '{first}'\nhost = '{one}'\n"
            f"[[process]]\nagents = ['b']\nlisten = '{second}'\nhost = '{other}'\n"
        )
        with pytest.raises(DeploymentError, match=r"cannot both listen on port 7451|the same endpoint"):
            read_deployment(path)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    st.lists(
        st.tuples(
            st.integers(0, 10_000),
            st.integers(0, 12),
            st.sampled_from(['"', "'", "[", "]", "=", ",", "\n", "#", "-1", "1e400", "true", "{", "}", "[[", "]]", ""]),
        ),
        min_size=1,
        max_size=3,
    )
)
def test_a_damaged_deployment_file_is_refused_with_a_deployment_error_only(
    tmp_path: Path, edits: list[tuple[int, int, str]]
) -> None:
    """Whatever is cut or inserted, reading and checking a deployment raises DeploymentError or nothing."""
    text = (PICK_AND_PLACE / "deploy.toml").read_text()
    for start, length, insert in edits:
        start %= len(text) + 1
        text = text[:start] + insert + text[start + length :]
    path = tmp_path / "deploy.toml"
    path.write_text(text)
    try:
        deployment = read_deployment(path)
        deployment.check_agents(["task/a", "manip/a", "grip/a"])
        assert all(isinstance(process.is_local, bool) for process in deployment.processes)
    except DeploymentError as error:
        assert str(error) and "\n" not in str(error)  # one sentence


def test_a_deployment_must_cover_the_agents_of_the_system(tmp_path: Path) -> None:
    path = tmp_path / "deploy.toml"
    path.write_text("[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n")
    deployment = read_deployment(path)
    with pytest.raises(DeploymentError, match=r"deploy\.toml:1: the agent `receiver/a` runs in no process"):
        deployment.check_agents(["sender/a", "receiver/a"])
    with pytest.raises(DeploymentError, match=r"deploy\.toml:1: no process runs exactly the agents receiver/a"):
        deployment.group_of(["receiver/a"])
    # an unknown agent is said at its line of the process's `agents`, as it is written there
    path.write_text(
        "[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n[[process]]\nagents = [\n  'x',\n  'sender2',\n]\n"
        "listen = 'tcp/127.0.0.1:2'\n"
    )
    with pytest.raises(DeploymentError, match=r"deploy\.toml:7: process 2: `sender2/a` is not an agent of this system"):
        read_deployment(path).check_agents(["sender/a", "x/a"])
    with pytest.raises(DeploymentError, match=r"deploy\.toml:6: no process runs exactly the agents x/a"):
        read_deployment(path).group_of(["x"])


def packed(values: Any) -> bytes:
    """msgpack of an array of reals as earl writes it: an ext of packed little-endian float64."""
    return bytes(msgpack.packb(msgpack.ExtType(REAL_ARRAY_EXT, struct.pack(f"<{len(values)}d", *values))))


@pytest.mark.parametrize("size", [0, 1, 7, 511])
def test_arrays_of_doubles_travel_as_packed_little_endian_doubles(size: int) -> None:
    types = type_system(f"system wire\ntype Joints = double[{size}]\n")
    codec = LinkCodec(types, TypeReference("Joints"), "a test")
    value = tuple(float(i) * -1.5 for i in range(size))
    payload = codec.encode(value)
    assert payload == codec.fingerprint + packed(value)
    assert 8 * size < len(payload) - 8 <= 8 * size + 6  # 8 bytes an element and the ext's header
    decoded = codec.decode(payload)
    assert decoded == value and type(decoded) is Reals
    # the general path reads what another msgpack writer sends: an array, ints where doubles are declared
    assert codec.decode(codec.fingerprint + msgpack.packb(list(range(size)))) == tuple(float(i) for i in range(size))
    if not size:
        return
    extremes = (float("inf"), float("-inf"), 1e308, -5e-324, *value[4:])
    assert codec.decode(codec.encode(extremes[:size])) == extremes[:size]
    bad_nan = struct.pack("<d", float("nan"))
    negative_nan = bytes.fromhex("ffffffffffffffff")  # a NaN with the sign and every payload bit set
    for nan in (bad_nan, negative_nan):
        with pytest.raises(MalformedMessage, match="NaN"):
            codec.decode(payload[: len(payload) - 8] + nan)
    with pytest.raises(MalformedMessage, match="NaN"):
        codec.decode(codec.fingerprint + msgpack.packb([float("nan")] * size))
    with pytest.raises(MalformedMessage):
        codec.decode(codec.fingerprint + msgpack.packb(["x"] * size))
    header = len(payload) - 8 * size
    malformed = [
        payload[:-1],  # one byte short
        payload + b"\x00",  # one byte too many
        codec.fingerprint + packed((*value, 1.0)),  # one element too many
        payload[: header - 1] + bytes([payload[header - 1] + 1]) + payload[header:],  # an unknown ext type
        codec.fingerprint + msgpack.packb(msgpack.ExtType(REAL_ARRAY_EXT, b"\x00" * (8 * size - 3))),  # not 8k bytes
    ]
    for wrong in malformed:
        with pytest.raises(MalformedMessage):
            codec.decode(wrong)
    other = LinkCodec(type_system(f"system wire\ntype Joints = double[{size + 1}]\n"), TypeReference("Joints"), "t")
    with pytest.raises(FingerprintMismatch):
        codec.decode(other.encode((0.5,) * (size + 1)))
    with pytest.raises(FingerprintMismatch):
        codec.decode(b"\x00" * 8 + payload[8:])


EVERY_KIND = """
system kinds
type Matrix = double[3][2]
struct Pose { position: double[3]  orientation: float32[4] }
struct Sample {
    flag: boolean  small: int8  count: uint16  big: int64  plain: int
    ratio: float32  value: double  exact: float64
    name: string  blob: bytes
    pose: Pose  maybe: Pose?  joints: double[2]?  ranges: float32[]  ids: uint8[]
    matrix: Matrix  path: Pose[]  grid: int[2][2]  names: string[]
}
"""


def test_every_kind_of_data_type_round_trips_with_its_arrays_of_reals_packed() -> None:
    types = type_system(EVERY_KIND)
    codec = LinkCodec(types, TypeReference("Sample"), "a test")
    pose = {"position": [1.0, 2.0, 3.0], "orientation": [0.0, 0.0, 0.0, 1.0]}
    value = types.coerce(
        {
            "flag": True,
            "small": -8,
            "count": 65535,
            "big": -(2**63),
            "plain": 7,
            "ratio": 0.5,
            "value": -1.25,
            "exact": 1e-300,
            "name": "zażółć",
            "blob": b"\x00\xff",
            "pose": pose,
            "maybe": None,
            "joints": [0.1, 0.2],
            "ranges": [],
            "ids": [0, 255],
            "matrix": [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
            "path": [pose, {**pose, "position": [4.0, 5.0, 6.0]}],
            "grid": [[1, 2], [3, 4]],
            "names": ["a", ""],
        },
        TypeReference("Sample"),
    )
    payload = codec.encode(value)
    decoded = codec.decode(payload)
    assert decoded == value
    assert isinstance(decoded, Record) and isinstance(decoded.pose, Record) and decoded.maybe is None
    assert all(isinstance(p, Record) for p in decoded.path) and type(decoded.path) is tuple
    assert type(decoded.matrix) is tuple and all(type(row) is Reals for row in decoded.matrix)
    # on the wire: every array of reals, however deep, is one packed ext; other arrays stay msgpack arrays
    wire = msgpack.unpackb(payload[8:], raw=False)
    assert wire["joints"] == msgpack.ExtType(REAL_ARRAY_EXT, struct.pack("<2d", 0.1, 0.2))
    assert wire["ranges"] == msgpack.ExtType(REAL_ARRAY_EXT, b"")
    assert [type(row) for row in wire["matrix"]] == [msgpack.ExtType] * 2
    assert wire["path"][1]["position"] == msgpack.ExtType(REAL_ARRAY_EXT, struct.pack("<3d", 4.0, 5.0, 6.0))
    assert wire["ids"] == [0, 255] and wire["grid"] == [[1, 2], [3, 4]] and wire["maybe"] is None
    # the optional fields present, then a NaN deep inside: refused, with where it is
    present = types.coerce({**value, "maybe": pose, "joints": None}, TypeReference("Sample"))
    assert codec.decode(codec.encode(present)) == present
    wire["path"][0]["position"] = msgpack.ExtType(REAL_ARRAY_EXT, struct.pack("<3d", 0.0, float("nan"), 0.0))
    with pytest.raises(MalformedMessage, match=r"path\[0\]\.position\[1\] is NaN"):
        codec.decode(codec.fingerprint + msgpack.packb(wire))
    wire["path"][0]["position"] = msgpack.ExtType(REAL_ARRAY_EXT, struct.pack("<2d", 0.0, 0.0))
    with pytest.raises(MalformedMessage, match="3 elements"):
        codec.decode(codec.fingerprint + msgpack.packb(wire))
    wire["path"][0]["position"] = msgpack.ExtType(9, b"\x00" * 24)
    with pytest.raises(MalformedMessage, match="ext type 9"):
        codec.decode(codec.fingerprint + msgpack.packb(wire))
    wire["path"] = []
    wire["ids"] = msgpack.ExtType(REAL_ARRAY_EXT, struct.pack("<2d", 0.5, 1.5))  # reals where uint8 are declared
    with pytest.raises(MalformedMessage, match="ids"):
        codec.decode(codec.fingerprint + msgpack.packb(wire))


def test_the_inbox_wakes_its_sleeper_and_hands_over_in_arrival_order() -> None:
    inbox = Inbox()
    got: list[tuple[int, Any]] = []

    def action(time: int, value: Any) -> None:
        got.append((time, value))

    inbox.put(action, "before")  # a signal sent before anyone sleeps is not lost
    inbox.wait(30.0)
    assert inbox.pending
    inbox.drain(5)
    assert got == [(5, "before")] and not inbox.pending
    inbox.wait(0.01)  # nothing pending, and the drained message's signal was consumed: it just times out
    assert not inbox.pending
    producers = [threading.Thread(target=lambda n=n: [inbox.put(action, (n, k)) for k in range(200)]) for n in range(3)]
    for producer in producers:
        producer.start()
    received: list[Any] = []
    started = time.monotonic()
    while len(received) < 600 and time.monotonic() - started < 60:
        inbox.wait(30.0)
        got.clear()
        inbox.drain(6)
        received.extend(value for _, value in got)
    for producer in producers:
        producer.join()
    assert len(received) == 600
    for n in range(3):  # each producer's messages arrive in its order
        assert [k for m, k in received if m == n] == list(range(200))


def test_wait_for_peers_takes_0_written_any_way_the_duration_parser_reads() -> None:
    from earl.transport.process import peers_wait

    for zero in ("0", "0s", "0 ms", "0.0", "00", "0min", ".0us", "0e3s"):
        assert peers_wait(zero) == 0.0, zero
    assert peers_wait("1.5s") == 1.5 and peers_wait(None) == 30.0
    with pytest.raises(ValueError, match="a duration must be 0 or more"):
        peers_wait("-1s")
    with pytest.raises(ValueError, match="is not a duration"):
        peers_wait("zero")


@pytest.mark.parametrize(
    ("arguments", "fragment"),
    [
        (["--transport", "zenoh"], "--transport zenoh needs --agents"),
        (["--transport", "zenoh", "--agents", "nobody"], "`nobody/a` is not an agent of this system"),
        (["--transport", "zenoh", "--agents", "sender/a"], "deploy.toml"),
        (["--agents", "sender/a", "--zenoh-config", "z.json5"], "go with --transport zenoh"),
        (["--agents", "sender/a", "--wait-for-peers", "5s"], "--wait-for-peers go with --transport zenoh"),
        (["--agents", "sender/a,nobody"], "`nobody/a` is not an agent of this system"),
        (["--transport", "zenoh", "--agents", "sender/a", "--wait-for-peers", "soon"], "is not a duration"),
        (["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", "/no/such.json5"], "no such file"),
        (["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", __file__], "cannot use the Zenoh"),
        (["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", "/tmp"], "a directory, not a file"),
        (["--transport", "zenoh", "--agents", "sender/b"], "`sender/b` is not an agent of this system"),
        (["--agents", "sender,sender/a"], "`sender/a` is named twice"),
        (
            ["--transport", "zenoh", "--agents", "sender/a", "--zenoh-config", str(BAD_PORT)],
            "Zenoh could not start: ",
        ),
    ],
)
def test_distributed_usage_errors_exit_2_with_one_line(
    arguments: list[str], fragment: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from earl.cli.main import main

    assert main(["run", str(PINGPONG), *arguments]) == 2
    error = capsys.readouterr().err
    assert fragment in error and "Traceback" not in error
    assert ".rs:" not in error  # Zenoh's Rust source lines are of no use to the reader


def test_a_deployment_that_does_not_cover_the_system_stops_earl_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from earl.cli.main import main

    deploy = tmp_path / "deploy.toml"
    deploy.write_text("[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n")
    arguments = ["run", str(PINGPONG), "--transport", "zenoh", "--agents", "sender", "--deployment", str(deploy)]
    assert main(arguments) == 1  # as `earl launch` says it: the file is wrong, not the command line
    assert "earl run: " in (said := capsys.readouterr().err) and "the agent `receiver/a` runs in no process" in said


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
    # (here the echo's messages still come, in one process: each instant the buffer took one it did not time out)
    engine.channels["echo"] = Channel()  # and now none come
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
        ("[[process]\n", 1, "deploy.toml:1:10: not valid TOML"),
        (
            "[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\n",
            1,
            "deploy.toml:1: the agent `receiver/a` runs in no process",
        ),
        (
            "[[process]]\nagents = ['sender', 'receiver']\nlisten = 'tcp/192.0.2.1:1'\nhost = 'elsewhere.invalid'\n",
            1,
            "deploy.toml:4: no process for this host, `",
        ),
        (
            "[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--trace', 'same.mcap']\n"
            "[[process]]\nagents = ['receiver']\nlisten = 'tcp/127.0.0.1:2'\nargs = ['--trace=same.mcap']\n",
            1,
            "deploy.toml:8: process 2 (receiver/a) writes same.mcap (--trace), as sender/a does",
        ),
        (
            "[[process]]\nagents = ['sender']\nlisten = 'tcp/127.0.0.1:1'\nargs = ['--tra', 'p.mcap']\n"
            "[[process]]\nagents = ['receiver']\nlisten = 'tcp/127.0.0.1:2'\nargs = ['--plot', 'p.png']\n",
            1,
            "deploy.toml:8: process 2 (receiver/a) writes p.mcap (--plot's trace), as sender/a does",
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
    assert captured.err.count("\n") == 1, captured.err  # one line, `deploy.toml:LINE: …`


SERVED_SPEC = """\
system served
waiter/a {
    cs {
        in/ib: double
        seen/m: double = 0.0
        false/pp = false
        take/pf(in/ib -> seen/mo) = python "served:take"
        run/bb {
            tf = {take/pf}
            tc = false/pp
        }
        fsm {
            initial run
            state run: run/bb { obligatory in/ib }
        }
    }
}
servedRobot/r {
    waiter/a
}
"""

SERVED_CODE = """\
import threading

#: (value read, the thread that ran the function)
calls = []


def take(inputs, outputs, context):
    calls.append((inputs["in/ib"], threading.current_thread().name))
    outputs.seen = inputs["in/ib"]
"""


class _InboxOnly:
    """What a Simulation needs of a transport whose links are all local: its inbox."""

    def __init__(self) -> None:
        self.inbox = Inbox()

    def start(self, specification: str | None = None) -> None:
        pass

    def close(self) -> None:
        pass


class _Plant:
    """An environment: its presence keeps every event on the scheduler's thread."""

    def advance(self, time: float) -> None:
        pass


def _served_simulation(tmp_path: Path, environment: object) -> tuple[Simulation, _InboxOnly]:
    (tmp_path / "system.earl").write_text(SERVED_SPEC)
    (tmp_path / "served.py").write_text(SERVED_CODE)
    transport = _InboxOnly()
    # the messages come from the test's transport, not over a link of the spec: unchecked (EARL-E016)
    simulation = Simulation(
        earl.load(tmp_path / "system.earl"), environment=environment, realtime=True, transport=transport, check=False
    )
    return simulation, transport


def _served_run(tmp_path: Path, environment: object, values: list[float]) -> tuple[Any, list[tuple[float, str]]]:
    simulation, transport = _served_simulation(tmp_path, environment)
    import served  # type: ignore[import-not-found]  # bound by the Simulation from tmp_path

    served.calls.clear()
    engine = simulation.network.engines[0]
    channel = engine.channels["in"]

    def arrive(time: int, value: Any) -> None:  # what the transport's `_Input.arrive` does
        channel.deliver(value)
        if engine.waiting and engine.on_delivery is not None:
            engine.on_delivery(engine)

    def producer() -> None:  # stands for Zenoh's thread
        for value in values:
            time.sleep(0.02)
            transport.inbox.put(arrive, value)

    thread = threading.Thread(target=producer, name="receiving-thread")
    thread.start()
    deadline = time.monotonic() + 20
    while len(served.calls) < len(values) + 1 and time.monotonic() < deadline:
        simulation.advance_to(simulation.time + 0.05)
    thread.join()
    simulation.close()
    return simulation, list(served.calls)


def test_a_message_is_served_on_its_receiving_thread_while_the_scheduler_sleeps(tmp_path: Path) -> None:
    _, calls = _served_run(tmp_path, None, [1.0, 2.0, 3.0])
    # the first call reads the buffer's initial value; each message then wakes the subsystem at once,
    # and since the scheduler slept, on the thread that received it
    assert [value for value, _ in calls] == [0.0, 1.0, 2.0, 3.0]
    assert [thread for _, thread in calls[1:]] == ["receiving-thread"] * 3


def test_with_an_environment_every_message_is_handed_over_to_the_scheduler(tmp_path: Path) -> None:
    _, calls = _served_run(tmp_path, _Plant(), [1.0, 2.0])
    assert [value for value, _ in calls] == [0.0, 1.0, 2.0]
    assert {thread for _, thread in calls} == {threading.current_thread().name}


def test_what_fails_while_serving_is_raised_in_the_scheduler_thread(tmp_path: Path) -> None:
    simulation, transport = _served_simulation(tmp_path, None)
    simulation.advance_to(0.01)

    def broken(time: int, value: Any) -> None:
        raise OSError("the disk is full")

    thread = threading.Thread(target=transport.inbox.put, args=(broken, None))
    thread.start()
    thread.join()
    with pytest.raises(OSError, match="the disk is full"):
        simulation.advance_to(simulation.time + 0.05)
    simulation.close()


def test_zenohs_messages_are_given_in_plain_words() -> None:
    from earl.transport.zenoh_transport import zenoh_reason

    raw = (
        "Can not create a new TCP listener bound to tcp/127.0.0.1:7451: [Address already in use (os error 98) "
        "at /root/.cargo/git/checkouts/zenoh-1/io/tcp.rs:61.] at /root/.cargo/git/checkouts/zenoh-1/unicast.rs:338."
    )
    assert zenoh_reason(RuntimeError(raw)) == (
        "Can not create a new TCP listener bound to tcp/127.0.0.1:7451: Address already in use (os error 98)"
    )
    json = 'JSON error: Message { msg: "unknown variant `bogus`, expected `peer`", location: Some(Location { line: 1, column: 9 }) }'
    assert zenoh_reason(RuntimeError(json)) == "JSON error: unknown variant `bogus`, expected `peer` (line 1, column 9)"


def test_a_zenoh_configuration_zenoh_refuses_is_explained_without_rust_source_lines(tmp_path: Path) -> None:
    from earl.transport.zenoh_transport import TransportError, config_from_file

    wrong = tmp_path / "zenoh.txt"
    wrong.write_text("not a configuration")
    with pytest.raises(TransportError) as refused:
        config_from_file(wrong)
    message = str(refused.value)
    assert message.startswith(f"cannot use the Zenoh configuration {wrong}: ")
    assert ".rs:" not in message


def test_zenoh_failing_to_start_for_the_network_exits_1_with_a_configuration_file_or_a_deployment_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An endpoint another program holds is no usage error, whichever file names it; an endpoint that is no
    endpoint, in the user's own configuration, is (BAD_PORT above)."""
    import socket

    from earl.cli.main import main
    from earl.transport.zenoh_transport import network_failure

    holder = socket.socket()
    holder.bind(("127.0.0.1", 0))
    holder.listen()
    try:
        port = holder.getsockname()[1]
        config = tmp_path / "zenoh.json5"
        config.write_text(
            f'{{mode: "peer", scouting: {{multicast: {{enabled: false}}}}, listen: {{endpoints: ["tcp/127.0.0.1:{port}"]}}}}'
        )
        deploy = tmp_path / "deploy.toml"
        deploy.write_text(
            f'[[process]]\nagents = ["sender/a"]\nlisten = "tcp/127.0.0.1:{port}"\n'
            '[[process]]\nagents = ["receiver/a"]\nlisten = "tcp/127.0.0.1:1"\n'
        )
        for option, named in (("--zenoh-config", config), ("--deployment", deploy)):
            command = ["run", str(PINGPONG), "--transport", "zenoh", "--agents", "sender", option, str(named)]
            assert main([*command, "--wait-for-peers", "0", "--duration", "0.1s"]) == 1, option
            error = capsys.readouterr().err
            assert error.startswith("earl run: Zenoh could not start: ") and "Address already in use" in error, error
    finally:
        holder.close()
    assert network_failure("Unable to connect to any of [Single(tcp/127.0.0.1:17999)]!")
    assert not network_failure("invalid port value") and not network_failure("Missing TLS private key")


def test_this_host_is_known_by_its_name_in_any_case_and_by_its_addresses() -> None:
    import socket

    from earl.transport.deployment import is_this_host

    name = socket.gethostname()
    assert is_this_host(name.upper()) and is_this_host(name + ".") and is_this_host("127.0.1.1")
    assert not is_this_host("no-such-host.invalid")


def test_the_run_options_sharing_a_prefix_with_the_launch_options_are_known_to_the_deployment_reader() -> None:
    """A deployment's `args` may not set what `earl launch` sets, abbreviated or not; an abbreviation that
    another `earl run` option shares (`--tra`) is left to `earl run`, which refuses it as ambiguous."""
    from earl.cli.main import build_parser
    from earl.transport.deployment import LAUNCH_SETS, SHARING_A_PREFIX

    parser = build_parser("run")
    run = next(a for a in parser._subparsers._group_actions[0].choices.values())  # type: ignore[union-attr]
    options = {o for action in run._actions for o in action.option_strings if o.startswith("--")}
    assert set(LAUNCH_SETS) <= options
    sharing = {
        other for other in options - set(LAUNCH_SETS) - {"--help"} for launch in LAUNCH_SETS if other[:3] == launch[:3]
    }
    assert sharing == set(SHARING_A_PREFIX)


def test_a_deployment_names_a_family_of_agents_whole_or_member_by_member(tmp_path: Path) -> None:
    """`worker[*]`, `worker[K]` or `worker` is every member, as in a robot; a member in two processes is
    said at its line, whichever way it is named."""
    path = tmp_path / "deploy.toml"
    agents = ["boss/a", "worker[1]/a", "worker[2]/a", "worker[3]/a"]
    for family in ("worker[*]", "worker[K]/a", "worker"):
        path.write_text(
            "[[process]]\nagents = ['boss']\nlisten = 'tcp/127.0.0.1:1'\n"
            f"[[process]]\nagents = ['{family}']\nlisten = 'tcp/127.0.0.1:2'\n"
        )
        deployment = read_deployment(path).check_agents(agents)
        assert [process.agents for process in deployment.processes] == [
            ("boss/a",),
            ("worker[1]/a", "worker[2]/a", "worker[3]/a"),
        ]
        assert deployment.group_of(["worker[3]", "worker[1]", "worker[2]"]) is deployment.processes[1]
    path.write_text(
        "[[process]]\nagents = ['boss', 'worker[2]']\nlisten = 'tcp/127.0.0.1:1'\n"
        "[[process]]\nagents = [\n  'worker[*]',\n]\nlisten = 'tcp/127.0.0.1:2'\n"
    )
    with pytest.raises(
        DeploymentError,
        match=r"deploy\.toml:6: process 2: `worker\[2\]/a` \(a member of `worker\[\*\]/a`\) already runs in process 1",
    ):
        read_deployment(path).check_agents(agents)
