"""`earl doc`: the manual's tables computed from the spec, the document's links, and the page in a browser.

The flagship example is the manual's own §3 system, so its tables must say what
the manual's tables say.  Needs Graphviz's `dot`; the browser test needs Debian's
`chromium` and Playwright (both installed by scripts/setup.sh).
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest

import earl
from earl.check import check
from earl.cli.main import main
from earl.render.build import Subject
from earl.render.document import write_site
from earl.render.mermaid import mermaid_of
from earl.render.tables import (
    assumption_table,
    composition_table,
    condition_table,
    memory_table,
    predicate_table,
    transition_table,
)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "pick_and_place" / "system.earl"
CHROMIUM = Path("/usr/bin/chromium")

# ---------------------------------------------------------------- Table 6, cell by cell
#
# The manual's Table 6 (manip/a.cs.bb.tf.pf), written out by hand from the manual.  The text copy
# in shared/reference garbles it in three ways, resolved here:
#
# 1. Its header lists one /ob column, `ManipulatorState`, while the rows put the bullets of both
#    output functions in that last column.  The manual's §3.2 says outputMotorCon/pf composes the
#    motor controllers' commands (Figure 14b), so the table has a second /ob column,
#    MotorControllerCommandK (`DriveControllerCommandK/ob` in Figure 14b; `motorControllerCommand[K]`
#    in the spec, as §3.2 names the type).
# 2. The text puts calculatePosition/pf's bullets under motionFinished and currentJointPos.  §3.2
#    says it "calculates manipulator joint positions and end-effector operational space pose", and
#    Eq. (7) forbids two functions of one transition function writing the same memory, which
#    jointMove/pf (motionFinished, windingCurrentK) would violate in jointMove/bb.  The bullets are
#    shifted by one column in the text: the truth is currentJointPos and currentOperationalPos.
# 3. The header abbreviates `emergencyStopCommandK/m` (Table 3, Eq. 5) as `emergencyStop`.
#
# Columns are named as the spec declares them (Table 3's names, families with their index K).
MO = ("motionFinished", "currentJointPos", "currentOperationalPos", "emergencyStopCommand[K]", "windingCurrent[K]")
OB = ("manipulatorState", "motorControllerCommand[K]")
MANUAL_TABLE_6: dict[tuple[str, str], set[str]] = {}
for behaviour, own_function, own_writes in [
    ("idle", "passiveRegulation", {"windingCurrent[K]"}),
    ("jointMove", "jointMove", {"motionFinished", "windingCurrent[K]"}),
    ("operationalMove", "operationalMove", {"motionFinished", "windingCurrent[K]"}),
    ("emergencyStop", "emergencyStop", {"emergencyStopCommand[K]"}),
]:
    MANUAL_TABLE_6[(behaviour, "outputManipState")] = {"manipulatorState"}
    MANUAL_TABLE_6[(behaviour, "outputMotorCon")] = {"motorControllerCommand[K]"}
    MANUAL_TABLE_6[(behaviour, "calculatePosition")] = {"currentJointPos", "currentOperationalPos"}
    MANUAL_TABLE_6[(behaviour, own_function)] = own_writes


@pytest.fixture(scope="module")
def manip_cs() -> earl.Subsystem:
    cs = earl.load(EXAMPLE).agent("manip").control_subsystem  # type: ignore[union-attr]
    assert cs is not None
    return cs


def test_table_6_of_manip_cs_equals_the_manuals_cell_by_cell(manip_cs: earl.Subsystem) -> None:
    table = composition_table(manip_cs)
    assert {column.name for column in table.columns} == set(MO) | set(OB)
    assert [c.name for c in table.columns if c.kind is earl.Kind.OUTPUT_BUFFER] == list(OB)
    generated = table.matrix()
    assert set(generated) == set(MANUAL_TABLE_6)  # the same 16 rows: behaviour and function
    for row, expected in MANUAL_TABLE_6.items():
        for column in (*MO, *OB):
            assert (column in generated[row]) == (column in expected), f"Table 6, row {row}, column {column}"


def test_table_6_changes_with_the_spec(manip_cs: earl.Subsystem) -> None:
    # The bullets come from the declared writes, not from a copy of the manual: change one, the cell changes.
    function = manip_cs.partial_transition_function("calculatePosition")
    assert function is not None
    original = list(function.writes)
    try:
        function.writes = [w for w in original if w.name != "currentOperationalPos"]
        assert composition_table(manip_cs).matrix()[("idle", "calculatePosition")] == {"currentJointPos"}
    finally:
        function.writes = original


def test_tables_3_4_and_5_follow_the_manual(manip_cs: earl.Subsystem) -> None:
    memory = {row.name: row.data_type for row in memory_table(manip_cs)}
    assert memory == {  # Table 3
        "motionFinished": "boolean",
        "currentOperationalPos": "OperPosition",
        "currentJointPos": "JointPosition",
        "emergencyStopCommand[K]": "boolean",
        "windingCurrent[K]": "double",
    }
    predicates = {row.name: row.fun for row in predicate_table(manip_cs)}  # Table 4
    assert list(predicates) == ["emergencyStop", "motionFinished", "newJointPos", "newOperationalPos", "false"]
    assert predicates["newJointPos"] == "newData(manipulatorCommand/ib.jointPosSetpoint)"
    assert predicates["motionFinished"] == "motionFinished/mi"
    transitions = {row.name: row.predicate for row in transition_table(manip_cs)}  # Table 5
    assert transitions == {
        "*,emergencyStop": "emergencyStop/pp",
        "idle,jointMove": "newJointPos/pp and not emergencyStop/pp",
        "idle,operationalMove": "newOperationalPos/pp and not emergencyStop/pp",
        "jointMove,jointMove": "newJointPos/pp and not emergencyStop/pp",
        "operationalMove,operationalMove": "newOperationalPos/pp and not emergencyStop/pp",
        "jointMove,idle": "not emergencyStop/pp",
        "operationalMove,idle": "not emergencyStop/pp",
    }
    terminal = {row.behaviour: row.terminal_condition for row in condition_table(manip_cs)}
    assert terminal == {
        "idle": "newJointPos/pp or newOperationalPos/pp or emergencyStop/pp",
        "jointMove": "motionFinished/pp or emergencyStop/pp",
        "operationalMove": "motionFinished/pp or emergencyStop/pp",
        "emergencyStop": "false/pp",
    }
    # Table 5's caption: "It is assumed that task/a can not set simultaneously a new joint position and an
    # operational space pose"
    (assumed,) = assumption_table(manip_cs.fsm)
    assert assumed.formula == "not (newJointPos/pp and newOperationalPos/pp)"
    assert assumed.comment == "Table 5: task/a never sets a new joint position and an operational pose at once."


def test_table_5_states_what_the_fsm_assumes(site: Path) -> None:
    """The FSM's `assume` formulas were in no table and no diagram: they are a line of Table 5's caption,
    as the manual states its assumption, with the formula's names linked and its comment after it."""
    from markdown_it import MarkdownIt

    html = (site / "index.html").read_text(encoding="utf-8")
    caption = re.search(r"<caption>Table 5: initial conditions labelling manip/a\.cs\.fsm.*?</caption>", html)
    assert caption is not None
    assert '<div class="note">Assumed: <code>not (<a href="#pp-manip-a-cs-newJointPos">newJointPos/pp</a>' in (
        caption.group().replace("<wbr>", "")  # where a narrow window may break a name
    )
    assert "— Table 5: task/a never sets a new joint position and an operational pose at once." in caption.group()
    # a subsystem whose FSM assumes nothing says nothing
    other = re.search(r"<caption>Table 5: initial conditions labelling manip/a\.motorController.*?</caption>", html)
    assert other is not None and "Assumed" not in other.group()
    # the Markdown copy: a paragraph under the caption's title, read back as GitHub reads it
    read = MarkdownIt("commonmark").enable("table").render((site / "index.md").read_text(encoding="utf-8"))
    assert re.search(
        r"<p><strong>Table 5: initial conditions labelling manip/a\.cs\.fsm[^<]*</strong></p>\s*"
        r"<p>Assumed: <code>not \(</code><a href=\"#pp-manip-a-cs-newJointPos\"><code>newJointPos/pp</code></a>",
        read,
    )


def test_table_5_of_an_fsm_of_one_state_says_so_instead_of_an_empty_transition_header(site: Path) -> None:
    """motor[K]/re and fingerDrive/re have one state and no transition: Table 5 showed a `t | PREDICATE |
    priority` header over no row.  A line under the caption says the FSM has one state and stays in it, and
    the table holds the terminal conditions under their own header, in the HTML and in the Markdown."""
    from markdown_it import MarkdownIt

    html = (site / "index.html").read_text(encoding="utf-8")
    read = MarkdownIt("commonmark").enable("table").render((site / "index.md").read_text(encoding="utf-8"))
    for qualified, escaped in [
        ("manip/a.motor[K]/re", r"manip/a\.motor\[K\]/re"),
        ("grip/a.fingerDrive/re", r"grip/a\.fingerDrive/re"),
    ]:
        table = re.search(rf"<caption>Table 5: initial conditions labelling {escaped}\.fsm.*?</table>", html)
        assert table is not None
        said = f'<div class="note">No transition: {qualified}.fsm has one state, <code>drive</code>, and stays in it.</div>'
        assert said in table.group()
        assert "<thead><tr><th>bb</th><th>PREDICATE (terminal condition tc; error condition ec)</th></tr></thead>" in (
            table.group()
        )
        assert "<th>t</th>" not in table.group() and "priority" not in table.group()
        written = re.search(
            rf"<p><strong>Table 5: initial conditions labelling {escaped}\.fsm[^<]*</strong></p>\s*"
            rf"<p>No transition: {escaped}\.fsm has one state, <code>drive</code>, and stays in it\.</p>\s*"
            r"<table>\s*<thead>\s*<tr>\s*<th>bb</th>",
            read,
        )
        assert written is not None
    # an FSM with transitions keeps its `t` header and its `bb` sub-header, and says nothing of the kind
    cs = re.search(r"<caption>Table 5: initial conditions labelling manip/a\.cs\.fsm.*?</table>", html)
    assert cs is not None and "<th>t</th>" in cs.group() and "No transition" not in cs.group()


# ---------------------------------------------------------------- the written document


class _Page(HTMLParser):
    """The ids, internal links, images and external references of an HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []
        self.images: list[str] = []
        self.external: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = {name: value or "" for name, value in attrs}
        if "id" in values:
            assert values["id"] not in self.ids, f"duplicate id {values['id']}"
            self.ids.add(values["id"])
        for attribute in ("href", "src"):
            target = values.get(attribute, "")
            if target.startswith(("http:", "https:", "//")):
                self.external.append(target)
        if tag == "a" and values.get("href", "").startswith("#"):
            self.links.append(values["href"][1:])
        if tag == "img":
            self.images.append(values["src"])


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("site")
    assert main(["doc", str(EXAMPLE), "-o", str(directory)]) == 0
    return directory


def test_document_is_offline_and_every_link_and_image_resolves(site: Path) -> None:
    page = _Page()
    page.feed((site / "index.html").read_text(encoding="utf-8"))
    assert page.external == []  # no CDN, no font service: the page works offline
    assert "<script" not in (site / "index.html").read_text(encoding="utf-8")
    assert sorted(set(page.links) - page.ids) == []
    assert len(page.links) > 200  # tables and expressions are cross-linked, not just the contents
    assert page.images and all((site / src).is_file() for src in page.images)
    for diagram in (site / "diagrams").glob("*.svg"):
        assert "http://www.w3.org/Graphics/SVG/1.1/DTD" not in diagram.read_text(encoding="utf-8")


def test_document_holds_the_manuals_tables_and_diagrams(site: Path) -> None:
    html = (site / "index.html").read_text(encoding="utf-8")
    for caption in [
        "Table 3: manip/a.cs.m dataTypes",
        "Table 4: definitions of manip/a.cs.pp.fun",
        "Table 5: initial conditions labelling manip/a.cs.fsm transitions",
        "Table 6: compositions of Transition Functions manip/a.cs.bb.tf.pf",
        "Check results",
        "Agents and their types (Table 1",
    ]:
        assert caption in html
    diagrams = {path.name for path in (site / "diagrams").glob("*.svg")}
    assert {
        "system.svg",
        "agent-manip-a.svg",
        "fsm-manip-a-cs.svg",
        "act-manip-a-cs-jointMove.svg",
        "types-manip-a.svg",
        "types-between-agents.svg",
    } <= diagrams
    # one activity diagram per basic behaviour of every subsystem, families drawn once
    system = earl.load(EXAMPLE)
    behaviours = sum(len(s.basic_behaviours) for a in system.agents for s in a.subsystems)
    assert len([name for name in diagrams if name.startswith("act-")]) == behaviours


def test_agent_types_of_table_1_are_computed(site: Path) -> None:
    markdown = (site / "index.md").read_text(encoding="utf-8")
    # §3: "a single robot multi-agent system containing CT and CET agents"
    assert "| [`task/a`](#agent-task-a) | `manipulationRobot/r` | **CT** | purely computational agent |" in markdown
    assert "| [`manip/a`](#agent-manip-a) | `manipulationRobot/r` | **CET** | teleoperated agent |" in markdown


def test_markdown_has_table_6_with_bullets_and_every_image(site: Path) -> None:
    markdown = (site / "index.md").read_text(encoding="utf-8")
    header = next(line for line in markdown.splitlines() if line.startswith("| bb | pf | /mo `motionFinished`"))
    assert header.endswith("/ob `manipulatorState` | /ob `motorControllerCommand[K]` |")
    row = next(line for line in markdown.splitlines() if "[`jointMove/pf`]" in line and "•" in line)
    assert row.count("•") == 2
    for image in [line for line in markdown.splitlines() if line.startswith("![")]:
        assert (site / image[image.index("](") + 2 : -1]).is_file()


class _Cells(HTMLParser):
    """The text of every table cell (or of every element `tags` names) of an HTML page, spaces collapsed."""

    def __init__(self, tags: tuple[str, ...] = ("td", "th")) -> None:
        super().__init__()
        self.tags = tags
        self.cells: list[str] = []
        self._text: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag in self.tags:
            self._text = []

    def handle_endtag(self, tag: str) -> None:
        if tag in self.tags and self._text is not None:
            self.cells.append(" ".join("".join(self._text).split()))
            self._text = None

    def handle_data(self, data: str) -> None:
        if self._text is not None:
            self._text.append(data)


def _cells(html: str) -> list[str]:
    parser = _Cells()
    parser.feed(html)
    return parser.cells


def _markdown_cells_missing_from_the_html(site: Path) -> list[str]:
    """index.md read as GitHub reads it (CommonMark with tables): every cell must say what index.html's
    cells say. Only a header group's label differs by design: Markdown has no spanning cells, so it
    prefixes the columns under it (`/mo phaseComplete`)."""
    from markdown_it import MarkdownIt

    html = set(_cells((site / "index.html").read_text(encoding="utf-8")))
    markdown = MarkdownIt("commonmark").enable("table").render((site / "index.md").read_text(encoding="utf-8"))
    return [
        cell
        for cell in _cells(markdown)
        if cell and cell not in html and not (cell.startswith(("/mo ", "/ob ")) and cell[4:] in html)
    ]


def test_markdown_reads_back_as_the_html_says(site: Path) -> None:
    """Expressions keep their spaces (`a/pp and not b/pp`, not `a/ppand notb/pp`), neighbouring code
    does not merge into a double-backtick span, and every cell reads as in the HTML."""
    assert _markdown_cells_missing_from_the_html(site) == []
    markdown = (site / "index.md").read_text(encoding="utf-8")
    assert "[`phaseComplete/pp`](#pp-task-a-cs-phaseComplete) `and not` [`manipulatorEmergency/pp`]" in markdown


def test_markdown_writes_a_bar_inside_code_as_github_reads_it(tmp_path: Path) -> None:
    spec = tmp_path / "bar.earl"
    # in a string of a condition: a function's name with a bar is no Python identifier (EARL-E044)
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace("false/pp = false", 'false/pp = "appr|oach" == "x"', 1),
        encoding="utf-8",
    )
    assert "appr|oach" in spec.read_text(encoding="utf-8")
    site = tmp_path / "site"
    assert main(["doc", str(spec), "-o", str(site)]) == 0
    markdown = (site / "index.md").read_text(encoding="utf-8")
    assert "&#124;" not in markdown and "appr\\|oach" in markdown
    assert _markdown_cells_missing_from_the_html(site) == []


def test_check_errors_are_shown_and_fail_the_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "lonely.earl"
    # A virtual effector without its real effector breaks Equation (1).
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace(
            "    link cs,fingerController:", "    sparePart/ve {\n    }\n\n    link cs,fingerController:"
        ),
        encoding="utf-8",
    )
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 1
    assert "the document shows them" in capsys.readouterr().out
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    assert '<td class="error">error</td>' in html


def test_documenting_never_imports_code_the_spec_names(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    marker = tmp_path / "imported"
    (tmp_path / "trap_module.py").write_text(
        f"open({str(marker)!r}, 'w').write('imported')\n\ndef f(*a):\n    return None\n", encoding="utf-8"
    )
    spec = tmp_path / "trap.earl"
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace(
            'python "pick_and_place.manip:joint_move"', 'python "trap_module:f"'
        ),
        encoding="utf-8",
    )
    monkeypatch.syspath_prepend(str(tmp_path))  # the module could be imported, if anything tried
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 0
    assert main(["diagram", str(spec), "--view", "activity", "--target", "manip/a.cs.jointMove/bb"]) == 0
    assert not marker.exists()
    assert "trap_module" not in sys.modules
    assert "trap_module:f" in (tmp_path / "site" / "index.html").read_text(encoding="utf-8").replace("<wbr>", "")


def test_expanded_document_tabulates_every_member(tmp_path: Path) -> None:
    system = earl.load(EXAMPLE, {"N": 2})
    result = write_site(Subject(system, True, {"N": 2}), check(system, {"N": 2}), tmp_path)
    html = result.html.read_text(encoding="utf-8")
    assert "manip/a.motorController[2]/ve" in html and "motorController[K]" not in html
    page = _Page()
    page.feed(html)
    assert sorted(set(page.links) - page.ids) == []


# ---------------------------------------------------------------- the page in a browser


def _chromium() -> tuple[Any, str]:
    """Playwright's sync API and Debian's Chromium; the test is skipped without them (failed on CI)."""
    sync_api = pytest.importorskip("playwright.sync_api") if not os.environ.get("CI") else None
    if sync_api is None:
        import playwright.sync_api as sync_api
    if not CHROMIUM.exists() and shutil.which("chromium") is None:
        if os.environ.get("CI"):
            pytest.fail("Debian's chromium is missing; scripts/setup.sh installs it")
        pytest.skip("Debian's chromium is not installed (scripts/setup.sh installs it)")
    return sync_api, str(CHROMIUM) if CHROMIUM.exists() else str(shutil.which("chromium"))


def test_document_opens_in_headless_chromium_without_errors(site: Path, tmp_path: Path) -> None:
    sync_api, executable = _chromium()
    screenshot = tmp_path / "earl-doc.png"
    with sync_api.sync_playwright() as playwright:
        # Playwright cannot download its own browser here: it drives the system's Chromium.
        browser = playwright.chromium.launch(executable_path=executable, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            problems: list[str] = []
            page.on("console", lambda message: problems.append(message.text) if message.type == "error" else None)
            page.on("pageerror", lambda error: problems.append(str(error)))
            page.on("requestfailed", lambda request: problems.append(f"failed to load {request.url}"))
            page.goto((site / "index.html").as_uri(), wait_until="load")
            broken = page.evaluate(
                "Array.from(document.images).filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src)"
            )
            count = page.evaluate("document.images.length")
            title = page.title()
            table_6_bullets = page.evaluate(
                "document.getElementById('table6-manip-a-cs').querySelectorAll('td.bullet').length"
            )
            # Table 5's caption as a reader sees it: the assumption on a line of its own, not bold
            assumed = page.evaluate(
                "Array.from(document.querySelectorAll('caption .note')).filter(n => n.innerText.startsWith('Assumed'))"
                ".map(n => [n.innerText, "
                "getComputedStyle(n).fontWeight, n.getBoundingClientRect().top > "
                "n.parentElement.getBoundingClientRect().top + 5])"
            )
            # Figure 10 is wider than the page: shrunk to 80 % at most (at 43 % its text was 5 px high), its
            # box scrolls sideways, and it links to the SVG at full size
            agent = page.evaluate(
                "(() => { const i = document.querySelector('#fig-agent-manip-a img'); const d = i.closest('.diagram');"
                " return [i.getBoundingClientRect().width / i.naturalWidth, d.scrollWidth > d.clientWidth,"
                " i.parentElement.getAttribute('href')]; })()"
            )
            page.goto((site / "index.html").as_uri() + "#ss-manip-a-cs", wait_until="load")
            page.screenshot(path=str(screenshot))
        finally:
            browser.close()
    assert problems == []
    assert broken == []
    assert count == len(list((site / "diagrams").glob("*.svg")))
    assert title == "pickAndPlace: an EARL specification"
    assert table_6_bullets == 16 * 7
    assert assumed == [
        [
            "Assumed: not (newJointPos/pp and newOperationalPos/pp) — Table 5: task/a never sets a new joint "
            "position and an operational pose at once.",
            "400",
            True,
        ]
    ]
    assert agent[0] >= 0.8 - 0.01 and agent[1:] == [True, "diagrams/agent-manip-a.svg"]
    assert screenshot.read_bytes()[:4] == b"\x89PNG"
    print(f"screenshot: {screenshot}")


def test_document_is_usable_in_a_window_800_pixels_wide(site: Path, tmp_path: Path) -> None:
    """At 800 px the 280 px sidebar stayed beside the text: 44 tables and figures scrolled sideways,
    Table 1's caption was cut and the buffer tables' "linked with" column was off-screen.  Below
    960 px the contents go above the text, and long names in table cells break at dots and between
    camelCase words: no table needs sideways scrolling, and every caption and cell is in the window
    (only diagrams wider than the text scroll, as at any width)."""
    sync_api, executable = _chromium()
    screenshot = tmp_path / "earl-doc-800.png"
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": 800, "height": 1000})
            page.goto((site / "index.html").as_uri(), wait_until="load")
            layout = page.evaluate(
                """(() => {
                  const nav = document.querySelector('nav').getBoundingClientRect();
                  const main = document.querySelector('main').getBoundingClientRect();
                  const scrolling = Array.from(document.querySelectorAll('.wide'))
                    .filter(box => box.scrollWidth > box.clientWidth + 1)
                    .map(box => box.querySelector('caption').innerText.slice(0, 60));
                  const outside = Array.from(document.querySelectorAll('caption, td, th'))
                    .filter(cell => cell.getBoundingClientRect().right > window.innerWidth + 1)
                    .map(cell => cell.innerText.slice(0, 60));
                  // a rule's code on one line: `EARL-I063` broke after its hyphen
                  const rules = Array.from(document.querySelectorAll('td.rule code'))
                    .map(code => code.getClientRects().length);
                  return {navBottom: nav.bottom, mainTop: main.top, mainLeft: main.left,
                          pageWidth: document.documentElement.scrollWidth, scrolling, outside, rules};
                })()"""
            )
            page.screenshot(path=str(screenshot))
        finally:
            browser.close()
    assert layout["mainTop"] >= layout["navBottom"] - 1 and layout["mainLeft"] < 20  # contents above the text
    assert layout["pageWidth"] <= 800
    assert layout["scrolling"] == []
    assert layout["outside"] == []
    assert layout["rules"] and set(layout["rules"]) == {1}
    print(f"screenshot: {screenshot}")


@pytest.mark.parametrize("width", [1400, 1920])
def test_no_table_scrolls_sideways_in_a_wide_window(site: Path, tmp_path: Path, width: int) -> None:
    """The comment and keeps columns pushed tables past the text in a wide window: at 1400 px the buffers
    table of manip/a.cs was 1122 px in a 1040 px box (its comment cut), the pf table 1241 px, still
    scrolling at 1920 px.  A comment wraps at a readable width, and a table that would not fit with its
    names whole breaks them at their `<wbr>`, not in its first column; one that fits keeps every name on one
    line."""
    sync_api, executable = _chromium()
    mobile = tmp_path / "mobile_robot"
    assert main(["doc", str(ROOT / "examples" / "mobile_robot"), "-o", str(mobile)]) == 0
    found = {}
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": width, "height": 1000})
            for name, directory in (("pick_and_place", site), ("mobile_robot", mobile)):
                page.goto((directory / "index.html").as_uri(), wait_until="load")
                found[name] = page.evaluate(
                    """(() => {
                      const scrolling = Array.from(document.querySelectorAll('.wide'))
                        .filter(box => box.scrollWidth > box.clientWidth + 1)
                        .map(box => box.querySelector('caption').innerText.slice(0, 60));
                      // in a table that fits with its names whole, no name is broken
                      const keeps = table => {  // whether a table keeps its names whole (its first column always does)
                        const wbr = table.querySelector('td:not(:first-child) wbr');
                        return wbr !== null && getComputedStyle(wbr).display === 'none';
                      };
                      const broken = Array.from(document.querySelectorAll('.wide table')).filter(keeps)
                        .flatMap(table => Array.from(table.querySelectorAll('td code, th code')))
                        .filter(code => !/\\s/.test(code.textContent) && code.getClientRects().length > 1)
                        .map(code => code.textContent);
                      // the name a row is about stays whole in every table (`calculate`/`Position/pf` split)
                      const first = Array.from(document.querySelectorAll('.wide td:first-child code'))
                        .filter(code => !/\\s/.test(code.textContent) && code.getClientRects().length > 1)
                        .map(code => code.textContent);
                      const comments = Array.from(document.querySelectorAll('td.comment'))
                        .map(cell => cell.getBoundingClientRect().width);
                      const whole = Array.from(document.querySelectorAll('.wide table')).filter(keeps).length;
                      return {scrolling, broken, first, widest: Math.max(...comments), whole};
                    })()"""
                )
        finally:
            browser.close()
    for name, layout in found.items():
        assert layout["scrolling"] == [], name
        assert layout["broken"] == [], name
        assert layout["first"] == [], name
        assert layout["whole"] > 10, name  # most tables keep their names whole in a wide window
        assert layout["widest"] <= 32 * 13.5 + 2 * 8 + 1, name  # a comment wraps at 32em


AGENT_FAMILY = """\
system swarm

param M: int = 3

struct Order {
    x: double
}

swarmRobot/r {
    coord/a
    worker[1]/a
    worker[2]/a
    worker[3]/a
}

coord/a {
    cs {
        period 10 ms
        order[K in 1..M]/ob: Order
        report[K in 1..M]/ib: Order
        o/m: Order
        got/pp = newData(report[1]/ib)
        send/pf(report[*]/ib -> o/mo)
        emit/pf(o/mi -> order[*]/ob)
        run/bb {
            tf = {send/pf} then {emit/pf}
            tc = got/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when got/pp
        }
    }
}

worker[K in 1..M]/a {
    cs {
        period 10 ms
        order/ib: Order
        report/ob: Order
        o/m: Order
        got/pp = newData(order/ib)
        take/pf(order/ib -> o/mo)
        back/pf(o/mi -> report/ob)
        run/bb {
            tf = {take/pf} then {back/pf}
            tc = got/pp
        }
        fsm {
            initial run
            state run: run/bb
            run -> run when got/pp
        }
    }
}

link coord,worker[K in 1..M]: coord/a.cs.order[K] -> worker[K]/a.cs.order
link worker[K in 1..M],coord: worker[K]/a.cs.report -> coord/a.cs.report[K]
"""


@pytest.mark.parametrize("expand", [False, True], ids=["declared", "expanded"])
def test_a_family_of_agents_is_documented_with_every_link_resolving(tmp_path: Path, expand: bool) -> None:
    system = earl.loads(AGENT_FAMILY, "swarm.earl")
    diagnostics = check(system)
    assert [d for d in diagnostics if d.severity.value == "error"] == []
    html = write_site(Subject(system, expand), diagnostics, tmp_path).html.read_text(encoding="utf-8")
    page = _Page()
    page.feed(html)  # also refuses duplicate ids
    assert sorted(set(page.links) - page.ids) == []
    if expand:
        assert all(f"worker[{k}]/a" in html for k in (1, 2, 3)) and "worker[K]/a" not in html
    else:
        assert "worker[K]/a" in html and "worker[1]/a" not in html
    # Table 1 counts every member of the family: the coordinator talks to three workers, in both directions
    assert "<strong>CT</strong>" in html


def test_a_second_run_leaves_no_stale_diagram(tmp_path: Path) -> None:
    system = earl.loads(AGENT_FAMILY, "swarm.earl")
    write_site(Subject(system), [], tmp_path)
    renamed = earl.loads(AGENT_FAMILY.replace("worker", "helper"), "swarm.earl")
    result = write_site(Subject(renamed), [], tmp_path)
    assert sorted((tmp_path / "diagrams").glob("*.svg")) == sorted(result.diagrams)
    assert not any("worker" in path.name for path in result.diagrams)


def test_doc_leaves_what_it_did_not_write_and_refuses_a_users_index(tmp_path: Path) -> None:
    """`earl doc -o docs/` in a folder of the user's: their own pictures stay, their index is not replaced."""
    diagrams = tmp_path / "diagrams"
    diagrams.mkdir()
    logo = diagrams / "logo.svg"
    logo.write_text("<svg/>")
    system = earl.loads(AGENT_FAMILY, "swarm.earl")
    write_site(Subject(system), [], tmp_path)
    write_site(Subject(system), [], tmp_path)  # a second run replaces its own files
    assert logo.read_text() == "<svg/>"
    own = tmp_path / "mine"
    own.mkdir()
    (own / "index.html").write_text("<html>my project page</html>")
    assert main(["doc", str(EXAMPLE), "-o", str(own)]) == 2
    assert (own / "index.html").read_text() == "<html>my project page</html>"
    assert not (own / "diagrams").exists()


def test_distinct_elements_get_distinct_anchors_and_diagrams(tmp_path: Path) -> None:
    """System `arm_a` and agent `arm/a`; transitions `idle -> wait_home` and `idle_wait -> home`; a
    `* -> idle`: each has its own anchor, and each figure its own file (none silently dropped)."""
    spec = Path(__file__).parent / "doc_specs" / "collisions" / "system.earl"
    site = tmp_path / "site"
    assert main(["doc", str(spec), "-o", str(site)]) == 0
    page = (site / "index.html").read_text(encoding="utf-8")
    ids = re.findall(r'\bid="([^"]+)"', page)
    assert len(ids) == len(set(ids)), sorted({i for i in ids if ids.count(i) > 1})
    images = re.findall(r'<img[^>]*\bsrc="([^"]+)"', page)
    assert len(images) == len(set(images)) == len(list((site / "diagrams").glob("*.svg")))
    system_types = next(i for i in images if i.endswith("types-arm_a.svg"))
    assert "[Package] arm_a dataTypes" in (site / system_types).read_text(encoding="utf-8")


def test_a_name_too_long_for_a_file_name_still_makes_a_document(tmp_path: Path) -> None:
    long = "a" + "VeryLongName" * 30
    spec = tmp_path / "long.earl"
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace("jointMove", long),
        encoding="utf-8",
    )
    site = tmp_path / "site"
    assert main(["doc", str(spec), "-o", str(site)]) == 0
    names = [path.name for path in (site / "diagrams").iterdir()]
    assert names and max(len(name) for name in names) <= 130


MEMBER_LINK = """\
system member

a1/a {
    cs {
        period 1 ms
        out/ob: double
    }
}

a2/a {
    cs {
        period 1 ms
        inp[K in 1..2]/ib: double
    }
}

link a1,a2: a1/a.cs.out -> a2/a.cs.inp[1]

r/r {
    a1/a
    a2/a
    link a1,a2
}
"""


def test_a_link_into_one_member_of_a_family_is_drawn_into_that_member(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`-> a2/a.cs.inp[1]` feeds `inp[1]` only (`earl check` says `inp[2]` is fed by no link): the
    document, the system diagram and its Mermaid text say `inp[1]`, not the family `inp[K]`."""
    spec = tmp_path / "member.earl"
    spec.write_text(MEMBER_LINK, encoding="utf-8")
    assert main(["diagram", str(spec), "--view", "system", "--format", "mermaid"]) == 0
    assert "a1,a2: out/ob → inp[1]/ib : double" in capsys.readouterr().out
    assert main(["diagram", str(spec), "--view", "system", "-o", str(tmp_path / "system.svg")]) == 0
    drawing = (tmp_path / "system.svg").read_text(encoding="utf-8")
    assert "inp[1]/ib" in drawing and "inp[K]" not in drawing
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 0
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    assert "[`a2/a.cs.inp[1]/ib`](#ib-a2-a-cs-inp-K)" in markdown
    assert "(a1,a2, into inp[1])" in markdown


def test_the_agents_table_puts_each_member_in_the_robot_that_lists_it(tmp_path: Path) -> None:
    """The robot lists `worker[1]/a` and `worker[2]/a` of the family `worker[K in 1..3]/a`: expanded,
    `worker[3]/a` belongs to no robot, as the system diagram draws it."""
    spec = Path(__file__).parent / "doc_specs" / "fleet" / "system.earl"
    assert main(["doc", str(spec), "--expand", "-o", str(tmp_path / "site")]) == 0
    rows = {
        line.split(" | ")[0]: line.split(" | ")[1]
        for line in (tmp_path / "site" / "index.md").read_text(encoding="utf-8").splitlines()
        if line.startswith("| [`worker[")
    }
    assert rows == {
        "| [`worker[1]/a`](#agent-worker-1-a)": "`fleetRobot/r`",
        "| [`worker[2]/a`](#agent-worker-2-a)": "`fleetRobot/r`",
        "| [`worker[3]/a`](#agent-worker-3-a)": "no robot",
    }


def test_a_finding_about_a_robot_links_to_where_the_robots_are_named(tmp_path: Path) -> None:
    spec = tmp_path / "robot.earl"
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace("    grip/a\n    link task,manip", "    link task,manip")
    )
    site = tmp_path / "site"
    assert main(["doc", str(spec), "-o", str(site)]) == 1  # the document is written; the errors fail the command
    rows = [line for line in (site / "index.md").read_text(encoding="utf-8").splitlines() if "`EARL-E004`" in line]
    assert rows and all("[`manipulationRobot/r`](#system)" in row for row in rows)


def test_the_agents_table_names_every_robot_a_family_drawn_once_belongs_to(tmp_path: Path) -> None:
    spec = tmp_path / "system.earl"
    fleet = (Path(__file__).parent / "doc_specs" / "fleet" / "system.earl").read_text(encoding="utf-8")
    assert "    worker[2]/a\n}\n" in fleet
    spec.write_text(fleet.replace("    worker[2]/a\n}\n", "    worker[2]/a\n}\n\notherRobot/r {\n    worker[3]/a\n}\n"))
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 0
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    row = (
        "| [`worker[K]/a`](#agent-worker-K-a) | `fleetRobot/r (worker[1]/a, worker[2]/a), otherRobot/r (worker[3]/a)` |"
    )
    assert row in markdown


def test_the_agents_table_says_which_members_of_a_family_drawn_once_are_in_no_robot(tmp_path: Path) -> None:
    """fleet's robot lists `worker[1]/a` and `worker[2]/a` only: the family's row must not put all of
    `worker[K]/a` in fleetRobot/r."""
    spec = Path(__file__).parent / "doc_specs" / "fleet" / "system.earl"
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 0
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    row = "| [`worker[K]/a`](#agent-worker-K-a) | `fleetRobot/r (worker[1]/a, worker[2]/a), no robot (worker[3]/a)` |"
    assert row in markdown


def _summary(spec: Path, site: Path, *options: str) -> str:
    """The overview's first paragraph: how many agents, which robot holds which, how many links."""
    assert main(["doc", str(spec), *options, "-o", str(site)]) in (0, 1)
    lines = (site / "index.md").read_text(encoding="utf-8").splitlines()
    return lines[lines.index("## System " + lines[0].split(":")[0].removeprefix("# ")) + 2]


def test_the_summary_says_which_robot_holds_which_agent(tmp_path: Path) -> None:
    """mobile_robot's coordinator/a belongs to no robot: the overview must not put both agents in
    mobileRobot/r."""
    summary = _summary(ROOT / "examples" / "mobile_robot" / "system.earl", tmp_path / "mobile")
    assert summary.startswith(
        "2 agents. mobileRobot/r holds base/a; coordinator/a belongs to no robot. 2 inter-agent links. "
    )


def test_the_summary_counts_members_of_agent_and_link_families(tmp_path: Path) -> None:
    """fleet: `worker[K in 1..3]/a`, members 1 and 2 in fleetRobot/r, and two link families of three
    links each; declared and concrete counts are both said, and member 3 is in no robot."""
    spec = Path(__file__).parent / "doc_specs" / "fleet" / "system.earl"
    assert _summary(spec, tmp_path / "declared").startswith(
        "2 agents (4 once the family worker[K]/a is expanded). fleetRobot/r holds boss/a, worker[1]/a and "
        "worker[2]/a; worker[3]/a belongs to no robot. 2 inter-agent links declared, 2 of them link families: "
        "6 once expanded. "
    )
    assert _summary(spec, tmp_path / "expanded", "--expand").startswith(
        "4 agents. fleetRobot/r holds boss/a, worker[1]/a and worker[2]/a; worker[3]/a belongs to no robot. "
        "6 inter-agent links. "
    )
    # members named by a range are several: they belong, not belongs
    assert "; worker[3..5]/a belong to no robot." in _summary(spec, tmp_path / "five", "--param", "N=5")


MEMBER_ONLY_LINKS = """\
system members

arm/a {
    cs {
        period 2 ms
        cmd[K in 1..3]/ob: double
        special/ob: double
        extra/ib: double
    }

    mc[K in 1..3]/ve {
        period 1 ms
        command/ib: double
        boost/ib: double
        current/ob: double
    }

    link cs,mc[K in 1..3]: cs.cmd[K] -> mc[K]/ve.command
    link cs,mcBoost[2]: cs.special -> mc[2]/ve.boost
    link mc[3],csExtra: mc[3]/ve.current -> cs.extra
}
"""


def test_the_buffers_table_says_which_member_a_link_reaches_with_its_real_name(tmp_path: Path) -> None:
    """Drawn once, `mc[K]/ve` has one row per buffer, but `cs,mcBoost[2]` feeds only mc[2]'s boost and
    `mc[3],csExtra` leaves only mc[3]: the rows name the links as declared and the member they reach,
    not `(cs,mc)` as if every member were linked."""
    spec = tmp_path / "system.earl"
    spec.write_text(MEMBER_ONLY_LINKS, encoding="utf-8")
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) in (0, 1)  # warnings only
    rows = {
        line.split("</a>`")[1].split("`")[0]: line.rsplit(" | ", 1)[1]
        for line in (tmp_path / "site" / "index.md").read_text(encoding="utf-8").splitlines()
        if line.startswith('| <a id="ib-') or line.startswith('| <a id="ob-')
    }
    assert rows["boost/ib"] == "← [`arm/a.cs.special/ob`](#ob-arm-a-cs-special) (cs,mcBoost[2], into mc[2]/ve.boost) |"
    assert rows["special/ob"] == "→ [`arm/a.mc[2]/ve.boost/ib`](#ib-arm-a-mc-K-ve-boost) (cs,mcBoost[2]) |"
    assert rows["current/ob"] == "→ [`arm/a.cs.extra/ib`](#ib-arm-a-cs-extra) (mc[3],csExtra, from mc[3]/ve.current) |"
    assert rows["extra/ib"] == "← [`arm/a.mc[3]/ve.current/ob`](#ob-arm-a-mc-K-ve-current) (mc[3],csExtra) |"
    assert rows["command/ib"] == "← [`arm/a.cs.cmd[K]/ob`](#ob-arm-a-cs-cmd-K) (cs,mc[K]) |"


TWO_WAYS = """\
system dup

a1/a {
    cs {
        period 10 ms
        c/m: int = 0
        lo/pp = c/mi < 3
        hi/pp = c/mi > 5
        b1/bb {
            tf = {}
            tc = lo/pp or hi/pp
        }
        fsm {
            initial one
            state one: b1/bb
            state two: b1/bb
            one -> two when lo/pp priority 1
            one -> two when hi/pp priority 2
            two -> one when lo/pp priority 1
        }
    }
}
"""


def test_two_transitions_between_the_same_states_get_distinct_anchors(tmp_path: Path) -> None:
    """`one -> two when lo/pp` and `one -> two when hi/pp` are both valid and both named `one,two`:
    each row of Table 5 has its own id, in the HTML and in the Markdown, and every link still resolves."""
    system = earl.loads(TWO_WAYS, "dup.earl")
    result = write_site(Subject(system), check(system), tmp_path)
    page = _Page()
    page.feed(result.html.read_text(encoding="utf-8"))  # refuses a duplicate id
    assert {"t-a1-a-cs-one-two", "t-a1-a-cs-one-two-2"} <= page.ids
    assert sorted(set(page.links) - page.ids) == []
    ids = re.findall(r'<a id="([^"]+)"></a>', (tmp_path / "index.md").read_text(encoding="utf-8"))
    assert len(ids) == len(set(ids))


ENTITIES = """\
system esc

a1/a {
    cs {
        period 10 ms
        s/m: string = "<&>"
        c/m: int = 0
        b1/bb {
            tf = {}
            tc = c/mi < 3 and s/mi != "&amp;<x>"
        }
        fsm {
            initial one
            state one: b1/bb
            state two: b1/bb
            one -> two when c/mi < 3 and s/mi != "&lt;" priority 1
        }
    }
}
"""


def test_markdown_and_mermaid_show_ampersands_and_entities_as_written(tmp_path: Path) -> None:
    """A spec's strings `"&amp;<x>"` and `"&lt;"` are shown as written: index.md read as GitHub reads it
    says in its findings and tables what index.html says, and Mermaid does not turn `&lt;` into `<`."""
    from markdown_it import MarkdownIt

    system = earl.loads(ENTITIES, "esc.earl")
    diagnostics = check(system)
    findings = [d.message for d in diagnostics if '"&amp;<x>"' in d.message]
    assert findings  # the checker quotes the strings in a finding, which goes into a bullet list
    write_site(Subject(system), diagnostics, tmp_path)
    page = (tmp_path / "index.html").read_text(encoding="utf-8")
    read = MarkdownIt("commonmark").enable("table").render((tmp_path / "index.md").read_text(encoding="utf-8"))
    assert _markdown_cells_missing_from_the_html(tmp_path) == []
    shown, written = _Cells(("li",)), _Cells(("li",))
    shown.feed(page)
    written.feed(read)
    assert written.cells == shown.cells
    assert any('"&amp;<x>"' in item for item in written.cells)
    assert any('"&amp;<x>"' in cell for cell in _cells(read))
    mermaid = mermaid_of(Subject(system), "fsm", None)
    assert "&lt;" not in mermaid and "#38;lt;" in mermaid


class _Rows(HTMLParser):
    """The rows of one table of an HTML page (by its id), each a list of its cells' text, spaces collapsed."""

    def __init__(self, table: str) -> None:
        super().__init__()
        self.table = table
        self.rows: list[list[str]] = []
        self.caption = ""
        self._depth = 0  # inside the table: how many tables deep
        self._text: list[str] | None = None
        self._in_caption = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "table" and (self._depth or dict(attrs).get("id") == self.table):
            self._depth += 1
        elif self._depth and tag == "tr":
            self.rows.append([])
        elif self._depth and tag in ("td", "th"):
            self._text = []
        elif self._depth and tag == "caption":
            self._in_caption = True

    def handle_endtag(self, tag: str) -> None:
        if tag == "table" and self._depth:
            self._depth -= 1
        elif tag in ("td", "th") and self._text is not None:
            self.rows[-1].append(" ".join("".join(self._text).split()))
            self._text = None
        elif tag == "caption":
            self._in_caption = False

    def handle_data(self, data: str) -> None:
        if self._text is not None:
            self._text.append(data)
        elif self._in_caption:
            self.caption += data


def _table(html: str, table: str) -> list[list[str]]:
    parser = _Rows(table)
    parser.feed(html)
    assert parser.rows, f"no table {table}"
    return parser.rows


def test_the_document_tabulates_parameters_with_their_values_and_where_they_were_given(tmp_path: Path) -> None:
    """`N=6`, `WHEELS=2` and agents' and subsystems' parameters appeared nowhere, and `--param N=3` was not
    recorded: the system, each agent and each subsystem with parameters get a table of them (type, value,
    what the spec computes it from, the spec's line or the --param that gave it, a person's comment), and
    the subtitle names the --param options."""
    assert main(["doc", str(EXAMPLE), "--param", "N=3", "-o", str(tmp_path / "pp")]) == 0
    html = (tmp_path / "pp" / "index.html").read_text(encoding="utf-8")
    assert "(indexed families drawn once; --param N=3)" in html
    rows = _table(html, "parameters")
    assert rows[0] == ["parameter", "type", "value", "given by", "comment"]
    assert rows[1][:4] == ["N", "int", "3", "--param N=3"]
    assert "The manipulator has N joints" in rows[1][4]
    joint = _table(html, "parameters-manip-a-motorController-K-ve")
    assert joint[1][:3] == ["joint", "int", "K: 1 (K = 1), 2 (K = 2), 3 (K = 3)"]
    assert re.fullmatch(r"spec, system\.earl:\d+", joint[1][3])

    mobile = ROOT / "examples" / "mobile_robot" / "system.earl"
    assert main(["doc", str(mobile), "-o", str(tmp_path / "mr")]) == 0
    html = (tmp_path / "mr" / "index.html").read_text(encoding="utf-8")
    system = {row[0]: row for row in _table(html, "parameters")[1:]}
    assert system["WHEELS"][1:3] == ["int", "2"] and system["WHEELS"][3].startswith("spec, system.earl:")
    base = {row[0]: row for row in _table(html, "parameters-base-a")[1:]}
    assert base["TRACK_WIDTH"][1:3] == ["double", "0.42"]
    cs = {row[0]: row for row in _table(html, "parameters-base-a-cs")[1:]}
    assert cs["STANDSTILL"][2] == "0.05" and "rad/s" in cs["STANDSTILL"][4]
    # a parameter named in an expression links to its row: the innermost one of that name
    assert '<a href="#parameters-base-a-cs-STANDSTILL">STANDSTILL</a>' in html
    assert '<a href="#parameters-WHEELS">WHEELS</a>' in html
    page = _Page()
    page.feed(html)
    assert sorted(set(page.links) - page.ids) == []
    markdown = (tmp_path / "mr" / "index.md").read_text(encoding="utf-8")
    assert "Parameters of the system mobileRobot" in markdown and "`WHEELS` | `int` | `2` | spec" in markdown


def test_a_document_of_a_broken_spec_says_so_at_the_top_and_lists_errors_first(tmp_path: Path) -> None:
    """`earl doc` of a spec with errors exits 1, but its title area said nothing: the errors were listed
    only at the end, after notes.  Under the subtitle it now says how many errors and warnings there are,
    linked to the check results, which list errors, then warnings, then notes."""
    spec = tmp_path / "broken.earl"
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace(
            "    link cs,fingerController:", "    sparePart/ve {\n    }\n\n    link cs,fingerController:"
        ),
        encoding="utf-8",
    )
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) == 1
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    findings = check(earl.load(spec))
    errors = sum(1 for d in findings if d.severity.value == "error")
    warnings = sum(1 for d in findings if d.severity.value == "warning")
    assert errors and any(d.severity.value == "note" for d in findings)
    said = re.search(r'<p class="notice error" id="check-summary">(.*?)</p>', html)
    assert said is not None and html.index("check-summary") < html.index('<section id="system">')
    many = f"{errors} error{'s' if errors > 1 else ''}" + (
        f" and {warnings} warning{'s' if warnings > 1 else ''}" if warnings else ""
    )
    assert said.group(1).startswith(f"earl check found {many}. The specification breaks rules")
    assert '<a href="#check">' in said.group(1)
    severities = [row[0] for row in _table(html, "findings")[1:]]
    assert severities == sorted(severities, key=["error", "warning", "note"].index)
    assert severities[-1] == "note"
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    assert f"> **earl check found {many}." in markdown.split("## ")[0]

    assert main(["doc", str(EXAMPLE), "-o", str(tmp_path / "clean")]) == 0
    assert "check-summary" not in (tmp_path / "clean" / "index.html").read_text(encoding="utf-8")


def test_the_buffers_table_says_what_an_input_buffer_with_a_fifo_keeps(tmp_path: Path) -> None:
    """`goal/ib: NavigationGoal fifo 4 overflow dropOldest` (mobile_robot) was shown as a plain buffer:
    capacity and overflow policy were nowhere in the document.  A subsystem with a FIFO gets a column
    saying what each Input Buffer keeps; a capacity naming a parameter is given with its value."""
    mobile = ROOT / "examples" / "mobile_robot" / "system.earl"
    assert main(["doc", str(mobile), "-o", str(tmp_path / "mr")]) == 0
    html = (tmp_path / "mr" / "index.html").read_text(encoding="utf-8")
    rows = {row[0]: row for row in _table_by_caption(html, "Input and Output Buffers of base/a.cs")}
    assert rows["buffer"][:3] == ["buffer", "dataType", "keeps"]
    assert rows["goal/ib"][2] == "a FIFO of 4 messages; when full: dropOldest"
    assert rows["obstacles/ib"][2] == "the latest message" and rows["status/ob"][2] == "—"

    spec = tmp_path / "queued" / "system.earl"
    spec.parent.mkdir()
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8").replace(
            "manipulatorCommand/ib: ManipulatorCommand",
            "manipulatorCommand/ib: ManipulatorCommand fifo N overflow fault",
        ),
        encoding="utf-8",
    )
    assert main(["doc", str(spec), "--param", "N=3", "-o", str(tmp_path / "pp")]) == 0
    html = (tmp_path / "pp" / "index.html").read_text(encoding="utf-8")
    rows = {row[0]: row for row in _table_by_caption(html, "Input and Output Buffers of manip/a.cs")}
    assert rows["manipulatorCommand/ib"][2] == "a FIFO of N = 3 messages; when full: fault"
    # a subsystem without a FIFO keeps its three columns
    assert _table_by_caption(html, "Input and Output Buffers of task/a.cs")[0] == ["buffer", "dataType", "linked with"]


def _table_by_caption(html: str, caption: str) -> list[list[str]]:
    """The rows of the table whose caption is `caption`."""
    for found in re.finditer(r"<table[^>]*>(.*?)</table>", html, re.DOTALL):
        if re.search(r"<caption>" + re.escape(caption) + r"[<]", found.group(0)):
            parser = _Rows("wanted")
            parser.feed(found.group(0).replace("<table", '<table id="wanted"', 1))
            return parser.rows
    raise AssertionError(f"no table captioned {caption}")


@pytest.mark.parametrize("expand", [False, True])
def test_the_comments_of_the_spec_are_shown_with_their_elements(tmp_path: Path, expand: bool) -> None:
    """Comments giving units and explanations ("radians (counter-clockwise from x)", "metres to the goal")
    were in the SysML export but nowhere in the document.  A table of elements of which any has one gets
    a comment column, a struct's field has its comment after it, and an agent's, a subsystem's and the
    system's are said in their sections; an expanded document finds them too (expansion keeps where an
    element was written, not its comments)."""
    options = ["--expand"] if expand else []
    mobile = ROOT / "examples" / "mobile_robot" / "system.earl"
    assert main(["doc", str(mobile), *options, "-o", str(tmp_path / "mr")]) == 0
    html = (tmp_path / "mr" / "index.html").read_text(encoding="utf-8")
    types = {row[0]: row for row in _table_by_caption(html, "Data types of the specification")}
    assert types["dataType"] == ["dataType", "definition", "comment"]
    assert types["Pose2D"][2].startswith("A pose in the plane of the floor: metres, metres, radians")
    memory = {row[0]: row for row in _table_by_caption(html, "Table 3: base/a.cs.m dataTypes")}
    assert memory["goalWayClear/m"][3].startswith("written by avoid/pf")
    assert memory["velocity/m"][3] == ""
    caption = "Table 5: initial conditions labelling base/a.cs.fsm transitions and terminal conditions of base/a.cs.bb"
    conditions = {row[0]: row for row in _table_by_caption(html, caption)}
    assert conditions["drive,avoidObstacle/t"][3].startswith("An obstacle outranks a new goal")
    assert conditions["avoidObstacle,idle/t"][3] == "a cancel outranks a clear path"
    assert conditions["start/bb"][3].startswith("Within each first stage")

    warehouse = Path(__file__).parent / "doc_specs" / "warehouse" / "system.earl"
    assert main(["doc", str(warehouse), *options, "-o", str(tmp_path / "wh")]) in (0, 1)
    html = (tmp_path / "wh" / "index.html").read_text(encoding="utf-8")
    types = {row[0]: row for row in _table_by_caption(html, "Data types of the specification")}
    assert "remaining: double (metres to the goal)" in types["Report"][1]
    assert types["Order"][2] == "An order for one worker: where to go."


def test_table_5_tells_apart_two_transitions_between_the_same_states(tmp_path: Path) -> None:
    """Table 5 named `dispatching,waiting/t` twice alike: each of two transitions between the same states
    has its number among them and its line (as `earl check` names it), one alone its name only."""
    spec = Path(__file__).parent / "doc_specs" / "warehouse" / "system.earl"
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) in (0, 1)
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    caption = "Table 5: initial conditions labelling supervisor/a.cs.fsm transitions"
    names = [row[0] for row in _table_by_caption(html, caption + " and terminal conditions of supervisor/a.cs.bb")]
    lines = [
        number
        for number, line in enumerate(spec.read_text(encoding="utf-8").splitlines(), start=1)
        if line.strip().startswith("dispatching -> waiting")
    ]
    assert names[1:6] == [
        "dispatching,stopped/t",
        f"dispatching,waiting/t #1 (line {lines[0]})",
        f"dispatching,waiting/t #2 (line {lines[1]})",
        "waiting,dispatching/t",
        "waiting,stopped/t",
    ]


def test_table_6_lists_a_behaviour_whose_transition_function_is_empty(tmp_path: Path) -> None:
    """`nothing/bb { tf = {} … }` was left out of Table 6 without a word: it has a row saying it has no stage."""
    spec = Path(__file__).parent / "doc_specs" / "edge" / "system.earl"
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) in (0, 1)
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    rows = _table(html, "table6-solo-a-cs")
    assert rows[2] == ["nothing/bb", "no stage: its transition function is empty (tf = {})"]
    assert [row[0] for row in rows[3:]] == ["three/bb", "f2/pf", "f3/pf"]
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    assert "| no stage: its transition function is empty (`tf = {}`) |" in markdown


def test_a_family_of_agents_is_introduced_as_a_family_of_subsystems_is(tmp_path: Path) -> None:
    """`worker[I in 1..M]/a`'s section lacked the "An indexed family, drawn once: …" sentence that a family
    of subsystems has; it now opens with it, saying how many agents it stands for."""
    spec = Path(__file__).parent / "doc_specs" / "warehouse" / "system.earl"
    assert main(["doc", str(spec), "-o", str(tmp_path / "site")]) in (0, 1)
    markdown = (tmp_path / "site" / "index.md").read_text(encoding="utf-8")
    section = markdown.split("## Agent `worker[I]/a`", 1)[1]
    first = section.strip().splitlines()[0]
    assert first.startswith("An indexed family, drawn once: worker[I]/a for I ∈ 1..M (3 agents). Type ")
    assert (
        "An indexed family" not in markdown.split("## Agent `supervisor/a`", 1)[1].split("## Agent")[0].split("###")[0]
    )


def test_a_finding_links_to_the_row_of_the_element_it_is_about(tmp_path: Path) -> None:
    """Check results linked to the subsystem's section where the element has a row of its own: W044 about
    `lost/pp` links to its row of Table 4, W062 about the second `n,t/t` to its row of Table 5, I063 about
    `stop/bb` to its row; the subsystem's section still lists them."""
    warehouse = Path(__file__).parent / "doc_specs" / "warehouse" / "system.earl"
    assert main(["doc", str(warehouse), "-o", str(tmp_path / "wh")]) in (0, 1)
    html = (tmp_path / "wh" / "index.html").read_text(encoding="utf-8")
    rows = _table(html, "findings")[1:]

    def where(rule: str, message: str) -> str:
        [found] = [row[2] for row in rows if row[1] == rule and row[3].startswith(message)]
        return found

    assert where("EARL-W044", "timeout(report[1]/ib) in lost/pp").startswith("supervisor/a.cs.lost/pp (")
    assert where("EARL-I063", "stop/bb never ends").startswith("supervisor/a.cs.stop/bb (")
    assert '<a href="#pp-supervisor-a-cs-lost"><code>' in html and 'id="pp-supervisor-a-cs-lost"' in html
    section = html.split('<section id="ss-supervisor-a-cs">', 1)[1].split("<table", 1)[0]
    assert "EARL-W044" in section and "EARL-I063" in section  # listed in the subsystem's section too
    page = _Page()
    page.feed(html)
    assert sorted(set(page.links) - page.ids) == []

    edge = Path(__file__).parent / "doc_specs" / "edge" / "system.earl"
    assert main(["doc", str(edge), "-o", str(tmp_path / "edge")]) in (0, 1)
    html = (tmp_path / "edge" / "index.html").read_text(encoding="utf-8")
    assert re.search(r'<td class="rule"><code>EARL-W062</code></td><td><a href="#t-solo-a-cs-n-t-2">', html)
    assert 'id="t-solo-a-cs-n-t-2"' in html


#: For each text of an SVG's nodes and of the frame's name tab: how far its visible glyphs (the spaces
#: padding it left out) stay inside the box around it, in px (negative: it runs over the border); and for
#: each stage of an activity, how far left of its label's glyphs the control flow runs past it.
_TEXT_FIT = """(() => {
  const visible = t => {
    const s = t.textContent; let a = 0, b = s.length - 1;
    while (a <= b && /\\s/.test(s[a])) a++;
    while (b >= a && /\\s/.test(s[b])) b--;
    if (a > b) return null;
    const first = t.getExtentOfChar(a), last = t.getExtentOfChar(b);
    return [first.x, last.x + last.width];
  };
  const fits = [], stages = [];
  document.querySelectorAll('g.node, g.cluster').forEach(g => {
    const title = g.querySelector('title').textContent;
    const shapes = [...g.querySelectorAll(':scope polygon, :scope path')].map(s => s.getBBox());
    g.querySelectorAll('text').forEach(t => {
      const span = visible(t); if (!span) return;
      const box = t.getBBox(); const y = box.y + box.height / 2;
      // the smallest shape around the text's middle: a node's border, the frame's name tab
      const around = shapes.filter(b => b.y <= y && y <= b.y + b.height && b.x <= span[0] + 1
                                        && span[1] - 1 <= b.x + b.width + 40)
                           .sort((p, q) => p.width - q.width)[0];
      if (!around) return;
      if (title.startsWith('cluster_stage')) {
        // how far right of the label each edge passing at its height runs (negative: through it)
        const clear = [...document.querySelectorAll('g.edge path')].map(e => e.getBBox())
          .filter(e => e.y <= box.y + box.height && box.y <= e.y + e.height && e.x + e.width >= span[0])
          .map(e => e.x - span[1]);
        stages.push([t.textContent.trim(), +Math.min(99, ...clear).toFixed(1)]);
      } else {
        fits.push([title, t.textContent.trim(),
                   +Math.min(span[0] - around.x, around.x + around.width - span[1]).toFixed(1)]);
      }
    });
  });
  return {fits, stages};
})()"""


def test_the_text_of_activity_diagrams_stays_inside_its_borders(site: Path, tmp_path: Path) -> None:
    """Bold action names (`outputManipState/pf`, `sendManipulatorCommand/pf`) touched or overran their
    border, the `)` of a frame's name tab ran over the tab (13 diagrams), and the control flow struck
    through `stage 1` in a narrow stage: dot measures the text narrower than a browser draws it.  Drawn
    by Chromium, every glyph is now at least 1.5 px inside its border and every stage's label left of
    the control flow."""
    sync_api, executable = _chromium()
    edge = Path(__file__).parent / "doc_specs" / "edge" / "system.earl"  # `three/bb`: stages of one `f1/pf`
    assert main(["doc", str(edge), "-o", str(tmp_path / "edge")]) in (0, 1)
    diagrams = [
        *sorted((site / "diagrams").glob("act-*.svg")),
        tmp_path / "edge" / "diagrams" / "act-solo-a-cs-three.svg",
    ]
    assert len(diagrams) > 10
    crowded: list[tuple[str, str, str, float]] = []
    struck: list[tuple[str, str, float]] = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=["--no-sandbox"])
        try:
            page = browser.new_page()
            for diagram in diagrams:
                page.goto(diagram.as_uri(), wait_until="load")
                found = page.evaluate(_TEXT_FIT)
                crowded += [(diagram.name, title, said, gap) for title, said, gap in found["fits"] if gap < 1.5]
                struck += [(diagram.name, label, gap) for label, gap in found["stages"] if gap < 2]
                assert any(title == "cluster_frame" for title, _, _ in found["fits"])
        finally:
            browser.close()
    assert crowded == []
    assert struck == []


def test_table_1_and_the_links_table_say_what_they_count_and_where_each_belongs(tmp_path: Path) -> None:
    """Table 1's caption said "counts of one member for a family" beside manip/a's |ve| 6 (a family of
    subsystems counts every member); its robot column said "—" for an agent in no robot but "no robot (…)"
    for a family's members; a robot's `link` references were shown nowhere; and Table 4 broke a line
    between a unary minus and its operand (`> -` / `STANDSTILL`)."""
    assert main(["doc", str(EXAMPLE), "-o", str(tmp_path / "pp")]) == 0
    html = (tmp_path / "pp" / "index.html").read_text(encoding="utf-8")
    agents = {row[0]: row for row in _table(html, "agents")}
    assert agents["manip/a"][5] == "6"  # |ve|: motorController[K in 1..N]/ve, N = 6
    caption = _Rows("agents")
    caption.feed(html)
    assert "a family of subsystems or links counts every member" in caption.caption
    links = _table(html, "links")
    assert links[0][-1] == "robot" and {row[-1] for row in links[1:]} == {"manipulationRobot/r"}

    mobile = ROOT / "examples" / "mobile_robot" / "system.earl"
    assert main(["doc", str(mobile), "-o", str(tmp_path / "mr")]) == 0
    html = (tmp_path / "mr" / "index.html").read_text(encoding="utf-8")
    agents = {row[0]: row for row in _table(html, "agents")}
    assert agents["coordinator/a"][1] == "no robot" and agents["base/a"][1] == "mobileRobot/r"
    assert "robot" not in _table(html, "links")[0]  # no robot lists a link: no robot column
    negated = '<span class="whole">-<a href="#parameters-base-a-cs-STANDSTILL">STANDSTILL</a></span>'
    assert negated in html and ".whole { white-space: nowrap; }" in html.replace("td.rule, ", "")


def test_a_computed_double_is_shown_without_the_noise_of_binary_arithmetic(tmp_path: Path) -> None:
    """`param STATION: double = 0.4 + 0.3 * K` showed `1.2999999999999998 (K = 3)` in its parameters table:
    a computed double is rounded to 12 significant digits and written in its shortest form."""
    sorter = ROOT / "tests" / "runtime_specs" / "sorter"
    assert main(["doc", str(sorter), "-o", str(tmp_path / "site")]) in (0, 1)
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    row = re.search(r'id="[^"]*-STATION">.*?</tr>', html)
    assert row is not None
    said = re.sub(r"<[^>]+>", "", row.group())
    assert "0.7 (K = 1), 1.0 (K = 2), 1.3 (K = 3)" in said and "99999" not in said


def test_a_comment_heading_a_group_of_declarations_is_a_caption_of_their_rows(site: Path, tmp_path: Path) -> None:
    """`// Table 3: manip/a.cs.m`, written above five memories, was shown as motionFinished/m's comment, and
    `// §3.2: the partial transition functions; …` began calculatePosition/pf's.  A comment block that a
    blank line parts from the declaration heads the rows from it on and is a caption row across the table;
    a row's own comment is the block right above its declaration and the one on its line."""
    html = (site / "index.html").read_text(encoding="utf-8")
    memory = _table_by_caption(html, "Table 3: manip/a.cs.m dataTypes")
    assert memory[:3] == [
        ["m", "dataType", "initial value"],  # no row has a comment of its own: no comment column
        ["Table 3: manip/a.cs.m"],
        ["motionFinished/m", "boolean", "true"],
    ]
    predicates = _table_by_caption(html, "Table 4: definitions of manip/a.cs.pp.fun")
    assert predicates[1] == ["Table 4: manip/a.cs.pp.fun"] and predicates[2][0] == "emergencyStop/pp"
    assert "Table 4" not in "".join(predicates[2])
    functions = _table_by_caption(html, "Partial transition functions of manip/a.cs (§2.2, Figure 6; Eq. 4 and 6)")
    assert functions[1] == ["§3.2: the partial transition functions; Table 6 says what each writes."]
    assert functions[2][0] == "calculatePosition/pf"
    assert functions[2][-1] == "calculates manipulator joint positions and the end-effector's operational space pose"
    assert '<td colspan="6" class="group"><div>§3.2: the partial transition functions;' in html

    mobile = ROOT / "examples" / "mobile_robot"
    assert main(["doc", str(mobile), "-o", str(tmp_path / "mr")]) == 0
    html = (tmp_path / "mr" / "index.html").read_text(encoding="utf-8")
    rows = _table_by_caption(html, "Partial transition functions of base/a.cs (§2.2, Figure 6; Eq. 4 and 6)")
    named = {row[0]: row for row in rows}
    assert named["initialise/pf"][-1] == "The odometry origin is wherever the base is switched on."
    assert named["outputWheelCommands/pf"][-1] == "Inverse kinematics: desiredTwist to one angular velocity per wheel."
    assert [row[0] for row in rows if len(row) == 1] == [
        "First stage, Eq. (4): read input buffers (and memory), write memory only.",
        "Second stage, Eq. (6): read memory only, compose the output buffers.",
    ]
    memory = _table_by_caption(html, "Table 3: base/a.cs.m dataTypes")
    assert memory[1][0].startswith("Eq. (5) for this subsystem") and memory[2][:2] == ["pose/m", "Pose2D"]
    assert memory[2][-1] == ""  # pose/m has no comment of its own; goalWayClear/m has
    parameters = _table(html, "parameters-base-a-cs")
    assert parameters[1][0].startswith("Distances in metres.") and len(parameters[1]) == 1
    assert parameters[2][0] == "STOP_DISTANCE" and parameters[2][-1] == ""
    # the comment types.earl opens with is the file's, not a heading of the parameters
    assert all(len(row) > 1 for row in _table(html, "parameters"))

    # without the blank line, the block right above is the declaration's own, and so is one on its line
    spec = tmp_path / "tight" / "system.earl"
    spec.parent.mkdir()
    spec.write_text(
        EXAMPLE.read_text(encoding="utf-8")
        .replace(
            "// Table 3: manip/a.cs.m\n\n        motionFinished/m: boolean = true\n",
            "// Table 3: manip/a.cs.m\n        motionFinished/m: boolean = true\n"
            "        currentOperationalPos/m: OperPosition  // from calculatePosition/pf\n",
        )
        .replace("        currentOperationalPos/m: OperPosition\n        currentJointPos", "        currentJointPos"),
        encoding="utf-8",
    )
    assert main(["doc", str(spec), "-o", str(tmp_path / "tight-site")]) == 0
    html = (tmp_path / "tight-site" / "index.html").read_text(encoding="utf-8")
    memory = _table_by_caption(html, "Table 3: manip/a.cs.m dataTypes")
    assert memory[1] == ["motionFinished/m", "boolean", "true", "Table 3: manip/a.cs.m"]
    assert memory[2] == ["currentOperationalPos/m", "OperPosition", "—", "from calculatePosition/pf"]
