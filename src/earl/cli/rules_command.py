"""`earl rules [CODE]`: what each rule of `earl check` enforces, and why (like `rustc --explain`)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from earl.check.registry import RULES, rules_by_code
from earl.cli.common import usage_error
from earl.diagnostics import did_you_mean
from earl.lang.codes import READING_CODES
from earl.runtime.codes import RUNNING_CODES


def register(commands: Any) -> None:
    parser = commands.add_parser(
        "rules",
        help="list the rules of `earl check`, or explain one",
        description="Without CODE, list every rule with its manual reference; with CODE, explain that rule.",
        epilog="examples:\n  earl rules\n  earl rules E060\n\nexit codes: 0 listed or explained, 2 usage error "
        "(no such code, an empty CODE), 130 interrupted (Ctrl-C)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("code", metavar="CODE", nargs="?", help="a code such as EARL-E060 (or just E060)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    if arguments.code is None:
        for rule in rules_by_code():
            sys.stdout.write(f"{rule.code}  {rule.severity.value:<7}  {rule.title}  ({rule.reference})\n")
        return 0
    code = arguments.code.strip().upper()
    if not code:  # `earl rules ''`: no code, not a misspelt one
        return usage_error("name a code, e.g. `earl rules E060`; `earl rules` alone lists the rules")
    if not code.startswith("EARL-"):
        code = f"EARL-{code}"
    if code in RULES:
        rule = RULES[code]
        sys.stdout.write(f"{rule.code}: {rule.title}\n{rule.severity.value}; manual {rule.reference}\n\n")
        sys.stdout.write(f"{rule.explanation}\n")
        return 0
    if code in READING_CODES:
        sys.stdout.write(f"{code}: {READING_CODES[code]} (found while reading the spec; see docs/rules.md)\n")
        return 0
    if code in RUNNING_CODES:
        sys.stdout.write(
            f"{code}: {RUNNING_CODES[code]} (found when `earl run` binds the spec to its code; see docs/runtime.md)\n"
        )
        return 0
    # a suggestion of the same family of codes only (`EARL-X999` is no misspelt `EARL-S019`)
    family = code[: len("EARL-") + 1]
    hint = did_you_mean(code, [c for c in [*RULES, *READING_CODES, *RUNNING_CODES] if c.startswith(family)])
    return usage_error(f"no rule {arguments.code}" + (f"; {hint}" if hint else "; `earl rules` lists them"))
