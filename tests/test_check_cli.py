"""`earl check` and `earl rules` on the command line: output formats, exit codes, and safety."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from earl.check.registry import RULES
from earl.cli.main import main
from earl.lang.codes import READING_CODES

EXAMPLE = Path(__file__).parent.parent / "examples" / "pick_and_place" / "system.earl"

# Two purely computational agents joined by one link: every rule holds.  (The periods share the
# `cs {` lines, so that the line numbers below stay those of the canonical layout.)
CLEAN = """\
system demo

a1/a {
    cs { period 1 ms
        out/ob: double
        x/m: double = 0.0
        go/pp = x/mi > 1.0
        compute/pf(x/mi -> x/mo)
        emit/pf(x/mi -> out/ob)
        run/bb {
            tf = {compute/pf} then {emit/pf}
            tc = go/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when go/pp
        }
    }
}

a2/a {
    cs { period 1 ms
        inp/ib: double
        y/m: double = 0.0
        got/pp = newData(inp/ib)
        take/pf(inp/ib -> y/mo)
        run/bb {
            tf = {take/pf}
            tc = got/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when got/pp
        }
    }
}

link a1,a2: a1/a.cs.out -> a2/a.cs.inp

r/r {
    a1/a
    a2/a
    link a1,a2
}
"""

# An unwritten output buffer (EARL-W040 at 6:9) only.
WARNING = CLEAN.replace("        out/ob: double\n", "        out/ob: double\n        spare/ob: double\n")

# The warning, and two overlapping transitions out of `run` (EARL-E060 at 20:13).
ERROR = WARNING.replace(
    "            state run: run/bb\n            run -> run when go/pp\n",
    "            state run: run/bb\n            state other: run/bb\n"
    "            run -> run when go/pp\n            run -> other when go/pp\n            other -> run when go/pp\n",
)

# A behaviour that never ends (EARL-I063 at 28:9), nothing else.
NOTE = CLEAN.replace("tc = got/pp", "tc = false")


def write(tmp_path: Path, text: str, name: str = "spec.earl") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def run(capsys: pytest.CaptureFixture[str], *arguments: str) -> tuple[int, str, str]:
    status = main(list(arguments))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_the_specs_above_are_what_they_claim(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for text, codes in (
        (CLEAN, []),
        (WARNING, ["EARL-W040"]),
        (ERROR, ["EARL-W040", "EARL-E060"]),
        (NOTE, ["EARL-I063"]),
    ):
        status, out, _ = run(capsys, "check", str(write(tmp_path, text)), "--format", "json")
        assert [d["code"] for d in json.loads(out)] == codes
        assert status == (1 if text is ERROR else 0)


# ---------------------------------------------------------------- human output


def test_human_output_quotes_the_line_with_a_caret_and_a_hint(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = write(tmp_path, ERROR)
    status, out, err = run(capsys, "check", str(spec))
    assert status == 1
    assert out == ""  # findings go to stderr, so stdout stays clean for pipes
    lines = err.splitlines()
    head = lines.index(
        "error[EARL-E060]: transitions `run,run/t` and `run,other/t` of a1/a.cs can both hold, e.g. when go/pp = true"
    )
    assert lines[head + 1].strip() == f"--> {spec}:20:13"
    source = next(line for line in lines[head + 1 :] if line.endswith("run -> other when go/pp"))
    caret = lines[lines.index(source) + 1]
    # the caret line underlines the transition, starting under its first character
    assert caret.index("^") == source.index("run -> other")
    assert caret.rstrip().endswith("^" * len("run -> other when go/pp"))
    assert "= hint: give them distinct priorities (`priority 1` is evaluated first)" in err
    assert f"--> {spec}:6:9" in err and "warning[EARL-W040]" in err
    assert lines[-1] == "1 error, 1 warning"
    # errors and warnings in the order of the file
    assert err.index("EARL-W040") < err.index("EARL-E060")


def test_human_output_groups_findings_by_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """With an imported file, each file's findings come under its own heading, the spec's own first."""
    write(tmp_path, "lonely/a {\n    cs {\n    }\n}\n", "lib.earl")
    spec = write(tmp_path, WARNING.replace("system demo\n", 'system demo\n\nimport "lib.earl"\n'))
    status, out, err = run(capsys, "check", str(spec))
    assert status == 0 and "(3 warnings)" in out  # the lonely agent's cs has no FSM, either (W043)
    lines = err.splitlines()
    headings = [line for line in lines if line.startswith("── ")]
    assert headings == [f"── {spec}: 1 warning", f"── {tmp_path / 'lib.earl'}: 2 warnings"]
    own, imported = lines.index(headings[0]), lines.index(headings[1])
    assert own < lines.index(f" --> {spec}:8:9") < imported < lines.index(f" --> {tmp_path / 'lib.earl'}:1:1")
    assert "warning[EARL-W001]: agent `lonely/a` is of type C (zombie)" in err
    # one file: no headings
    _, _, err = run(capsys, "check", str(write(tmp_path, WARNING, "single.earl")))
    assert "── " not in err


def test_human_output_of_a_clean_spec_says_ok(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, CLEAN)
    status, out, err = run(capsys, "check", str(spec))
    assert status == 0
    assert out == f"{spec}: ok — system `demo` follows the rules of the EARL manual\n"
    assert err == ""


def test_notes_are_shown_with_verbose_only(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, NOTE)
    status, out, err = run(capsys, "check", str(spec))
    assert status == 0
    assert "EARL-I063" not in err
    assert "(1 note, shown with --verbose)" in out
    status, out, err = run(capsys, "check", str(spec), "--verbose")
    assert status == 0
    assert "note[EARL-I063]: `run/bb` never ends" in err
    assert f"--> {spec}:28:9" in err
    assert "(1 note)" in out


def test_a_syntax_error_is_reported_with_exit_1(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, CLEAN.replace("run -> run when go/pp", "run run when go/pp"))
    status, out, err = run(capsys, "check", str(spec))
    assert status == 1
    assert "error[EARL-S" in err and f"{spec}:17:" in err
    assert "Traceback" not in err + out


# ---------------------------------------------------------------- machine-readable output


def test_json_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, ERROR)
    status, out, err = run(capsys, "check", str(spec), "--format", "json")
    assert status == 1
    assert err == ""
    findings = json.loads(out)
    assert isinstance(findings, list) and len(findings) == 2
    keys = {"code", "severity", "message", "file", "line", "column", "end_line", "end_column"}
    for finding in findings:
        assert isinstance(finding, dict)
        assert keys <= finding.keys()
        assert finding["file"] == str(spec)
    warning, error = findings
    assert (warning["code"], warning["severity"], warning["line"], warning["column"]) == ("EARL-W040", "warning", 6, 9)
    assert (warning["end_line"], warning["end_column"]) == (6, 9 + len("spare/ob: double"))
    assert (error["code"], error["severity"], error["line"], error["column"]) == ("EARL-E060", "error", 20, 13)
    assert (error["end_line"], error["end_column"]) == (20, 13 + len("run -> other when go/pp"))
    assert "can both hold" in error["message"]


def test_json_output_of_notes_and_of_a_clean_spec(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = run(capsys, "check", str(write(tmp_path, NOTE)), "--format", "json")
    assert [(d["code"], d["severity"]) for d in json.loads(out)] == [("EARL-I063", "note")]  # notes without --verbose
    status, out, _ = run(capsys, "check", str(write(tmp_path, CLEAN)), "--format", "json")
    assert status == 0 and json.loads(out) == []


def test_json_output_of_a_spec_that_cannot_be_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(
        tmp_path,
        CLEAN.replace(
            "state run: run/bb\n            run -> run when go/pp",
            "state run: walk/bb\n            run -> run when go/pp",
        ),
    )
    status, out, _ = run(capsys, "check", str(spec), "--format", "json")
    assert status == 1
    (finding,) = json.loads(out)
    assert finding["code"] == "EARL-R030" and finding["severity"] == "error"
    assert (finding["file"], finding["line"]) == (str(spec), 16)


def sarif(capsys: pytest.CaptureFixture[str], spec: Path) -> tuple[int, dict[str, Any]]:
    status, out, _ = run(capsys, "check", str(spec), "--format", "sarif")
    log = json.loads(out)
    assert isinstance(log, dict)
    return status, log


def test_sarif_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, ERROR)
    status, log = sarif(capsys, spec)
    assert status == 1
    assert log["version"] == "2.1.0"
    assert "sarif" in log["$schema"]
    (only_run,) = log["runs"]
    driver = only_run["tool"]["driver"]
    assert driver["name"] == "earl"
    rules = driver["rules"]
    # the rules, then what reading a spec finds (S…, R…), which results name too
    assert [rule["id"] for rule in rules] == sorted(RULES) + sorted(READING_CODES)
    for rule in rules:
        assert rule["name"].isidentifier()
        described = RULES[rule["id"]].title if rule["id"] in RULES else READING_CODES[rule["id"]]
        assert rule["shortDescription"]["text"] == described
        assert rule["defaultConfiguration"]["level"] in ("error", "warning", "note")
    assert len({rule["name"] for rule in rules}) == len(rules)
    results = only_run["results"]
    assert [(r["ruleId"], r["level"]) for r in results] == [("EARL-W040", "warning"), ("EARL-E060", "error")]
    for result in results:
        assert rules[result["ruleIndex"]]["id"] == result["ruleId"]
        assert result["message"]["text"]
        physical = result["locations"][0]["physicalLocation"]
        assert physical["artifactLocation"]["uri"] == spec.as_uri()
    region = results[1]["locations"][0]["physicalLocation"]["region"]
    assert (region["startLine"], region["startColumn"]) == (20, 13)
    # SARIF's endColumn is the column after the region, as earl's end columns are
    assert (region["endLine"], region["endColumn"]) == (20, 13 + len("run -> other when go/pp"))


def test_a_sarif_result_of_reading_names_a_rule_of_the_driver(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A syntax error (EARL-S…) or a name that does not resolve (EARL-R…) was a result whose rule the driver
    did not describe: SARIF viewers showed it without one."""
    spec = write(tmp_path, "system s\n\nagent/a {\n")
    status, log = sarif(capsys, spec)
    assert status == 1
    (only_run,) = log["runs"]
    rules = only_run["tool"]["driver"]["rules"]
    (result,) = only_run["results"]
    assert result["ruleId"].startswith("EARL-S")
    assert rules[result["ruleIndex"]]["id"] == result["ruleId"]


def test_sarif_names_a_relative_file_relative(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    write(tmp_path, ERROR)
    monkeypatch.chdir(tmp_path)
    _, log = sarif(capsys, Path("spec.earl"))
    uris = {r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] for r in log["runs"][0]["results"]}
    assert uris == {"spec.earl"}


def test_sarif_file_references_are_percent_encoded_uris() -> None:
    from earl.check.report import artifact_uri

    assert artifact_uri("my spec#1.earl") == "my%20spec%231.earl"  # a `#` would cut the name
    assert artifact_uri("lib/types.earl") == "lib/types.earl"
    assert artifact_uri("/tmp/x y.earl") == "file:///tmp/x%20y.earl"
    assert artifact_uri("sp\udcfe.earl") == "sp%FE.earl"  # the byte the file name has


def test_sarif_output_of_a_clean_spec_still_describes_the_rules(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, log = sarif(capsys, write(tmp_path, CLEAN))
    assert status == 0
    assert log["runs"][0]["results"] == []
    assert len(log["runs"][0]["tool"]["driver"]["rules"]) == len(RULES) + len(READING_CODES)


# ---------------------------------------------------------------- exit codes


def test_exit_codes_and_strict(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    clean, warning, error, note = (
        str(write(tmp_path, text, name))
        for text, name in ((CLEAN, "c.earl"), (WARNING, "w.earl"), (ERROR, "e.earl"), (NOTE, "n.earl"))
    )
    assert run(capsys, "check", clean)[0] == 0
    assert run(capsys, "check", clean, "--strict")[0] == 0
    status, out, err = run(capsys, "check", warning)
    assert status == 0
    assert "(1 warning)" in out and "warning[EARL-W040]" in err
    status, out, err = run(capsys, "check", warning, "--strict")
    assert status == 1
    assert "ok" not in out and "warning[EARL-W040]" in err
    assert run(capsys, "check", warning, "--strict", "--format", "json")[0] == 1
    assert run(capsys, "check", error)[0] == 1
    assert run(capsys, "check", note, "--strict")[0] == 0  # notes never fail


def test_usage_errors_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    status, _, err = run(capsys, "check", str(tmp_path / "missing.earl"))
    assert status == 2 and "no such file" in err
    status, _, err = run(capsys, "check", str(tmp_path))  # a directory without system.earl
    assert status == 2 and "directory" in err
    status, _, err = run(capsys, "check", str(EXAMPLE), "--param", "N")
    assert status == 2 and "NAME=VALUE" in err
    status, _, err = run(capsys, "check", str(EXAMPLE), "--param", "N=3", "--param", "N=4")
    assert status == 2 and "--param sets `N` twice" in err
    with pytest.raises(SystemExit) as exit_:
        main(["check", str(EXAMPLE), "--format", "xml"])
    assert exit_.value.code == 2
    with pytest.raises(SystemExit) as exit_:
        main(["check"])
    assert exit_.value.code == 2


def test_an_unknown_parameter_is_an_invalid_spec(capsys: pytest.CaptureFixture[str]) -> None:
    status, _, err = run(capsys, "check", str(EXAMPLE), "--param", "M=3")
    assert status == 1
    assert "EARL-R001" in err


@pytest.mark.parametrize(
    ("value", "fragment"),
    [
        ("x", 'its value is "x"'),
        ("nan", "its value is NaN"),
        ("true", "its value is true"),
        ("1e400", "is inf"),
        ("1_000", 'its value is "1_000"'),  # Python would read these as numbers; a spec cannot
        ("٣", 'its value is "٣"'),
    ],
)
def test_a_param_of_the_wrong_type_is_one_error_not_one_per_use(
    capsys: pytest.CaptureFixture[str], value: str, fragment: str
) -> None:
    """The spec's own `N` stands in once `--param N=…` is refused: its uses are not errors too."""
    status, _, err = run(capsys, "check", str(EXAMPLE), "--param", f"N={value}")
    assert status == 1
    assert err.count("error[") == 1 and "EARL-R005" in err and fragment in err
    # the caret is at the spec's own value, which is right: the message says where the wrong one came from
    assert "given from outside the spec (`--param`" in err and "as the spec's own (marked) is" in err


def test_a_family_range_emptied_by_a_param_is_one_error_at_the_param_naming_where_it_came_from(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """`--param N=0` said "the family range 1..0 is empty" ten times, at lines whose text is right, never
    saying that `N` came from the command line (EARL-R005 says "given from outside the spec")."""
    status, _, err = run(capsys, "check", str(EXAMPLE), "--param", "N=0")
    assert status == 1
    assert err.count("error[") == 1
    assert (
        "error[EARL-R016]: `N` = 0, given from outside the spec (`--param`, or `parameters=` in Python), leaves "
        "the family range 1..0 empty: `1..N` at lines 200, 204, 211, 212, 294, 348, 374, 375, 376 and 377"
    ) in err
    assert "system.earl:8:16" in err  # `param N: int = 6`: the value the spec itself gives
    assert "= hint: give `N` a value of at least 1" in err


def test_a_family_range_made_too_large_by_a_param_it_derives_from_is_told_once(tmp_path: Path) -> None:
    """Through a parameter computed from the one given (`M = 2 * N`), and by the Python API's `parameters=`;
    a range the spec's own values empty is still told at its own line."""
    import earl

    text = (
        "system s\n\nparam N: int = 2\nparam M: int = 2 * N\n\nx/a {\n    cs {\n        period 1 ms\n"
        "        v[J in 1..M]/m: int = 0\n        w[J in 1..M]/m: int = 0\n        u[J in 3..2]/m: int = 0\n    }\n}\n"
    )
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(text, "s.earl", {"N": 60_000})
    told = [(d.code, d.message, d.location.line if d.location else None) for d in refused.value.diagnostics]
    assert refused.value.diagnostics[1].hint == "give `N` a smaller value"
    assert told == [
        ("EARL-R016", "the family range 3..2 is empty", 11),
        (
            "EARL-R017",
            "`N` = 60000, given from outside the spec (`--param`, or `parameters=` in Python), gives the family "
            "range 1..120000 120,000 members; at most 100,000 are allowed: `1..M` at lines 9 and 10",
            3,
        ),
    ]


def test_a_problem_is_reported_once_at_the_place_it_was_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A link family written without its index (`link motorController[K]/ve… -> motor[K]/re…`) meets the
    unknown `K` at each of its two ends — and used to say each twice."""
    import shutil

    copy = tmp_path / "pick"
    shutil.copytree(EXAMPLE.parent, copy)
    spec = copy / "system.earl"
    text = spec.read_text()
    line = (
        "    link motorController[K in 1..N],motor[K]: motorController[K]/ve.motorCommand -> motor[K]/re.motorCommand"
    )
    assert line in text
    spec.write_text(text.replace(line, "    link motorController[K]/ve.motorCommand -> motor[K]/re.motorCommand"))
    status, _, err = run(capsys, "check", str(copy))
    assert status == 1
    assert err.count("error[EARL-R020]") == 2 and "2 errors" in err


def test_export_refuses_a_nan_parameter_before_writing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "g.earl"
    spec.write_text(
        "system g\nparam G: double = 1e308 * 10 - 1e308 * 10\nx/a {\n    cs {\n        period 1 ms\n    }\n}\n"
    )
    status, _, err = run(capsys, "export", "sysml", str(spec), "-o", str(tmp_path / "g.sysml"))
    assert status == 1 and "its value is NaN" in err
    assert not (tmp_path / "g.sysml").exists()


# ---------------------------------------------------------------- --verbose and --param


def test_verbose_lists_agent_types(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, err = run(capsys, "check", str(EXAMPLE), "--verbose")
    assert status == 0
    rows = {line.split()[1]: line for line in out.splitlines() if "/a " in line}
    assert "CT — purely computational agent" in rows["task/a"]
    assert "CET — teleoperated agent" in rows["manip/a"] and "1 cs, 6 ve, 6 re" in rows["manip/a"]
    assert "CET — teleoperated agent" in rows["grip/a"] and "1 cs, 1 ve, 1 re" in rows["grip/a"]
    assert err.count("note[EARL-I063]") == 8
    assert "(8 notes)" in out


def test_param_changes_the_expanded_system(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run(capsys, "check", str(EXAMPLE.parent), "--param", "N=3", "--verbose")
    assert status == 0
    assert "1 cs, 3 ve, 3 re" in out


def test_verbose_lists_a_zombie(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = write(tmp_path, CLEAN + "\nlonely/a {\n    cs {\n    }\n}\n")
    status, out, err = run(capsys, "check", str(spec), "--verbose")
    assert status == 0
    assert "warning[EARL-W001]: agent `lonely/a` is of type C (zombie)" in err
    assert any("lonely/a" in line and "C — zombie (useless)" in line for line in out.splitlines())


# ---------------------------------------------------------------- earl rules


def test_rules_lists_every_rule(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run(capsys, "rules")
    assert status == 0
    lines = out.splitlines()
    assert [line.split()[0] for line in lines] == sorted(RULES)
    e060 = next(line for line in lines if line.startswith("EARL-E060"))
    assert "error" in e060 and "transitions leaving a state do not overlap" in e060 and "Figure 5a" in e060


def test_rules_explains_one_rule(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run(capsys, "rules", "E060")
    assert status == 0
    assert out.startswith(
        "EARL-E060: transitions leaving a state do not overlap\nerror; manual §2.2, Figure 5a, Table 5\n"
    )
    assert "`jointMove,jointMove/t` and `jointMove,idle/t`" in out
    assert run(capsys, "rules", "earl-w061")[1].startswith("EARL-W061: ")


def test_rules_knows_reading_codes_and_refuses_unknown_ones(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = run(capsys, "rules", "R031")
    assert status == 0 and out.startswith("EARL-R031: ")
    status, out, err = run(capsys, "rules", "E061")
    assert status == 2 and out == ""
    assert "no rule E061" in err
    status, out, _ = run(capsys, "rules", "X003")
    assert status == 0 and out.startswith("EARL-X003: importing the module raised an error")
    status, _, err = run(capsys, "rules", "X999")
    assert status == 2 and "EARL-S" not in err and "EARL-E" not in err  # no code of another family offered
    status, _, err = run(capsys, "rules", "X030")
    assert status == 2 and "did you mean `EARL-X020`?" in err
    status, _, err = run(capsys, "rules", "S19")
    assert "did you mean `EARL-S019`?" in err
    status, _, err = run(capsys, "rules", "")  # no code at all: not a misspelt one (it offered EARL-X021)
    assert status == 2 and "name a code" in err and "did you mean" not in err


# ---------------------------------------------------------------- safety


def earl_command() -> list[str]:
    script = Path(sys.executable).with_name("earl")
    if script.exists():
        return [str(script)]
    return [sys.executable, "-c", "import sys; from earl.cli.main import main; sys.exit(main(sys.argv[1:]))"]


def test_check_never_imports_code_the_spec_names(tmp_path: Path) -> None:
    marker = tmp_path / "imported.txt"
    (tmp_path / "evilmod.py").write_text(
        "from pathlib import Path\n"
        f"Path({str(marker)!r}).write_text('evilmod was imported')\n"
        "def f(*arguments):\n"
        f"    Path({str(marker)!r}).write_text('evilmod.f was called')\n"
    )
    spec = write(tmp_path, CLEAN.replace("compute/pf(x/mi -> x/mo)", 'compute/pf(x/mi -> x/mo) = python "evilmod:f"'))
    environment = dict(os.environ)
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(tmp_path), environment.get("PYTHONPATH")]))

    # The trap works: with this environment, importing the module leaves the marker.
    subprocess.run([sys.executable, "-c", "import evilmod"], cwd=tmp_path, env=environment, check=True)
    assert marker.exists()
    marker.unlink()

    for options in ([], ["--verbose", "--strict"], ["--format", "json"], ["--format", "sarif"]):
        result = subprocess.run(
            [*earl_command(), "check", spec.name, *options],
            cwd=tmp_path,
            env=environment,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert result.returncode == 0, result.stdout + result.stderr
        assert not marker.exists(), f"earl check {' '.join(options)} imported evilmod"
    assert (
        "ok — system `demo`"
        in subprocess.run(
            [*earl_command(), "check", spec.name],
            cwd=tmp_path,
            env=environment,
            capture_output=True,
            text=True,
            timeout=120,
        ).stdout
    )


def test_on_a_terminal_a_spinner_names_the_phase_and_elsewhere_nothing_is_added() -> None:
    """A spec of 100,000 subsystems takes seconds per phase: a terminal is told which one runs."""
    example = str(Path(__file__).parent.parent / "examples" / "pick_and_place")
    command = [sys.executable, "-m", "earl.cli.main", "check", example]
    plain = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    terminal = subprocess.run(
        command, capture_output=True, text=True, timeout=120, check=False, env={**os.environ, "FORCE_COLOR": "1"}
    )
    assert plain.returncode == terminal.returncode == 0
    assert plain.stderr == ""
    for phase in ("reading the specification", "expanding the indexed families", "applying the rules to 17 subsystems"):
        assert phase in terminal.stderr
    assert plain.stdout.strip().endswith(terminal.stdout.strip()[-60:])  # the verdict itself is the same


def test_a_refused_family_range_is_not_followed_by_index_errors_against_it(tmp_path: Path) -> None:
    spec = tmp_path / "rng.earl"
    spec.write_text(
        "system rng\n\nx/a {\n    cs {\n        period 1 ms\n        v[J in 3..2]/m: int = 0\n"
        "        p/pp = v[1]/mi > 0\n    }\n}\n"
    )
    import earl

    with pytest.raises(earl.EarlError) as refused:
        earl.load(spec)
    assert [d.code for d in refused.value.diagnostics] == ["EARL-R016"]  # no R027 against the empty range


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full here")
def test_an_output_with_no_room_left_is_one_line_not_a_traceback() -> None:
    with open("/dev/full", "w") as full:
        result = subprocess.run(
            [sys.executable, "-m", "earl.cli.main", "check", str(EXAMPLE)],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert result.returncode == 1
    assert result.stderr == "earl: cannot write the output: No space left on device\n"
