"""`earl fmt`: print, check and rewrite in canonical form; library files without `system` too."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import earl
from earl.cli.main import main

MESSY = "system  demo\nparam N:int=2   // joints\nstruct S{a:int,b:double[N]?}\n"
CANONICAL = "system demo\n\nparam N: int = 2  // joints\n\nstruct S {\n    a: int\n    b: double[N]?\n}\n"


def test_fmt_prints_canonical_text(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text(MESSY)
    assert main(["fmt", str(spec)]) == 0
    assert capsys.readouterr().out == CANONICAL
    assert spec.read_text() == MESSY  # printing never touches the file


def test_fmt_check_fails_on_non_canonical_and_passes_on_canonical(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    messy = tmp_path / "messy.earl"
    messy.write_text(MESSY)
    tidy = tmp_path / "tidy.earl"
    tidy.write_text(CANONICAL)
    assert main(["fmt", "--check", str(messy)]) == 1
    assert "not canonical" in capsys.readouterr().err
    assert main(["fmt", "--check", str(tidy)]) == 0


def test_fmt_write_rewrites_in_place_and_keeps_comments(tmp_path: Path) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text(MESSY)
    assert main(["fmt", "--write", str(spec)]) == 0
    assert spec.read_text() == CANONICAL
    assert main(["fmt", "--check", str(spec)]) == 0


def test_fmt_write_follows_a_link_and_keeps_the_file_s_permissions(tmp_path: Path) -> None:
    spec = tmp_path / "real.earl"
    spec.write_text(MESSY)
    spec.chmod(0o640)
    link = tmp_path / "link.earl"
    link.symlink_to(spec)
    assert main(["fmt", "--write", str(link)]) == 0
    assert link.is_symlink() and spec.read_text() == CANONICAL
    assert spec.stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.earl", "real.earl"]  # no temporary left


@pytest.mark.parametrize("line_end", ["\r\n", "\r"])
def test_fmt_check_finds_line_ends_other_than_newline_and_write_makes_them_newlines(
    tmp_path: Path, line_end: str
) -> None:
    spec = tmp_path / "s.earl"
    spec.write_bytes(CANONICAL.replace("\n", line_end).encode())
    assert main(["fmt", "--check", str(spec)]) == 1
    assert main(["fmt", "--write", str(spec)]) == 0
    assert spec.read_bytes() == CANONICAL.encode()


def test_fmt_write_refuses_a_read_only_file(tmp_path: Path) -> None:
    locked = tmp_path / "locked.earl"
    locked.write_text(MESSY)
    locked.chmod(0o444)  # no one may write it: root neither, though the system would let root
    assert main(["fmt", "--write", str(locked)]) == 1
    assert locked.read_text() == MESSY


def test_fmt_write_keeps_hard_links_a_users_temp_like_file_and_long_names(tmp_path: Path) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text(MESSY)
    other = tmp_path / "other-name.earl"
    other.hardlink_to(spec)
    theirs = tmp_path / ".s.earl.tmp"  # the user's own file, named as an old temporary was
    theirs.write_text("mine")
    assert main(["fmt", "--write", str(spec)]) == 0
    assert spec.read_text() == CANONICAL and other.read_text() == CANONICAL  # one file, two names
    assert theirs.read_text() == "mine"
    long = tmp_path / ("x" * 245 + ".earl")  # a temporary named after it would be too long
    long.write_text(MESSY)
    assert main(["fmt", "--write", str(long)]) == 0
    assert long.read_text() == CANONICAL


def test_save_replaces_only_a_regular_file_and_leaves_it_whole_when_writing_fails(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import os

    system = earl.loads(CANONICAL)
    pipe = tmp_path / "pipe.earl"
    os.mkfifo(pipe)
    with pytest.raises(OSError, match="not a regular file"):
        earl.save(system, pipe)  # renaming a file over it would put a file where the pipe (or /dev/null) was
    assert pipe.is_fifo()
    spec = tmp_path / "s.earl"
    spec.write_text(MESSY)

    def disk_full(self: Path, target: Path) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Path, "replace", disk_full)
    assert main(["fmt", "--write", str(spec)]) == 1
    assert spec.read_text() == MESSY
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.earl", "s.earl"]


def test_fmt_diff_shows_the_change(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text(MESSY)
    assert main(["fmt", "--diff", str(spec)]) == 0
    out = capsys.readouterr().out
    assert "-param N:int=2   // joints" in out
    assert "+param N: int = 2  // joints" in out


def test_fmt_formats_an_imported_library_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    library = tmp_path / "types.earl"
    library.write_text("// shared types\nstruct A { x: int }\n")
    assert main(["fmt", str(library)]) == 0
    assert capsys.readouterr().out == "// shared types\nstruct A {\n    x: int\n}\n"


def test_fmt_reports_a_syntax_error_with_exit_1_and_leaves_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "bad.earl"
    spec.write_text("system demo\nparam N int = 2\n")
    assert main(["fmt", "--write", str(spec)]) == 1
    err = capsys.readouterr().err
    assert "bad.earl:2:9" in err
    assert spec.read_text() == "system demo\nparam N int = 2\n"


def test_fmt_on_a_missing_file_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fmt", str(tmp_path / "nope.earl")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_save_writes_canonical_text_that_loads_back(tmp_path: Path) -> None:
    system = earl.loads(MESSY)
    target = tmp_path / "saved.earl"
    earl.save(system, target)
    assert target.read_text() == CANONICAL
    assert earl.load(target) == system


@pytest.mark.parametrize(
    "body",
    ["cs { timeout/ib: boolean  period 1 ms }", "cs { state/pp = true  count/m: int = 0 }"],
)
def test_fmt_never_writes_a_canonical_text_that_would_not_read_back(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str
) -> None:
    """Canonical order moves `period` and memory first; a name that is also a keyword (`timeout/ib`,
    `state/pp`) reads differently there. The file is left as it is, and the command says why."""
    spec = tmp_path / "kw.earl"
    text = f"system k\n\na/a {{\n    {body}\n}}\n"
    spec.write_text(text)
    for mode in ([], ["--check"], ["--write"], ["--diff"]):
        assert main(["fmt", *mode, str(spec)]) == 1
        err = capsys.readouterr().err
        assert "cannot be put in canonical form" in err and "rename it" in err and "left as it is" in err
    assert spec.read_text() == text


def test_fmt_diff_marks_a_last_line_without_its_newline(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "n.earl"
    spec.write_text("system d\nparam N: int = 1")
    assert main(["fmt", "--diff", str(spec)]) == 0
    assert "-param N: int = 1\n\\ No newline at end of file\n" in capsys.readouterr().out


def test_fmt_reads_a_pipe_once(tmp_path: Path) -> None:
    """`earl fmt --check <(cat spec)` reads a pipe, which can be read only once: read twice, the second
    read found nothing and a canonical file was called not canonical."""
    import shutil
    import subprocess
    import sys

    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("no bash here")
    spec = tmp_path / "tidy.earl"
    spec.write_text(CANONICAL)
    command = f"{sys.executable} -m earl.cli.main fmt --check <(cat {spec}) && {sys.executable} -m earl.cli.main fmt <(cat {spec})"
    result = subprocess.run([bash, "-c", command], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout == CANONICAL


def test_fmt_keeps_the_blank_lines_between_the_header_s_comment_blocks(tmp_path: Path) -> None:
    spec = tmp_path / "h.earl"
    text = "// licence\n\n// what this file is\nsystem h\n\nparam N: int = 1\n"
    spec.write_text(text)
    assert main(["fmt", "--check", str(spec)]) == 0


def test_fmt_diff_of_a_file_with_cr_line_ends_is_a_patch_that_applies(tmp_path: Path) -> None:
    """A `\\r` ends no line for `diff` and `patch`: the diff marks only the real last line."""
    import shutil
    import subprocess

    patch = shutil.which("patch")
    if patch is None:
        pytest.skip("no patch here")
    spec = tmp_path / "cr.earl"
    spec.write_bytes(CANONICAL.replace("\n", "\r").encode())
    # bytes: text mode would read each `\r` as a line end
    diff = subprocess.run(
        [sys.executable, "-m", "earl.cli.main", "fmt", "--diff", str(spec)], capture_output=True, timeout=60
    ).stdout
    assert diff.count(b"\\ No newline at end of file") == 1
    subprocess.run([patch, "-s", str(spec)], input=diff, check=True, timeout=60)
    assert spec.read_text() == CANONICAL


BLOCK_COMMENTS = """\
system s

struct Empty {
    // nothing yet
}

struct Pose {
    x: double
    // y and z to come
}

x/a {
    cs {
        period 1 ms
        f/pp = true
        b/bb {
            tf = {}
            tc = f/pp
            // the error condition to come
        }
        fsm {
            initial r
            state r: b/bb
            *  // from every state
                // however it was reached
                -> r when f/pp

            // TODO: a way out
        }
        // end of the control subsystem
    }
    // end of the agent
}  // after the `}`: about the agent, and kept there

r/r {
    x/a
    // the robot's other agents
}
"""


def test_a_comment_that_ends_a_block_stays_in_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A comment after the last line of a block's body (a TODO before an fsm's `}`) used to leave the block
    for the next top-level declaration; and a comment between `*` and `->` made the `*` a syntax error."""
    path = tmp_path / "blocks.earl"
    path.write_text(BLOCK_COMMENTS)
    assert main(["fmt", str(path)]) == 0
    formatted = capsys.readouterr().out
    for comment, closing in [
        ("    // nothing yet", "}"),
        ("    // y and z to come", "}"),
        ("            // the error condition to come", "        }"),
        ("            // TODO: a way out", "        }"),
        ("        // end of the control subsystem", "    }"),
        ("    // end of the agent", "}  // after the `}`: about the agent, and kept there"),
        ("    // the robot's other agents", "}"),
    ]:
        lines = formatted.splitlines()
        assert lines[lines.index(comment) + 1] == closing, formatted
    assert (
        # the blank line left before the TODO stays too
        "            * -> r when f/pp  // from every state  // however it was reached\n\n            // TODO"
        in formatted
    )
    assert "    // end of the agent\n}  // after the `}`: about the agent, and kept there\n\nr/r {" in formatted
    again = tmp_path / "again.earl"
    again.write_text(formatted)
    assert main(["fmt", "--check", str(again)]) == 0
    assert earl.load(again) == earl.load(path)


def test_comments_at_a_behaviour_s_clauses_stay_where_they_were_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A comment above `tf` and one above `tc` stay there (they all gathered at the end of the behaviour)."""
    path = tmp_path / "behaviour.earl"
    path.write_text(
        "system s\nx/a {\n    cs {\n        period 1 ms\n        w/pf(->)\n        b/bb {\n            // the work\n"
        "            tf = {w/pf}\n            // until true\n            tc = true\n        }\n    }\n}\n"
    )
    assert main(["fmt", str(path)]) == 0
    assert (
        "        b/bb {\n            // the work\n            tf = {w/pf}\n            // until true\n            tc = true\n"
        "        }\n" in capsys.readouterr().out
    )


def test_comments_at_clauses_stay_on_their_lines() -> None:
    """`period 5 ms  // fast`, `tc = …  // why`, `initial …  // why` and the lines of a state's body keep
    their comments: each clause line had nowhere to keep one, so it went to the line below."""
    text = (
        "system s\n\na/a {\n    cs {\n        period 5 ms  // fast\n\n        in/ib: double\n\n"
        "        p/pp = true\n\n        f/pf(in/ib ->)\n\n"
        "        b/bb {\n            tf = {f/pf}  // the work\n            // until the command\n"
        "            tc = p/pp  // came\n            ec = p/pp  // or not\n        }\n\n"
        "        fsm {\n            initial b  // first\n"
        "            state b: b/bb {  // waits\n                // the command\n"
        "                obligatory in/ib  // every period\n                timeout 5 ms  // then stop\n"
        "                // nothing more\n            }\n"
        "            state c: b/bb { optional in/ib }  // written on one line\n\n"
        "            b -> c when p/pp\n        }\n    }\n}\n"
    )
    system = earl.loads(text, "s.earl")
    assert system.to_earl() == text
    cs = system.agents[0].control_subsystem
    assert cs is not None and cs.period_location is not None and cs.period_location.line == 5
    assert cs.fsm is not None and cs.fsm.states[0].timeout_location is not None


def test_comments_of_a_clause_written_on_several_lines_are_all_kept() -> None:
    text = (
        "system s\na/a {\n    cs {\n        period 5 ms\n        in/ib: double\n        j/ib: double\n"
        "        f/pf(in/ib ->)\n        b/bb {\n            tf = {f/pf}\n            tc = true\n        }\n"
        "        fsm {\n            initial b\n            state b: b/bb {\n                obligatory in/ib  // one\n"
        "                obligatory j/ib  // two\n            }\n        }\n    }\n}\n"
    )
    formatted = earl.loads(text, "s.earl").to_earl()
    assert "                // two\n                obligatory in/ib, j/ib  // one\n" in formatted
    assert earl.loads(formatted, "s.earl").to_earl() == formatted


def test_comments_at_a_robot_s_members_stay_where_they_were_written() -> None:
    # a member is a reference, which had nowhere to keep a comment: every one moved to after the last member
    text = (
        "system c\n\nr/r {\n    // the arm\n    a/a  // trailing\n    // the gripper\n    b/a\n"
        "    // the link between them\n    link b,a\n    // the end\n}\n\n"
        "a/a {\n    cs {\n        period 1 ms\n\n        i/ib: double\n    }\n}\n\n"
        "b/a {\n    cs {\n        period 1 ms\n\n        o/ob: double\n    }\n}\n\n"
        "link b,a: b/a.cs.o -> a/a.cs.i\n"
    )
    assert earl.loads(text, "c.earl").to_earl() == text


def test_a_member_a_robot_lists_twice_keeps_its_own_comments() -> None:
    # both `a/a` shared one set of comments: the second's were printed at both, and reading failed (KeyError)
    text = (
        "system c\n\nr/r {\n    // first\n    a/a\n    b/a\n    // second\n    a/a  // tb\n"
        "    link b,a  // l1\n    link b,a\n}\n\n"
        "a/a {\n    cs {\n        period 1 ms\n\n        i/ib: double\n    }\n}\n\n"
        "b/a {\n    cs {\n        period 1 ms\n\n        o/ob: double\n    }\n}\n\n"
        "link b,a: b/a.cs.o -> a/a.cs.i\n"
    )
    assert earl.loads(text, "c.earl").to_earl() == text


def test_a_comment_on_a_later_line_of_a_clause_ends_that_clause_s_line() -> None:
    """`tf = {f/pf}` / `then {g/pf}  // the second stage sends`: the comment went above the next clause (`tc`),
    and the SysML export said it was about `tc`."""
    text = (
        "system s\na/a {\n    cs {\n        period 1 ms\n        p/pp = true\n        q/pp = p/pp\n"
        "            // inside\n            and true\n        f/pf(->)\n        g/pf(->)\n        b/bb {\n"
        "            tf = {f/pf}\n                then {g/pf}  // the second stage sends\n"
        "            tc = p/pp\n                or q/pp  // the reverse case\n            ec = not p/pp\n"
        "        }\n        fsm {\n            initial b\n            state b: b/bb\n        }\n    }\n}\n"
    )
    formatted = earl.loads(text, "s.earl").to_earl()
    assert "        q/pp = p/pp and true  // inside\n" in formatted
    assert "            tf = {f/pf} then {g/pf}  // the second stage sends\n" in formatted
    assert "            tc = p/pp or q/pp  // the reverse case\n            ec = not p/pp\n" in formatted
    assert earl.loads(formatted, "s.earl").to_earl() == formatted


MEMBER_GROUPS = """\
system s

struct Pose {
    x: double
    y: double


    // the orientation
    yaw: double
    pitch: double

    // to come: roll
}

arm/r {
    shoulder/a
    elbow/a

    wrist/a
    link shoulder,elbow  // the first joint

    // between the agents
    link elbow,wrist
}
"""


def test_fmt_keeps_a_blank_line_that_groups_a_robot_s_members_or_a_struct_s_fields(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`earl fmt` dropped every blank line inside `name/r { … }` and `struct … { … }`, so members a person had
    grouped ran together; blank lines in a row are one, as elsewhere."""
    path = tmp_path / "groups.earl"
    path.write_text(MEMBER_GROUPS)
    assert main(["fmt", str(path)]) == 0
    formatted = capsys.readouterr().out
    assert formatted == MEMBER_GROUPS.replace("    y: double\n\n\n", "    y: double\n\n")
    again = tmp_path / "again.earl"
    again.write_text(formatted)
    assert main(["fmt", "--check", str(again)]) == 0


def test_a_comment_after_a_closing_brace_stays_after_it_whatever_the_layout(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`r/r { a/a }  // c` gave the comment to the robot's first line, the same comment after a `}` written on
    a line of its own went to the next declaration: both now stay after the `}` of the block they follow."""
    one_line = "system s\n\nstruct S { a: int }  // the struct\n\nr/r { a/a }  // the robot\n\nparam N: int = 1\n"
    over_lines = (
        "system s\n\nstruct S {\n    a: int\n}  // the struct\n\nr/r {\n    a/a\n}  // the robot\n\nparam N: int = 1\n"
    )
    for text in (one_line, over_lines):
        path = tmp_path / "closed.earl"
        path.write_text(text)
        assert main(["fmt", str(path)]) == 0
        assert capsys.readouterr().out == over_lines


# blank lines a person left in every kind of body: one kept where there were several, none added where
# `earl fmt` writes its own (before the first memory, the transitions, a type after a parameter)
GROUPED_BODIES = """\
system s

import "a.earl"


import "b.earl"

param A: int = 1


param B: int = 2
param C: int = 3

type T = int

type U = int

x/a {
    param K: int = 1

    param L: int = 2

    cs {
        period 1 ms

        param M: int = 3
        i/ib: int


        j/ib: int
        o/ob: int

        m/m: int = 0

        n/m: int = 0

        // the limits
        q/pp = m/mi > 0

        r/pp = m/mi < 0

        f/pf(m/mi -> n/mo)

        g/pf(m/mi -> n/mo)

        stage s1 = {f/pf}

        stage s2 = {g/pf}

        b/bb {
            tf = {f/pf}

            tc = q/pp
        }

        fsm {
            initial x

            state x: b/bb

            state y: b/bb
            x -> y when q/pp

            y -> x when r/pp

            assume true

            assume false


            // to come
        }
    }

    link l1: cs.o -> cs.i

    link l2: cs.o -> cs.j
}

link x,x: x/a.cs.o -> x/a.cs.i

link x,x: x/a.cs.o -> x/a.cs.j

r/r {
    link l

    x/a
}
"""

GROUPED_BODIES_FORMATTED = (
    GROUPED_BODIES.replace('"a.earl"\n\n\n', '"a.earl"\n\n')
    .replace("param A: int = 1\n\n\n", "param A: int = 1\n\n")
    .replace("        param M: int = 3\n", "        param M: int = 3\n\n")
    .replace("i/ib: int\n\n\n", "i/ib: int\n\n")
    .replace("            state y: b/bb\n", "            state y: b/bb\n\n")
    .replace("assume false\n\n\n", "assume false\n\n")
    .replace("    link l\n\n    x/a\n", "    x/a\n    link l\n")
)


def test_fmt_keeps_a_blank_line_that_groups_members_in_every_body(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`earl fmt` dropped a blank line left between two buffers, memories, predicates, functions, stages,
    states, transitions, assumptions, clauses of a basic behaviour, an agent's parameters or links, and
    top-level parameters, type aliases or links; it keeps one now, and adds none to the ones it writes."""
    path = tmp_path / "grouped.earl"
    path.write_text(GROUPED_BODIES)
    assert main(["fmt", str(path)]) == 0
    formatted = capsys.readouterr().out
    assert formatted == GROUPED_BODIES_FORMATTED
    assert "\n\n\n" not in formatted
    with pytest.raises(SystemExit):
        main(["fmt", "--help"])
    assert "one blank line where one or more were left" in " ".join(capsys.readouterr().out.split())
    again = tmp_path / "again.earl"
    again.write_text(formatted)
    assert main(["fmt", "--check", str(again)]) == 0


def test_to_earl_writes_no_blank_line_first_in_a_body() -> None:
    """A model built in Python with a blank line asked for before the first member of a body (or of a
    group, where one is written anyway) gets none there, nor two: it would not read back."""
    from earl.model import Agent, ControlSubsystem, InputBuffer, Literal, Parameter, PrimitiveType, System
    from earl.model.location import Comments

    buffer = InputBuffer("i", PrimitiveType("int"), comments=Comments([""]))
    subsystem = ControlSubsystem(input_buffers=[buffer], comments=Comments([""]))
    parameter = Parameter("K", PrimitiveType("int"), Literal(1), comments=Comments([""]))
    agent = Agent("a", parameters=[parameter], subsystems=[subsystem])
    text = System("s", agents=[agent], order=[agent]).to_earl()
    assert text == "system s\n\na/a {\n    param K: int = 1\n\n    cs {\n        i/ib: int\n    }\n}\n"
    assert earl.loads(text, "s.earl").to_earl() == text


@pytest.mark.parametrize(
    ("closing", "written"),
    [
        ([""], ""),
        (["", ""], ""),
        (["", "// end", ""], "\n        // end\n"),
        (["// end", "", "", "// more", "", ""], "        // end\n\n        // more\n"),
    ],
)
def test_to_earl_writes_no_blank_line_last_in_a_body(closing: list[str], written: str) -> None:
    """A model built in Python with a blank line asked for last among a body's closing comments: it was
    written before the `}`, and read back as no comment, so that the text was written otherwise the second
    time. A blank line between the comments stays, once."""
    from earl.model import Agent, ControlSubsystem, Memory, PrimitiveType, System
    from earl.model.location import Comments

    memory = Memory("m", PrimitiveType("int"))
    subsystem = ControlSubsystem(memories=[memory], comments=Comments(closing=closing))
    agent = Agent("a", subsystems=[subsystem])
    text = System("s", agents=[agent], order=[agent]).to_earl()
    assert text == f"system s\n\na/a {{\n    cs {{\n        m/m: int\n{written}    }}\n}}\n"
    assert earl.loads(text, "s.earl").to_earl() == text


def test_fmt_keeps_a_blank_line_after_the_member_written_before_when_it_reorders(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Parts written out of the manual's order: the blank line stays above the part that followed it."""
    path = tmp_path / "mixed.earl"
    path.write_text(
        "x/a {\n    cs {\n        i/ib: int\n        m/m: int\n\n        j/ib: int\n"
        "        n/m: int\n        o/ob: int\n\n        // the end\n    }\n}\n"
    )
    assert main(["fmt", str(path)]) == 0
    assert capsys.readouterr().out == (
        "x/a {\n    cs {\n        i/ib: int\n\n        j/ib: int\n        o/ob: int\n\n"
        "        m/m: int\n        n/m: int\n\n        // the end\n    }\n}\n"
    )
