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
    """The declared reads of one function, read where they live (a snapshot for the whole stage)."""

    __slots__ = ("_fields", "_function")

    def __init__(self, function: str, fields: dict[str, tuple[dict[str, Any], str] | FamilyInputs]) -> None:
        self._function = function
        self._fields = fields

    def __getattr__(self, name: str) -> Any:
        try:
            entry = self._fields[name]
        except KeyError:
            raise UndeclaredAccess(
                f"`{self._function}` does not declare that it reads `{name}`; it reads: "
                f"{', '.join(n for n in self._fields if '/' not in n) or 'nothing'}"
            ) from None
        if isinstance(entry, FamilyInputs):
            return entry
        store, key = entry
        return store[key]

    def __getitem__(self, name: str) -> Any:
        return self.__getattr__(name)

    def __dir__(self) -> list[str]:
        return [n for n in self._fields if "/" not in n]


class _Target:
    """One declared write: where it goes, its key and its type."""

    __slots__ = ("data_type", "is_memory", "key")

    def __init__(self, key: str, is_memory: bool, data_type: DataType) -> None:
        self.key = key
        self.is_memory = is_memory
        self.data_type = data_type


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
    """The declared writes of one function; values are checked against their types as they are written."""

    __slots__ = ("_fields", "_function", "_memory", "_types", "written")

    def __init__(self, function: str, types: TypeSystem, memory: dict[str, Any]) -> None:
        object.__setattr__(self, "_function", function)
        object.__setattr__(self, "_types", types)
        object.__setattr__(self, "_memory", memory)
        object.__setattr__(self, "_fields", {})
        #: (is_memory, key) -> value written in the current call
        object.__setattr__(self, "written", {})

    def _declare(self, name: str, entry: _Target | FamilyOutputs) -> None:
        self._fields[name] = entry

    def _write(self, target: _Target, value: Any) -> None:
        kind = "mo" if target.is_memory else "ob"
        self.written[(target.is_memory, target.key)] = self._types.coerce(
            value, target.data_type, f"{target.key}/{kind}"
        )

    def _current(self, target: _Target) -> Value:
        marker = (target.is_memory, target.key)
        if marker in self.written:
            return self.written[marker]
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
        entry = self._entry(name)
        if isinstance(entry, FamilyOutputs):
            raise UndeclaredAccess(f"`{name}` is a family: write one member, e.g. `outputs.{name}[1] = …`")
        self._write(entry, value)

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
    """About the run, for the function being called: time, iteration, parameters, the environment."""

    __slots__ = (
        "behaviour",
        "environment",
        "iteration",
        "parameters",
        "period",
        "random",
        "state",
        "subsystem",
        "time",
    )

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
        self.time = 0.0
        self.iteration = 0
        self.state = ""
        self.behaviour = ""

    def __repr__(self) -> str:
        return f"<context of {self.subsystem} at t={self.time:.6f} s, {self.state}, iteration {self.iteration}>"


def build_inputs(
    function: str,
    reads: list[ElementReference],
    input_values: dict[str, Any],
    memory_values: dict[str, Any],
) -> Inputs:
    fields: dict[str, Any] = {}
    families: dict[str, dict[int, tuple[dict[str, Any], str]]] = {}
    for reference in reads:
        store = input_values if reference.kind is Kind.INPUT_BUFFER else memory_values
        key = reference_key(reference)
        index = reference_index(reference)
        suffix = "ib" if reference.kind is Kind.INPUT_BUFFER else "mi"
        fields[f"{key}/{suffix}"] = (store, key)
        if index is None:
            _add_unique(fields, reference.name, (store, key), function)
        else:
            families.setdefault(reference.name, {})[index] = (store, key)
    for name, members in families.items():
        family = FamilyInputs(name, dict(sorted(members.items())))
        _add_unique(fields, name, family, function)
    return Inputs(function, fields)


def build_outputs(
    function: str,
    writes: list[ElementReference],
    types: TypeSystem,
    memory_values: dict[str, Any],
    data_type_of: Callable[[ElementReference], DataType],
) -> Outputs:
    outputs = Outputs(function, types, memory_values)
    families: dict[str, dict[int, _Target]] = {}
    for reference in writes:
        is_memory = reference.kind is not Kind.OUTPUT_BUFFER
        key = reference_key(reference)
        target = _Target(key, is_memory, data_type_of(reference))
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


_AMBIGUOUS = object()


def _add_unique(fields: dict[str, Any], name: str, entry: Any, function: str) -> None:
    """An input buffer and a memory may share a name; then only `inputs["name/ib"]` tells them apart."""
    if name in fields and fields[name] is not entry:
        del fields[name]
        return
    fields[name] = entry
