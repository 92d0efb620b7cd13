"""Links between processes over Eclipse Zenoh (docs/distributed.md).

A `ZenohTransport` serves the links of one process whose other end runs elsewhere:

- an **outgoing** link (its output buffer is here) gets a Zenoh publisher on the link's
  key; the engine's send hands each message to it as it would to a local channel;
- an **incoming** link (its input buffer is here) gets a subscriber; a message is
  decoded and type-checked on Zenoh's thread and delivered to the input buffer's
  channel in the scheduler's thread (see `inbox.py`).

Liveliness: the process declares one token per agent it runs.  When the token of an
agent that feeds one of our input buffers disappears, those buffers go *stale* —
`newData()` stays false (nothing arrives), `stale(x/ib)` and `timeout(x/ib)` read true —
until the token comes back; nothing is restarted.
"""

from __future__ import annotations

import contextlib
import json
import re
import threading
import time as wall
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import zenoh

from earl.diagnostics import escape_controls
from earl.model.types import DataType
from earl.runtime.engine import SubsystemEngine
from earl.runtime.values import TypeSystem
from earl.transport.codec import FingerprintMismatch, LinkCodec, MalformedMessage
from earl.transport.inbox import Inbox
from earl.transport.keys import (
    UNKNOWN_SPECIFICATION,
    alive_key,
    alive_prefix,
    escape,
    finished_key,
    finished_prefix,
    link_key,
    type_key,
    unescape,
)

#: how long a restarted peer waits between attempts to reach the others (ms): restarts resume quickly
RETRY_INITIAL_MS = 100
RETRY_MAX_MS = 1000


#: how long Zenoh waits for a peer to answer as it opens a connection (ms; Zenoh's default is 10 s): closing
#: the session waits for an attempt under way, so that a process whose connect endpoint is a port held by a
#: program that never speaks Zenoh took that long to stop, and `earl launch` killed it after its 5 s of grace.
#: Unanswered, the attempt is retried (connect/retry), so a slow peer is still reached.
OPEN_TIMEOUT_MS = 2000


#: seconds a session may take to close before the process says why it waits
CLOSE_SAID_AFTER = 1.0
SLOW_CLOSE = (
    "earl run: the Zenoh session is still closing: it waits for a connection it is opening to answer or time out "
    "(Zenoh's transport/unicast/open_timeout); a connect endpoint may be held by a program that does not speak Zenoh"
)


#: seconds between saying an agent finished and withdrawing its liveliness token, as a run closes
FINISHED_LEAD = 0.05


class TransportError(RuntimeError):
    """Zenoh could not be configured or started; the message says what to change."""


def default_config(listen: list[str], connect: list[str]) -> zenoh.Config:
    """Peer mode, no multicast scouting, explicit endpoints: nothing is found by accident."""
    config = zenoh.Config()
    try:
        config.insert_json5("mode", json.dumps("peer"))
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("listen/endpoints", json.dumps(listen))
        config.insert_json5("connect/endpoints", json.dumps(connect))
        config.insert_json5("transport/unicast/open_timeout", json.dumps(OPEN_TIMEOUT_MS))
        config.insert_json5(
            "connect/retry",
            json.dumps(
                {"period_init_ms": RETRY_INITIAL_MS, "period_max_ms": RETRY_MAX_MS, "period_increase_factor": 2}
            ),
        )
    except Exception as error:  # zenoh reports a bad endpoint as a plain exception
        raise TransportError(f"the Zenoh endpoints {listen + connect} are not valid: {zenoh_reason(error)}") from None
    return config


def zenoh_reason(error: BaseException) -> str:
    """Zenoh's message for a reader: without the Rust source lines it names (`at …/tcp.rs:61.`), of no
    use to them, and with a JSON5 error's own words and place instead of Rust's debug form."""
    text = re.sub(r"\s*at \S+\.rs:\d+\.?", "", str(error))
    text = re.sub(
        r'Message \{ msg: "(.*?)", location: Some\(Location \{ line: (\d+), column: (\d+) \}\) \}',
        r"\1 (line \2, column \3)",
        text,
    )
    text = re.sub(r'Message \{ msg: "(.*?)", location: None \}', r"\1", text)
    text = re.sub(r": \[(.*)\]$", r": \1", text.strip().rstrip(".").strip())  # Zenoh's nesting of causes
    return text or type(error).__name__


#: what Zenoh says when the network, not its configuration, keeps a session from opening: an error of the
#: system (an endpoint another program holds, an address not of this host), no peer or router to connect
#: to, a host name that does not resolve
_NETWORK_FAILURE = re.compile(r"\(os error \d+\)|Unable to connect|failed to lookup address")


def network_failure(reason: str) -> bool:
    """Whether Zenoh's `reason` for not starting is the network's (else its configuration's: an endpoint
    that is no endpoint, a protocol it does not have, a TLS listener without its key)."""
    return _NETWORK_FAILURE.search(reason) is not None


def config_from_file(path: Path) -> zenoh.Config:
    """A user's own Zenoh configuration (JSON5), passed through unchanged."""
    try:
        return zenoh.Config.from_file(str(path))
    except Exception as error:
        raise TransportError(f"cannot use the Zenoh configuration {path}: {zenoh_reason(error)}") from None


@dataclass
class LinkStatistics:
    """What went over one remote link in this process."""

    link: str
    key: str
    direction: str  # "out" | "in"
    messages: int = 0
    malformed: int = 0
    refused: int = 0
    failed: int = 0  # sends Zenoh refused (the session closing)


class _Output:
    """The sending end of a remote link: the engine's send calls `deliver` as on a local channel."""

    __slots__ = ("_encode", "_put", "statistics")

    def __init__(self, codec: LinkCodec, statistics: LinkStatistics) -> None:
        self._put: Callable[[bytes], object] = _unopened
        self._encode = codec.encode
        self.statistics = statistics

    def attach(self, publisher: zenoh.Publisher) -> None:
        """The session is open: messages go to `publisher` (bound once, for every message)."""
        self._put = publisher.put

    def deliver(self, value: Any) -> None:
        try:
            self._put(self._encode(value))
        except Exception:  # a closing session: the sender's iteration must go on
            self.statistics.failed += 1
            return
        self.statistics.messages += 1


def _unopened(payload: bytes) -> object:
    """A send before the session is open (none is made: the run starts after `ZenohTransport.start`)."""
    raise TransportError("the Zenoh session is not open")


class _Input:
    """The receiving end of a remote link: one input buffer of one engine, fed by one remote agent."""

    def __init__(
        self,
        transport: ZenohTransport,
        link: str,
        engine: SubsystemEngine,
        buffer: str,
        source_agent: str,
        codec: LinkCodec,
        statistics: LinkStatistics,
    ) -> None:
        self.transport = transport
        self.link = link
        self.engine = engine
        self.buffer = buffer
        self.source_agent = source_agent
        self.codec = codec
        self.statistics = statistics
        self.channel = engine.channels[buffer]
        # bound once: every message goes through these on Zenoh's thread
        self._decode = codec.decode
        #: a fixed array of reals' own decoder (None otherwise), called first: one call less per message
        self._decode_fixed = codec.fixed_decoder
        self._hand_over = transport.inbox.put
        self._arrive = self.arrive

    # ---------------------------------------------------------------- on Zenoh's thread
    def on_sample(self, sample: zenoh.Sample) -> None:
        """Never raises: a bad message is counted (and the first one of each kind reported)."""
        payload = sample.payload.to_bytes()
        fixed = self._decode_fixed
        value = fixed(payload) if fixed is not None else None
        if value is not None:
            self.statistics.messages += 1
            self._hand_over(self._arrive, value)
            return
        try:
            value = self._decode(payload)
        except FingerprintMismatch as mismatch:
            self.statistics.refused += 1
            if self.statistics.refused == 1:
                self.transport.explain_mismatch(self, mismatch.received)
            return
        except MalformedMessage as error:
            self._malformed(str(error))
            return
        except Exception as error:  # anything else a broken payload can provoke
            self._malformed(f"{type(error).__name__}: {error}")
            return
        self.statistics.messages += 1
        self._hand_over(self._arrive, value)  # last: the scheduler wakes as this thread lets go of the GIL

    def _malformed(self, why: str) -> None:
        self.statistics.malformed += 1
        if self.statistics.malformed == 1:
            message = (
                f"link {self.link} ({self.statistics.key}): dropped malformed bytes ({why}); "
                "further malformed messages on this link are only counted"
            )
            self.transport.inbox.put(self.report, ("malformed", message))

    # ---------------------------------------------------------------- on the scheduler's thread
    def arrive(self, time: int, value: Any) -> None:
        self.channel.deliver(value)
        engine = self.engine
        if engine.waiting and engine.on_delivery is not None:
            engine.on_delivery(engine)

    def report(self, time: int, item: tuple[str, str]) -> None:
        kind, message = item
        self.engine.report_fault(time, kind, message)
        self.transport.log(f"earl run: {self.engine.name}: {message}")


class ZenohTransport:
    """One process's Zenoh session, its remote links, and its peers' liveliness.

    The session opens in `start` (or `open`), once the network is built: the links the builder
    declares meanwhile are declared on the session as it opens. Whatever can fail in the spec's
    code or the run's options (a function that cannot be bound, an environment that does not
    start) thus fails before this process listens, connects or shows itself to its peers.
    `announce` is logged once the session is open; `context` ends the message of a session that
    cannot open (which endpoints, from which file).
    """

    def __init__(
        self,
        system: str,
        local_agents: list[str],
        config: zenoh.Config,
        log: Callable[[str], None],
        *,
        announce: str | None = None,
        context: str | None = None,
    ) -> None:
        self.system = system
        self.local_agents = list(local_agents)
        self.log = log
        self.inbox = Inbox()
        self.statistics: list[LinkStatistics] = []
        self._inputs_by_agent: dict[str, list[_Input]] = {}
        self._peers: set[str] = set()  # the agents other processes must run for our links
        self._alive: set[str] = set()
        self._seen: set[str] = set()  # peers seen alive at least once (scheduler's thread)
        self._lost: set[str] = set()  # peers seen, then gone (scheduler's thread)
        self._alive_changed = threading.Condition()
        self._descriptions: dict[str, str] = {}  # fingerprint hex -> description, for the types queryable
        #: links whose receivers said they refuse our messages, and which subsystem refuses them
        self._refused_by: dict[str, str] = {}
        self._declared: list[Any] = []
        self._tokens: list[zenoh.LivelinessToken] = []
        self._types: TypeSystem | None = None
        #: peers that said they finished (closed in order): their going is no fault
        self._finished: set[str] = set()
        #: this process among those that run agents of the system: its liveliness tokens carry it
        self.process_id = uuid.uuid4().hex[:12]
        #: the processes each agent is seen alive in (more than one: the agent was started twice)
        self._instances: dict[str, set[str]] = {}
        #: the digest of the expanded system this process runs (`start`), None until it says
        self.specification: str | None = None
        #: what each peer process's tokens say it runs: (an agent of it, the digest of its system)
        self._peer_specifications: dict[str, tuple[str, str]] = {}
        #: peer processes found running another specification (said once each)
        self._other_specifications: set[str] = set()
        self._config = config
        self._announce = announce
        self._context = context
        #: None until `open`
        self.session: zenoh.Session | None = None
        #: what the builder declared before the session opened: declared on it as it opens
        self._pending: list[Callable[[zenoh.Session], None]] = []
        self._closed = False

    def open(self) -> None:
        """Open the Zenoh session (once) and declare on it every link built so far."""
        if self.session is not None:
            return
        if self._closed:
            raise TransportError("the transport was closed before its Zenoh session opened")
        try:
            session = zenoh.open(self._config)
        except Exception as error:
            context = f" ({self._context})" if self._context else ""
            raise TransportError(f"Zenoh could not start: {zenoh_reason(error)}{context}") from None
        self.session = session
        system = self.system
        self._declared.append(session.declare_queryable(f"earl/{escape(system)}/types/*", self._answer_type_query))
        self._declared.append(
            session.liveliness().declare_subscriber(alive_prefix(system) + "**", self._on_liveliness, history=True)
        )
        self._declared.append(session.declare_subscriber(finished_prefix(system) + "*", self._on_finished))
        pending, self._pending = self._pending, []
        for declare in pending:
            declare(session)
        if self._announce:
            self.log(self._announce)

    # ---------------------------------------------------------------- building (RemoteLinks)
    def outgoing(
        self, link: str, data_type: DataType, types: TypeSystem, source: str, destination_agent: str
    ) -> _Output:
        codec = self._codec(types, data_type, f"the link {link}")
        key = link_key(self.system, link)
        statistics = LinkStatistics(link, key, "out")
        self.statistics.append(statistics)
        self._peers.add(destination_agent)
        output = _Output(codec, statistics)

        def declare(session: zenoh.Session) -> None:
            publisher = session.declare_publisher(key, express=True)
            self._declared.append(publisher)
            output.attach(publisher)

        self._when_open(declare)
        return output

    def incoming(
        self, link: str, data_type: DataType, types: TypeSystem, engine: SubsystemEngine, buffer: str, source_agent: str
    ) -> None:
        codec = self._codec(types, data_type, f"a message on the link {link}")
        key = link_key(self.system, link)
        statistics = LinkStatistics(link, key, "in")
        self.statistics.append(statistics)
        self._peers.add(source_agent)
        remote = _Input(self, link, engine, buffer, source_agent, codec, statistics)
        self._inputs_by_agent.setdefault(source_agent, []).append(remote)
        with self._alive_changed:
            if source_agent not in self._alive:
                engine.stale.add(buffer)  # stale until its sender is seen
        self._when_open(lambda session: self._declared.append(session.declare_subscriber(key, remote.on_sample)))

    def _when_open(self, declare: Callable[[zenoh.Session], None]) -> None:
        if self.session is None:
            self._pending.append(declare)
        else:
            declare(self.session)

    def _codec(self, types: TypeSystem, data_type: DataType, where: str) -> LinkCodec:
        codec = LinkCodec(types, data_type, where)
        self._descriptions[codec.fingerprint.hex()] = codec.description
        return codec

    def start(self, specification: str | None = None) -> None:
        """Declare this process's agents alive: called once every link is declared, so a peer that
        sees the token also finds the subscribers.  `specification` is the digest of the expanded
        system this process runs (`earl.model.digest.model_digest`); a peer that runs another is
        reported once (None: this process does not say, and compares with none).  Opens the session
        first, if it is not open yet (`TransportError` when Zenoh cannot start)."""
        self.open()
        assert self.session is not None
        with self._alive_changed:
            self.specification = specification
            seen = list(self._peer_specifications.items())
        for process, (agent, theirs) in seen:  # peers whose tokens came before this process knew its own
            self._compare_specifications(agent, process, theirs)
        said = UNKNOWN_SPECIFICATION if specification is None else specification
        for agent in self.local_agents:
            key = alive_key(self.system, agent, self.process_id, said)
            self._tokens.append(self.session.liveliness().declare_token(key))

    # ---------------------------------------------------------------- peers
    @property
    def peers(self) -> list[str]:
        return sorted(self._peers)

    def missing_peers(self) -> list[str]:
        with self._alive_changed:
            return sorted(self._peers - self._alive)

    def wait_for_peers(self, seconds: float) -> list[str]:
        """Wait until every agent our links talk to is alive, at most `seconds`; those still missing."""
        deadline = wall.monotonic() + seconds
        with self._alive_changed:
            while True:
                missing = self._peers - self._alive
                remaining = deadline - wall.monotonic()
                if not missing or remaining <= 0:
                    return sorted(missing)
                self._alive_changed.wait(min(remaining, 0.5))

    def _on_finished(self, sample: zenoh.Sample) -> None:
        """On Zenoh's thread: a peer agent is about to go because its run ended in order."""
        with self._alive_changed:
            self._finished.add(unescape(str(sample.key_expr).rsplit("/", 1)[-1]))

    def _on_liveliness(self, sample: zenoh.Sample) -> None:
        """On Zenoh's thread: a process declared one of its agents alive, or that token went."""
        # `<agent>/<process>/<spec>`; a process of an earlier earl says no spec (`<agent>/<process>`)
        chunks = str(sample.key_expr).removeprefix(alive_prefix(self.system)).split("/")
        if len(chunks) not in (2, 3):
            return  # not a token of earl's
        agent, process = unescape(chunks[0]), unescape(chunks[1])
        specification = unescape(chunks[2]) if len(chunks) == 3 else UNKNOWN_SPECIFICATION
        if process == self.process_id:
            return  # our own token
        if sample.kind == zenoh.SampleKind.PUT:
            with self._alive_changed:
                self._peer_specifications[process] = (agent, specification)
            self._compare_specifications(agent, process, specification)
        with self._alive_changed:
            instances = self._instances.setdefault(agent, set())
            was_alive = bool(instances)
            if sample.kind == zenoh.SampleKind.PUT:
                instances.add(process)
            else:
                instances.discard(process)
            alive = bool(instances)
            twice = len(instances) > 1 or (bool(instances) and agent in self.local_agents)
            if alive:
                self._alive.add(agent)
                self._finished.discard(agent)  # back (restarted): a later loss is news again
            else:
                self._alive.discard(agent)
            self._alive_changed.notify_all()
        if twice and sample.kind == zenoh.SampleKind.PUT:
            where = "here and in another process" if agent in self.local_agents else f"in {len(instances)} processes"
            self.log(
                f"earl run: {agent} runs {where}: the messages of its links mix, as if one agent sent them; "
                "stop all but one (each agent belongs to one process of the deployment)"
            )
        if alive != was_alive:
            # always handed over: the buffers it feeds may not be declared yet (the token can come first)
            self.inbox.put(self._peer_changed, (agent, alive))

    def _compare_specifications(self, agent: str, process: str, theirs: str) -> None:
        """Say once per peer process that it runs another specification than this one: links whose data types
        agree still carry its messages, but the two processes each run their own version of the system (a
        period, a condition or a `--param` value that no link's type shows)."""
        with self._alive_changed:  # from Zenoh's thread, and from `start`
            ours = self.specification
            if ours is None or theirs in (ours, UNKNOWN_SPECIFICATION) or process in self._other_specifications:
                return
            self._other_specifications.add(process)
        self.log(
            escape_controls(  # a peer's words: none may forge a line of this process's output
                f"earl run: {agent} runs another specification than this process (digest {theirs} there, {ours} "
                "here): the spec, its imports or the --param values differ; start every process from the same "
                "spec with the same parameters"
            )
        )

    def _peer_changed(self, time: int, item: tuple[str, bool]) -> None:
        """On the scheduler's thread: the buffers fed by `agent` go stale, or flow again."""
        agent, alive = item
        inputs = self._inputs_by_agent.get(agent, [])
        if alive == (agent in self._seen and agent not in self._lost):
            return  # nothing changed (a token seen twice, or lost twice)
        by_engine: dict[str, list[_Input]] = {}
        for remote in inputs:
            by_engine.setdefault(remote.engine.name, []).append(remote)
        for name, remotes in by_engine.items():
            listed = ", ".join(f"{remote.buffer}/ib" for remote in remotes)
            engine = remotes[0].engine
            if alive:
                engine.stale.difference_update(remote.buffer for remote in remotes)
                again = "again " if agent in self._seen else ""
                self.log(f"earl run: {agent} is alive: {name} {listed} receive {again}from it")
            else:
                engine.stale.update(remote.buffer for remote in remotes)
                with self._alive_changed:
                    finished = agent in self._finished
                if finished:  # its run ended in order: no fault, though nothing more comes
                    self.log(f"earl run: {name}: {agent} finished its run: {listed} receive nothing more (stale)")
                    continue
                message = (
                    f"{agent} disappeared: {listed} are stale (newData false, stale and timeout true) until it returns"
                )
                engine.report_fault(time, "stale", message)
                self.log(f"earl run: {name}: {message}")
        if alive:
            self._seen.add(agent)
            self._lost.discard(agent)
        else:
            self._lost.add(agent)

    # ---------------------------------------------------------------- data types
    def _answer_type_query(self, query: zenoh.Query) -> None:
        fingerprint = str(query.key_expr).rsplit("/", 1)[-1]
        description = self._descriptions.get(fingerprint)
        if description is not None:
            query.reply(query.key_expr, description.encode("utf-8"))
            self._told_of_refusal(query, description)

    def _told_of_refusal(self, query: zenoh.Query, ours: str) -> None:
        """The peer asking refuses our messages and says where (`explain_mismatch`): this side says it too,
        once per link, so that the process whose messages are lost is not the one that stays silent."""
        try:
            payload = query.payload
            asked: dict[str, Any] = json.loads(payload.to_bytes()) if payload is not None else {}
            link, receiver, buffer, expects = (str(asked[k]) for k in ("link", "receiver", "buffer", "expects"))
        except Exception:  # an older peer, or one that says nothing: its own report is the one
            return
        if link in self._refused_by:
            return
        self._refused_by[link] = receiver
        message = escape_controls(  # a peer's words: none may forge a line of this process's output
            f"earl run: link {link}: {receiver} refuses this process's messages of `{ours}`: its {buffer}/ib "
            f"expects `{expects}` — the two processes run different specifications"
        )
        self.inbox.put(lambda _time, said: self.log(said), message)

    def explain_mismatch(self, remote: _Input, received: bytes) -> None:
        """Ask the peers what `received` stands for (off Zenoh's callback thread), then report once."""

        def ask() -> None:
            theirs = f"an unknown type (fingerprint {received.hex()}; its sender did not describe it)"
            try:
                # what this side expects goes with the question: the sender says the refusal too
                said = {
                    "link": remote.link,
                    "receiver": remote.engine.name,
                    "buffer": remote.buffer,
                    "expects": remote.codec.description,
                }
                session = self.session
                if session is None:
                    raise TransportError("the session is not open")
                replies = session.get(type_key(self.system, received), timeout=2.0, payload=json.dumps(said))
                for reply in replies:
                    ok = reply.ok
                    if ok is not None:
                        theirs = f"`{ok.payload.to_bytes().decode('utf-8', errors='replace')}`"
                        break
            except Exception as error:  # the session may be closing; the report still goes out
                theirs += f" (asking for it failed: {error})"
            message = (
                f"link {remote.link} ({remote.statistics.key}): refused a message of {theirs} from "
                f"{remote.source_agent}; {remote.engine.name} {remote.buffer}/ib expects `{remote.codec.description}` "
                "— the two processes run different specifications; further mismatches are only counted"
            )
            self.inbox.put(remote.report, ("fingerprint", message))

        threading.Thread(target=ask, name="earl-type-query", daemon=True).start()

    # ---------------------------------------------------------------- the end
    def refused_links(self) -> dict[str, str]:
        """The links whose messages were refused for another data type (lost), and where: `52 refused here`
        on the receiving side, `receiver/a.cs refused this process's` on a sending side its receiver told."""
        refused = {
            statistics.link: f"{statistics.refused} refused here"
            for statistics in self.statistics
            if statistics.direction == "in" and statistics.refused
        }
        for link, receiver in list(self._refused_by.items()):  # a copy: Zenoh's threads may still add one
            refused.setdefault(link, f"{receiver} refused this process's")
        return refused

    def close(self) -> None:
        session = self.session
        if session is None:  # never opened (the run could not be set up): nothing was declared
            self._pending.clear()
            self._closed = True
            return
        if self._tokens:
            # said before the liveliness tokens go, and given a moment to arrive first (declarations and
            # data may travel at different priorities): the peers then know this is an end, not a crash
            for agent in self.local_agents:
                with contextlib.suppress(Exception):
                    session.put(finished_key(self.system, agent), b"")
            wall.sleep(FINISHED_LEAD)
        for token in self._tokens:
            with contextlib.suppress(Exception):  # already gone with the session
                token.undeclare()  # type: ignore[no-untyped-call]
        self._tokens.clear()
        # Zenoh's close waits for a connection it is still opening (a connect endpoint held by a program that
        # never answers): said when it takes long, rather than a process that seems to hang as it stops
        slow = threading.Timer(CLOSE_SAID_AFTER, self.log, args=(SLOW_CLOSE,))
        slow.daemon = True
        slow.start()
        try:
            with contextlib.suppress(Exception):  # closing twice, or Zenoh already shut down at interpreter exit
                session.close()  # type: ignore[no-untyped-call]
        finally:
            slow.cancel()
