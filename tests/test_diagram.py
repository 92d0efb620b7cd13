"""`earl diagram`: each view of the manual's §3 example as SVG, PNG, DOT and Mermaid, and its errors.

Every SVG must be well-formed XML whose text names the elements the view is
about, in the manual's notation, inside a SysML frame whose header says the
diagram kind.  Needs Graphviz's `dot` (scripts/setup.sh installs it).
"""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

import earl
from earl.cli.main import main
from earl.model.elements import System
from earl.render import GraphvizError, TargetError, build_diagram
from earl.render.build import Subject
from earl.render.mermaid import mermaid_of

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "pick_and_place" / "system.earl"
MOBILE = ROOT / "examples" / "mobile_robot" / "system.earl"
SVG_NAMESPACE = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def system() -> System:
    return earl.load(EXAMPLE)


def svg_text(svg: str) -> str:
    """Every text run of the drawing, joined: what a reader of the picture sees."""
    root = ElementTree.fromstring(svg)  # raises on anything that is not well-formed XML
    assert root.tag == f"{SVG_NAMESPACE}svg"
    return "\n".join("".join(node.itertext()) for node in root.iter(f"{SVG_NAMESPACE}text"))


# (view, target, expected header, names the picture must show)
CASES = [
    (
        "system",
        None,
        "ibd [System] pickAndPlace",
        ["task/a", "manip/a", "grip/a", "manipulationRobot/r", "task,manip", "ManipulatorCommand", "GripperStatus"],
    ),
    (
        "agent",
        "manip/a",
        "ibd [Agent] manip/a",
        [
            "cs",
            "motorController[K]/ve",
            "motor[K]/re",
            "K ∈ 1..N",
            "manipulatorCommand/ib",
            "motorControllerCommand[K]/ob",
            "windingCurrent[K]/m",
            "cs,motorController[K]",
            "task/a",
        ],
    ),
    (
        "fsm",
        "manip/a.cs",
        "stm [FSM] manip/a.cs.fsm",
        [
            "idle",
            "jointMove",
            "operationalMove",
            "emergencyStop",
            "do / jointMove/bb",
            "[newJointPos/pp and not emergencyStop/pp]",
            "priority 3",
            "every state i ≠ emergencyStop",
        ],
    ),
    (
        "activity",
        "manip/a.cs.jointMove/bb",
        "act [Operation] manip/a.cs.jointMove/bb.tf.execute()",
        [
            "calculatePosition/pf",
            "jointMove/pf",
            "outputManipState/pf",
            "outputMotorCon/pf",
            "stage 1: pf",
            "stage 2: pfo",
        ],
    ),
    (
        "types",
        "manip/a",
        "bdd [Package] manip/a dataTypes",
        ["ManipulatorCommand", "MotorControllerState", "jointPosSetpoint: JointPosition [0..1]", "= double[N]"],
    ),
    ("types", None, "bdd [Package] pickAndPlace dataTypes", ["GripperCommand", "EncoderReading", "OperPosition"]),
]


@pytest.mark.parametrize(("view", "target", "header", "names"), CASES, ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_each_view_is_valid_svg_naming_its_elements(
    system: System, view: str, target: str | None, header: str, names: list[str]
) -> None:
    diagram = build_diagram(system, view, target)
    assert diagram.header == header
    shown = svg_text(diagram.svg())
    kind, _, rest = header.partition(" ")
    # The frame's tab: the kind in bold, then the rest (a no-break space keeps them apart in every viewer).
    assert kind in shown and rest in shown.replace("\xa0", " ")
    missing = [name for name in names if name not in shown]
    assert missing == []


def _block_centres(svg: str) -> dict[str, float]:
    """The mean x of the text in each node's drawing, by the node's DOT name (its SVG title)."""
    root = ElementTree.fromstring(svg)
    centres = {}
    for group in root.iter(f"{SVG_NAMESPACE}g"):
        title = group.find(f"{SVG_NAMESPACE}title")
        if group.get("class") != "node" or title is None or title.text is None:
            continue
        xs = [float(text.get("x", "nan")) for text in group.iter(f"{SVG_NAMESPACE}text")]
        if xs:
            centres[title.text] = sum(xs) / len(xs)
    return centres


def test_the_system_view_lays_agents_out_along_their_links(system: System) -> None:
    """The task agent, which commands the two others, stands left of them, not in one column with them:
    the links' label nodes are inside the robot cluster that holds both their ends."""
    left = _block_centres(build_diagram(system, "system").svg())
    task, manip, grip = left["n_agent_task_a"], left["n_agent_manip_a"], left["n_agent_grip_a"]
    assert task + 100 < manip and task + 100 < grip


@pytest.mark.parametrize(("path", "agent"), [(EXAMPLE, "manip/a"), (MOBILE, "base/a")])
def test_the_agent_view_draws_senders_left_and_receivers_right_of_every_subsystem(path: Path, agent: str) -> None:
    left = _block_centres(build_diagram(earl.load(path), "agent", agent).svg())
    subsystems = [x for name, x in left.items() if name.startswith("n_ss_")]
    senders = [x for name, x in left.items() if name.startswith("n_ext_in_")]
    receivers = [x for name, x in left.items() if name.startswith("n_ext_out_")]
    assert len(subsystems) >= 3 and senders and receivers
    assert max(senders) < min(subsystems) and min(receivers) > max(subsystems)


def test_a_family_is_drawn_once_with_its_index_and_expand_draws_every_member(system: System) -> None:
    once = svg_text(build_diagram(system, "agent", "manip/a", parameters={"N": 3}).svg())
    assert once.count("motorController[K]/ve") == 1
    assert "motorController[1]/ve" not in once
    every = svg_text(build_diagram(system, "agent", "manip/a", expand=True, parameters={"N": 3}).svg())
    for member in (1, 2, 3):
        assert f"motorController[{member}]/ve" in every
        assert f"cs,motorController[{member}]" in every
    assert "motorController[K]/ve" not in every and "motorController[4]/ve" not in every


def test_expanded_fsm_draws_the_wildcard_transition_from_every_other_state(system: System) -> None:
    once = build_diagram(system, "fsm", "manip/a.cs")
    every = build_diagram(system, "fsm", "manip/a.cs", expand=True)
    assert "every state i ≠ emergencyStop" not in svg_text(every.svg())
    # three states other than emergencyStop, each with its own arrow into it
    assert sum(1 for name in every.names if name.endswith(",emergencyStop/t")) == 3
    assert sum(1 for name in once.names if name.endswith(",emergencyStop/t")) == 1


def test_png_is_a_png(system: System) -> None:
    assert build_diagram(system, "fsm", "manip/a.cs").render("png").startswith(b"\x89PNG\r\n\x1a\n")


def test_render_takes_the_formats_of_earl_diagram_and_names_them_for_another(system: System) -> None:
    """`render("dot")` said "unknown Graphviz output format 'dot'", though `earl diagram --format dot` exists."""
    diagram = build_diagram(system, "fsm", "manip/a.cs")
    assert diagram.render("dot") == diagram.dot.encode("utf-8") and diagram.dot.startswith("digraph")
    with pytest.raises(ValueError, match=r"^unknown diagram format 'svgz': the formats are svg, png, dot, mermaid$"):
        diagram.render("svgz")


def test_targets_name_what_can_be_drawn(system: System) -> None:
    with pytest.raises(TargetError, match=r"`manip/a\.cs`.*`grip/a\.fingerDrive/re`"):
        build_diagram(system, "fsm", "manip/a.cx")
    with pytest.raises(TargetError, match="has no basic behaviour `walk/bb`; it has `idle/bb`"):
        build_diagram(system, "activity", "manip/a.cs.walk/bb")
    with pytest.raises(TargetError, match="the agents are `task/a`, `manip/a`, `grip/a`"):
        build_diagram(system, "agent", "arm/a")
    # said in the words of build_diagram's caller, its `target`: `--target` is `earl diagram`'s option
    with pytest.raises(TargetError, match=r"^the agent view needs a target naming one of the agents: task/a"):
        build_diagram(system, "agent")
    with pytest.raises(TargetError, match=r"^the system view shows the whole system; give no target \(None\)$"):
        build_diagram(system, "system", "manip/a")
    # a family answers to its name, with or without the index variable; `.tf.execute()` may follow a behaviour
    assert build_diagram(system, "fsm", "manip/a.motorController[K]/ve").header.endswith("motorController[K]/ve.fsm")
    assert build_diagram(system, "activity", "manip/a.cs.idle/bb.tf.execute()").header.startswith("act")
    # a member is named by its number once families are expanded
    member = build_diagram(system, "fsm", "manip/a.motorController[2]/ve", expand=True)
    assert member.header == "stm [FSM] manip/a.motorController[2]/ve.fsm"


def test_mermaid_system_and_fsm(system: System) -> None:
    flowchart = mermaid_of(Subject(system), "system", None)
    assert flowchart.splitlines()[3] == "flowchart LR"
    assert (
        'a_task_a -->|"task,manip: manipulatorCommand/ob → manipulatorCommand/ib : ManipulatorCommand"| a_manip_a'
        in flowchart
    )
    assert "CET: teleoperated agent" in flowchart
    states = mermaid_of(Subject(system), "fsm", "manip/a.cs")
    lines = states.splitlines()
    assert "stateDiagram-v2" in lines
    # inside the composite state that stands for the state machine, which its assumption is a note on
    assert "        [*] --> s_idle" in lines
    transitions = [line for line in lines if " --> " in line and "[*]" not in line]
    # Table 5: six transitions between named states and `i,emergencyStop/t` from each of the three others
    assert len(transitions) == 9
    assert "        s_jointMove --> s_idle : [not emergencyStop/pp] priority 3" in lines
    with pytest.raises(TargetError, match="system and fsm views only"):
        mermaid_of(Subject(system), "types", None)


def test_jupyter_displays_model_objects_as_svg(system: System) -> None:
    interactive = pytest.importorskip("IPython.core.interactiveshell")
    shell = interactive.InteractiveShell.instance()
    try:
        from earl.render import load_ipython_extension

        load_ipython_extension(shell)
        cs = system.agent("manip").control_subsystem  # type: ignore[union-attr]
        assert cs is not None
        for element, expected in [
            (system, "ibd"),
            (system.agent("manip"), "motorController[K]/ve"),
            (cs, "stm"),
            (cs.basic_behaviour("jointMove"), "calculatePosition/pf"),
            (system.type_named("ManipulatorCommand"), "emergencyStopCommand: boolean"),
        ]:
            data, _ = shell.display_formatter.format(element)
            assert expected in svg_text(data["image/svg+xml"])
    finally:
        interactive.InteractiveShell.clear_instance()


# ---------------------------------------------------------------- the command line


def test_cli_writes_svg_png_dot_and_mermaid(tmp_path: Path) -> None:
    for name, view, target in [
        ("agent.svg", "agent", "manip/a"),
        ("fsm.png", "fsm", "manip/a.cs"),
        ("system.dot", "system", None),
        ("fsm.mmd", "fsm", "grip/a.cs"),
    ]:
        arguments = ["diagram", str(EXAMPLE), "--view", view, "-o", str(tmp_path / name)]
        assert main([*arguments, *(["--target", target] if target else [])]) == 0
    svg_text((tmp_path / "agent.svg").read_text(encoding="utf-8"))
    assert (tmp_path / "fsm.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "system.dot").read_text(encoding="utf-8").startswith("digraph earl {")
    assert "stateDiagram-v2" in (tmp_path / "fsm.mmd").read_text(encoding="utf-8")


def test_cli_prints_to_stdout_and_expands_with_parameters(capfdbinary: pytest.CaptureFixture[bytes]) -> None:
    status = main(["diagram", str(EXAMPLE), "--view", "agent", "--target", "manip/a", "--expand", "--param", "N=2"])
    assert status == 0
    shown = svg_text(capfdbinary.readouterr().out.decode("utf-8"))
    assert "motor[2]/re" in shown and "motor[3]/re" not in shown


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--view", "fsm", "--target", "nowhere/a.cs"], "no subsystem `nowhere/a.cs`"),
        (["--view", "types", "--format", "mermaid"], "Mermaid text exists for the system and fsm views"),
        (["--view", "system", "-o", "x.svg", "--format", "png"], "does not match"),
        (["--view", "system", "-o", "x.pdf"], "cannot tell the format"),
        (["--view", "system", "--target", "manip/a"], "leave out --target"),
    ],
)
def test_cli_usage_errors_exit_2(arguments: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["diagram", str(EXAMPLE), *arguments]) == 2
    assert message in capsys.readouterr().err


def test_missing_dot_is_a_clear_usage_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))  # an empty directory: no `dot` anywhere
    monkeypatch.delenv("EARL_DOT", raising=False)
    assert main(["diagram", str(EXAMPLE), "--view", "system", "-o", str(tmp_path / "s.svg")]) == 2
    err = capsys.readouterr().err
    assert "Graphviz's `dot` program, which was not found" in err
    assert "apt-get install graphviz" in err
    assert "Traceback" not in err
    assert not (tmp_path / "s.svg").exists()
    assert main(["doc", str(EXAMPLE), "-o", str(tmp_path / "site")]) == 2
    assert "apt-get install graphviz" in capsys.readouterr().err
    with pytest.raises(GraphvizError):
        build_diagram(earl.load(EXAMPLE), "system").svg()


def test_an_unreadable_spec_exits_1_with_located_diagnostics(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    broken = tmp_path / "broken.earl"
    broken.write_text("system broken\n\nrobot/a {\n    cs {\n        x/m: nosuchtype\n    }\n}\n", encoding="utf-8")
    assert main(["diagram", str(broken), "--view", "system"]) == 1
    assert "broken.earl:5" in capsys.readouterr().err


def test_every_example_draws_every_view_it_has() -> None:
    system = earl.load(MOBILE)
    svg_text(build_diagram(system, "system").svg())
    for agent in system.agents:
        svg_text(build_diagram(system, "agent", f"{agent.name}/a").svg())


def test_importing_the_model_loads_no_renderer() -> None:
    # The model must import nothing of the renderers (design brief): checked in a fresh interpreter.
    code = "import sys, earl, earl.model; print(sorted(m for m in sys.modules if m.startswith('earl.render')))"
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert completed.stdout.strip() == "[]"


def test_diagram_and_export_never_write_over_a_file_of_the_spec(tmp_path: Path) -> None:
    import shutil

    copy = tmp_path / "mobile"
    shutil.copytree(MOBILE.parent, copy)
    spec = copy / "system.earl"
    before = {path: path.read_bytes() for path in copy.glob("*.earl")}
    (tmp_path / "view.svg").symlink_to(copy / "types.earl")  # through a link too
    attempts = [
        ["diagram", str(copy), "--view", "system", "--format", "svg", "-o", str(spec)],
        ["diagram", str(copy), "--view", "system", "-o", str(tmp_path / "view.svg")],
        ["export", "sysml", str(copy), "-o", str(spec)],
    ]
    for arguments in attempts:
        assert main(arguments) == 2, arguments
    assert {path: path.read_bytes() for path in copy.glob("*.earl")} == before


def test_the_activity_view_without_a_target_suggests_one_of_the_spec(capsys: pytest.CaptureFixture[bytes]) -> None:
    assert main(["diagram", str(MOBILE), "--view", "activity"]) == 2
    err = capsys.readouterr().err
    assert "e.g. base/a.cs." in str(err) and "manip/a" not in str(err)


PRIMITIVES_ONLY = """\
system prim

r/r {
    a/a
}

a/a {
    cs {
        period 10 ms
        x/m: int = 0
        f/pf(x/mi -> x/mo)
        idle/bb {
            tf = {f/pf}
            tc = false
        }
        fsm {
            initial idle
            state idle: idle/bb
        }
    }
}

empty/a {
}
"""


def test_a_view_with_nothing_in_it_still_draws_its_frame_and_says_so() -> None:
    """Graphviz draws no cluster without a node: the frame and its header would vanish, leaving a
    blank picture."""
    system = earl.loads(PRIMITIVES_ONLY, "prim.earl")
    drawn = svg_text(build_diagram(system, "types").svg())
    assert "[Package] prim dataTypes" in drawn and "only primitive types" in drawn
    drawn = svg_text(build_diagram(system, "agent", "empty/a").svg())
    assert "[Agent] empty/a" in drawn and "no subsystem" in drawn


def test_a_family_member_outside_the_range_is_no_target(system: System) -> None:
    assert build_diagram(system, "fsm", "manip/a.motorController[6]/ve").header.endswith("motorController[6]/ve.fsm")
    for outside in ("7", "0", "-1"):
        with pytest.raises(TargetError, match="no subsystem"):
            build_diagram(system, "fsm", f"manip/a.motorController[{outside}]/ve")


def test_the_only_fsm_is_drawn_without_a_target_in_every_format(capsys: pytest.CaptureFixture[str]) -> None:
    system = earl.loads(PRIMITIVES_ONLY, "prim.earl")
    assert build_diagram(system, "fsm").header == "stm [FSM] a/a.cs.fsm"
    assert "title: stm [FSM] a/a.cs.fsm" in mermaid_of(Subject(system), "fsm", None)


def test_the_fsm_view_shows_what_each_state_waits_for_and_how_long(system: System) -> None:
    """A state's buffer group (obligatory and optional buffers, timeout) is how it is paced: the
    diagram, and the document that shows it, say it under the state's behaviour."""
    drawn = svg_text(build_diagram(system, "fsm", "manip/a.cs").svg())
    assert "obligatory motorControllerState[*]/ib;" in drawn and "timeout 4 ms" in drawn


def test_a_family_member_named_without_expand_is_drawn_alone(system: System, tmp_path: Path) -> None:
    """`--target 'manip/a.motorController[2]/ve'` without --expand drew the whole family, headed
    `motorController[K]/ve`, saying nothing of the member asked for: the member is drawn, as --expand draws
    it; the family is still what its name, `[K]` or `[*]` names."""
    for target in ("manip/a.motorController[2]/ve", "manip/a.motorController[N]/ve"):
        number = "2" if "[2]" in target else "6"
        drawn = build_diagram(system, "fsm", target)
        assert drawn.header == f"stm [FSM] manip/a.motorController[{number}]/ve.fsm"
        assert drawn.dot == build_diagram(system, "fsm", target, expand=True).dot
        assert f"title: stm [FSM] manip/a.motorController[{number}]/ve.fsm" in mermaid_of(
            Subject(system), "fsm", target
        )
    behaviour = build_diagram(system, "activity", "manip/a.motorController[3]/ve.start/bb")
    assert behaviour.header.startswith("act [Operation] manip/a.motorController[3]/ve.start/bb")
    for family in ("manip/a.motorController/ve", "manip/a.motorController[K]/ve", "manip/a.motorController[*]/ve"):
        assert build_diagram(system, "fsm", family).header.endswith("motorController[K]/ve.fsm")
    agents = earl.loads(SPLIT_FAMILY, "robots.earl")
    assert build_diagram(agents, "agent", "worker[2]/a").header.endswith("worker[2]/a")
    assert build_diagram(agents, "agent", "worker[K]/a").header.endswith("worker[K]/a")
    output = tmp_path / "member.dot"
    arguments = ["--view", "fsm", "--target", "manip/a.motorController[2]/ve", "-o", str(output)]
    assert main(["diagram", str(EXAMPLE), *arguments]) == 0
    assert "manip/a.motorController[2]/ve.fsm" in output.read_text(encoding="utf-8")


def _nested_families() -> str:
    """pick_and_place with its manipulator a family of two agents, each holding `motorController[K in 1..N]/ve`."""
    text = EXAMPLE.read_text(encoding="utf-8")
    for old, new in [
        ("\nmanip/a {", "\nmanip[I in 1..2]/a {"),
        (
            "link task,manip: task/a.cs.manipulatorCommand -> manip/a.cs.manipulatorCommand",
            "link task,manip[I in 1..2]: task/a.cs.manipulatorCommand -> manip[I]/a.cs.manipulatorCommand",
        ),
        (
            "link manip,task: manip/a.cs.manipulatorState -> task/a.cs.manipulatorState",
            "link manip[1],task: manip[1]/a.cs.manipulatorState -> task/a.cs.manipulatorState",
        ),
        ("    manip/a\n", "    manip[1]/a\n    manip[2]/a\n"),
        ("    link task,manip\n", "    link task,manip[I in 1..2]\n"),
        ("    link manip,task\n", "    link manip[1],task\n"),
    ]:
        assert old in text, old
        text = text.replace(old, new)
    return text


def test_a_target_naming_a_family_inside_a_member_or_a_member_inside_a_family_draws_the_declared_family(
    tmp_path: Path,
) -> None:
    """In a family of agents holding a family of subsystems, a target naming a member of one family and the
    other family (`manip[2]/a.motorController[K]/ve`) was matched against the expansion, where `[K]` names
    nothing: exit 2 "no subsystem". It names a family, drawn once as declared; a member of each family is
    still drawn alone."""
    spec = tmp_path / "system.earl"
    spec.write_text(_nested_families(), encoding="utf-8")
    nested = earl.load(spec)
    family = "manip[I]/a.motorController[K]/ve"
    for target in (
        "manip[2]/a.motorController[K]/ve",
        "manip[I]/a.motorController[3]/ve",
        "manip/a.motorController[2]/ve",  # no index: the family of `manip`, as `manip[*]`
        "manip[*]/a.motorController[02]/ve",
    ):
        assert build_diagram(nested, "fsm", target).header == f"stm [FSM] {family}.fsm", target
        assert f"title: stm [FSM] {family}.fsm" in mermaid_of(Subject(nested), "fsm", target), target
    behaviour = build_diagram(nested, "activity", "manip[2]/a.motorController[K]/ve.operate/bb")
    assert behaviour.header.startswith(f"act [Operation] {family}.operate/bb")
    for member in ("manip[2]/a.motorController[3]/ve", "manip[2]/a.motorController[03]/ve"):
        drawn = build_diagram(nested, "fsm", member)
        assert drawn.header == "stm [FSM] manip[2]/a.motorController[3]/ve.fsm"
        assert drawn.dot == build_diagram(nested, "fsm", member, expand=True).dot
    for outside in ("manip[3]/a.motorController[K]/ve", "manip[2]/a.motorController[7]/ve", "manip[J]/a.cs"):
        with pytest.raises(TargetError, match="no subsystem"):
            build_diagram(nested, "fsm", outside)
    for view, target, fmt in [
        ("fsm", "manip[2]/a.motorController[K]/ve", "dot"),
        ("fsm", "manip[2]/a.motorController[K]/ve", "mermaid"),
        ("fsm", "manip[I]/a.motorController[3]/ve", "dot"),
        ("activity", "manip[2]/a.motorController[K]/ve.operate/bb", "dot"),
    ]:
        output = tmp_path / f"drawn.{fmt}"
        arguments = ["diagram", str(spec), "--view", view, "--target", target, "--format", fmt, "-o", str(output)]
        assert main(arguments) == 0, (view, target, fmt)
        assert family in output.read_text(encoding="utf-8")


def test_a_member_number_is_read_as_a_number_with_or_without_expand(system: System, tmp_path: Path) -> None:
    """`motorController[02]/ve` drew member 2 when the family was drawn once; once a member was drawn from the
    expansion its index was compared as text, and `02` named nothing (exit 2)."""
    for expand in (False, True):
        drawn = build_diagram(system, "fsm", "manip/a.motorController[02]/ve", expand=expand)
        assert drawn.header == "stm [FSM] manip/a.motorController[2]/ve.fsm"
        output = tmp_path / "member.mmd"
        arguments = ["diagram", str(EXAMPLE), "--view", "fsm", "--target", "manip/a.motorController[02]/ve"]
        arguments += ["--expand"] if expand else []
        assert main([*arguments, "--format", "mermaid", "-o", str(output)]) == 0
        assert "manip/a.motorController[2]/ve.fsm" in output.read_text(encoding="utf-8")
    for outside in ("7", "0", "-1", "J", "007"):
        for expand in (False, True):
            with pytest.raises(TargetError, match="no subsystem"):
                build_diagram(system, "fsm", f"manip/a.motorController[{outside}]/ve", expand=expand)


SPLIT_FAMILY = """\
system robots

fleetRobot/r {
    worker[1]/a
}

otherFleet/r {
    worker[2]/a
}

allRobot/r {
    helper[1]/a
    helper[2]/a
}

worker[K in 1..3]/a {
    cs {
        period 10 ms
    }
}

helper[K in 1..2]/a {
    cs {
        period 10 ms
    }
}

supervisor/a {
    cs {
        period 100 ms
    }
}
"""


def _clusters(dot: str) -> dict[str, str]:
    """The statements inside each robot's cluster of a system view's DOT text, by the cluster's name."""
    clusters = {}
    for part in dot.split("subgraph cluster_robot_")[1:]:
        body = part[: part.index("\n    }")]
        clusters[re.search(r"<b>([^<]+)</b>", body).group(1)] = body  # type: ignore[union-attr]
    return clusters


def test_a_family_split_over_robots_is_drawn_outside_them_naming_where_each_member_is() -> None:
    """`worker[1]/a` in fleetRobot/r, `worker[2]/a` in otherFleet/r, `worker[3]/a` in no robot: drawn once,
    the family is in no robot, and each robot holds a dashed stand-in for its members, tied to the family.
    `helper[K]/a`, whose members are all in allRobot/r, is drawn inside it."""
    system = earl.loads(SPLIT_FAMILY, "robots.earl")
    diagram = build_diagram(system, "system")
    clusters = _clusters(diagram.dot)
    assert "worker[1]/a" in clusters["fleetRobot/r"] and "worker[2]/a" not in clusters["fleetRobot/r"]
    assert "worker[2]/a" in clusters["otherFleet/r"] and "worker[1]/a" not in clusters["otherFleet/r"]
    assert all("n_agent_worker_K__a [" not in body for body in clusters.values())
    assert "n_agent_helper_K__a [" in clusters["allRobot/r"]
    drawn = svg_text(diagram.svg())
    for line in ("fleetRobot/r: worker[1]/a", "otherFleet/r: worker[2]/a", "no robot: worker[3]/a"):
        assert line in drawn
    mermaid = mermaid_of(Subject(system), "system", None)
    other_fleet = mermaid[mermaid.index("«Robot» otherFleet/r") :].split("    end")[0]
    assert "worker[2]/a<br/>member of worker[K]/a" in other_fleet
    assert "no robot: worker[3]/a" in mermaid
    # every member drawn: each in the robot that lists it, worker[3]/a in none
    expanded = _clusters(build_diagram(system, "system", expand=True).dot)
    assert "n_agent_worker_1__a [" in expanded["fleetRobot/r"] and "n_agent_worker_2__a [" in expanded["otherFleet/r"]
    assert all("n_agent_worker_3__a [" not in body for body in expanded.values())


def test_a_large_family_split_over_robots_names_its_members_by_ranges(tmp_path: Path) -> None:
    """Every member of a family of 1,200 in one label was more than Graphviz reads (16,384 characters)."""
    spec = tmp_path / "big.earl"
    spec.write_text(
        """\
system big

param N: int = 1200

alpha/a {
    cs {
        period 10 ms
        out[K in 1..N]/ob: double
    }
}

worker[K in 1..N]/a {
    cs {
        period 10 ms
        in/ib: double
    }
}

link alpha,worker[K in 1..N]: alpha/a.cs.out[K] -> worker[K]/a.cs.in

fleetRobot/r {
    alpha/a
    worker[1]/a
    worker[5]/a
}
"""
    )
    picture = tmp_path / "system.svg"
    assert main(["diagram", str(spec), "--view", "system", "-o", str(picture)]) == 0
    drawn = picture.read_text()
    assert "no robot: worker[2..4]/a, worker[6..1200]/a" in drawn
    assert "worker[1]/a" in drawn and "worker[5]/a" in drawn and "worker[7]/a" not in drawn


@pytest.mark.parametrize("index", ["J", "foo bar", "K + 1", "٢", "２"])
def test_a_family_target_with_an_index_that_is_neither_its_letter_nor_a_member_is_refused(
    index: str, tmp_path: Path
) -> None:
    pick_and_place = Path(__file__).parent.parent / "examples" / "pick_and_place"
    target = f"manip/a.motorController[{index}]/ve"
    assert (
        main(["diagram", str(pick_and_place), "--view", "fsm", "--target", target, "-o", str(tmp_path / "x.svg")]) == 2
    )
    for accepted in ("K", "2", "*", "N"):  # its letter, a member, every member, a parameter naming a member
        target = f"manip/a.motorController[{accepted}]/ve"
        out = tmp_path / f"{accepted}.svg"
        assert main(["diagram", str(pick_and_place), "--view", "fsm", "--target", target, "-o", str(out)]) == 0


def test_an_fsm_or_behaviour_shown_alone_is_headed_without_a_dangling_dot(system: System) -> None:
    """Shown alone (Jupyter), they know no owner: the headers were `stm [FSM] .fsm` and `act [Operation] .x/bb…`."""
    from earl.render.jupyter import diagram_for

    cs = system.agent("manip").control_subsystem  # type: ignore[union-attr]
    assert cs is not None and cs.fsm is not None
    fsm = diagram_for(cs.fsm)
    behaviour = diagram_for(cs.basic_behaviour("jointMove"))
    assert fsm is not None and behaviour is not None
    assert fsm.header == "stm [FSM] fsm"
    assert behaviour.header == "act [Operation] jointMove/bb.tf.execute()"


def test_an_expanded_member_is_named_by_its_number_or_a_parameter_that_is_it(tmp_path: Path) -> None:
    pick_and_place = Path(__file__).parent.parent / "examples" / "pick_and_place"
    for target, code in [
        ("manip/a.motorController[N]/ve", 0),
        ("manip/a.motorController[6]/ve", 0),
        ("manip/a.motorController[K]/ve", 2),
    ]:
        out = tmp_path / "m.mmd"
        arguments = ["diagram", str(pick_and_place), "--view", "fsm", "--expand", "--target", target]
        assert main([*arguments, "--format", "mermaid", "-o", str(out)]) == code, target


_ASSUMES_NOTHING = """system plain

a/a {
    cs {
        period 1 ms
        x/ib: double
        p/pp = x/ib > 1.0
        b/bb {
            tf = {}
            tc = p/pp
        }
        fsm {
            initial s
            state s: b/bb
            s -> s when p/pp
        }
    }
}
"""


def test_the_fsm_view_shows_the_fsm_s_assumptions_as_a_note(system: System) -> None:
    """`assume not (newJointPos/pp and newOperationalPos/pp)` was drawn nowhere, though the manual states it in
    Table 5's caption and the FSM's conditions are read under it: it is a SysML note of the state machine, with
    its comment, in the Graphviz drawing (SVG, PNG, DOT) and in Mermaid, where a note must be on a state and the
    state machine becomes a composite state."""
    diagram = build_diagram(system, "fsm", "manip/a.cs")
    assert 'shape="note"' in diagram.dot
    shown = svg_text(diagram.svg())
    assert "assume not (newJointPos/pp and" in shown and "newOperationalPos/pp)" in shown
    assert "Table 5: task/a never sets a new joint" in shown  # its comment, under it
    # expanded, the assumption is the same
    assert 'shape="note"' in build_diagram(system, "fsm", "manip/a.cs", expand=True).dot
    assert "assume" not in svg_text(build_diagram(system, "fsm", "manip/a.motorController/ve").svg())

    states = mermaid_of(Subject(system), "fsm", "manip/a.cs").splitlines()
    assert '    state "manip/a.cs.fsm" as fsm {' in states
    note = states[states.index("    note right of fsm") :]
    assert note[1:4] == [
        "        assume not (newJointPos/pp and newOperationalPos/pp)",
        "        Table 5: task/a never sets a new joint position and an operational pose at once.",
        "    end note",
    ]
    # an FSM that assumes nothing is drawn as before: its states at the top, no note
    plain = mermaid_of(Subject(earl.loads(_ASSUMES_NOTHING, "plain.earl")), "fsm", None).splitlines()
    assert "    [*] --> s_s" in plain and not any("note" in line or "{" in line for line in plain)
    assert 'shape="note"' not in build_diagram(earl.loads(_ASSUMES_NOTHING, "plain.earl"), "fsm").dot


def test_a_mermaid_label_keeps_a_backslash() -> None:
    """Mermaid dropped the `\\` of a string `"a\\"b"` in an assumption's note; it is an entity code now."""
    from earl.render.mermaid import text

    assert text('"a\\"b"') == "#quot;a#92;#quot;b#quot;"


def test_a_mermaid_note_is_not_ended_by_end_note_in_a_comment() -> None:
    """Mermaid's lexer ends a note at the first `end note`, in any case: a comment saying "the end note of
    Table 5" ended it there, and the rest was read as states."""
    text = _ASSUMES_NOTHING.replace(
        "            s -> s when p/pp",
        "            s -> s when p/pp\n            // the End  Note of Table 5 says so\n            assume p/pp",
        1,
    )
    lines = mermaid_of(Subject(earl.loads(text, "plain.earl")), "fsm", None).splitlines()
    note = lines[lines.index("    note right of fsm") :]
    assert note[2] == "        the End#160;Note of Table 5 says so"
    assert [line for line in lines if "end note" in line.lower()] == ["    end note"]


def test_each_composition_arrow_of_the_types_view_leaves_the_row_of_its_field(system: System) -> None:
    """Figures 9 and 11: the diamond of `currentJointPos` sat beside `currentOperationalPos` and its arrow
    crossed the other, for the arrows left the block anywhere; each now starts at its field's port."""
    diagram = build_diagram(system, "types")
    assert 'port="f0"' in diagram.dot and 'tailport="f0:e"' in diagram.dot
    root = ElementTree.fromstring(diagram.svg())
    rows: dict[str, dict[str, float]] = {}  # node -> field -> y of its row's text
    starts: list[tuple[str, str, float]] = []  # (node, field, y where the arrow starts)
    for group in root.iter(f"{SVG_NAMESPACE}g"):
        title = group.findtext(f"{SVG_NAMESPACE}title") or ""
        texts = ["".join(t.itertext()) for t in group.iter(f"{SVG_NAMESPACE}text")]
        ys = [float(t.get("y", "nan")) for t in group.iter(f"{SVG_NAMESPACE}text")]
        if group.get("class") == "node":
            rows[title] = {text.split(":")[0]: y for text, y in zip(texts, ys, strict=True) if ": " in text}
        elif group.get("class") == "edge":
            path = group.find(f"{SVG_NAMESPACE}path")
            assert path is not None
            start = re.match(r"M([-\d.]+),([-\d.]+)", path.get("d", ""))
            assert start is not None and texts
            starts.append((title.split("->")[0].split(":")[0], texts[0], float(start.group(2))))
    assert {(node, field) for node, field, _ in starts} >= {
        ("n_type_ManipulatorState", "currentJointPos"),
        ("n_type_ManipulatorState", "currentOperationalPos"),
        ("n_type_ManipulatorCommand", "jointPosSetpoint"),
        ("n_type_ManipulatorCommand", "operationalPosSetpoint"),
    }
    for node, field, y in starts:
        nearest = min(rows[node], key=lambda name: abs(rows[node][name] - y))
        assert nearest == field, (node, field, y, rows[node])


@pytest.mark.parametrize(
    "target", ["task/a.cs", "manip/a.cs", "grip/a.cs", "manip/a.motorController[K]/ve", "grip/a.fingerController/ve"]
)
def test_every_transition_label_of_an_fsm_is_inside_its_frame(system: System, target: str) -> None:
    """dot sizes a cluster by its nodes: `[phaseComplete/pp and not manipulatorEmergency/pp]` of
    approach→grasp, and the labels of self-loops on the right, were drawn across the stm frame's border.
    The frame's margin is widened by what sticks out."""
    import json

    from earl.render.graphviz import _dot, frame_overflow

    diagram = build_diagram(system, "fsm", target)
    assert frame_overflow(json.loads(_dot(diagram.dot, "json"))) > 0  # as dot lays the source out
    assert frame_overflow(json.loads(_dot(diagram.laid_out, "json"))) <= 0  # as earl draws it
    assert diagram.laid_out != diagram.dot and 'margin="14"' in diagram.dot
    # what is drawn is the widened source: the frame's rectangle holds the label's text
    root = ElementTree.fromstring(diagram.svg())
    frame = next(g for g in root.iter(f"{SVG_NAMESPACE}g") if g.findtext(f"{SVG_NAMESPACE}title") == "cluster_frame")
    polygon = frame.find(f"{SVG_NAMESPACE}polygon")
    assert polygon is not None
    right = max(float(point.split(",")[0]) for point in polygon.get("points", "").split())
    centres = [
        float(text.get("x", "nan"))
        for g in root.iter(f"{SVG_NAMESPACE}g")
        if g.get("class") == "edge"
        for text in g.iter(f"{SVG_NAMESPACE}text")
    ]
    assert centres and max(centres) < right


@pytest.mark.parametrize(("path", "agent"), [(EXAMPLE, "manip/a"), (EXAMPLE, "grip/a"), (MOBILE, "base/a")])
def test_the_agent_view_keeps_links_back_to_earlier_subsystems_inside_its_frame(path: Path, agent: str) -> None:
    """Figure 10: `motorController[K],cs` ran along the frame's top border and `motor[K],motorController[K]`
    looped outside the frame under the re box, for their first half was left free of the layout; both
    halves now constrain it, the label just before the Input Buffer it feeds, and every link inside."""
    import json

    from earl.render.graphviz import _dot, frame_overflow

    diagram = build_diagram(earl.load(path), "agent", agent)
    assert 'constraint="false"' not in diagram.dot
    # the way back may need a wider frame than dot gives it, which fit_frame gives
    assert frame_overflow(json.loads(_dot(diagram.laid_out, "json"))) <= 0
    left = _block_centres(diagram.svg())
    cs = left["n_ss_cs"]
    back_to_cs = re.findall(r'(link_\d+) \[shape="plain"[^\n]*tooltip="[^"]*,cs"', diagram.dot)
    assert back_to_cs and all(left[node] < cs for node in back_to_cs)  # its label is before the cs it feeds


def test_the_agent_view_of_manip_is_narrower_than_it_was(system: System) -> None:
    """The manip/a agent view was 1800 pt wide (shown at 43 % in the document): ranks are closer now and
    a link's label going back to cs shares the rank of the inter-agent link's label."""
    svg = build_diagram(system, "agent", "manip/a").svg()
    width = re.search(r'<svg width="([\d.]+)pt"', svg)
    assert width is not None and float(width.group(1)) < 1550


def test_a_diagram_built_in_python_renders_as_mermaid_where_the_view_has_it() -> None:
    """`build_diagram(…).render("mermaid")` said `unknown Graphviz output format 'mermaid'`: the Mermaid
    text is the one `earl diagram --format mermaid` writes; a view without one says which views have it."""
    system = earl.load(EXAMPLE)
    fsm = build_diagram(system, "fsm", "manip/a.cs")
    assert fsm.render("mermaid").decode("utf-8") == mermaid_of(Subject(system), "fsm", "manip/a.cs")
    assert build_diagram(system, "system").mermaid() == mermaid_of(Subject(system), "system", None)
    with pytest.raises(ValueError, match="Mermaid draws the system and fsm views"):
        build_diagram(system, "agent", "manip/a").render("mermaid")


@pytest.mark.parametrize("json_output", ["refused", "not json"])
def test_a_graphviz_without_json_output_still_draws_the_diagram(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, system: System, json_output: str
) -> None:
    """The frame is fitted to the edge labels by one layout as JSON first; Graphviz before 2.40 has no JSON
    output, and every SVG and `earl doc` failed with it ("Format: "json" not recognized")."""
    import shutil

    real = shutil.which("dot")
    assert real is not None
    answer = (
        "echo 'Error: Format: \"json\" not recognized' >&2; exit 1"
        if json_output == "refused"
        else "echo 'not json'; exit 0"
    )
    wrapper = tmp_path / "dot"
    wrapper.write_text(f'#!/bin/sh\nfor a in "$@"; do case "$a" in -Tjson) {answer};; esac; done\nexec {real} "$@"\n')
    wrapper.chmod(0o755)
    monkeypatch.setenv("EARL_DOT", str(wrapper))
    assert "approach" in build_diagram(system, "fsm", "task/a.cs").svg()


def test_the_notebook_s_system_diagram_has_its_mermaid_text(system: System) -> None:
    """`diagram_for(system).render("mermaid")` said "this system diagram has no Mermaid text: Mermaid draws the
    system and fsm views": only build_diagram attached it."""
    from earl.render.jupyter import diagram_for

    shown = diagram_for(system)
    assert shown is not None
    assert shown.render("mermaid").decode() == mermaid_of(Subject(system), "system", None)


def _layout_boxes(layout: dict[str, object]) -> dict[str, tuple[float, float, float, float]]:
    """The nodes of dot's JSON layout by name: (left, bottom, right, top) in points."""
    boxes = {}
    for node in layout.get("objects", []):  # type: ignore[attr-defined]
        if "pos" not in node or "width" not in node:
            continue
        x, y = (float(v) for v in node["pos"].split(","))
        half_width, half_height = float(node["width"]) * 36, float(node["height"]) * 36
        boxes[node["name"]] = (x - half_width, y - half_height, x + half_width, y + half_height)
    return boxes


def _edge_points(layout: dict[str, object], edge: dict[str, object]) -> list[tuple[float, float]]:
    from earl.render.graphviz import _bezier_points

    points: list[tuple[float, float]] = []
    for operation in edge.get("_draw_", []):  # type: ignore[attr-defined]
        if operation.get("op") in ("b", "B"):
            points += _bezier_points([(float(a), float(b)) for a, b in operation["points"]])
    return points


WAREHOUSE = ROOT / "tests" / "doc_specs" / "warehouse" / "system.earl"


@pytest.mark.parametrize(
    ("spec", "view", "target", "expand"),
    [
        (EXAMPLE, "system", None, False),
        (EXAMPLE, "agent", "manip/a", False),
        (MOBILE, "agent", "base/a", False),
        (WAREHOUSE, "system", None, False),
        (WAREHOUSE, "agent", "worker[1]/a", True),
    ],
)
def test_a_link_going_back_leaves_its_output_buffer_eastwards_and_crosses_no_block(
    spec: Path, view: str, target: str | None, expand: bool
) -> None:
    """`manip,task` hugged manip/a's bottom edge, `grip,task` dipped below the robot's border,
    `worker[I],supervisor` ran through worker[I]/a and `wheel[1],cs` entered wheel[1]/ve through its
    bottom: a link back was declared from its label to the east side of its Output Buffer, which dot
    could only reach from the west, round its own block.  It now runs east to a turn point and back
    past the blocks: every point of its path is outside every block, the first half right of its own
    block, and in the system view inside the robot that holds both its ends."""
    import json

    from earl.render.graphviz import _dot

    diagram = build_diagram(earl.load(spec), view, target, expand=expand)
    layout = json.loads(_dot(diagram.laid_out, "json"))
    boxes = _layout_boxes(layout)
    names = {index: node["name"] for index, node in enumerate(layout["objects"])}
    blocks = {name: box for name, box in boxes.items() if name.startswith(("n_agent_", "n_ss_"))}
    #: the robots by the nodes they hold: a link between two agents of a robot runs inside it
    robots = {
        names[member]: [float(v) for v in node["bb"].split(",")]
        for node in layout["objects"]
        if node.get("name", "").startswith("cluster_robot_")
        for member in node.get("nodes", [])
    }
    from_outputs = 0
    for edge in layout["edges"]:
        if "invis" in edge.get("style", ""):
            continue
        tail, head = names[edge["tail"]], names[edge["head"]]
        points = _edge_points(layout, edge)
        for x, y in points:
            for name, (left, bottom, right, top) in blocks.items():
                inside = left + 2 < x < right - 2 and bottom + 2 < y < top - 2
                assert not inside, f"{edge.get('tooltip')} runs through {name} at ({x:.0f}, {y:.0f})"
            if tail in robots and head in robots:
                left, bottom, right, top = robots[head]
                assert left <= x <= right and bottom <= y <= top, f"{edge.get('tooltip')} leaves its robot"
        # the half from an Output Buffer runs east of its block all the way, however it is declared
        for end, port in ((tail, edge.get("tailport", "")), (head, edge.get("headport", ""))):
            if port.startswith("p_ob_") and end in blocks:
                from_outputs += 1
                assert min(x for x, _ in points) >= blocks[end][2] - 2, f"{edge.get('tooltip')} turns round {end}"
    assert from_outputs


@pytest.mark.parametrize(("spec", "target"), [(EXAMPLE, "grip/a.cs"), (EXAMPLE, "manip/a.cs"), (MOBILE, "base/a.cs")])
def test_a_self_loop_starts_away_from_where_other_transitions_arrive(spec: Path, target: str) -> None:
    """grip/a.cs: the arrowhead of `start → move` landed where the `move → move` loop began, so the two
    read as one line.  Every loop now starts at least 8 pt from the tip of every other transition into
    its state."""
    import json

    from earl.render.graphviz import _dot

    diagram = build_diagram(earl.load(spec), "fsm", target)
    layout = json.loads(_dot(diagram.laid_out, "json"))
    loops = [edge for edge in layout["edges"] if edge["tail"] == edge["head"]]
    assert loops
    for loop in loops:
        start = _edge_points(layout, loop)[0]
        tips = [
            (float(x), float(y))
            for edge in layout["edges"]
            if edge["head"] == loop["head"] and edge is not loop
            for operation in edge.get("_hdraw_", [])
            if operation.get("op") in ("P", "p")
            for x, y in operation["points"]
        ]
        assert tips
        nearest = min(((x - start[0]) ** 2 + (y - start[1]) ** 2) ** 0.5 for x, y in tips)
        assert nearest >= 8, f"{loop.get('tooltip')} starts {nearest:.1f} pt from an arrowhead"


@pytest.mark.parametrize(
    ("spec", "agent", "expand"),
    [
        (EXAMPLE, "manip/a", True),
        (EXAMPLE, "manip/a", False),
        (EXAMPLE, "grip/a", True),
        (MOBILE, "base/a", True),
        (WAREHOUSE, "worker[1]/a", True),
        (WAREHOUSE, "supervisor/a", False),
    ],
)
def test_no_link_crosses_the_agent_view_s_name_tab(spec: Path, agent: str, expand: bool) -> None:
    """`--view agent --target manip/a --expand --param N=2`: the dashed `task,manip` link crossed the
    `ibd [Agent] manip/a` tab (it ran from task/a, placed under the frame, up round its top-left corner).
    No drawn link passes within 3 pt of the tab."""
    import json

    from earl.render.graphviz import _dot

    diagram = build_diagram(earl.load(spec, {"N": 2} if spec == EXAMPLE else None), "agent", agent, expand=expand)
    layout = json.loads(_dot(diagram.laid_out, "json"))
    [frame] = [o for o in layout["objects"] if o.get("name") == "cluster_frame"]
    x, y = (float(v) for v in frame["lp"].split(","))
    half_width, half_height = float(frame["lwidth"]) * 36 + 3, float(frame["lheight"]) * 36 + 3
    crossing = {
        edge.get("tooltip")
        for edge in layout["edges"]
        if "invis" not in edge.get("style", "")
        for px, py in _edge_points(layout, edge)
        if abs(px - x) <= half_width and abs(py - y) <= half_height
    }
    assert crossing == set()


def test_the_agent_view_marks_an_input_buffer_that_keeps_a_fifo() -> None:
    """`goal/ib: NavigationGoal fifo 4 overflow dropOldest`: the agent view showed it as any buffer; its
    port says `{fifo 4, dropOldest}` after its name, as UML writes a property's modifiers."""
    texts = svg_text(build_diagram(earl.load(MOBILE), "agent", "base/a").svg())
    assert "goal/ib {fifo 4, dropOldest}" in texts
    assert "obstacles/ib {" not in texts
