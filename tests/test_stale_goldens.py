"""Nothing stale: a file in a golden directory that no check reads fails ``test_no_stale_goldens``,
naming it, and ``regen --prune`` deletes exactly those files (and never a golden a check reads, even
when one scene is named)."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from conformance.rendering import golden

STRAYS = ("gone/frame-0000.png", "gone/frame-0000.json", "chain/frame-0099.png", "chain/frame-0099.json", "notes.txt")


@pytest.fixture
def goldens(tmp_path):
    """A copy of the kit's goldens with a removed scene's, a stale frame's and a stray file added."""
    copy = tmp_path / "golden"
    shutil.copytree(golden.default_dir(), copy)
    for name in STRAYS:
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        (copy / name).write_bytes(b"stale")
    return copy


def test_the_check_names_every_file_no_check_reads(pytester, goldens):
    result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "-k", "test_no_stale_goldens",
                                           "--conformance-golden-dir", str(goldens))
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    for name in STRAYS:
        assert str(goldens / name) in out, out
    assert "5 file(s) in the golden directories are read by no check" in out
    assert f"python -m conformance regen --prune --golden-dir {goldens}" in out


def test_the_prune_line_keeps_the_runs_own_scenes_and_deletes_only_the_strays(pytester, goldens):
    """With an own scene in the run, the printed prune names its source: without it `regen` sees only the
    kit's scenes and would take the own scene's goldens for stale."""
    import shlex

    from test_own_scenes import _example

    pytester.makepyfile(my_scenes=_example())
    own = goldens / "tossed_die"
    own.mkdir()
    (own / "frame-0000.png").write_bytes(b"a golden of the own scene")
    result = pytester.runpytest_subprocess("--pyargs", "conformance", "-p", "no:cacheprovider", "-k", "test_no_stale_goldens",
                                           "--conformance-golden-dir", str(goldens), "--scenes", "my_scenes.py")
    out = result.stdout.str()
    line = next(line for line in out.splitlines() if "Delete exactly those with:" in line)
    command = line.split("Delete exactly those with: ", 1)[1].strip()
    assert "--scenes my_scenes.py" in command, command
    done = subprocess.run([sys.executable, *shlex.split(command)[1:]], cwd=pytester.path, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert (own / "frame-0000.png").exists() and not any((goldens / name).exists() for name in STRAYS)


def test_the_shipped_goldens_have_nothing_stale():
    from conformance import scenes

    wanted = {n: scenes.get(n).frames_with_goldens() for n in scenes.names(origin=None)}
    assert golden.stale(golden.default_dir(), wanted) == []


@pytest.mark.parametrize("named", [[], ["chain"]])
def test_prune_deletes_exactly_the_stale_files(goldens, named):
    before = {p for p in goldens.rglob("*") if p.is_file()}
    done = subprocess.run([sys.executable, "-m", "conformance", "regen", *named, "--prune", "--golden-dir", str(goldens)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    after = {p for p in goldens.rglob("*") if p.is_file()}
    assert before - after == {goldens / name for name in STRAYS}, sorted(map(str, before - after))
    assert not (goldens / "gone").exists(), "an emptied scene folder is removed too"
    assert "5 file(s) no check reads deleted" in done.stdout
