"""``app-table``: example apps state what the kit must answer (``EXPECT:``), and the table says whether it did.

The example set itself (``examples/``) is run by ``tests/test_examples.py``; here, the parsing of the
lines, their errors, and that a disagreement of the kit with an example is reported and fails the command."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conformance import backends
from conformance.apps import examples
from conformance.errors import ConformanceError

APP = Path(__file__).parent / "apps" / f"box_{backends.NAME}.py"
SOURCE = APP.read_text(encoding="utf-8")
STEP = "    p.stepSimulation()\n"


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _with_expect(lines: str) -> str:
    return SOURCE.replace("EXPECT: pass", lines, 1)


@pytest.mark.parametrize("lines, expected", [
    ("EXPECT: pass", examples.Expectation(True)),
    ("MISTAKE: late\nEXPECT: fail attached previous-step", examples.Expectation(False, "attached", "previous-step", "late")),
    ("EXPECT: fail perturbed euler-order", examples.Expectation(False, "perturbed", "euler-order")),
    ("EXPECT: fail drawn -", examples.Expectation(False, "drawn", "-")),
    ("EXPECT: fail runs", examples.Expectation(False, "runs", None)),
])
def test_expect_lines_are_read(tmp_path, lines, expected):
    assert examples.expectation(_write(tmp_path / "app.py", _with_expect(lines))) == expected


@pytest.mark.parametrize("lines, needle", [
    ("", "EXPECT line is None, but should be 'pass' or 'fail CHECK"),
    ("EXPECT: fail sideways", "EXPECT line is 'fail sideways'"),
    ("EXPECT: fail attached upside-down", "names the diagnosis 'upside-down', but should name one of"),
])
def test_a_bad_expect_line_is_one_paragraph_naming_the_file(tmp_path, lines, needle):
    path = _write(tmp_path / "app.py", _with_expect(lines))
    with pytest.raises(ConformanceError) as err:
        examples.expectation(path)
    assert needle in str(err.value) and str(path) in str(err.value)


@pytest.mark.parametrize("expected, passed, failed, agrees", [
    ("EXPECT: pass", True, {}, True),
    ("EXPECT: pass", False, {"attached": []}, False),
    ("EXPECT: fail attached previous-step", False, {"attached": ["previous-step"]}, True),
    ("EXPECT: fail attached previous-step", False, {"attached": ["wxyz"]}, False),      # the wrong diagnosis
    ("EXPECT: fail attached previous-step", False, {"drawn": ["previous-step"]}, False),  # the wrong check
    ("EXPECT: fail attached previous-step", True, {}, False),
    ("EXPECT: fail attached -", False, {"attached": []}, True),
    ("EXPECT: fail attached -", False, {"attached": [], "placed": ["com-frame"]}, False),  # a diagnosis where none fits
])
def test_agreement_needs_the_check_and_the_diagnosis(tmp_path, expected, passed, failed, agrees):
    expectation = examples.expectation(_write(tmp_path / "app.py", _with_expect(expected)))
    assert examples._agrees(expectation, passed, failed) is agrees


@pytest.mark.full("a whole app-table run over example apps: the table tool's own test; CI runs every example app (test_examples)")
def test_app_table_writes_the_table_and_fails_on_a_disagreement(tmp_path):
    late = SOURCE.replace(STEP, "").replace("    showm.render()\n", "    showm.render()\n" + STEP)
    assert late != SOURCE
    _write(tmp_path / "right.py", SOURCE)
    _write(tmp_path / "late.py", late.replace("EXPECT: pass", "MISTAKE: syncs before it steps\n"
                                              "EXPECT: fail attached previous-step"))
    _write(tmp_path / "claims_right.py", late)  # wrong, but its author says it passes
    out = tmp_path / "table.md"
    done = subprocess.run([sys.executable, "-m", "conformance", "app-table", str(tmp_path), "--perturbed", "0",
                           "--ticks", "30", "--out", str(out)], capture_output=True, text=True, timeout=900)
    assert done.returncode == 1, done.stdout + done.stderr
    assert f"DIFF {tmp_path / 'claims_right.py'}: expected pass, got fail attached (previous-step)" in done.stdout
    table = out.read_text(encoding="utf-8")
    assert "1/2 right apps accepted" in table  # claims_right.py says it is right
    assert "1/1 wrong apps rejected" in table
    assert f"| `{tmp_path / 'late.py'}` | syncs before it steps | fail attached previous-step | fail attached (previous-step) | yes |" in table
