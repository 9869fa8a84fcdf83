"""The CI templates of ``docs/ci/`` (issue 50, point 1), run as far as they run without the CI service.

Each template parses, and has both jobs (a sync, apps) on both FURYs, keeping its files when the checks fail.
For the FURY of this environment every ``run:``/``script:`` line of each job runs, one after the other as the
job would, in a fresh directory holding a sample project (a sync module, and an app copied from ``examples/``).
The three commands that need root or a network (``sudo``, ``apt-get``, ``pip``) are stubs that note what they
were asked: the packages are the ones the kit's own set-up installs for this FURY, and pip installs the kit with
this FURY's extra. Everything else runs for real, the checks narrowed to one by ``$PYTEST_ADDOPTS`` (the
template's own command line, untouched), and the files the job keeps as artifacts are there afterwards. The
sync job's shards, collected, hold every check of the whole run exactly once.
"""

from __future__ import annotations

import itertools
import os
import re
import shutil
import subprocess
import sys
import tomllib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

import children
from conformance import backends, scenes

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES = {"github": ROOT / "docs" / "ci" / "github-actions.yml", "gitlab": ROOT / "docs" / "ci" / "gitlab-ci.yml"}
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
#: The extra of each FURY, and the one of this environment.
EXTRAS = {"vtk": "fury012", "pygfx": "fury2"}
EXTRA = EXTRAS[backends.NAME]
#: One check of each job, for the runs here: a vertex check the sample sync fails (so that there are
#: failure pictures to keep), and one app check (the app's one run is shared by its checks).
NARROW = {"sync": "free_fall and test_vertices_match_poses_every_frame", "apps": "attached"}
SAMPLE_SYNC = '''"""The sample project's sync: it has the kit's reference sync draw each scene at the first call, and
never again after it (so every check of a moving body fails, with pictures)."""
from conformance.implementations.reference import ReferenceSync


class MySync:
    def __init__(self, world):
        self.draw = ReferenceSync(world)
        self.called = False

    def __call__(self):
        if not self.called:
            self.draw()
        self.called = True
'''
STUBS = {"sudo": '#!/bin/sh\nexec "$@"\n',  # GitHub's runners have it; a GitLab job's image runs as root
         "apt-get": '#!/bin/sh\necho "apt-get $*" >> "$STUB_LOG"\n',
         "pip": '#!/bin/sh\necho "pip $*" >> "$STUB_LOG"\n'}


@dataclass
class Job:
    """One job of a template, for this environment's FURY: the variables each of its matrix's jobs runs with,
    its shell scripts in order (each a step, or an entry of ``before_script``/``script``), what it keeps."""

    template: str
    name: str
    kind: str
    combos: list
    scripts: list
    kept: list
    raw: dict


def _github_jobs() -> list[Job]:
    workflow = yaml.safe_load(TEMPLATES["github"].read_text(encoding="utf-8"))
    jobs = []
    for name, job in workflow["jobs"].items():
        matrix = job["strategy"]["matrix"]
        keys = [k for k in matrix if k not in ("include", "exclude")]
        combos = []
        for values in itertools.product(*(matrix[k] for k in keys)):
            values = dict(zip(keys, map(str, values)))
            if values["fury"] == EXTRA:
                combos.append({**{k: str(v) for k, v in workflow["env"].items()},
                               **{k: _matrix_value(v, values) for k, v in job.get("env", {}).items()}})
        scripts = [step["run"] for step in job["steps"] if "run" in step]
        kept = [line.strip() for step in job["steps"] if step.get("uses", "").startswith("actions/upload-artifact@")
                for line in step["with"]["path"].splitlines() if line.strip()]
        jobs.append(Job("github", name, "apps" if "apps" in name else "sync", combos, scripts, kept, job))
    return jobs


def _matrix_value(value, matrix: dict) -> str:
    """A job's ``env`` value with its ``${{ matrix.NAME }}`` filled in; no other expression is allowed there."""
    text = re.sub(r"\$\{\{\s*matrix\.(\w+)\s*\}\}", lambda m: matrix[m.group(1)], str(value))
    assert "${{" not in text, f"an expression other than matrix.NAME in a job's env: {value!r}"
    return text


def _gitlab_jobs() -> list[Job]:
    ci = yaml.safe_load(TEMPLATES["gitlab"].read_text(encoding="utf-8"))
    jobs = []
    for name, job in ci.items():
        if name.startswith(".") or not isinstance(job, dict) or "script" not in job:
            continue
        job = {**ci.get(job.get("extends", ""), {}), **job}
        combos = []
        for entry in job["parallel"]["matrix"]:
            lists = {k: [v] if isinstance(v, str) else v for k, v in entry.items()}
            for values in itertools.product(*lists.values()):
                values = dict(zip(lists, values))
                if values["FURY"] == EXTRA:
                    combos.append({**{k: str(v) for k, v in ci["variables"].items()}, **values})
        jobs.append(Job("gitlab", name, "apps" if "apps" in name else "sync", combos,
                        list(job.get("before_script", [])) + list(job["script"]), list(job["artifacts"]["paths"]), job))
    return jobs


JOBS = {"github": _github_jobs, "gitlab": _gitlab_jobs}


def _kit_packages() -> set[str]:
    """The Debian packages ``./kit`` installs to render with this environment's FURY (its ``missing_packages``)."""
    script = (ROOT / "kit").read_text(encoding="utf-8")
    body = re.search(r"^missing_packages\(\) \{\n(.*?)^\}", script, re.S | re.M).group(1)
    vtk, pygfx = re.search(r'if \[ "\$BACKEND" = vtk \]; then\n(.*?)\n\s*else\n(.*?)\n\s*fi\n', body, re.S).groups()
    words = re.findall(r"\|\| (?:echo|printf '%s\\n') ([^\n]+)", {"vtk": vtk, "pygfx": pygfx}[backends.NAME])
    return {word for line in words for word in line.split()}


def test_each_template_runs_both_ways_on_both_furys_and_keeps_its_files_when_checks_fail():
    """What cannot run here, read: the jobs and their matrix, the kit named by its name, pip's cache kept per
    FURY, and the report, the pictures and the JUnit XML kept (and the JUnit XML shown) when the checks fail."""
    extras = set(EXTRAS.values())
    assert extras <= set(PROJECT["optional-dependencies"])
    for template, jobs in JOBS.items():
        jobs = jobs()
        assert sorted(job.kind for job in jobs) == ["apps", "sync"], template
        for job in jobs:
            assert job.combos and all(c["KIT"] == PROJECT["name"] for c in job.combos), (template, job.name)
            assert "junit.xml" in job.kept and "conformance-results/" in job.kept, (template, job.name)
            assert not any("${{" in script for script in job.scripts), "GitHub fills ${{ }} in before the shell: use env"
            if template == "github":
                matrix = job.raw["strategy"]["matrix"]
                assert set(map(str, matrix["fury"])) == extras
                steps = job.raw["steps"]
                kept = [s for s in steps if s.get("uses", "").startswith(("actions/upload-artifact@", "mikepenz/action-junit-report@"))]
                assert len(kept) == 2 and all(s.get("if") in ("${{ !cancelled() }}", "${{ always() }}") for s in kept), kept
                cache = next(s for s in steps if s.get("uses", "").startswith("actions/cache@"))
                assert cache["with"]["path"] == "~/.cache/pip" and "matrix.fury" in cache["with"]["key"], cache
            else:
                furies = {f for entry in job.raw["parallel"]["matrix"] for f in entry["FURY"]}
                assert furies == extras
                assert job.raw["artifacts"]["when"] == "always" and job.raw["artifacts"]["reports"]["junit"] == "junit.xml"
                assert "$FURY" in job.raw["cache"]["key"] and job.raw["cache"]["paths"] == [".cache/pip"]
                assert job.combos[0]["PIP_CACHE_DIR"] == "$CI_PROJECT_DIR/.cache/pip"


@pytest.fixture(scope="module")
def stubs(tmp_path_factory) -> Path:
    where = tmp_path_factory.mktemp("stubs")
    for name, text in STUBS.items():
        (where / name).write_text(text)
        (where / name).chmod(0o755)
    return where


def _sample_project(where: Path) -> Path:
    """A fresh project: the sample sync as ``my_package.sync:MySync``, and an app of the guide's in ``apps/<backend>/``."""
    (where / "my_package").mkdir(parents=True)
    (where / "my_package" / "__init__.py").write_text("")
    (where / "my_package" / "sync.py").write_text(SAMPLE_SYNC)
    (where / "apps" / backends.NAME).mkdir(parents=True)
    shutil.copy(ROOT / "examples" / backends.NAME / "ball_collision.py", where / "apps" / backends.NAME)
    return where


def _environment(job: Job, combo: dict, project: Path, stubs: Path, addopts: str) -> dict:
    """The job's variables (GitLab's ``$CI_PROJECT_DIR`` filled in), the stubs and this environment's
    ``python``/``pytest`` first on the path, the selection narrowed."""
    env = {k: v for k, v in children.environment().items() if not k.startswith(("GITHUB_", "CI_"))}
    ci = {"CI_PROJECT_DIR": str(project)} if job.template == "gitlab" else {
        "GITHUB_STEP_SUMMARY": str(project.parent / f"{project.name}-step-summary.md")}
    env.update(ci)
    env.update({k: re.sub(r"\$(\w+)", lambda m: ci.get(m.group(1), m.group(0)), v) for k, v in combo.items()})
    env["PATH"] = os.pathsep.join([str(stubs), str(Path(sys.executable).parent), env.get("PATH", "")])
    env["STUB_LOG"] = str(project.parent / f"{project.name}-stubs.log")
    env["PYTEST_ADDOPTS"] = f"-p no:cacheprovider {addopts}"
    env["PYTEST_XDIST_AUTO_NUM_WORKERS"] = "1"  # -n auto: one worker here, where the runs are of one check
    return env


def _bash(script: str, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    # GitHub's `run:` shell, and what a GitLab job's script stops at: the first command that fails.
    return subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c", script], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("template, kind", [(t, k) for t in TEMPLATES for k in ("sync", "apps")])
def test_every_line_of_the_job_runs_in_a_fresh_project(template, kind, tmp_path, stubs):
    """The setup lines ask for this FURY's packages and the kit with its extra; the checks' line runs the sample
    project's wrong sync (a failure, with its pictures and report kept) or its app (a pass), and shows the summary."""
    job = next(j for j in JOBS[template]() if j.kind == kind)
    project = _sample_project(tmp_path / "project")
    env = _environment(job, job.combos[0], project, stubs, f"-k '{NARROW[kind]}'")
    *setup, checks = job.scripts
    for script in setup:
        done = _bash(script, project, env)
        assert done.returncode == 0, (script, children.said(done))
    asked = Path(env["STUB_LOG"]).read_text().splitlines()
    installs = [line.split()[2:] for line in asked if line.startswith("apt-get install")]
    assert len(installs) == 1 and {w for w in installs[0] if not w.startswith("-")} == _kit_packages(), asked
    assert [line for line in asked if line.startswith("pip ")] == [f"pip install {PROJECT['name']}[{EXTRA}]"], asked

    done = _bash(checks, project, env)
    said = children.said(done)
    assert "pytest" in checks and done.returncode == (1 if kind == "sync" else 0), said  # the sample sync is wrong
    cases = list(ET.parse(project / "junit.xml").iter("testcase"))
    assert len(cases) == 1, said
    if kind == "sync":  # a failing run: everything kept is there, the failure's pictures and report among it
        assert cases[0].find("failure") is not None and "reproduce: " in cases[0].find("failure").text
        for path in job.kept:
            assert (project / path).exists(), f"{path} is kept as an artifact but the job did not write it"
        results = project / "conformance-results"
        assert (results / "report.html").is_file() and list(results.rglob("*.png")), "no failure pictures to keep"
    shown = Path(env["GITHUB_STEP_SUMMARY"]) if template == "github" else project / "conformance-summary.md"
    verdict = "FAIL" if kind == "sync" else "PASS"
    assert shown.read_text(encoding="utf-8").startswith(f"## {'❌' if kind == 'sync' else '✅'} FURY–pyBullet conformance: {verdict}")


def _collected(job: Job, combo: dict, project: Path, stubs: Path) -> list[str]:
    done = _bash(job.scripts[-1], project, _environment(job, combo, project, stubs, "--collect-only -q"))
    assert done.returncode == 0, children.said(done)
    return [line for line in done.stdout.splitlines() if "::" in line]


@pytest.fixture(scope="module")
def whole_run(tmp_path_factory) -> list[str]:
    """The checks of the whole run, as ``pytest --pyargs conformance --sync …`` collects them without shards."""
    project = _sample_project(tmp_path_factory.mktemp("whole") / "project")
    done = subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "--sync",
                           "my_package.sync:MySync", "--collect-only", "-q"], cwd=project, env=children.environment(),
                          capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, children.said(done)
    return [line for line in done.stdout.splitlines() if "::" in line]


@pytest.mark.parametrize("template", TEMPLATES)
def test_the_shards_of_the_sync_job_check_every_check_exactly_once(template, tmp_path, stubs, whole_run):
    """Every check of the whole run is in exactly one of the sync job's shards (the matrix's K/N, K from 1 to N)."""
    job = next(j for j in JOBS[template]() if j.kind == "sync")
    shards = sorted(combo["SHARD"] for combo in job.combos)
    n = len(shards)
    assert n > 1 and shards == [f"{k}/{n}" for k in range(1, n + 1)], shards
    project = _sample_project(tmp_path / "project")
    parts = [_collected(job, combo, project, stubs) for combo in job.combos]
    together = [nodeid for part in parts for nodeid in part]
    assert len(together) == len(set(together)), "a check in two shards"
    assert sorted(together) == sorted(whole_run), "the shards do not add up to the whole run"
    assert {m.group(1).split("-")[0] for m in map(re.compile(r"\[([^\]]+)\]$").search, whole_run) if m} >= set(scenes.names())
