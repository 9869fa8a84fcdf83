"""What CI shows of a run (issue 50, point 2): the Markdown summary (:mod:`conformance.reports.summary`), written
to ``--conformance-summary`` and added to ``$GITHUB_STEP_SUMMARY``, and the JUnit XML's failure messages, which
carry the diagnosis (:mod:`conformance.reports.junit`). Read as a reviewer reads them: the files a run wrote."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import pytest

from conformance.reports import junit, summary

TESTS = str(Path(__file__).resolve().parent)
#: A property check whose first failure line is too long for pytest to keep its diagnosis line in the XML's
#: message attribute, and a vertex check whose failing frame is pictured.
CHECKS = "test_pass_through_is_drawn_overlapping or (free_fall and test_vertices_match_poses_every_frame)"
PREVIOUS = "## what an earlier step wrote\n"


@pytest.fixture(scope="module")
def failing_run(tmp_path_factory):
    """One run of a sync a step late: its JUnit XML, its summary file, and the step summary it added to."""
    from conformance.backends.display import child_environment

    where = tmp_path_factory.mktemp("failing-run")
    step = where / "step-summary.md"
    step.write_text(PREVIOUS, encoding="utf-8")
    env = {**child_environment(), "PYTHONPATH": os.pathsep.join(filter(None, [TESTS, os.environ.get("PYTHONPATH")])),
           "GITHUB_STEP_SUMMARY": str(step), "GITHUB_SERVER_URL": "https://github.example",
           "GITHUB_REPOSITORY": "owner/project", "GITHUB_RUN_ID": "42"}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q", "-k", CHECKS,
         "--sync", "wrong_syncs:OneStepLate", "--junitxml", "junit.xml", "--conformance-summary", "out/summary.md",
         "--hypothesis-profile", "default"],  # not the "ci" profile Hypothesis picks under $CI: no shrinking here
        cwd=where, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == pytest.ExitCode.TESTS_FAILED, done.stdout[-3000:] + done.stderr[-2000:]
    return SimpleNamespace(where=where, xml=ET.parse(where / "junit.xml"), file=where / "out" / "summary.md", step=step)


def test_the_junit_failure_message_carries_the_diagnosis(failing_run):
    """The message attribute is what CI lists for a failing check; pytest keeps only its first 500 characters of
    whole lines, and the property check's first line alone is over 400."""
    failures = {case.get("name"): case.find("failure") for case in failing_run.xml.iter("testcase")}
    assert set(failures) == {"test_pass_through_is_drawn_overlapping", "test_vertices_match_poses_every_frame[free_fall]"}
    for name, failure in failures.items():
        message = failure.get("message")
        assert re.search(r"^diagnosis: drawn exactly at pyBullet's pose of the previous step", message, re.M), (name, message)
        assert message.startswith("Failed: 'a' (body 0)" if "pass_through" in name else "Failed: 'body' (body 0)"), message
        # the whole failure stays in the element's text, as pytest wrote it
        assert "reproduce: python -m conformance check" in failure.text


def test_the_summary_file_has_each_scene_the_first_failure_and_links_to_its_pictures(failing_run):
    text = failing_run.file.read_text(encoding="utf-8")
    assert text.startswith("## ❌ FURY–pyBullet conformance: FAIL\n"), text[:300]
    assert "sync `wrong_syncs:OneStepLate`" in text and "pytest exit status 1" in text
    rows = dict(re.findall(r"^\| ❌ FAIL \| (\S+) \| (.*) \|$", text, re.M))
    assert set(rows) == {"crossing", "free\\_fall"}, text
    first = text[text.index("### First failure"):]
    assert "**Diagnosis:** drawn exactly at pyBullet's pose of the previous step" in first, first
    assert re.search(r"\*\*Reproduce:\*\*\n\n```sh\npython -m conformance check (crossing|free_fall) --sync wrong_syncs:OneStepLate",
                     first), first
    links = [link for link in re.findall(r"\]\(([^)]+)\)", text) if not link.startswith("https://")]
    pictures = [link for link in links if link.endswith(".png")]
    assert pictures and "report.html" in " ".join(links), links
    for link in links:  # relative to the summary's own directory, as a Markdown viewer follows them
        assert (failing_run.file.parent / link).is_file(), link
    assert text.count("FURY–pyBullet conformance:") == 1


def test_the_step_summary_is_added_to_once_with_paths_not_links(failing_run):
    """Under pytest-xdist (where a sync that is not the kit's runs) only the controller writes it; GitHub's page
    cannot follow a link into the run's artifacts, so pictures are named by path, and the artifacts linked."""
    text = failing_run.step.read_text(encoding="utf-8")
    assert text.startswith(PREVIOUS + "\n## ❌ FURY–pyBullet conformance: FAIL\n"), text[:300]
    assert text.count("FURY–pyBullet conformance:") == 1
    assert not re.search(r"\]\([^)]*\.png\)", text) and "`conformance-results/report.html`" in text
    assert "[the run's kept files (artifacts)](https://github.example/owner/project/actions/runs/42#artifacts)" in text


def test_a_run_without_the_kits_checks_writes_no_summary(pytester, monkeypatch):
    """The plugin is loaded in every pytest run of the environment: a suite of the user's own gets no summary."""
    step = pytester.path / "step-summary.md"
    monkeypatch.setenv("GITHUB_STEP_SUMMARY", str(step))
    pytester.makepyfile(test_own="def test_own():\n    assert False\n")
    result = pytester.runpytest("-p", "no:cacheprovider", "--conformance-summary", "summary.md")
    result.assert_outcomes(failed=1)
    assert not step.exists() and not (pytester.path / "summary.md").exists()


def test_text_from_records_cannot_break_the_markdown():
    nasty = "a | b `code` <script>alert(1)</script> **bold** [link](x)\nsecond line"
    run = summary.Run(sync="s", backend="backend vtk", exitstatus=1, scenes=[("FAIL", "chain", "1 failed")],
                      records=[{"nodeid": "t.py::test_x[chain]", "scene": "chain", "outcome": "failed",
                                "message": nasty, "diagnosis": nasty, "reproduce": "echo ```"}])
    text = summary.render(run)
    row = next(line for line in text.splitlines() if line.startswith("| `t.py::test_x[chain]`"))
    assert len(re.findall(r"(?<!\\)\|", row)) == 6, row  # five cells: no unescaped pipe inside them
    outside_code = re.sub(r"(`{3,})\w*\n.*?\n\1", "", text, flags=re.S)
    assert not re.search(r"(?<!\\)<script>|(?<!\\)\]\(x\)", outside_code), outside_code
    assert "````sh\necho ```\n````" in text  # a fence longer than the backticks it holds


def test_a_passing_run_is_a_pass_without_failure_sections():
    run = summary.Run(sync="s", backend="backend pygfx", exitstatus=0, scenes=[("PASS", "chain", "19 passed")],
                      records=[{"nodeid": "t.py::test_x[chain]", "scene": "chain", "outcome": "passed"}])
    text = summary.render(run)
    assert text.startswith("## ✅ FURY–pyBullet conformance: PASS") and "1 passed" in text
    assert "First failure" not in text and "failing check" not in text


def _report(message: str):
    """A failed report as the junit module reads it: its crash line, and its whole text."""
    crash = SimpleNamespace(message=message)
    return SimpleNamespace(failed=True, longrepr=type("Repr", (), {"reprcrash": crash, "__str__": lambda self: message})())


def test_a_diagnosis_already_kept_is_left_as_it_was_and_an_app_s_indented_one_is_brought_up():
    short = "Failed: 'body' drawn off [free_fall, frame 1]\ndiagnosis: a step late\nreproduce: python -m conformance check"
    report = _report(short)
    junit.lead_with_the_diagnosis(report)
    assert report.longrepr.reprcrash.message == short
    app = "attached [app a.py, 120 ticks]\n" + "\n".join(f"  body {i}: {'x' * 80}" for i in range(8)) + \
          "\n    diagnosis: drawn at the centre-of-mass frame\nreproduce: python -m conformance app a.py"
    report = _report(app)
    junit.lead_with_the_diagnosis(report)
    lines = report.longrepr.reprcrash.message.splitlines()
    assert lines[:2] == ["attached [app a.py, 120 ticks]", "diagnosis: drawn at the centre-of-mass frame"]
    assert len("\n".join(lines[:3])) <= junit.BUDGET and lines[2] == "reproduce: python -m conformance app a.py"
