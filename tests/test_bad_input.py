"""Bad input: each gets one clear, located error and exit code 1 — never a traceback, a hang or a crash.

Empty files, binary garbage, text that is not UTF-8, a 10 MB file, expressions and types
nested 10,000 deep, unknown and duplicate names, import cycles and families with a negative
or huge range (issue 2, "Bad input").
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import earl
from earl.cli.main import main
from earl.diagnostics import Diagnostic, EarlError
from earl.lang.parser import MAX_FILE_BYTES

_HEAD = "system s\n\nr/r {\n    a/a\n}\n\n"


def _in_cs(body: str) -> str:
    return _HEAD + "a/a {\n    cs {\n" + body + "    }\n}\n"


def _errors(path: Path) -> list[Diagnostic]:
    with pytest.raises(EarlError) as caught:
        earl.load(path)
    return caught.value.diagnostics


def _check_exits_1(path: Path, capsys: pytest.CaptureFixture[str]) -> str:
    assert main(["check", str(path)]) == 1
    output = capsys.readouterr()
    printed = output.out + output.err
    assert "Traceback" not in printed
    return printed


@pytest.mark.parametrize(
    ("content", "code", "fragment", "where"),
    [
        (b"", "EARL-S033", "a specification starts with `system NAME`", (1, 1)),
        (b"   \n\n// only a comment\n", "EARL-S033", "a specification starts with `system NAME`", (1, 1)),
        (bytes(range(256)) * 16, "EARL-S021", "this is a binary file", (1, 1)),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "EARL-S021", "this is a binary file", (1, 1)),
        (b"system s\n// caf\xe9\n", "EARL-S022", "byte 0xe9 cannot be decoded", (2, 7)),
        (b"\xff\xfes\x00y\x00s\x00", "EARL-S021", "this is a binary file", (1, 1)),  # UTF-16 is not UTF-8
    ],
    ids=["empty", "blank and comments", "binary", "a PNG", "latin-1", "UTF-16"],
)
def test_a_file_that_is_no_specification_is_refused_plainly(
    content: bytes,
    code: str,
    fragment: str,
    where: tuple[int, int],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    path = tmp_path / "bad.earl"
    path.write_bytes(content)
    [error] = _errors(path)
    assert error.code == code
    assert fragment in error.message
    assert error.location is not None and (error.location.line, error.location.column) == where
    assert code in _check_exits_1(path, capsys)


def test_a_byte_order_mark_and_windows_line_ends_are_fine(tmp_path: Path) -> None:
    path = tmp_path / "windows.earl"
    path.write_bytes(
        b"\xef\xbb\xbf" + _in_cs("        period 1 ms\n        x/m: int\n").encode().replace(b"\n", b"\r\n")
    )
    system = earl.load(path)
    assert system.agent("a").control_subsystem.memories[0].location.line == 10


def test_old_mac_line_ends_are_lines_and_end_comments(tmp_path: Path) -> None:
    """A lone `\\r` ends a line: `// note\\rparam N …` must not hide the parameter inside the comment."""
    path = tmp_path / "mac.earl"
    path.write_bytes(b"system s\r// the number of joints\rparam N: int = 3\r")
    system = earl.load(path)
    assert [(p.name, p.location.line if p.location else 0) for p in system.parameters] == [("N", 3)]
    assert system.parameters[0].comments.leading == ["// the number of joints"]


def test_an_error_after_a_unicode_line_separator_quotes_its_own_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """U+2028 or U+0085 in a comment is no line end for the reader, so none for the quoted source either."""
    path = tmp_path / "separators.earl"
    path.write_text("system s\n// one \u2028 two \x85 three\nparam N: int = $\n", encoding="utf-8")
    printed = _check_exits_1(path, capsys)
    assert "3 | param N: int = $" in printed


def test_a_10_mb_file_is_refused_before_it_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "huge.earl"
    line = b"        x/pp = true or false and not true\n"
    path.write_bytes(_in_cs("").encode() + line * (10_000_000 // len(line)))
    assert path.stat().st_size > MAX_FILE_BYTES
    [error] = _errors(path)
    assert error.code == "EARL-S020"
    assert "MiB" in error.message and "refused" in error.message
    assert error.hint is not None and "import" in error.hint
    _check_exits_1(path, capsys)
    assert "9.5 MiB" in error.message  # the file's own size, though only 8 MiB and a byte are read


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_an_endless_file_is_read_no_further_than_the_size_limit(capsys: pytest.CaptureFixture[str]) -> None:
    """`/dev/zero` (or a pipe that never ends) must not be read for ever, nor into memory whole."""
    [error] = _errors(Path("/dev/zero"))
    assert error.code == "EARL-S020"
    assert "more than 8 MiB" in error.message
    _check_exits_1(Path("/dev/zero"), capsys)


def test_an_import_of_a_loop_of_symbolic_links_points_at_the_import(tmp_path: Path) -> None:
    (tmp_path / "one.earl").symlink_to(tmp_path / "two.earl")
    (tmp_path / "two.earl").symlink_to(tmp_path / "one.earl")
    spec = tmp_path / "system.earl"
    spec.write_text('system s\nimport "one.earl"\n', encoding="utf-8")
    [error] = _errors(spec)
    assert error.code == "EARL-S030"
    assert error.location is not None and (error.location.line, error.location.column) == (2, 1)
    assert "cannot read" in error.message and "one.earl" in error.message


@pytest.mark.parametrize("linked", ["the root file", "an imported file"])
def test_imports_are_looked_up_where_a_symbolic_link_points(linked: str, tmp_path: Path) -> None:
    """One rule for every file: its imports are next to the file itself, not next to a link to it."""
    library, project = tmp_path / "library", tmp_path / "project"
    library.mkdir()
    project.mkdir()
    (library / "units.earl").write_text("struct Pose {\n    x: double\n}\n", encoding="utf-8")
    (project / "units.earl").write_text("struct Other {\n    y: double\n}\n", encoding="utf-8")
    agent = "a/a {\n    cs {\n        p/m: Pose\n    }\n}\n"
    if linked == "the root file":
        (library / "system.earl").write_text(f'system s\nimport "units.earl"\n\n{agent}', encoding="utf-8")
        (project / "system.earl").symlink_to(library / "system.earl")
    else:
        (library / "types.earl").write_text('import "units.earl"\n', encoding="utf-8")
        (project / "types.earl").symlink_to(library / "types.earl")
        (project / "system.earl").write_text(f'system s\nimport "types.earl"\n\n{agent}', encoding="utf-8")
    system = earl.load(project / "system.earl")
    assert [t.name for t in system.types] == ["Pose"]


DEEP = 10_000


@pytest.mark.parametrize(
    ("expression", "code"),
    [
        ("not " * DEEP + "true", "EARL-S015"),
        ("-(" * DEEP + "1" + ")" * DEEP + " > 0", "EARL-S015"),
        ("1" + " + 1" * DEEP + " > 0", "EARL-S015"),
        ("x/mi" + " and x/mi" * DEEP, None),  # a flat chain is one level, however long
        ("(" * DEEP + "x/mi" + ")" * DEEP, None),  # parentheses nest no expression
        ("f(" * DEEP + "1" + ")" * DEEP, "EARL-S015"),
        ("[" * DEEP + "]" * DEEP, "EARL-S015"),
    ],
    ids=["not", "negation", "sum", "flat and", "parentheses", "calls", "lists"],
)
def test_an_expression_nested_10000_deep_is_refused_or_read_without_recursion(
    expression: str, code: str | None, tmp_path: Path
) -> None:
    path = tmp_path / "deep.earl"
    path.write_text(_in_cs(f"        x/m: boolean\n        p/pp = {expression}\n"))
    if code is None:
        system = earl.load(path)
        assert system.agent("a").control_subsystem.primitive_predicates[0].name == "p"
        return
    [error] = _errors(path)
    assert error.code == code
    assert "nested more than" in error.message
    assert error.location is not None and error.location.line == 10


def test_a_type_nested_10000_deep_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "deep.earl"
    path.write_text("system s\n\ntype T = int" + "[1]" * DEEP + "\n")
    [error] = _errors(path)
    assert error.code == "EARL-S017"
    assert error.location is not None and (error.location.line, error.location.column) == (3, 10)


@pytest.mark.parametrize(
    ("types", "line", "message"),
    [
        ("type A = A[]\n", 3, "type `A` is an alias of itself (A -> A), so it names no type"),
        ("type A = B[]\ntype B = A[3]\n", 3, "type `A` is an alias of itself (A -> B -> A)"),
        (
            "type A0 = int\n" + "".join(f"type A{i} = A{i - 1}[]\n" for i in range(1, 3001)),
            36,
            "type `A33` written out is 33 array dimensions: at most 32",
        ),
        (
            "type A0 = int\n" + "".join(f"type A{i} = A{i - 1}\n" for i in range(1, 5001)),
            103,
            "type `A100` written out is 101 aliases and arrays deep",
        ),
    ],
    ids=["itself", "through another", "3000 aliases of arrays", "5000 aliases"],
)
def test_an_alias_that_names_itself_or_nests_beyond_the_limits_is_refused_once(
    types: str, line: int, message: str, tmp_path: Path
) -> None:
    """An alias is written out wherever it is used: the SysML export recursed for ever on `type A = A[]`
    and on a chain of thousands of aliases, which check accepted. One error, at the first alias too deep."""
    import time

    path = tmp_path / "aliases.earl"
    path.write_text("system s\n\n" + types)
    started = time.monotonic()
    [error] = _errors(path)
    assert time.monotonic() - started < 10  # a walk from every type in turn took a minute for 5,000
    assert message in error.message
    assert error.location is not None and error.location.line == line


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        (
            "struct S0 {\n    v: double\n}\n"
            + "".join(f"struct S{i} {{\n    a: S{i - 1}\n}}\n" for i in range(1, 3001)),
            303,
            "struct `S100` holds structs 101 levels deep: at most 100",
        ),
        (
            "param N: int = 1000\nstruct Frame {\n    pixels: uint8[N][N]\n}\nstruct Video {\n    frames: Frame[100]\n}\n",
            7,
            "a value of type `Video` holds 100,000,000 numbers, Booleans and strings: at most 10,000,000",
        ),
        (
            _in_cs("        arr/m: double[1000000000000]\n").removeprefix("system s\n\n"),
            9,
            "a value of `double[1000000000000]` holds 1,000,000,000,000 numbers, Booleans and strings",
        ),
        (
            "struct Big {\n    v: double[100000000]\n}\n"
            + "".join(f"struct B{i} {{\n    a: {'Big' if i == 0 else f'B{i - 1}'}[2]\n}}\n" for i in range(50)),
            3,
            "a value of type `Big` holds 100,000,000",
        ),
    ],
    ids=["3000 nested structs", "a video of frames", "a memory of a trillion reals", "once, at the first too large"],
)
def test_a_value_too_deep_or_too_large_to_build_is_refused_once(
    text: str, line: int, message: str, tmp_path: Path
) -> None:
    """`earl run` built a `double[1000000000000]` memory's first value element by element (it never ended),
    and a value of 3,000 nested structs ended in "maximum recursion depth exceeded"; check accepted both."""
    path = tmp_path / "large.earl"
    path.write_text("system s\n\n" + text)
    [error] = _errors(path)
    assert message in error.message
    assert error.location is not None and error.location.line == line


def test_a_struct_holding_itself_through_a_variable_array_is_a_type(tmp_path: Path) -> None:
    path = tmp_path / "tree.earl"
    path.write_text("system s\n\nstruct Tree {\n    children: Tree[]\n}\n\ntype Forest = Tree[]\n")
    assert [t.name for t in earl.load(path).types] == ["Tree", "Forest"]


def test_unknown_and_duplicate_names_are_all_reported(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "names.earl"
    path.write_text(
        _in_cs(
            "        count/m: int\n"
            "        count/m: double\n"
            "        ready/pp = cuont/mi > 0\n"
            "        other/pp = missing/ib\n"
            "        go/pf(-> count/mo)\n"
            "        go/pf(-> count/mo)\n"
        )
    )
    errors = _errors(path)
    found = {(e.code, e.location.line if e.location else 0) for e in errors}
    assert {("EARL-R002", 10), ("EARL-R022", 11), ("EARL-R022", 12), ("EARL-R002", 14)} <= found
    misspelt = next(e for e in errors if e.location is not None and e.location.line == 11)
    assert misspelt.hint == "did you mean `count`?"
    printed = _check_exits_1(path, capsys)
    assert "errors" in printed


@pytest.mark.parametrize(
    ("files", "cycle"),
    [
        (
            {
                "system.earl": 'system s\nimport "a.earl"\n',
                "a.earl": 'import "b.earl"\n',
                "b.earl": 'import "a.earl"\n',
            },
            3,
        ),
        ({"system.earl": 'system s\nimport "a.earl"\n', "a.earl": 'import "a.earl"\n'}, 2),
        ({"system.earl": 'system s\nimport "system.earl"\n'}, 2),
    ],
    ids=["two files", "a file importing itself", "the root importing itself"],
)
def test_an_import_cycle_is_reported_with_its_files(
    files: dict[str, str], cycle: int, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    [error] = _errors(tmp_path / "system.earl")
    assert error.code == "EARL-S031"
    assert error.message.startswith("import cycle: ")
    assert error.message.count(" -> ") == cycle - 1
    assert error.location is not None and error.location.column == 1
    _check_exits_1(tmp_path / "system.earl", capsys)


def test_importing_a_missing_file_points_at_the_import(tmp_path: Path) -> None:
    (tmp_path / "system.earl").write_text('system s\n\nimport "types.earl"\n')
    [error] = _errors(tmp_path / "system.earl")
    assert error.code == "EARL-S030"
    assert "types.earl" in error.message
    assert error.location is not None and (error.location.line, error.location.column) == (3, 1)


@pytest.mark.parametrize(
    ("holds", "hint"),
    [
        # a `system.earl` starts a specification: a directory stands for it only as a command's SPEC
        (
            {"system.earl": "system t\n"},
            "an import names a file, not a directory; `sub/system.earl` starts a specification of its own "
            "and cannot be imported: move what both need into a file without a `system` line",
        ),
        (
            {"system.earl": "system t\n", "types.earl": "param P: int = 1\n"},
            'an import names a file, not a directory: e.g. `import "sub/types.earl"`',
        ),
        ({}, "an import names an `.earl` file, not a directory"),
    ],
)
def test_importing_a_directory_points_at_the_import_and_names_a_file_to_import(
    holds: dict[str, str], hint: str, tmp_path: Path
) -> None:
    (tmp_path / "sub").mkdir()
    for name, text in holds.items():
        (tmp_path / "sub" / name).write_text(text)
    (tmp_path / "system.earl").write_text('system s\n\nimport "sub/"\n')
    [error] = _errors(tmp_path / "system.earl")
    assert error.code == "EARL-S030"
    assert error.message.endswith("sub is a directory, not an `.earl` file")
    assert error.location is not None and (error.location.line, error.location.column) == (3, 1)
    assert error.hint == hint


def test_a_directory_given_as_the_specification_stands_for_its_system_earl_or_is_refused(tmp_path: Path) -> None:
    [error] = _errors(tmp_path)
    assert error.code == "EARL-S030"
    assert error.hint == "name the specification file, or a directory holding `system.earl`"
    (tmp_path / "system.earl").write_text("system s\n")
    assert earl.load(tmp_path).name == "s"


@pytest.mark.parametrize(
    ("family", "code", "fragment"),
    [
        ("K in 1..-5", "EARL-R016", "the family range 1..-5 is empty"),
        ("K in 3..1", "EARL-R016", "the family range 3..1 is empty"),
        ("K in 1..1000000000", "EARL-R017", "1,000,000,000 members"),
        ("K in -1000000000000000000000..1", "EARL-R016", "starts at 0 or more"),
        ("K in 0..1000000000000000000000", "EARL-R017", "at most 100,000"),
        ("K in 1..BIG", "EARL-R017", "at most 100,000"),
        ("K in 1..2.5", "EARL-R014", "whole number"),
    ],
    ids=[
        "negative last",
        "backwards",
        "a billion",
        "negative first",
        "beyond 64 bits",
        "through a parameter",
        "fractional",
    ],
)
def test_a_family_with_a_negative_or_huge_range_is_refused_before_expanding(
    family: str, code: str, fragment: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "family.earl"
    path.write_text(
        "system s\n\nparam BIG: int = 2000000000\n\nr/r {\n    a/a\n}\n\n"
        f"a/a {{\n    cs {{\n    }}\n\n    motor[{family}]/re {{\n        current/ib: double\n    }}\n}}\n"
    )
    errors = _errors(path)
    assert errors[0].code == code
    assert fragment in errors[0].message
    assert errors[0].location is not None and errors[0].location.line == 13
    _check_exits_1(path, capsys)


def test_a_huge_family_of_buffers_is_refused_too(tmp_path: Path) -> None:
    path = tmp_path / "family.earl"
    path.write_text(_in_cs("        reading[K in 0..99999999999]/ib: double\n"))
    [error] = _errors(path)
    assert error.code == "EARL-R017"
    assert error.location is not None and error.location.line == 9


# ---------------------------------------------------------------------- mutated specs
#: the specs mutated below, with the files beside them (imports, code): each a real system
_MUTATED = sorted((Path(__file__).parent.parent / "examples").glob("*/system.earl"))
#: what a mutation may insert: punctuation, the language's own words and suffixes, odd numbers and characters
_INSERTS = [
    *"{}()[],:;/.-><=!*?\"'\\@#$%^&|~`+",
    "->",
    "..",
    " in ",
    " and ",
    " not ",
    "newData(",
    "/ib",
    "/ob",
    "/m",
    "/pp",
    "/pf",
    "/bb",
    "/a",
    "/r",
    "N",
    "-1",
    "1e309",
    "99999999999999999999",
    "\n",
    "\t",
    "é",
    "\ufeff",
    "state",
    "fsm",
    "link",
    'import "x.earl"',
    "param",
    "period",
    "obligatory",
    "timeout",
    "tf =",
    "then",
    'python "a:b"',
    '"\\q"',
]


@st.composite
def _mutated_text(draw: st.DrawFn) -> tuple[Path, str]:
    """An example with one to three random cuts, insertions and copies of its own text."""
    path = draw(st.sampled_from(_MUTATED))
    text = path.read_text(encoding="utf-8")
    for _ in range(draw(st.integers(1, 3))):
        start = draw(st.integers(0, len(text)))
        end = min(len(text), start + draw(st.integers(0, 20)))
        action = draw(st.sampled_from(["cut", "insert", "copy", "in a string"]))
        strings = [found.span() for found in re.finditer(r'"[^"\n]*"', text)]
        if action == "in a string" and strings:  # what only a string's reader sees: escapes, control characters
            opening, closing = draw(st.sampled_from(strings))
            at = draw(st.integers(opening + 1, closing - 1))
            text = text[:at] + draw(st.sampled_from(["\\q", "\t", "\\u12", "\\ud800", "\\n", "\x01"])) + text[at:]
        elif action == "cut":
            text = text[:start] + text[end:]
        elif action == "insert":
            text = text[:start] + draw(st.sampled_from(_INSERTS)) + text[start:]
        else:
            source = draw(st.integers(0, len(text)))
            text = text[:start] + text[source : source + draw(st.integers(1, 40))] + text[start:]
    return path, text


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(_mutated_text())
def test_a_mutated_example_gets_a_verdict_never_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], case: tuple[Path, str]
) -> None:
    """`earl check`, `fmt`, `diagram` and `export` of a damaged spec end with a documented code, never a
    traceback; `check`'s errors name the file."""
    example, text = case
    for sibling in example.parent.iterdir():  # the files it imports, the code it names
        if sibling.is_file() and sibling.name != example.name:
            (tmp_path / sibling.name).write_bytes(sibling.read_bytes())
    spec = tmp_path / example.name
    spec.write_text(text, encoding="utf-8")
    for command in (
        ["check", str(spec)],
        ["fmt", str(spec)],
        ["diagram", "--view", "system", "-o", str(tmp_path / "system.dot"), str(spec)],
        ["export", "sysml", str(spec), "-o", str(tmp_path / "system.sysml")],
    ):
        code = main(command)
        output = capsys.readouterr()
        printed = output.out + output.err
        assert code in (0, 1, 2), (command[0], text)  # 2: a spec export refuses, say
        assert "Traceback" not in printed
        if code == 1 and command[0] == "check":
            assert f"{example.name}:" in printed and "error" in printed


def test_a_named_pipe_nobody_writes_to_is_read_as_empty_not_waited_on(tmp_path: Path) -> None:
    import os
    import subprocess
    import sys

    pipe = tmp_path / "pipe.earl"
    os.mkfifo(pipe)
    result = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "check", str(pipe)], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 1 and "EARL-S033" in result.stderr


NESTED_FAMILIES = """\
system big

param A: int = 3
param S: int = 3
param B: int = 3

w[I in 1..A]/a {
    cs {
        period 1 ms
    }

    d[J in 1..S]/ve {
        period 1 ms
        x[K in 1..B]/ib: int
    }
}
"""


def test_families_inside_families_that_multiply_beyond_memory_are_refused_at_once() -> None:
    """Each family within its own limit (100,000), together 10¹⁵ elements: one error, before any expansion
    (which used to run for a minute and die of MemoryError at 6 GB)."""
    with pytest.raises(earl.EarlError) as refused:
        earl.loads(NESTED_FAMILIES, "big.earl", {"A": 100_000, "S": 100_000, "B": 100_000})
    [diagnostic] = [d for d in refused.value.diagnostics if d.code == "EARL-R017"]
    assert "families inside families multiply" in diagnostic.message
    assert diagnostic.location is not None and diagnostic.location.line == 12
    earl.loads(NESTED_FAMILIES, "big.earl", {"A": 100, "S": 100, "B": 100})  # a million: allowed


def test_text_of_the_spec_in_a_message_cannot_start_a_line_of_its_own(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A string value is quoted as the spec writes it, escapes and all; any control character that reaches a
    message or hint another way is escaped when printed: a spec cannot print what looks like a diagnostic."""
    from earl.diagnostics import Severity, SourceMap, render

    path = tmp_path / "forged.earl"
    path.write_text('system s\n\nparam P: int = "a\\nerror[EARL-E999]: fake\\n --> x.earl:1:1"\n')
    printed = _check_exits_1(path, capsys)
    assert 'its value is "a\\nerror[EARL-E999]: fake\\n --> x.earl:1:1"' in printed
    assert not any(line.startswith("error[EARL-E999]") for line in printed.splitlines())
    text = render(Diagnostic(Severity.ERROR, "cannot open x\nerror: y\x1b[31m", None, hint="a\rb"), SourceMap())
    assert text == "error: cannot open x\\nerror: y\\x1b[31m\n = hint: a\\rb"


def test_the_source_line_and_the_file_name_of_a_diagnostic_are_printed_without_their_controls(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An ESC sequence in a comment on the line at fault, or a newline in the file's name, reached the
    terminal as they were: the first could rewrite the screen, the second forge an `error:` line."""
    path = tmp_path / "evil\nerror[EARL-E999]: fake.earl"
    path.write_text("system s\nparam P: int = true  // \x1b[2K\x1b[1A\u009b31m\n")
    printed = _check_exits_1(path, capsys)
    assert "\x1b" not in printed and "\u009b" not in printed
    assert not any(line.startswith("error[EARL-E999]") for line in printed.splitlines())
    assert "evil\\nerror[EARL-E999]: fake.earl:2:16" in printed
    source = next(line for line in printed.splitlines() if line.startswith("2 | "))
    caret = next(line for line in printed.splitlines() if line.strip().startswith("| ") and "^" in line)
    assert source.index("true") == caret.index("^")  # the caret still under the spot
