"""Running a system: the Python API behind `earl run`.

    >>> import earl
    >>> sim = earl.simulate(earl.load("tests/runtime_specs/counter"), seed=1)
    >>> sim.advance_to(0.05)                      # seconds of simulated time
    >>> sim.state_of("counter/a.cs").state
    'finished'

Like Drake's Simulator, the model (an `earl.System`) stays untouched; the run's
state lives in the subsystem engines this object owns.
"""

from __future__ import annotations

import contextlib
import inspect
import math
import numbers
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from earl import _program
from earl.diagnostics import Diagnostic, EarlError, Severity, SourceMap, did_you_mean
from earl.model.digest import model_digest
from earl.model.elements import Duration, System
from earl.model.expand import expand
from earl.model.location import SourceLocation
from earl.model.types import refuse_wrong_parameters
from earl.model.validate import explaining
from earl.runtime.binding import BindingProblem, resolve_callable, user_code_path
from earl.runtime.builder import NANOSECONDS, Network, RemoteLinks, build_network, to_nanoseconds
from earl.runtime.engine import exception_text
from earl.runtime.events import Fault, Recorder, Recorders, StatisticsRecorder
from earl.runtime.names import family_example, named_members
from earl.runtime.run_settings import RunSettings, read_run_settings
from earl.runtime.scheduler import Inbox, Scheduler
from earl.runtime.trace import TraceWriter
from earl.runtime.values import shown_value

ParameterValue = bool | int | float | str


@dataclass(frozen=True)
class SubsystemState:
    """A subsystem at one instant: its FSM state, behaviour, iteration number, buffers and memory."""

    name: str
    state: str
    behaviour: str
    iteration: int
    memory: dict[str, Any]
    inputs: dict[str, Any]
    new_data: dict[str, bool]
    timed_out: dict[str, bool]
    iterations: int
    faults: int
    waiting: bool


class Transport(RemoteLinks, Protocol):
    """Links to agents in other processes (earl.transport.zenoh_transport.ZenohTransport)."""

    @property
    def inbox(self) -> Inbox: ...

    def start(self, specification: str | None = None) -> None:
        """Every link is declared and the run set up: open the links (if they are not open yet) and
        announce this process's agents, and the digest of the expanded system it runs
        (`earl.model.digest.model_digest`), which peers compare with theirs."""

    def close(self) -> None: ...


class _FaultList(Recorder):
    def __init__(self) -> None:
        self.faults: list[Fault] = []

    def fault(self, fault: Fault) -> None:
        self.faults.append(fault)


class Simulation:
    """A running system in virtual time (or, with `realtime=True`, paced by the wall clock)."""

    def __init__(
        self,
        system: System,
        *,
        parameters: Mapping[str, ParameterValue] | None = None,
        seed: int = 0,
        environment: object | str | None = "run.toml",
        trace: str | Path | None = None,
        record_memory: list[str] | None = None,
        record_links: list[str] | None = None,
        record_outputs: list[str] | None = None,
        realtime: bool = False,
        check: bool = True,
        agents: list[str] | None = None,
        recorders: list[Recorder] | None = None,
        transport: Transport | None = None,
    ) -> None:
        _refuse_wrong_arguments(system, trace, record_memory=record_memory, record_links=record_links, agents=agents)
        _refuse_wrong_arguments(system, trace, record_outputs=record_outputs)
        refuse_wrong_parameters(parameters)
        parameters = dict(parameters or {})
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            # NumPy's seed sequences take whole numbers >= 0; anything else would fail inside the first
            # function that draws a random number, and look like that function's fault
            raise ValueError(f"the seed is a whole number >= 0, not {seed!r}")
        for flag, value in (("realtime", realtime), ("check", check)):
            if value is None or isinstance(value, (str, bytes)):
                # `check="no"` is truthy: it would check, and `realtime="yes"` would run paced by the clock;
                # None would skip the checker without a word
                raise TypeError(f"{flag} takes True or False, not {type(value).__name__} {value!r:.60}")
        realtime, check = bool(realtime), bool(check)  # NumPy's Booleans, 0 and 1: the trace says true/false
        if isinstance(trace, (str, Path)) and not Path(trace).parent.is_dir():
            # said before the network is built and user code imported, not when the trace file is opened
            raise FileNotFoundError(f"the trace cannot be written: the directory `{Path(trace).parent}` does not exist")
        if transport is not None and not realtime:
            raise ValueError("a run over a transport between processes runs in real time only (realtime=True)")
        if check:
            _check(system, parameters)
        else:
            _check_parameters(system, parameters)
        self.system = system
        self.expanded = expand(system, parameters)
        self.seed = seed
        directories = _code_directories(system)
        settings = RunSettings()
        if environment == "run.toml":
            # like `earl run`: the environment a run.toml next to the spec names, if any (said at its line)
            settings = read_run_settings(Path(system.source_file)) if system.source_file else RunSettings()
            environment = settings.environment
        #: where the environment is named (run.toml's line), for what is said of it before the run
        self._environment_named = _environment_named(system, settings, environment)
        self.environment = _environment(environment, self.expanded, seed, directories, *self._environment_named)
        _refuse_unfit_methods(self.environment, *self._environment_named)
        _bind(self.environment, self.expanded, *self._environment_named)
        self.trace: TraceWriter | None = None
        try:
            self.statistics = StatisticsRecorder()
            self._faults = _FaultList()
            own: list[Recorder] = [self.statistics, self._faults, *(recorders or [])]
            self.recorder = Recorders(own)
            # a value of the wrong type built in Python (`data_type="int"`), which only the checker looks for
            # beforehand, fails somewhere inside when run with check=False: said at its path instead
            with explaining(system):
                self.network: Network = build_network(
                    self.expanded,
                    recorder=self.recorder,
                    environment=self.environment,
                    seed=seed,
                    code_directories=directories,
                    agents=set(agents) if agents else None,
                    remote=transport,
                )
            self.transport = transport
            memory = _memory_recorded(record_memory or [], list(self.network.by_name))
            _refuse_unknown_outputs(record_outputs, self.expanded)
            _warn_of_patterns_matching_nothing(record_links, self.network.link_index_variables)
            if transport is not None:
                # last of what the spec and the options can get wrong (its code bound, the environment started):
                # only now does this process open its links and show itself to its peers
                transport.start(model_digest(self.expanded))
            if trace is not None:
                self.trace = TraceWriter(
                    trace,
                    self.network.types,
                    self.network.link_types,
                    self.network.memory_types,
                    record_links,
                    self.network.link_sources,
                    self.network.link_index_variables,
                    self.network.output_types,
                )
                # the links leaving these output buffers (`manip/a.cs.manipulatorState`), whatever record_links
                # says: what `earl run --plot` draws of an output buffer is the messages on its links
                wanted = set(record_outputs or [])
                self.trace.links_also_recorded = {
                    link
                    for link, source in self.network.link_sources.items()
                    if source in wanted or source.rsplit("[", 1)[0] in wanted  # a family named whole: each member
                }
                self.recorder.add(self.trace)
                self.trace.run_started(
                    {"system": system.name, "seed": seed, "parameters": parameters, "realtime": realtime}
                )
            self.scheduler = Scheduler(
                self.network,
                self.recorder,
                _Guarded(self.environment, *self._environment_named),
                realtime=realtime,
                record_memory=memory,
                inbox=None if transport is None else transport.inbox,
            )
            if _program.stop_received():
                # in the `earl` program, a Ctrl-C that compiled code swallowed while the environment or the
                # spec's modules were imported (a Cython module's initialisation clears it): still a stop
                raise KeyboardInterrupt
        except BaseException:
            # Ctrl-C (or a failure) before the run could start: the trace's writer, in a session of its own,
            # would otherwise outlive this and write its file after `earl run` had removed it, and what the
            # environment opened (a viewer) would stay open
            if self.trace is not None:
                self.trace.abandon()
            _close_refused(self.environment)
            raise
        self.closed = False
        #: why `advance_to` ended inside an instant, after which the run cannot go on
        self._stopped_inside: str | None = None

    # ------------------------------------------------------------------ running
    @property
    def time(self) -> float:
        """Seconds of run time reached."""
        return self.scheduler.now / NANOSECONDS

    def advance_to(self, seconds: float, should_stop: Callable[[], bool] | None = None) -> None:
        """Run every subsystem iteration due until `seconds` of run time."""
        if self.closed:
            raise RuntimeError("this simulation is closed")
        if isinstance(seconds, bool) or not isinstance(seconds, numbers.Real):
            raise TypeError(f"advance_to takes a run time in seconds (a number), not {seconds!r}")
        # compared, not converted: an int beyond any float (10**400) is as far out of range as infinity
        if seconds != seconds or seconds > Duration.MAX_SECONDS or seconds == -math.inf:
            raise ValueError(
                f"advance_to takes a finite run time of at most {Duration.MAX_SECONDS:g} s, not {shown_value(seconds)}"
            )
        if should_stop is not None and not callable(should_stop):
            raise TypeError(f"should_stop takes a function of no arguments, not {should_stop!r:.60}")
        if seconds < 0:
            # a run time starts at 0: a slip between advance_to and advance_by, most likely
            raise ValueError(
                f"advance_to takes a run time from 0 on, not {shown_value(seconds)} (advance_by takes a duration)"
            )
        if self._stopped_inside is not None:
            raise RuntimeError(
                f"this simulation stopped inside an instant ({self._stopped_inside}), so a subsystem may be "
                "halfway through an iteration and its run cannot go on: read its state, close it, and make a new "
                "one with earl.simulate"
            )
        try:
            self.scheduler.advance_to(to_nanoseconds(seconds), None if should_stop is None else _asked(should_stop))
        except _StopQuestionFailed as failed:
            # the scheduler asks `should_stop` only between instants: the run can go on from there
            raise failed.error.with_traceback(failed.error.__traceback__) from None
        except BaseException as error:
            # Ctrl-C, sys.exit() or a failed environment can stop the run between the steps of an iteration
            # (a function run, its writes not yet applied); going on from there would silently skip them
            self._stopped_inside = f"{type(error).__name__} at {self.time:.6f} s"
            raise

    def advance_by(self, seconds: float, should_stop: Callable[[], bool] | None = None) -> None:
        """Run on for `seconds` of run time (>= 0)."""
        if isinstance(seconds, bool) or not isinstance(seconds, numbers.Real):
            raise TypeError(f"advance_by takes a duration in seconds (a number), not {seconds!r}")
        if seconds < 0:
            raise ValueError(f"advance_by takes a duration of 0 s or more, not {shown_value(seconds)}")
        if seconds != seconds or seconds > Duration.MAX_SECONDS or self.time + seconds > Duration.MAX_SECONDS:
            raise ValueError(
                f"advance_by takes a finite duration that ends the run by {Duration.MAX_SECONDS:g} s of run time, "
                f"not {shown_value(seconds)} (the run is at {self.time:g} s)"
            )
        self.advance_to(self.time + seconds, should_stop)

    def close(self) -> None:
        """End the run: the statistics are closed, the trace file finished, the environment closed."""
        if self.closed:
            return
        self.closed = True
        self.scheduler.close()
        self.statistics.close(self.scheduler.now)
        # each part closes even when one before it fails (a full disk, a plant's own error): an open Zenoh
        # session would keep the process from ending
        try:
            if self.trace is not None:
                iterations = {engine.name: engine.total_iterations for engine in self.network.engines}
                self.trace.close(self.scheduler.now, {"faults": len(self._faults.faults), "iterations": iterations})
        finally:
            try:
                close = getattr(self.environment, "close", None)
                if callable(close):
                    try:
                        close()
                    except Exception as error:  # the trace is finished by now: a failure of the run
                        raise EnvironmentFailed(f"the environment's close() raised {exception_text(error)}") from error
            finally:
                if self.transport is not None:
                    self.transport.close()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ looking in
    @property
    def subsystems(self) -> list[str]:
        return [engine.name for engine in self.network.engines]

    @property
    def faults(self) -> list[Fault]:
        return list(self._faults.faults)

    def state_of(self, subsystem: str) -> SubsystemState:
        """The FSM state, behaviour, buffers and memory of `subsystem` (e.g. "manip/a.cs")."""
        engine = self.network.by_name.get(subsystem) if isinstance(subsystem, str) else None
        if engine is None:
            from earl.diagnostics import did_you_mean

            members = _members_of(subsystem, list(self.network.by_name)) if isinstance(subsystem, str) else []
            if members:  # the base name of a family: each member runs on its own
                shown = (
                    f"`{members[0]}` … `{members[-1]}`" if len(members) > 2 else " and ".join(f"`{m}`" for m in members)
                )
                raise UnknownSubsystem(
                    f"`{subsystem}` is a family of subsystems, each run on its own: name a member, {shown}"
                )
            hint = did_you_mean(subsystem, list(self.network.by_name)) if isinstance(subsystem, str) else None
            hint = hint or f"subsystems are named like `{next(iter(self.network.by_name), 'manip/a.cs')}`"
            raise UnknownSubsystem(f"no subsystem `{subsystem}` in this run. {hint}".strip())
        state = engine.state
        return SubsystemState(
            engine.name,
            state.name if state else "",
            state.behaviour.name if state else "",
            engine.iteration,
            dict(engine.memory),
            dict(engine.inputs),
            dict(engine.new_data),
            dict(engine.timed_out),
            engine.total_iterations,
            engine.faults,
            engine.waiting,
        )


def simulate(system: System, **options: Any) -> Simulation:
    """A `Simulation` of `system`; see `Simulation` for the options (seed, environment, trace, …)."""
    return Simulation(system, **options)


def _check(system: System, parameters: Mapping[str, ParameterValue]) -> None:
    """The checker runs before execution; its errors stop the run (warnings do not)."""
    from earl.check import check

    errors = [d for d in check(system, parameters) if d.severity is Severity.ERROR]
    if errors:
        raise EarlError(errors, system.sources)  # type: ignore[arg-type]


def _check_parameters(system: System, parameters: Mapping[str, ParameterValue]) -> None:
    """Without the checker, still no misspelt or mistyped parameter: it would run with the default."""
    from earl.check import unknown_parameters, wrong_parameter_values

    errors = unknown_parameters(system, parameters) + wrong_parameter_values(system, parameters)
    if errors:
        raise EarlError(errors, system.sources)  # type: ignore[arg-type]


def _code_directories(system: System) -> list[Path]:
    return [Path(system.source_file).resolve().parent] if system.source_file else []


def _refuse_unknown_outputs(outputs: list[str] | None, expanded: System) -> None:
    """record_outputs names output buffers whose links the trace records: a misspelt one would record nothing."""
    if not outputs:
        return
    from earl.diagnostics import did_you_mean
    from earl.model.text import subsystem_name
    from earl.runtime.names import indexed

    known = [
        f"{subsystem_name(a, s)}.{indexed(o.name, o.index)}"
        for a in expanded.agents
        for s in a.subsystems
        for o in s.output_buffers
    ]
    families = {name.rsplit("[", 1)[0] for name in known if name.endswith("]")}
    for name in outputs:
        if name in families:
            continue  # a family of output buffers: every member (`Simulation` records each)
        if name not in known:
            hint = (
                did_you_mean(name, known)
                or f"output buffers are named like `{known[0] if known else 'manip/a.cs.manipulatorState'}`"
            )
            raise ValueError(f"record_outputs: `{name}` is no output buffer of this run; {hint}")


def _warn_of_patterns_matching_nothing(patterns: list[str] | None, links: Mapping[str, frozenset[str]]) -> None:
    """A misspelt glob would leave the trace quietly without the links meant (`earl run` says the same);
    `links` are the run's, each with its families' index variables."""
    import warnings

    from earl.runtime.link_patterns import matching, no_link_matched

    for pattern in patterns or []:
        if not matching(pattern, links):
            warnings.warn(
                f"record_links: `{pattern}` {no_link_matched(pattern, links)}", RecordingWarning, stacklevel=3
            )


def _memory_recorded(named: list[str], subsystems: list[str]) -> set[str]:
    """The subsystems whose memory `record_memory` names: `all`, a subsystem, or every member of a
    family (`pusher[*]/a.cs`, `pusher[K]/a.cs`, `pusher/a.cs`, as a robot names one); a ValueError
    for a name of none."""
    if "all" in named:
        return set(subsystems)
    memory: set[str] = set()
    unknown: list[str] = []
    for name in named:
        members = named_members(name, subsystems)
        memory.update(members)
        if not members:
            unknown.append(name)
    if unknown:
        families = [re.sub(r"\[[0-9]+\]", "[*]", name) for name in subsystems]
        hint = did_you_mean(unknown[0], [*dict.fromkeys(families), *subsystems]) if len(unknown) == 1 else None
        family = family_example(subsystems)
        example = f"`{next(iter(subsystems), 'manip/a.cs')}`" + (f", a family's member {family}" if family else "")
        raise ValueError(
            "record_memory (--record-memory, run.toml's record_memory) names no subsystem of this run: "
            f"{', '.join(sorted(unknown))} ({f'{hint} ' if hint else ''}subsystems are named like {example})"
        )
    return memory


def _refuse_wrong_arguments(system: object, trace: object, **lists: object) -> None:
    """A TypeError that says what an argument takes, before anything fails deeper with Python's own words."""
    if not isinstance(system, System):
        raise TypeError(
            f"a simulation runs a System, as earl.load(path) returns it, not {type(system).__name__} {system!r:.60}"
        )
    if trace is not None and not isinstance(trace, (str, Path)) and not callable(getattr(trace, "write", None)):
        raise TypeError(f"trace takes a file name or a binary stream, not {type(trace).__name__}")
    for name, value in lists.items():
        if isinstance(value, (str, bytes)):
            raise TypeError(f"{name} takes a list of names, e.g. [{value!r:.60}], not a single string")


class _StopQuestionFailed(Exception):
    """`should_stop` raised `error`: between two instants, so the run is whole and may go on."""

    def __init__(self, error: Exception) -> None:
        super().__init__(error)
        self.error = error


def _asked(should_stop: Callable[[], bool]) -> Callable[[], bool]:
    """`should_stop`, whose exception is told apart from one raised inside an instant."""

    def ask() -> bool:
        try:
            return should_stop()
        except Exception as error:  # Ctrl-C and sys.exit() stay what they are
            raise _StopQuestionFailed(error) from error

    return ask


class RecordingWarning(UserWarning):
    """An option that chooses what the trace records chooses nothing (`earl run` says it in its own words)."""


def _members_of(family: str, names: list[str]) -> list[str]:
    """The subsystems of a run that are members of `family` (`manip/a.drive/ve`: `manip/a.drive[1]/ve`, …; an
    agent family's too: `worker/a.cs`: `worker[1]/a.cs`, …), in the run's order."""
    import re

    plain = re.compile(r"\[\d+\]")
    return [name for name in names if name != family and plain.sub("", name) == family]


class UnknownSubsystem(KeyError):
    """`state_of` a name no subsystem of the run has; a KeyError whose message prints without quotes."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class EnvironmentFailed(RuntimeError):
    """The environment (the simulated plant, `run.toml`'s `environment`) raised: the run cannot go on."""


class _Guarded:
    """The environment as the scheduler sees it: an `advance` that raises EnvironmentFailed, saying when.

    One call more per advance of the plant, which steps a physics engine each time."""

    def __init__(
        self, environment: object, location: SourceLocation | None = None, sources: SourceMap | None = None
    ) -> None:
        advance = _environment_method(environment, "advance", location, sources)
        if advance is None:
            return

        def guarded(seconds: float) -> None:
            try:
                advance(seconds)
            except (KeyboardInterrupt, SystemExit):
                raise
            except BaseException as error:  # a diverging simulation, a plant's own exception class
                raise EnvironmentFailed(
                    f"the environment's advance({seconds:.6f}) raised {exception_text(error)}"
                ) from error

        self.advance = guarded


def _environment(
    environment: object | str | None,
    expanded: System,
    seed: int,
    directories: list[Path],
    location: SourceLocation | None,
    sources: SourceMap,
) -> object:
    """The environment object; `location` is where it is named (run.toml's line), if it is."""
    if not isinstance(environment, str):
        return environment
    with user_code_path(directories):
        try:
            factory = resolve_callable(
                environment,
                "the environment",
                location,
                arity=2,
                signature="def NAME(system, seed) -> object",
                placeholder="FACTORY",
                use="earl calls it once, before the run, and the object it returns is the environment",
                classes=True,  # `environment = "plant:Plant"`: the class makes the object, as a factory would
            )
        except BindingProblem as problem:
            raise EarlError([problem.diagnostic], sources) from None
        try:
            return factory(expanded, seed)
        except Exception as error:
            raise EarlError(
                [
                    Diagnostic(
                        Severity.ERROR,
                        f"the environment `{environment}` failed to start: {type(error).__name__}: {error}",
                        location,
                        code="EARL-X020",
                    )
                ],
                sources,
            ) from None


def _environment_method(
    environment: object, name: str, location: SourceLocation | None, sources: SourceMap | None
) -> Callable[..., Any] | None:
    """The environment's optional method `name` (`advance`, `bind`), None when it has none; EARL-X020 when
    what it has under that name cannot be called."""
    method = getattr(environment, name, None)
    if method is not None and not callable(method):
        raise EarlError([_not_a_method(name, method, location)], sources)
    return method


def _not_a_method(name: str, found: object, location: SourceLocation | None) -> Diagnostic:
    message = f"the environment's `{name}` is a {type(found).__name__}, not a method"
    return Diagnostic(Severity.ERROR, message, location, code="EARL-X020")


#: the environment's optional methods, each with what earl passes it (docs/runtime.md, "The environment")
_ENVIRONMENT_CALLS = {"bind": ("system",), "advance": ("time",), "close": ()}


def _refuse_unfit_methods(environment: object, location: SourceLocation | None, sources: SourceMap) -> None:
    """Before the run, EARL-X020 for an environment method earl could not call as it will (`advance()`
    without the time): it would raise a TypeError at the first instant, or `close` only at the end. An
    `advance` or `bind` that is no method is refused too, as earl would call it; a `close` that is data
    (a gripper's closing width) is left alone, as `Simulation.close` leaves it. What the environment
    opened (a viewer) is closed before the refusal, as when its `bind` refuses."""
    if environment is None:
        return
    problems = []
    for name, arguments in _ENVIRONMENT_CALLS.items():
        method = getattr(environment, name, None)
        if method is None or (name == "close" and not callable(method)):
            continue
        if not callable(method):
            problems.append(_not_a_method(name, method, location))
            continue
        try:
            # the callable earl calls, not the function a decorator wraps (`functools.wraps` sets
            # `__wrapped__`, which `inspect.signature` follows by default)
            signature = inspect.signature(method, follow_wrapped=False)
        except (TypeError, ValueError):  # a builtin or extension method that does not say: called as it is
            continue
        try:
            signature.bind(*arguments)
        except TypeError as error:
            shown = f"{name}({', '.join(arguments)})"
            # as written (`*` and `/` kept), without annotations: `advance()`, `close(viewer)`, `advance(*, time)`
            written = signature.replace(
                parameters=[p.replace(annotation=inspect.Parameter.empty) for p in signature.parameters.values()],
                return_annotation=inspect.Signature.empty,
            )
            problems.append(
                Diagnostic(
                    Severity.ERROR,
                    f"the environment's `{name}{written}` cannot be called as earl calls it, {shown}: {error}",
                    location,
                    code="EARL-X020",
                    hint=f"define it as `def {name}(self{''.join(', ' + a for a in arguments)})`",
                )
            )
    if problems:
        _close_refused(environment)
        raise EarlError(problems, sources)


def _close_refused(environment: object) -> None:
    """The environment's `close()`, if it has one, when the run will not start: what it opened (a renderer,
    a video) is finished now; its own error would hide why the run was refused."""
    close = getattr(environment, "close", None)
    if callable(close):
        with contextlib.suppress(Exception):
            close()


def _bind(environment: object, expanded: System, location: SourceLocation | None, sources: SourceMap) -> None:
    """The environment's `bind(system)`, if it has one: its chance to refuse, before the first iteration, a
    system it cannot serve (a MuJoCo model whose timestep does not divide a real effector's period)."""
    bind = _environment_method(environment, "bind", location, sources)
    if bind is None:
        return
    try:
        bind(expanded)
    except Exception as error:
        _close_refused(environment)
        if isinstance(error, EarlError):  # located by the environment, at the spec's lines
            for diagnostic in error.diagnostics:
                # what is at no line of the spec (a map of the environment's own) is said where it is named
                diagnostic.location = diagnostic.location or location
            raise EarlError(error.diagnostics, sources) from None
        message = f"the environment does not fit the system: {exception_text(error)}"
        raise EarlError([Diagnostic(Severity.ERROR, message, location, code="EARL-X021")], sources) from None


def _environment_named(
    system: System, settings: RunSettings, environment: object
) -> tuple[SourceLocation | None, SourceMap]:
    """Where the run.toml next to the spec names the environment, if it does (a message about the
    environment points at that line), and the texts a diagnostic quotes: the spec's, and that run.toml's
    (an environment that refuses the system in `bind` says so at the spec's lines)."""
    sources = SourceMap()
    if isinstance(system.sources, SourceMap):
        sources.texts.update(system.sources.texts)
    if not isinstance(environment, str) or environment != settings.environment:
        return None, sources
    location = settings.location("environment")
    if location is not None:
        sources.texts.update(settings.sources().texts)
    return location, sources


def bind_report(report: str, spec: Path, settings: RunSettings) -> Callable[[Simulation], object]:
    """run.toml's `report = "module:function"`, bound before the run as the spec's functions are: a
    misspelt name or a wrong signature is said at once (EARL-X001…X005 at its run.toml line), not
    after a run of minutes."""
    with user_code_path([spec.resolve().parent]):
        try:
            return resolve_callable(
                report,
                "the run report",
                settings.location("report"),
                arity=1,
                signature="def NAME(simulation) -> str",
                use="earl calls it once the run ends and prints the text it returns",
            )
        except BindingProblem as problem:
            raise EarlError([problem.diagnostic], settings.sources()) from None
