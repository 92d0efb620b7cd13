"""The parameters of a system, an agent or a subsystem as the document tabulates them: each with its
type, what the spec writes, the value it takes and where that value was given (the spec or `--param`).

A parameter of an indexed family drawn once may be computed from the family's index (`param joint:
int = K`): its value is then given for each member.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from earl.model.elements import Family, Parameter
from earl.model.expand import family_members
from earl.model.expressions import ConstantError, Literal, evaluate_constant
from earl.model.text import expression_text, literal_text
from earl.model.types import type_text
from earl.render.document.remarks import Remark, row_remarks

Value = bool | int | float | str
Environment = dict[str, Value]

#: A family drawn once lists the value of each member up to this many; beyond, the first and last ones.
LISTED_MEMBERS = 8


@dataclass(frozen=True)
class ParameterRow:
    name: str
    data_type: str
    #: the spec's expression, when it is more than the value (`N - 1`, `K`); "" for a plain value
    written: str
    value: str
    given: str  # `--param N=3`, or `spec, line 5`
    #: the comment written at it, and one above it heading the parameters from it on
    remark: Remark = field(default_factory=Remark)


def parameter_rows(
    parameters: Sequence[Parameter],
    outer: Environment,
    given: Mapping[str, Value] | None = None,
    family: Family | None = None,
    index: int | None = None,
) -> tuple[list[ParameterRow], Environment]:
    """The rows of `parameters` declared in a block whose outer parameters have the values `outer`, and the
    environment inside the block.  `given`: the values set by `--param` (system parameters only);
    `family`/`index`: the block's family, and which member it is (None: the family drawn once)."""
    given = given or {}
    members: list[Environment] = [dict(outer)]
    if family is not None:
        if index is not None:
            members = [{**outer, family.index: index}]
        else:
            try:
                members = [{**outer, family.index: member} for member in family_members(family, outer)]
            except ConstantError:
                members = [dict(outer)]
    rows = []
    remarks = row_remarks(parameters, [parameter.comments for parameter in parameters])
    for parameter, remark in zip(parameters, remarks, strict=True):
        values: list[Value | None] = []
        for environment in members:
            try:
                value = evaluate_constant(parameter.value, environment)
            except (ConstantError, TypeError):
                value = None  # the checker reports what is wrong with it
            if value is not None:
                if getattr(parameter.data_type, "name", "") in ("double", "float32", "float64") and type(value) is int:
                    value = float(value)
                environment[parameter.name] = value
            values.append(value)
        if parameter.name in given:
            where = f"--param {parameter.name}={literal_text(given[parameter.name])}"
        elif parameter.location is not None:
            where = f"spec, {Path(parameter.location.file).name}:{parameter.location.line}"
        else:
            where = "spec"
        written = "" if isinstance(parameter.value, Literal) else expression_text(parameter.value)
        rows.append(
            ParameterRow(
                parameter.name,
                type_text(parameter.data_type),
                written,
                _values_text(values, family if len(members) > 1 else None, members),
                where,
                remark,
            )
        )
    return rows, members[0] if len(members) == 1 else dict(outer)


def _values_text(values: list[Value | None], family: Family | None, members: list[Environment]) -> str:
    if any(value is None for value in values):
        return "—"
    texts = [_value_text(value) for value in values if value is not None]
    if family is None or len(set(texts)) == 1:
        return texts[0] if texts else "—"
    indices = [environment[family.index] for environment in members]
    pairs = [f"{text} ({family.index} = {_value_text(index)})" for text, index in zip(texts, indices, strict=True)]
    if len(pairs) > LISTED_MEMBERS:
        pairs = [*pairs[: LISTED_MEMBERS - 2], "…", pairs[-1]]
    return ", ".join(pairs)


#: A computed double is shown to this many significant digits: `0.4 + 0.3 * K` at K = 3 is 1.3, where
#: its binary value's repr said 1.2999999999999998.
SIGNIFICANT_DIGITS = 12


def _value_text(value: Value) -> str:
    """A parameter's value as the spec would write it; a double rounded to `SIGNIFICANT_DIGITS`, then in its
    shortest form (`1.3`, `0.25`, `1e-09`), so the noise of binary arithmetic does not show."""
    if isinstance(value, float) and math.isfinite(value):
        value = float(f"{value:.{SIGNIFICANT_DIGITS}g}")
    return literal_text(value)
