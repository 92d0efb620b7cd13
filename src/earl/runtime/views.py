"""What a partial transition function sees: `inputs`, `outputs` and `context` (docs/runtime.md).

    def joint_move(inputs, outputs, context):
        error = inputs.manipulatorCommand.jointPosSetpoint[0] - inputs.currentJointPos[0]
        outputs.windingCurrent[1] = 2.0 * error

`inputs` shows only what the function declared it reads (`/ib`, `/mi`), `outputs`
only what it declared it writes (`/mo`, `/ob`); anything else is refused, so the
declarations in the spec are the truth about the data flow (Figure 6).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from types import MappingProxyType
from typing import Any

from earl.model.expressions import ElementReference
from earl.model.kinds import Kind
from earl.model.types import DataType
from earl.runtime.names import reference_index, reference_key
from earl.runtime.values import TypeSystem, Value


class UndeclaredAccess(AttributeError):
    """A function touched something its declaration in the spec does not list."""


class FamilyInputs:
    """`inputs.motorControllerState[K]`: the members of a family, by their index values (e.g. 1..N)."""

    __slots__ = ("_members", "_name")

    def __init__(self, name: str, members: dict[int, tuple[dict[str, Any], str]]) -> None:
        self._name = name
        self._members = members

    def __getitem__(self, index: int) -> Value:
        try:
            store, key = self._members[index]
        except KeyError:
            raise UndeclaredAccess(
                f"`{self._name}[{index}]` is not among the members this function reads "
                f"({', '.join(str(i) for i in self._members)})"
            ) from None
        return store[key]

    def __len__(self) -> int:
        return len(self._members)

    def __iter__(self) -> Iterator[Value]:
        for store, key in self._members.values():
            yield store[key]

    def indices(self) -> list[int]:
        return list(self._members)

    def items(self) -> Iterator[tuple[int, Value]]:
        for index, (store, key) in self._members.items():
            yield index, store[key]

    def __repr__(self) -> str:
        return f"<{self._name}[{', '.join(str(i) for i in self._members)}]>"


class Inputs:
    """The declared reads of one function, as they were when its stage began.

    Before each call the runtime copies the current value of every declared single
    read into this object's attributes (`refresh`), so `inputs.x` is a plain attribute
    read; families are live views over the same snapshot.
    """

    __slots__ = ("__dict__", "_full", "_function", "_singles")

    def __init__(
        self,
        function: str,
        singles: list[tuple[str, dict[str, Any], str]],
        families: dict[str, FamilyInputs],
        full: dict[str, tuple[dict[str, Any], str]],
    ) -> None:
        self._function = function
        self._singles = singles
        self._full = full
        self.__dict__.update(families)

    def refresh(self) -> None:
        values = self.__dict__
        for name, store, key in self._singles:
            values[name] = store[key]

    def __getattr__(self, name: str) -> Any:  # only for names that are not declared reads
        declared = sorted({n for n, _, _ in self._singles} | {n for n in self.__dict__})
        raise UndeclaredAccess(
            f"`{self._function}` does not declare that it reads `{name}`; it reads: {', '.join(declared) or 'nothing'}"
        )

    def __getitem__(self, name: str) -> Any:
        entry = self._full.get(name)
        if entry is not None:
            store, key = entry
            return store[key]
        return getattr(self, name)

    def __dir__(self) -> list[str]:
        return sorted({n for n, _, _ in self._singles} | set(self.__dict__))


class _Target:
    """One declared write: its key, its type, and the dictionary of the call's writes it goes to."""

    __slots__ = ("coerce", "data_type", "is_memory", "key", "store")

    def __init__(
        self, key: str, is_memory: bool, data_type: DataType, coerce: Callable[[Any], Value], store: dict[str, Any]
    ) -> None:
        self.key = key
        self.is_memory = is_memory
        self.data_type = data_type
        self.coerce = coerce
        self.store = store


class FamilyOutputs:
    """`outputs.windingCurrent[K] = value` for the members a function declares it writes."""

    __slots__ = ("_members", "_name", "_outputs")

    def __init__(self, name: str, outputs: Outputs, members: dict[int, _Target]) -> None:
        self._name = name
        self._outputs = outputs
        self._members = members

    def _target(self, index: int) -> _Target:
        try:
            return self._members[index]
        except KeyError:
            raise UndeclaredAccess(
                f"`{self._outputs._function}` does not declare that it writes `{self._name}[{index}]` "
                f"(it writes members {', '.join(str(i) for i in self._members)})"
            ) from None

    def __setitem__(self, index: int, value: Any) -> None:
        self._outputs._write(self._target(index), value)

    def __getitem__(self, index: int) -> Value:
        return self._outputs._current(self._target(index))

    def __len__(self) -> int:
        return len(self._members)

    def indices(self) -> list[int]:
        return list(self._members)


class Outputs:
    """The declared writes of one function; values are checked against their types as they are written.

    A call's writes are collected in `memory_written` (`/mo`) and `sent` (`/ob`); the engine
    applies them when the stage ends, and discards them when the function failed.
    """

    __slots__ = ("_fields", "_function", "_memory", "memory_written", "sent")

    def __init__(self, function: str, memory: dict[str, Any]) -> None:
        object.__setattr__(self, "_function", function)
        object.__setattr__(self, "_memory", memory)
        object.__setattr__(self, "_fields", {})
        object.__setattr__(self, "memory_written", {})
        object.__setattr__(self, "sent", {})

    def _declare(self, name: str, entry: _Target | FamilyOutputs) -> None:
        self._fields[name] = entry

    def clear(self) -> None:
        self.memory_written.clear()
        self.sent.clear()

    def _write(self, target: _Target, value: Any) -> None:
        target.store[target.key] = target.coerce(value)

    def _current(self, target: _Target) -> Value:
        """What the function wrote so far in this call; else memory's value before the stage."""
        if target.key in target.store:
            return target.store[target.key]
        return self._memory.get(target.key) if target.is_memory else None

    def _entry(self, name: str) -> _Target | FamilyOutputs:
        try:
            return self._fields[name]  # type: ignore[no-any-return]
        except KeyError:
            raise UndeclaredAccess(
                f"`{self._function}` does not declare that it writes `{name}`; it writes: "
                f"{', '.join(n for n in self._fields if '/' not in n) or 'nothing'}"
            ) from None

    def __setattr__(self, name: str, value: Any) -> None:
        entry = self._fields.get(name)
        if type(entry) is _Target:
            entry.store[entry.key] = entry.coerce(value)
            return
        if entry is None:
            self._entry(name)  # raises, naming what the function does write
        raise UndeclaredAccess(f"`{name}` is a family: write one member, e.g. `outputs.{name}[1] = …`")

    def __getattr__(self, name: str) -> Any:
        entry = self._entry(name)
        if isinstance(entry, FamilyOutputs):
            return entry
        return self._current(entry)

    def __setitem__(self, name: str, value: Any) -> None:
        self.__setattr__(name, value)

    def __getitem__(self, name: str) -> Any:
        return self.__getattr__(name)

    def __dir__(self) -> list[str]:
        return [n for n in self._fields if "/" not in n]


class Context:
    """About the run, for the function being called: time, iteration, parameters, the environment.

    `time`, `iteration`, `state` and `behaviour` are read from the running subsystem when
    asked for, so that keeping them current costs nothing per iteration.
    """

    __slots__ = ("_engine", "environment", "parameters", "period", "random", "subsystem")

    def __init__(
        self,
        subsystem: str,
        parameters: Mapping[str, Any],
        period: float | None,
        environment: object,
        random: Any,
    ) -> None:
        self.subsystem = subsystem
        self.parameters = MappingProxyType(dict(parameters))
        self.period = period
        self.environment = environment
        self.random = random
        self._engine: Any = None

    @property
    def time(self) -> float:
        """Seconds of run time at the start of this iteration."""
        return float(self._engine.iteration_start * 1e-9) if self._engine is not None else 0.0

    @property
    def iteration(self) -> int:
        """The behaviour's iterationNumber: 0 in the first iteration after its state was entered."""
        return int(self._engine.iteration) if self._engine is not None else 0

    @property
    def state(self) -> str:
        state = self._engine.state if self._engine is not None else None
        return str(state.name) if state is not None else ""

    @property
    def behaviour(self) -> str:
        state = self._engine.state if self._engine is not None else None
        return str(state.behaviour.name) if state is not None else ""

    def __repr__(self) -> str:
        return f"<context of {self.subsystem} at t={self.time:.6f} s, {self.state}, iteration {self.iteration}>"


def build_inputs(
    function: str,
    reads: list[ElementReference],
    input_values: dict[str, Any],
    memory_values: dict[str, Any],
) -> Inputs:
    singles: dict[str, tuple[str, dict[str, Any], str] | None] = {}
    families: dict[str, dict[int, tuple[dict[str, Any], str]]] = {}
    full: dict[str, tuple[dict[str, Any], str]] = {}
    for reference in reads:
        store = input_values if reference.kind is Kind.INPUT_BUFFER else memory_values
        key = reference_key(reference)
        index = reference_index(reference)
        suffix = "ib" if reference.kind is Kind.INPUT_BUFFER else "mi"
        full[f"{key}/{suffix}"] = (store, key)
        if index is None:
            # an input buffer and a memory may share a name: then only `inputs["x/ib"]` tells them apart
            singles[reference.name] = None if reference.name in singles else (reference.name, store, key)
        else:
            families.setdefault(reference.name, {})[index] = (store, key)
    family_views = {name: FamilyInputs(name, dict(sorted(members.items()))) for name, members in families.items()}
    return Inputs(function, [entry for entry in singles.values() if entry is not None], family_views, full)


def build_outputs(
    function: str,
    writes: list[ElementReference],
    types: TypeSystem,
    memory_values: dict[str, Any],
    data_type_of: Callable[[ElementReference], DataType],
) -> Outputs:
    outputs = Outputs(function, memory_values)
    families: dict[str, dict[int, _Target]] = {}
    for reference in writes:
        is_memory = reference.kind is not Kind.OUTPUT_BUFFER
        key = reference_key(reference)
        data_type = data_type_of(reference)
        target = _Target(
            key,
            is_memory,
            data_type,
            types.coercer(data_type, f"{key}/{'mo' if is_memory else 'ob'}"),
            outputs.memory_written if is_memory else outputs.sent,
        )
        outputs._declare(f"{key}/{'mo' if is_memory else 'ob'}", target)
        index = reference_index(reference)
        if index is None:
            if reference.name not in outputs._fields:
                outputs._declare(reference.name, target)
        else:
            families.setdefault(reference.name, {})[index] = target
    for name, members in families.items():
        outputs._declare(name, FamilyOutputs(name, outputs, dict(sorted(members.items()))))
    return outputs
