"""Diagnostics as JSON (a list of objects) and as SARIF 2.1.0 for code-scanning tools."""

from __future__ import annotations

import json
import os
import urllib.parse
from collections.abc import Sequence
from pathlib import Path, PurePath
from typing import Any

from earl import __version__
from earl.check.registry import rules_by_code
from earl.diagnostics import Diagnostic, Severity
from earl.lang.codes import READING_CODES

_SARIF_LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.NOTE: "note"}


def as_json(diagnostics: Sequence[Diagnostic]) -> str:
    return json.dumps(
        [
            {
                "code": d.code,
                "severity": d.severity.value,
                "message": d.message,
                "hint": d.hint,
                "file": d.location.file if d.location else None,
                "line": d.location.line if d.location else None,
                "column": d.location.column if d.location else None,
                "end_line": d.location.end_line if d.location else None,
                "end_column": d.location.end_column if d.location else None,
            }
            for d in diagnostics
        ],
        indent=2,
        ensure_ascii=False,
    )


def artifact_uri(file: str) -> str:
    """SARIF names files by URI: a relative path stays relative (code-scanning tools resolve it against
    the repository), an absolute one becomes a `file://` URI."""
    path = PurePath(file)
    if path.is_absolute():
        return Path(file).as_uri()
    # a relative reference: its characters percent-encoded as a URI needs them (`my spec#1.earl`
    # would otherwise be cut at `#`); undecodable bytes of the name are encoded as the bytes they were
    return urllib.parse.quote(os.fsencode(path.as_posix()), safe="/")


def as_sarif(diagnostics: Sequence[Diagnostic]) -> str:
    """A SARIF 2.1.0 log with one run; every registered rule, and every code of reading, is described in
    the tool's driver."""
    rules = [
        {
            "id": rule.code,
            "name": rule.check.__name__,
            "shortDescription": {"text": rule.title},
            "fullDescription": {"text": rule.explanation or rule.title},
            "defaultConfiguration": {"level": _SARIF_LEVEL[rule.severity]},
            "properties": {"manualReference": rule.reference},
        }
        for rule in rules_by_code()
    ]
    # what reading a spec finds before the rules apply (EARL-S…, EARL-R…): every result names a rule of the driver
    rules += [
        {
            "id": code,
            "name": "reading_" + code.removeprefix("EARL-").lower(),
            "shortDescription": {"text": text},
            "fullDescription": {"text": f"{text} (found while reading the spec; docs/rules.md)"},
            "defaultConfiguration": {"level": "error"},
        }
        for code, text in sorted(READING_CODES.items())
    ]
    index = {rule["id"]: position for position, rule in enumerate(rules)}
    results: list[dict[str, Any]] = []
    for d in diagnostics:
        text = d.message if not d.hint else f"{d.message}. Hint: {d.hint}"
        result: dict[str, Any] = {
            "ruleId": d.code or "EARL",
            "level": _SARIF_LEVEL[d.severity],
            "message": {"text": text},
        }
        if d.code in index:
            result["ruleIndex"] = index[d.code]
        if d.location is not None:
            result["locations"] = [
                {
                    "physicalLocation": {
                        "artifactLocation": {"uri": artifact_uri(d.location.file)},
                        "region": {
                            "startLine": d.location.line,
                            "startColumn": d.location.column,
                            "endLine": d.location.end_line,
                            "endColumn": d.location.end_column,
                        },
                    }
                }
            ]
        results.append(result)
    log = {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "earl",
                        "version": __version__,
                        "informationUri": "https://www.robotyka.ia.pw.edu.pl/projects/earl/",
                        "rules": rules,
                    }
                },
                "results": results,
            }
        ],
    }
    return json.dumps(log, indent=2, ensure_ascii=False)
