"""How a family named without saying which member is told to name one, or every one.

`any`/`all` take a condition, so they are proposed for a Boolean read only, over the range as the
spec writes it (`1..NBINS`, not `1..3`); a struct read is told to name a member, or to read every
member in a predicate computed by Python. A link's end inside a link family is told the link's index.
"""

from __future__ import annotations

import pytest

import earl
from earl.diagnostics import EarlError

SPEC = """\
system s

param NBINS: int = 3

struct ArmStatus {
    fault: boolean
    position: double
}

r/r {
    sorter/a
    pusher[*]/a
}

sorter/a {
    cs {
        period 1 ms
        armStatus[K in 1..NBINS]/ib: ArmStatus
        ready[K in 1..NBINS]/ib: boolean
        CONDITION
    }
}

pusher[K in 1..NBINS]/a {
    cs {
        status/ob: ArmStatus
    }
}

link pusher[K in 1..NBINS],sorter: pusher[K]/a.cs.status -> sorter/a.cs.armStatus[K]
"""


def _refused(text: str) -> tuple[str, str, str | None]:
    with pytest.raises(EarlError) as refused:
        earl.loads(text, "s.earl")
    problem = refused.value.diagnostics[0]
    return problem.code or "", problem.message, problem.hint


def test_the_quantifier_takes_a_letter_free_where_it_stands() -> None:
    """Inside `any(K …)` the family's letter `K` is taken: a second `any(K …)` would hide it (EARL-R015)."""
    code, _message, hint = _refused(SPEC.replace("CONDITION", "bad/pp = any(K in 1..2: ready[K]/ib and ready/ib)"))
    assert code == "EARL-R024"
    assert hint == "write `ready[1]/ib`, or every member: `any(J in 1..NBINS: ready[J]/ib)` or `all(…)`"


@pytest.mark.parametrize(
    ("condition", "code", "hint"),
    [
        (
            "bad/pp = armStatus/ib.fault",
            "EARL-R024",
            "write `armStatus[1]/ib`, or every member: `any(K in 1..NBINS: armStatus[K]/ib.fault)` or `all(…)`",
        ),
        (
            "bad/pp = ready[*]/ib",
            "EARL-R026",
            "name one member, `ready[1]/ib`, or every member: `any(K in 1..NBINS: ready[K]/ib)` or `all(…)`",
        ),
        (
            "bad/pp = armStatus[*]/ib.position > 0.5",
            "EARL-R026",
            "name one member, `armStatus[1]/ib`; a predicate computed by Python reads every member: "
            '`name/pp(armStatus[*]/ib) = python "module:function"`',
        ),
        (
            "bad/pp = armStatus/ib == armStatus[1]/ib",
            "EARL-R024",
            "write `armStatus[1]/ib`; a predicate computed by Python reads every member: "
            '`name/pp(armStatus[*]/ib) = python "module:function"`',
        ),
    ],
    ids=["Boolean field", "Boolean buffer with star", "number field with star", "struct"],
)
def test_any_and_all_are_proposed_for_a_boolean_over_the_range_as_written(condition: str, code: str, hint: str) -> None:
    """`any(K in 1..3: armStatus[K]/ib)` was proposed for a struct, with the range's value for `1..NBINS`."""
    refused = _refused(SPEC.replace("CONDITION", condition))
    assert (refused[0], refused[2]) == (code, hint)


def test_a_link_end_inside_a_link_family_is_told_the_links_index() -> None:
    """`-> pusher/a.cs.command` in `link sorter,pusher[K in 1..NBINS]` hinted `any(K in 1..3: pusher[K]/a)`."""
    text = SPEC.replace("CONDITION", "").replace("pusher[K]/a.cs.status", "pusher/a.cs.status")
    code, message, hint = _refused(text)
    assert (code, message) == ("EARL-R024", "`pusher/a` is a family of 3; say which member")
    assert hint == "write `pusher[K]/a`"


@pytest.mark.parametrize(
    ("condition", "hint"),
    [
        ("bad/pp = ready", "an element is read with its kind: write `ready/ib`"),
        ("bad/pp = remembered", "an element is read with its kind: write `remembered/mi`"),
        ("bad/pp = NBIN > 2", "did you mean `NBINS`?"),
    ],
    ids=["an input buffer", "a memory", "a parameter misspelt"],
)
def test_an_element_named_without_its_kind_is_told_its_kind(condition: str, hint: str) -> None:
    """`tc = extended` where `extended/pp` is declared said "declare it with `param`, or write an element with
    its kind (`x/pp`)", not which element it is."""
    text = SPEC.replace("CONDITION", f"ready/ib: boolean\n        remembered/m: int = 0\n        {condition}")
    text = text.replace("        ready[K in 1..NBINS]/ib: boolean\n", "")
    code, _message, given = _refused(text)
    assert (code, given) == ("EARL-R020", hint)
