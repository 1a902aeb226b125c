"""Ctrl-C (SIGINT) in ``slewing batch`` and ``slewing superelement``: one line on
stderr, exit status 130 (128 + SIGINT, as a shell reports a command it interrupted), and for a
study a valid ``summary.csv`` of the cases finished so far, which a rerun resumes."""
import csv
import glob
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SLEWING = str(Path(sys.executable).with_name("slewing"))
TABLE3 = (ROOT / "examples" / "bearings" / "table3.toml").as_posix()

pytest.importorskip("distributed", reason="the study engine needs dask[distributed] (extra 'study')")

# 40 small cases (rigid rings, 40 steps of 0.1 s each, about a tenth of a second of CPU) on one worker: the
# run lasts long enough to be interrupted after a few of them have finished (the 37 others take seconds).
# The tests check the interrupt, the summary and the resume, not the cases' results: 100 steps a case would
# cost the suite about 20 s more CPU (the two 40-case runs) for the same checks
STUDY = f"""[study]
name = "sigint"
[[loads]]
name = "light"
constant = [0, 0, 1e4, 0, 0, 0]
omega_rad_s = 0.1
duration_s = 4.0
steps = 40
[bearings]
files = ["{TABLE3}"]
ring_model = ["rigid"]
preload_um = [0, 10, 20, 30, 40]
error_seeds = {{first = 1, count = 8}}
[bearings.synthetic_errors]
waviness_orders = [2, 3]
"""


def _default_sigint():
    """In the child before exec: SIGINT's default action, as a shell gives a command it runs in a
    terminal (a command started in the background of a script, as this suite may be, inherits
    SIGINT ignored, and Python would then never see the Ctrl-C these tests send)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _interrupt_after(command, ready, timeout=120):
    """Start ``command``, send SIGINT once ``ready()`` holds; (rc, stdout, stderr)."""
    p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                         preexec_fn=_default_sigint)
    start = time.monotonic()
    while not ready():
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - start < timeout
        time.sleep(0.05)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    return p.returncode, out, err


def test_interrupted_batch_leaves_a_summary_of_the_finished_cases_and_resumes(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    out_dir = tmp_path / "out"
    command = [SLEWING, "batch", str(study), "-o", str(out_dir), "--workers", "1", "--quiet", "--no-figures"]
    finished = lambda: glob.glob(str(out_dir / "cases" / "*" / "result.json"))  # noqa: E731
    rc, out, err = _interrupt_after(command, lambda: len(finished()) >= 3)
    assert rc == 130, err
    assert len(err.strip().splitlines()) == 1 and "interrupted" in err and "Traceback" not in err, err
    with open(out_dir / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 40                                   # every case, each with its status
    done = {Path(p).parent.name for p in finished()}
    ok = {r["case"] for r in rows if r["status"] == "ok"}
    assert ok == done and len(ok) >= 3                       # exactly the cases whose result is on disk
    assert all(float(r["friction_torque_mean"]) > 0 for r in rows if r["status"] == "ok")
    assert all(r["status"].startswith("not finished") for r in rows if r["case"] not in ok)
    # the rerun resumes: it runs only the others
    again = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"{len(ok)} already finished" in again.stdout


def _hold_port(port):
    """A socket listening on ``port`` of this machine (None when another process holds it already):
    the port is taken either way, as when another Dask runs beside the study."""
    sock = socket.socket()
    try:
        sock.bind(("127.0.0.1", port))
        sock.listen()
    except OSError:
        sock.close()
        return None
    return sock


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process group from /proc (Linux)")
def test_ctrl_c_to_the_process_group_ends_the_workers_quietly(tmp_path):
    """A terminal's Ctrl-C goes to the whole process group: the parent and Dask's worker processes.
    The workers must end without a word (before: a traceback of each, 68-100 lines), the parent
    prints its one line, exit 130, summary.csv of the finished cases, and no process of the group
    is left behind. Dask's default dashboard port is held meanwhile, as when another Dask runs:
    no "Port 8787 is already in use" warning either."""
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    out_dir = tmp_path / "out"
    command = [SLEWING, "batch", str(study), "-o", str(out_dir), "--workers", "2", "--quiet", "--no-figures"]
    finished = lambda: glob.glob(str(out_dir / "cases" / "*" / "result.json"))  # noqa: E731
    port = _hold_port(8787)
    try:
        # its own session and process group, as a shell starts a command in a terminal
        p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
                             start_new_session=True, preexec_fn=_default_sigint)
        start = time.monotonic()
        while len(finished()) < 3:                                  # the workers are running cases
            assert p.poll() is None, p.communicate()
            assert time.monotonic() - start < 180
            time.sleep(0.05)
        group = os.getpgid(p.pid)
        assert group == p.pid
        workers = [pid for pid in _group_members(group) if pid != p.pid]
        assert len(workers) >= 2                                   # the worker processes are in the group
        os.killpg(group, signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if port is not None:
            port.close()
    assert p.returncode == 130, err
    printed = (out + err).splitlines()
    assert not [line for line in printed if re.search(r"Traceback|Exception ignored|Error|Warning|already in use",
                                                         line)], out + err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("slewing batch: interrupted;"), err
    with open(out_dir / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ok = {r["case"] for r in rows if r["status"] == "ok"}
    assert len(rows) == 40 and ok == {Path(f).parent.name for f in finished()} and len(ok) >= 3
    deadline = time.monotonic() + 30                                # and no worker outlives the run
    while _group_members(group) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _group_members(group)
    again = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"{len(ok)} already finished" in again.stdout


EARLY = """import os, signal, sys
if __name__ == "__main__":                      # Dask spawns its workers: they import this file
    import distributed

    class Cluster(distributed.LocalCluster):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            os.killpg(os.getpgid(0), signal.SIGINT)    # Ctrl-C while the cluster is starting
    distributed.LocalCluster = Cluster
    from slewing_model.cli import main
    sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process group from /proc (Linux)")
def test_ctrl_c_while_the_cluster_starts_is_kept_and_ends_the_run_quietly(tmp_path):
    """A Ctrl-C to the process group just as the embedded cluster has started (its workers up,
    before the first case): held back until the cluster is ours to close, then the same one line
    and exit 130, and nothing of the cluster left running."""
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    script = tmp_path / "early.py"
    script.write_text(EARLY)
    p = subprocess.Popen([sys.executable, str(script), "batch", str(study), "-o", str(tmp_path / "out"), "--workers",
                          "2", "--quiet", "--no-figures"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         cwd=ROOT, start_new_session=True, preexec_fn=_default_sigint)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 130, err
    assert [line for line in (out + err).splitlines() if line.strip()] == [
        f"slewing batch: interrupted; 0 of 40 cases finished, summary: {tmp_path / 'out' / 'summary.csv'} "
        f"(the same command resumes)"], out + err
    deadline = time.monotonic() + 30
    while _group_members(p.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _group_members(p.pid)


def _group_members(group):
    """The live (not zombie) processes of a process group, from /proc."""
    members = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == group and fields[0] != "Z":            # state, ppid, pgrp
            members.append(int(entry))
    return members


def test_interrupted_superelement_build_prints_one_line(tmp_path):
    # the fine mesh builds for several seconds: interrupted once the progress bar has started
    err_file = tmp_path / "err.txt"
    command = [SLEWING, "superelement", TABLE3, "--mesh", "fine", "--no-cache", "-o", str(tmp_path / "se.npz")]
    with open(err_file, "w") as err_fh:
        p = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=err_fh, text=True, cwd=ROOT,
                             preexec_fn=_default_sigint)
        start = time.monotonic()
        while "%" not in err_file.read_text():                # tqdm's bar: the build has begun
            assert p.poll() is None, err_file.read_text()
            assert time.monotonic() - start < 120
            time.sleep(0.05)
        p.send_signal(signal.SIGINT)
        p.communicate(timeout=60)
    lines = [line for line in err_file.read_text().replace("\r", "\n").splitlines()
             if line.strip() and "%" not in line]              # without the progress bar's own lines
    assert p.returncode == 130
    assert lines == ["slewing superelement: interrupted"], lines
    assert not (tmp_path / "se.npz").exists()


# ---- an output folder holds one study ----------------------------------------------------------

def _small_study(folder, name, preloads):
    path = Path(folder) / f"{name}.toml"
    path.write_text(STUDY.replace('name = "sigint"', f'name = "{name}"').replace(
        "preload_um = [0, 10, 20, 30, 40]", f"preload_um = {list(preloads)}").replace(
        "{first = 1, count = 8}", "[1]").replace("steps = 40", "steps = 5"))
    return path


def _batch(study, out_dir, *extra):
    return subprocess.run([SLEWING, "batch", str(study), "-o", str(out_dir), "--workers", "1", "--quiet", *extra],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)


def test_output_folder_of_another_study_is_refused_unless_overwrite(tmp_path):
    out_dir = tmp_path / "out"
    first = _batch(_small_study(tmp_path, "first", [0, 10]), out_dir)
    assert first.returncode == 0, first.stderr
    old_figures = set((out_dir / "figures").iterdir())
    assert old_figures
    second = _small_study(tmp_path, "second", [20])
    refused = _batch(second, out_dir)
    assert refused.returncode == 2
    assert "'first'" in refused.stderr and "'second'" in refused.stderr and "--overwrite" in refused.stderr
    assert len(list((out_dir / "cases").iterdir())) == 2                  # nothing touched
    done = _batch(second, out_dir, "--overwrite", "--no-figures")
    assert done.returncode == 0, done.stderr
    with open(out_dir / "summary.csv", newline="") as fh:
        assert [r["preload_um"] for r in csv.DictReader(fh)] == ["20.0"]
    assert len(list((out_dir / "cases").iterdir())) == 1                  # the old cases are gone
    assert not (out_dir / "figures").exists()                             # and the old figures


def test_rerun_of_the_same_study_resumes_even_when_extended(tmp_path):
    out_dir = tmp_path / "out"
    assert _batch(_small_study(tmp_path, "mc", [0, 10]), out_dir, "--no-figures").returncode == 0
    again = _batch(_small_study(tmp_path, "mc", [0, 10, 20]), out_dir, "--no-figures")
    assert again.returncode == 0, again.stderr
    assert "2 already finished" in again.stdout and "1 run now" in again.stdout


def test_the_embedded_clusters_workers_drop_only_a_heartbeat_that_meets_its_closing_scheduler():
    """A worker whose heartbeat meets the embedded cluster's scheduler as it closes (the run's end, a
    Ctrl-C) logs an error with a traceback (dask/distributed 7105, 9032; seen once in the Ctrl-C test
    above). The embedded cluster's workers drop that record, and only that one."""
    import logging

    from slewing_model.study.engine import HEARTBEAT_AT_CLOSE, _not_heartbeat_at_close, dask_client

    def record(message):
        return logging.LogRecord("distributed.worker", logging.ERROR, __file__, 1, message, None, None)

    assert not _not_heartbeat_at_close(record(HEARTBEAT_AT_CLOSE + "."))
    assert _not_heartbeat_at_close(record("Compute Failed"))
    owned = []
    try:
        client, _ = dask_client(1, None, owned)
        installed = client.run(lambda: _not_heartbeat_at_close in logging.getLogger("distributed.worker").filters)
        assert list(installed.values()) == [True]
    finally:
        for thing in reversed(owned):
            thing.close()


def test_a_ctrl_c_inside_distributeds_sync_before_its_future_exists_logs_nothing_in_a_run(monkeypatch):
    """A Ctrl-C that lands in ``distributed.utils.sync`` before the coroutine it runs has made its future
    makes the cancel callback read that future unassigned: tornado logs a NameError with a traceback
    (seen once in the Ctrl-C test above). Reproduced here: the wait for the coroutine interrupted at once.
    Within a run (``quiet_run_logs``) that record is dropped, and no other; outside it, it is logged."""
    import asyncio
    import logging
    import threading

    from distributed.utils import sync
    from tornado.ioloop import IOLoop

    from slewing_model.study.engine import quiet_run_logs

    ready, holder = threading.Event(), {}

    def serve():
        asyncio.set_event_loop(asyncio.new_event_loop())
        holder["loop"] = IOLoop.current()
        ready.set()
        holder["loop"].start()

    threading.Thread(target=serve, daemon=True).start()
    ready.wait(10)
    loop = holder["loop"]
    logged = []

    class Kept(logging.Handler):
        def emit(self, record):
            logged.append(record)

    logger = logging.getLogger("tornado.application")
    handler = Kept(level=logging.ERROR)
    logger.addHandler(handler)

    async def work():
        await asyncio.sleep(0.01)

    def interrupted(self, timeout=None):
        raise KeyboardInterrupt

    def ctrl_c_in_sync():
        held = threading.Lock()                     # the loop held, so that the coroutine's first step and the
        held.acquire()                              # cancel callback are both queued before it runs on
        loop.add_callback(lambda: (held.acquire(), held.release()))
        with monkeypatch.context() as patch:
            patch.setattr(threading.Event, "wait", interrupted)
            with pytest.raises(KeyboardInterrupt):
                sync(loop, work)
        held.release()
        sync(loop, work)                            # the loop has run the queued callbacks
    try:
        with quiet_run_logs():
            ctrl_c_in_sync()
            logger.error("another error")           # the filter drops that one record only
        quiet = [r.getMessage() for r in logged]
        logged.clear()
        ctrl_c_in_sync()
    finally:
        logger.removeHandler(handler)
        loop.add_callback(loop.stop)
    assert quiet == ["another error"]
    assert any(isinstance(r.exc_info[1], NameError) and "sync.<locals>.cancel" in r.getMessage() for r in logged)


def test_a_gather_of_keys_the_ctrl_c_released_logs_nothing_in_a_run():
    """A Ctrl-C that releases the run's futures while the embedded scheduler gathers one of their results makes
    the scheduler log "Couldn't gather keys: {key: 'forgotten'}" (seen once in the Ctrl-C test above). Within
    a run (``quiet_run_logs``) that record is dropped; one naming a key in another state (a worker lost with the
    result) is kept, and outside a run both are logged."""
    import logging

    from slewing_model.study.engine import quiet_run_logs

    logged = []

    class Kept(logging.Handler):
        def emit(self, record):
            logged.append(record.getMessage())

    logger = logging.getLogger("distributed.scheduler")
    handler = Kept(level=logging.ERROR)
    logger.addHandler(handler)

    def gathers():
        logger.error("Couldn't gather keys: %s", {"slewing-case-1": "forgotten", "slewing-case-2": "forgotten"})
        logger.error("Couldn't gather keys: %s", {"slewing-case-3": "memory"})
    try:
        with quiet_run_logs():
            gathers()
        quiet = list(logged)
        logged.clear()
        gathers()
    finally:
        logger.removeHandler(handler)
    assert quiet == ["Couldn't gather keys: {'slewing-case-3': 'memory'}"]
    assert len(logged) == 2 and "forgotten" in logged[0]
