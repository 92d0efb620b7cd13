from pathlib import Path

import earl


def test_load_and_format_round_trip(tmp_path: Path) -> None:
    spec = tmp_path / "s.earl"
    spec.write_text("system demo\n\nparam N: int = 2\n")
    system = earl.load(spec)
    assert system.name == "demo"
    assert system.parameters[0].name == "N"
    assert earl.loads(system.to_earl(), str(spec)) == system
