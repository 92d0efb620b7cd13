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
from typing import Any, NoReturn

from earl.model.expressions import ElementReference
from earl.model.kinds import Kind
from earl.model.types import DataType
from earl.runtime.codegen import compiled
from earl.runtime.names import reference_index, reference_key
from earl.runtime.values import QuickTest, TypeSystem, Value


class UndeclaredAccess(AttributeError):
    """A function touched something its declaration in the spec does not list."""

    def __init__(self, message: str, *, write: bool) -> None:
        super().__init__(message)
        #: a write (the fault `undeclared-write`), else a read (`undeclared-read`)
        self.write = write


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
                f"({', '.join(str(i) for i in self._members)})",
                write=False,
            ) from None
        return store[key]

    def __setitem__(self, index: int, value: Any) -> None:
        raise UndeclaredAccess(
            f"assigned `inputs.{self._name}[{index}]`; inputs are read-only: "
            "a function writes only its declared outputs (`outputs.…`, the names after `->`)",
            write=True,
        )

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


class _NoCollection:
    """What `Inputs` and `Outputs` share: neither is a collection of its names. Without this, `list(inputs)`
    and `x in inputs` would fall back on `inputs[0]`, `inputs[1]` … and fault as a read of an undeclared
    `0`; and a name reached by a loop would be a read or write the spec's declaration does not show."""

    __slots__ = ()

    def _earl_no_collection(self) -> TypeError:
        raise NotImplementedError  # each view says it in its own words

    def __iter__(self) -> NoReturn:
        raise self._earl_no_collection()

    def __len__(self) -> NoReturn:
        raise self._earl_no_collection()

    def __contains__(self, name: object) -> NoReturn:
        raise self._earl_no_collection()

    def __bool__(self) -> bool:
        return True  # as before `__len__` refused: `if inputs:` is no count


class Inputs(_NoCollection):
    """The declared reads of one function, as they were when its stage began.

    Before each call the runtime copies the current value of every declared single
    read into this object's attributes (`_earl_refresh`), so `inputs.x` is a plain
    attribute read; families are live views over the same snapshot. The object's own
    bookkeeping lives in slots named `_earl_…`, out of the way of any name of a spec.

    The class has no `__getattr__` on purpose: with one, CPython cannot specialise
    `inputs.x` into its fast attribute read, and every read of every function pays. A
    read of an undeclared name raises Python's own AttributeError, which the runtime
    rewords when it records the fault (`explain`).
    """

    __slots__ = ("__dict__", "_earl_full", "_earl_function", "_earl_refresh", "_earl_singles")

    def __init__(
        self,
        function: str,
        singles: list[tuple[str, dict[str, Any], str]],
        families: dict[str, FamilyInputs],
        full: dict[str, tuple[dict[str, Any], str]],
    ) -> None:
        self._earl_function = function
        self._earl_singles = singles
        self._earl_full = full
        self._earl_refresh = _compile_refresh(self.__dict__, singles)
        self.__dict__.update(families)

    def _earl_undeclared(self, name: str) -> UndeclaredAccess:
        declared = sorted({n for n, _, _ in self._earl_singles} | {n for n in self.__dict__})
        return UndeclaredAccess(
            f"`{self._earl_function}` does not declare that it reads `{name}`; "
            f"it reads: {', '.join(declared) or 'nothing'}",
            write=False,
        )

    def __setattr__(self, name: str, value: Any) -> None:
        # Reads stay CPython's fast attribute reads: only assignments come here.  Without this, an
        # assignment would land in the snapshot and vanish at the next call, without a word.
        if name.startswith("_earl_"):
            object.__setattr__(self, name, value)
            return
        raise UndeclaredAccess(
            f"`{self._earl_function}` assigned `inputs.{name}`; inputs are read-only: "
            "a function writes only its declared outputs (`outputs.…`, the names after `->`)",
            write=True,
        )

    def __delattr__(self, name: str) -> None:
        self.__setattr__(name, None)

    def __getitem__(self, name: str) -> Any:
        entry = self._earl_full.get(name)
        if entry is not None:
            store, key = entry
            return store[key]
        if name in self.__dict__:
            return self.__dict__[name]
        raise self._earl_undeclared(name)

    def __dir__(self) -> list[str]:
        return sorted({n for n, _, _ in self._earl_singles} | set(self.__dict__))

    def _earl_no_collection(self) -> TypeError:
        declared = self.__dir__()
        example = declared[0] if declared else "x"
        return TypeError(
            # no function's name: the fault that records the error names it
            f"inputs cannot be iterated, counted or searched (`for`, `len`, `in`); "
            f'read a declared name: `inputs.{example}` or `inputs["{example}"]` '
            f"(it reads: {', '.join(declared) or 'nothing'})"
        )


def _compile_refresh(values: dict[str, Any], singles: list[tuple[str, dict[str, Any], str]]) -> Callable[[], None]:
    """One straight-line function copying each declared read into `values`: it runs before every call.

    Generated rather than a loop over `singles` because it runs for every function in every
    iteration; the names are passed as constants through `repr`, never spliced in as code.
    """
    stores: list[dict[str, Any]] = []
    lines = ["def refresh():"]
    for name, store, key in singles:
        if not any(store is known for known in stores):
            stores.append(store)
        position = next(i for i, known in enumerate(stores) if known is store)
        lines.append(f"    values[{name!r}] = store_{position}[{key!r}]")
    if len(lines) == 1:
        lines.append("    pass")
    namespace: dict[str, Any] = {"values": values} | {f"store_{i}": store for i, store in enumerate(stores)}
    exec(compiled("\n".join(lines)), namespace)
    return namespace["refresh"]  # type: ignore[no-any-return]


class _Target:
    """One declared write: its key, its type, and the dictionary of the call's writes it goes to."""

    __slots__ = ("attribute", "coerce", "data_type", "is_memory", "key", "quick", "store")

    def __init__(
        self,
        key: str,
        attribute: str | None,
        is_memory: bool,
        data_type: DataType,
        coerce: Callable[[Any], Value],
        store: dict[str, Any],
        quick: QuickTest | None = None,
    ) -> None:
        self.key = key
        #: how a value passes as it is, tested inline by the engine; else `coerce` decides
        self.quick = quick
        #: the name a function writes it by (`outputs.x = …`), when it is not a family member
        self.attribute = attribute
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

    def _target(self, index: int, write: bool) -> _Target:
        try:
            return self._members[index]
        except KeyError:
            raise UndeclaredAccess(
                f"`{self._outputs._earl_function}` does not declare that it writes `{self._name}[{index}]` "
                f"(it writes members {', '.join(str(i) for i in self._members)})",
                write=write,
            ) from None

    def __setitem__(self, index: int, value: Any) -> None:
        target = self._members.get(index)  # `_target` only to refuse: this runs for every member written
        if target is None:
            target = self._target(index, write=True)
        target.store[target.key] = target.coerce(value)

    def __getitem__(self, index: int) -> Value:
        return self._outputs._earl_current(self._target(index, write=False))

    def __len__(self) -> int:
        return len(self._members)

    def indices(self) -> list[int]:
        return list(self._members)


class Outputs(_NoCollection):
    """The declared writes of one function, checked against their declarations and types.

    `outputs.x = value` is a plain attribute store, as cheap as writing any Python object:
    the engine takes the call's attributes when the function returns
    (earl/runtime/iteration.py), refusing an undeclared name and checking each value
    against its type. Family members (`outputs.x[K] = …`) and `outputs["x/mo"] = …` are
    checked as they are written. The checked writes are collected in
    `_earl_memory_written` (`/mo`) and `_earl_sent` (`/ob`); the engine applies them when
    the stage ends and discards them when the function failed.

    The object's own bookkeeping lives in slots named `_earl_…`, so that no name of a spec
    (`sent`, `clear`, …) can collide with it. Each function gets its own subclass, whose
    class attributes are its families (`outputs.windingCurrent` is found without any
    `__getattr__`, which would slow down every attribute store, see `Inputs`). Reading
    back a single write is `outputs["x"]`.
    """

    __slots__ = (
        "__dict__",
        "_earl_families",
        "_earl_function",
        "_earl_memory",
        "_earl_memory_written",
        "_earl_sent",
        "_earl_targets",
    )

    def __init__(self, function: str, memory: dict[str, Any]) -> None:
        self._earl_function = function
        self._earl_memory = memory
        #: single writes by the name a function uses, and by their `x/mo`, `x/ob` spelling
        self._earl_targets: dict[str, _Target] = {}
        self._earl_families: dict[str, FamilyOutputs] = {}
        self._earl_memory_written: dict[str, Any] = {}
        self._earl_sent: dict[str, Any] = {}

    def _earl_single_writes(self) -> list[tuple[str, _Target]]:
        """The writes a function makes by attribute (`outputs.x = …`), by that name."""
        return [(name, target) for name, target in self._earl_targets.items() if target.attribute == name]

    def _earl_clear(self) -> None:
        self.__dict__.clear()
        self._earl_memory_written.clear()
        self._earl_sent.clear()

    def _earl_refuse(self, name: str, write: bool = True) -> NoReturn:
        if name in self._earl_families:
            raise UndeclaredAccess(f"`{name}` is a family: write one member, e.g. `outputs.{name}[1] = …`", write=write)
        declared = [name for name, _ in self._earl_single_writes()] + list(self._earl_families)
        raise UndeclaredAccess(
            f"`{self._earl_function}` does not declare that it writes `{name}`; it writes: "
            f"{', '.join(declared) or 'nothing'}",
            write=write,
        )

    def _earl_current(self, target: _Target) -> Value:
        """What the function wrote so far in this call; else memory's value before the stage."""
        if target.attribute is not None and target.attribute in self.__dict__:
            return self.__dict__[target.attribute]
        if target.key in target.store:
            return target.store[target.key]
        if target.is_memory:
            return self._earl_memory.get(target.key)
        # an output buffer holds nothing before the call writes it: read back, it is no `None` to go on with
        raise UndeclaredAccess(
            f"`{self._earl_function}` reads back the output buffer `{target.key}` before writing it", write=False
        )

    def __setitem__(self, name: str, value: Any) -> None:
        target = self._earl_targets.get(name)
        if target is None:
            self._earl_refuse(name)
        if target.attribute is not None:
            self.__dict__.pop(target.attribute, None)  # the later write wins
        target.store[target.key] = target.coerce(value)

    def __getitem__(self, name: str) -> Any:
        """`outputs["x/mo"]`, `outputs["x"]`: what the call wrote so far, else memory's value before the stage."""
        target = self._earl_targets.get(name)
        if target is not None:
            return self._earl_current(target)
        family = self._earl_families.get(name)
        if family is not None:
            return family
        self._earl_refuse(name, write=False)

    def __dir__(self) -> list[str]:
        return [name for name, _ in self._earl_single_writes()] + list(self._earl_families)

    def _earl_no_collection(self) -> TypeError:
        declared = self.__dir__()
        example = declared[0] if declared else "x"
        return TypeError(
            # no function's name: the fault that records the error names it
            f"outputs cannot be iterated, counted or searched (`for`, `len`, `in`); "
            f'write a declared name: `outputs.{example} = …` or `outputs["{example}"] = …` '
            f"(it writes: {', '.join(declared) or 'nothing'})"
        )


class Context:
    """About the run, for the function being called: time, iteration, parameters, the environment.

    `time`, `iteration`, `state` and `behaviour` are read from the running subsystem when
    asked for, so that keeping them current costs nothing per iteration.
    """

    __slots__ = ("_engine", "_make_random", "_random", "environment", "parameters", "period", "subsystem")

    def __init__(
        self,
        subsystem: str,
        parameters: Mapping[str, Any],
        period: float | None,
        environment: object,
        random: Callable[[], Any],
    ) -> None:
        self.subsystem = subsystem
        self.parameters = MappingProxyType(dict(parameters))
        self.period = period
        self.environment = environment
        self._make_random = random
        self._random: Any = None
        self._engine: Any = None

    @property
    def random(self) -> Any:
        """This subsystem's own seeded stream (a `numpy.random.Generator`), made when first asked for:
        seeding one costs a millisecond, and most subsystems never draw a number."""
        if self._random is None:
            self._random = self._make_random()
        return self._random

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
        store = input_values if reference.kind == Kind.INPUT_BUFFER else memory_values
        key = reference_key(reference)
        index = reference_index(reference)
        suffix = "ib" if reference.kind == Kind.INPUT_BUFFER else "mi"
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
    # a class of its own: its families become class attributes below
    outputs: Outputs = type("Outputs", (Outputs,), {"__slots__": ()})(function, memory_values)
    families: dict[str, dict[int, _Target]] = {}
    targets = outputs._earl_targets
    for reference in writes:
        is_memory = reference.kind != Kind.OUTPUT_BUFFER
        key = reference_key(reference)
        spelled = f"{key}/{'mo' if is_memory else 'ob'}"
        index = reference_index(reference)
        # a memory and an output buffer may share a name: then only `outputs["x/ob"]` reaches the second
        attribute = reference.name if index is None and reference.name not in targets else None
        target = _Target(
            key,
            attribute,
            is_memory,
            data_type_of(reference),
            types.coercer(data_type_of(reference), spelled),
            outputs._earl_memory_written if is_memory else outputs._earl_sent,
            types.quick_test(data_type_of(reference)),
        )
        targets[spelled] = target
        if attribute is not None:
            targets[attribute] = target
        if index is not None:
            families.setdefault(reference.name, {})[index] = target
            targets.setdefault(key, target)  # `outputs["wheelSpeed[1]"]`, as `inputs["x[2]"]` reads a member
    for name, members in families.items():
        family = outputs._earl_families[name] = FamilyOutputs(name, outputs, dict(sorted(members.items())))
        setattr(type(outputs), name, family)
    return outputs


def explain(error: BaseException) -> BaseException:
    """A function's error as the fault records it: Python's AttributeError on a view, in the spec's words.

    `inputs.x` for an undeclared `x` raises AttributeError (the views have no `__getattr__`,
    see `Inputs`); this says which function did not declare what, and what it does declare.
    """
    if isinstance(error, AttributeError) and not isinstance(error, UndeclaredAccess):
        view = getattr(error, "obj", None)
        name = getattr(error, "name", None)
        if isinstance(name, str) and not name.startswith("_earl_"):
            if isinstance(view, Inputs):
                return view._earl_undeclared(name)
            if isinstance(view, Outputs):
                target = view._earl_targets.get(name)
                if target is not None:
                    # memory can be read back before it is written (its value before the stage); an
                    # output buffer holds nothing until the call writes it
                    advice = (
                        f'`outputs["{name}"]` reads what it holds (memory\'s value before the stage)'
                        if target.is_memory
                        else "an output buffer holds nothing until the call writes it: keep the value in a variable"
                    )
                    return UndeclaredAccess(
                        f"`{view._earl_function}` read `outputs.{name}` before writing it; {advice}", write=False
                    )
                try:
                    view._earl_refuse(name, write=False)
                except UndeclaredAccess as refused:
                    return refused
    return error
