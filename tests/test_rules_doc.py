"""docs/rules.md is generated from the registry; every code the source uses is documented."""

from __future__ import annotations

import re
from pathlib import Path

from earl.check.registry import RULES
from earl.check.rules_doc import DOC, render
from earl.lang.codes import READING_CODES
from earl.runtime.codes import RUNNING_CODES

SOURCE = Path(__file__).parent.parent / "src" / "earl"


def test_docs_rules_md_is_up_to_date() -> None:
    assert DOC.read_text(encoding="utf-8") == render(), "run `python -m earl.check.rules_doc --write`"


def test_every_code_used_in_the_source_is_documented() -> None:
    used = set()
    for path in SOURCE.rglob("*.py"):
        used.update(re.findall(r'"(EARL-[SREWI]\d{3})"', path.read_text(encoding="utf-8")))
    undocumented = sorted(code for code in used if code not in READING_CODES and code not in RULES)
    assert undocumented == []


def test_every_running_code_is_known_to_earl_rules_and_listed_in_the_runtime_page() -> None:
    used = set()
    for path in SOURCE.rglob("*.py"):
        used.update(re.findall(r'"(EARL-X\d{3})"', path.read_text(encoding="utf-8")))
    assert sorted(used) == sorted(RUNNING_CODES)
    page = (DOC.parent / "runtime.md").read_text(encoding="utf-8")
    assert sorted(set(re.findall(r"\| (EARL-X\d{3}) \|", page))) == sorted(RUNNING_CODES)


def test_every_rule_names_the_manual_and_explains_itself() -> None:
    for rule in RULES.values():
        assert rule.reference, rule.code
        assert len(rule.explanation) > 30, rule.code
        assert re.fullmatch(r"EARL-[EWI]\d{3}", rule.code)
