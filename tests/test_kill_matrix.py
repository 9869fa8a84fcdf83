"""The kill matrix reads survey runs right: each cell's state, the checks that kill nothing on their own
(flagged unless a reason is written), and the mistakes only one check kills."""

from __future__ import annotations

from conformance.discrimination import kill_matrix
from conformance.discrimination.verdicts import Outcome


def _record(check, outcome="passed", scene="chain", message="", kinds=None, module="test_vertices.py"):
    return {"check": check, "scene": scene, "outcome": outcome, "message": message, "kinds": kinds or {},
            "nodeid": f"conformance/{module}::{check}[{scene}]"}


OUTCOMES = [
    Outcome("w:Late", 1, [_record("test_a", "failed"), _record("test_b", "failed"), _record("test_c"),
                          _record("test_engine_defaults", module="test_materials.py")]),
    Outcome("w:Lonely", 1, [_record("test_a"), _record("test_b", "failed"), _record("test_c")]),
    Outcome("w:Crash", 1, [_record("test_a", "failed", kinds={"crashed": {}}), _record("test_b"),
                           _record("test_c", "failed", message="sync implementation 'x' did not return within 10 s")]),
]


def test_each_cell_is_a_mutant_state():
    checks, cells = kill_matrix.matrix(OUTCOMES)
    assert checks == ["test_a", "test_b", "test_c", "test_engine_defaults"]
    assert cells["w:Late"] == {"test_a": "killed", "test_b": "killed", "test_c": "survived", "test_engine_defaults": "survived"}
    assert cells["w:Crash"]["test_a"] == "crashed" and cells["w:Crash"]["test_c"] == "timed out"
    assert cells["w:Lonely"]["test_engine_defaults"] == "not run"


def test_idle_checks_and_single_points_are_listed():
    checks, cells = kill_matrix.matrix(OUTCOMES)
    assert kill_matrix.useless_checks(checks, cells) == ["test_c", "test_engine_defaults"]
    assert kill_matrix.single_points(checks, cells) == {"w:Lonely": "test_b"}
    text = kill_matrix.markdown(OUTCOMES)
    assert "| `w:Late` | ✕ | ✕ | · | · | 2 |" in text, text
    assert "- `test_c`: **no reason written: strengthen it or say why it stays**" in text, text
    assert "- `test_engine_defaults`: judges pyBullet's integrator" in text, text
    assert "- `w:Lonely`: only `test_b`" in text, text


def test_the_command_writes_the_matrix_with_the_command_that_made_it(tmp_path, monkeypatch):
    from conformance import cli
    from conformance.discrimination import verdicts

    monkeypatch.setattr(verdicts, "implementations", lambda module: [f"{module}:A"])
    monkeypatch.setattr(verdicts, "what_it_is", lambda spec: spec)
    monkeypatch.setattr(verdicts, "check_all", lambda specs, **kwargs: [
        Outcome(s, 1 if "wrong" in s else 0, [_record("test_a", "failed" if "wrong" in s else "passed")]) for s in specs])
    out = tmp_path / "matrix.md"
    status = cli.main(["kill-rate", "--wrong", "wrong_mod", "--right", "right_mod", "--matrix", str(out), "--", "-k", "chain"])
    assert status == 0
    text = out.read_text(encoding="utf-8")
    assert f"Made by `python -m conformance kill-rate --wrong wrong_mod --right right_mod --matrix {out} -- -k chain`" in text
    assert "| `wrong_mod:A` | ✕ | 1 |" in text, text
