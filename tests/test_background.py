"""The process that starts the kit's background runs from threads cannot deadlock in a fork
(``tests/background.py``): it computes BLAS on one thread before its first run starts."""

from __future__ import annotations

from threadpoolctl import threadpool_info, threadpool_limits

import background


def test_the_runs_pool_starts_after_blas_is_down_to_one_thread(monkeypatch):
    monkeypatch.setattr(background, "_pool", None)
    with threadpool_limits(limits=2, user_api="blas"):  # a machine of 2+ cores without OPENBLAS_NUM_THREADS
        assert {p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"} == {2}
        pool = background._executor()
        try:
            threads = {p["filepath"]: p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"}
        finally:
            pool.shutdown()
    assert threads and set(threads.values()) == {1}, (
        f"BLAS threads {threads} while the pool's threads fork, but should be 1 in every library: a fork "
        "during a multi-threaded OpenBLAS call deadlocks")


def test_a_run_started_while_a_test_stands_elsewhere_starts_where_the_session_did(tmp_path, monkeypatch):
    """A test runs the kit's commands in a directory of its own by changing this process's; a run the pool
    starts meanwhile still starts in the session's directory (test_animation found a background run's
    ``.hypothesis`` in its temporary directory)."""
    import subprocess
    import sys

    monkeypatch.setattr(background, "_pool", None)
    pool = background._executor()
    monkeypatch.chdir(tmp_path)
    try:
        where = pool.submit(subprocess.run, [sys.executable, "-c", "import os; print(os.getcwd())"],
                            capture_output=True, text=True).result().stdout.strip()
        here = subprocess.run([sys.executable, "-c", "import os; print(os.getcwd())"], capture_output=True,
                              text=True).stdout.strip()
    finally:
        pool.shutdown()
    assert where == background.HOME != str(tmp_path), f"a run of the pool started in {where}, but should in {background.HOME}"
    assert here == str(tmp_path), "the test's own commands still start where it stands"
