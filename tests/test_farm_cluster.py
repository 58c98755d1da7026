"""The farm on clusters a render wrangler meets: a scheduler and workers started with the
``dask scheduler`` / ``dask worker`` commands on 127.0.0.1, workers running another whitted or
none, workers stopped (SIGSTOP), killed or lost, the scheduler lost."""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

from farm_film import farm_film  # noqa: E402
from whitted.animation.frames import render_frame  # noqa: E402
from whitted.farm import ClusterLost, WhittedWorker  # noqa: E402
from whitted.farm.cluster import ready_cluster  # noqa: E402
from whitted.fingerprint import FINGERPRINT_KEY, renderer_fingerprint  # noqa: E402

SRC = Path(__file__).resolve().parents[1] / "src"
DASK_CLI = str(Path(sys.executable).parent / "dask")  # the `dask` command of this Python
DASK = [DASK_CLI, "worker"]
SCHEDULER = [DASK_CLI, "scheduler"]

FILM = """
[render]
width = 24
height = 16
samples = 1

[camera]
position = [0, 1.5, 5]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
type = "plane"
material = { kd = 0.8, texture = { type = "checker", checks = 2.0 } }

[[objects]]
name = "ball"
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5
material = "glass"

[animation]
frames = 8
fps = 12

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 1.5, 5]], [7, [3, 1.5, 4]]]
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, what: str, limit: float = 600.0) -> None:
    """Wait until ``condition()`` holds (checked every 50 ms); fail naming ``what`` after
    ``limit`` seconds (a hang guard, not a timing assert)."""
    end = time.monotonic() + limit
    while not condition():
        if time.monotonic() > end:
            raise AssertionError(f"still waiting for {what}")
        time.sleep(0.05)


def env_with(pythonpath: str | None = None, **extra: str) -> dict[str, str]:
    env = dict(os.environ, **extra)
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    return env


@contextmanager
def processes():
    """Processes started by a test, each in a process group of its own, ended with all
    its children when the test is done: a ``dask worker`` (a nanny) runs its worker as a
    child, which a test may have stopped (SIGSTOP) or left behind; a stopped orphan could
    hold the kernel cache's lock and make every later test wait for it."""
    started: list[subprocess.Popen] = []

    def start(args, **kwargs) -> subprocess.Popen:
        proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True, **kwargs)
        started.append(proc)
        return proc

    try:
        yield start
    finally:
        for proc in started:
            for sig in (signal.SIGCONT, signal.SIGKILL):
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, sig)  # the group outlives its leader's death
            proc.wait(timeout=30)


@pytest.fixture
def film_scene(tmp_path):
    from whitted import load_scene

    path = tmp_path / "film.toml"
    path.write_text(FILM)
    return load_scene(path)


@pytest.fixture
def local_frames(film_scene, tmp_path) -> dict[int, bytes]:
    folder = tmp_path / "local"
    folder.mkdir()
    frames = {}
    for k in range(film_scene.frame_count):
        render_frame(film_scene, k, folder / f"{k:04d}.png", threads=1)
        frames[k] = (folder / f"{k:04d}.png").read_bytes()
    return frames


def other_whitted(tmp_path: Path, module: str = "kernels/integrator.py") -> Path:
    """A copy of whitted's sources with one line of ``module`` changed."""
    copy = tmp_path / "other-src"
    shutil.copytree(SRC, copy, ignore=shutil.ignore_patterns("__pycache__"))
    changed = copy / "whitted" / module
    changed.write_text(changed.read_text() + "\nCHANGED_ON_THIS_WORKER = 1\n")
    return copy


def no_whitted(tmp_path: Path) -> Path:
    """A folder that, first on PYTHONPATH, makes ``import whitted`` fail as if it were not
    installed."""
    shadow = tmp_path / "no-whitted/whitted"
    shadow.mkdir(parents=True)
    (shadow / "__init__.py").write_text(
        "raise ModuleNotFoundError(\"No module named 'whitted'\", name='whitted')\n")
    return shadow.parent


@pytest.fixture
def scheduler():
    """A ``dask scheduler`` on 127.0.0.1 and a function starting ``dask worker``s for it."""
    port = free_port()
    with processes() as start:
        proc = start([*SCHEDULER, "--host", "127.0.0.1", "--port", str(port),
                      "--dashboard-address", ":0"], env=env_with())
        address = f"tcp://127.0.0.1:{port}"
        wait_for(lambda: _listening(port) or proc.poll() is not None, "the scheduler")
        assert proc.poll() is None

        def worker(*args: str, pythonpath: str | None = None, **env: str) -> subprocess.Popen:
            return start([*DASK, address, "--host", "127.0.0.1", "--nthreads", "1",
                          "--dashboard-address", ":0", *args],
                         env=env_with(pythonpath, NUMBA_NUM_THREADS="1", **env))

        yield address, worker, proc


def _listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=1):
            return True
    except OSError:
        return False


def workers_of(client) -> dict[str, dict]:
    return client.scheduler_info(n_workers=-1)["workers"]


# ------------------------------------------------------------------------------ fingerprint


def test_a_frame_records_its_renderer_and_another_renderers_frame_is_not_current(
        film_scene, tmp_path):
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    from whitted.animation.frames import frame_digest, frame_is_current, still_for_frame

    path = tmp_path / "0003.png"
    render_frame(film_scene, 3, path, threads=1)
    with Image.open(path) as im:
        record = dict(im.text)
    assert record[FINGERPRINT_KEY] == renderer_fingerprint()
    assert renderer_fingerprint().startswith("whitted ")
    digest = frame_digest(still_for_frame(film_scene, 3), 3)
    assert frame_is_current(path, digest)
    info = PngInfo()  # the same frame, as another whitted would have recorded it
    for key, value in record.items():
        info.add_text(key, "whitted 0.0.9 kernels 0123456789abcdef"
                      if key == FINGERPRINT_KEY else value)
    with Image.open(path) as im:
        im.save(tmp_path / "other.png", pnginfo=info)
    assert not frame_is_current(tmp_path / "other.png", digest)


def test_a_worker_with_a_changed_non_kernel_module_gets_no_tasks_and_is_named(
        scheduler, film_scene, local_frames, tmp_path):
    """Not only the kernels decide a frame's pixels: a worker whose scene interpolation
    differs from the client's is another renderer."""
    from whitted.fingerprint import fingerprint_fields, source_hash

    address, worker, _ = scheduler
    worker("--name", "good", pythonpath=str(SRC))
    other = other_whitted(tmp_path, "scene/interpolate.py")
    worker("--name", "other", pythonpath=str(other))
    notes: list[str] = []
    with distributed.Client(address) as client:
        client.wait_for_workers(2)
        ready = ready_cluster(client, WhittedWorker(threads=1), notes.append)
        by_name = {d["name"]: w for w, d in workers_of(client).items()}
        assert ready == [by_name["good"]]
        [line] = [n for n in notes if by_name["other"] in n]
        theirs = source_hash(other / "whitted")
        ours = fingerprint_fields(renderer_fingerprint())["source"]
        assert theirs != ours
        assert line == (f"farm: worker {by_name['other']} runs another renderer (source "
                        f"{theirs}, the client's {ours}): it gets no tasks")
        result = farm_film(client, film_scene, tmp_path / "frames", chunk=1,
                             note=notes.append)
    assert notes == [line]  # named once: by the readying, not again by the film
    assert set(result.report.workers.values()) == {by_name["good"]}
    for k in range(8):
        data = (tmp_path / "frames" / f"{k:04d}.png").read_bytes()
        assert data == local_frames[k]


def test_no_worker_with_this_whitted_is_one_line_naming_them(scheduler, tmp_path):
    address, worker, _ = scheduler
    worker("--name", "other", pythonpath=str(other_whitted(tmp_path)))
    worker("--name", "none", pythonpath=f"{no_whitted(tmp_path)}{os.pathsep}{SRC}")
    with distributed.Client(address) as client:
        client.wait_for_workers(2)
        by_name = {d["name"]: w for w, d in workers_of(client).items()}
        with pytest.raises(ClusterLost) as lost:
            ready_cluster(client, WhittedWorker(threads=1), None)
    message = str(lost.value)
    assert "\n" not in message and message.startswith("no worker can render: ")
    assert f"worker {by_name['other']} runs another renderer (source " in message
    assert (f"worker {by_name['none']} (none) cannot load whitted (ModuleNotFoundError: No "
            "module named 'whitted'; is whitted[farm] installed there?)") in message


# ------------------------------------------------------------------------------ hangs


def test_a_worker_without_whitted_joining_mid_film_is_named_and_does_not_hang_it(
        scheduler, film_scene, local_frames, tmp_path):
    address, worker, _ = scheduler
    worker("--name", "good", pythonpath=str(SRC))
    joined: list[subprocess.Popen] = []
    notes: list[str] = []
    with distributed.Client(address) as client:
        client.wait_for_workers(1)
        ready_cluster(client, WhittedWorker(threads=1), notes.append)
        assert notes == []

        def missing() -> list[dict]:
            return [m for _, m in client.get_events("whitted-worker")
                    if m.get("status") == "missing"]

        def join_one(done, total, frame) -> None:
            if joined:
                return
            joined.append(worker("--name", "bare",
                                 pythonpath=f"{no_whitted(tmp_path)}{os.pathsep}{SRC}"))
            # the film goes on only once the client named the bare worker (which then closes
            # itself at once: it cannot load the whitted plugin)
            wait_for(lambda: notes or joined[0].poll() is not None,
                     "the worker without whitted to be named")

        result = farm_film(client, film_scene, tmp_path / "frames", chunk=1,
                             progress=join_one, note=notes.append)
        good = {w for w, d in workers_of(client).items() if d["name"] == "good"}
        [event] = missing()
    assert joined and sorted(result.rendered) == list(range(8))
    assert set(result.report.workers.values()) == good
    assert event["name"] == "bare"
    # one line naming it (address and name) and what it lacks, once
    assert notes == [f"farm: worker {event['worker']} (bare) cannot load whitted "
                     "(ModuleNotFoundError: No module named 'whitted'; is whitted[farm] "
                     "installed there?): it gets no tasks"]
    for k in range(8):
        assert (tmp_path / "frames" / f"{k:04d}.png").read_bytes() == local_frames[k]


def _animate(scene: Path, output: Path, address: str, *extra: str,
             timeout: float = 300) -> subprocess.CompletedProcess:
    """``whitted animate`` on the scheduler at ``address`` (a hang guard of ``timeout``)."""
    return subprocess.run([sys.executable, "-m", "whitted", "animate", str(scene), "-o",
                           str(output), "--scheduler", address, *extra], capture_output=True,
                          text=True, timeout=timeout, env=env_with())


def _wait_for_bare(address: str, name: str) -> str:
    """The address of the worker ``name`` once it has said it cannot load whitted and the
    scheduler lists it as closing (a worker that failed to start, which answers nothing)."""
    with distributed.Client(address) as client:
        def listed() -> str | None:
            said = {m["worker"] for _, m in client.get_events("whitted-worker")
                    if m.get("name") == name and m.get("status") == "missing"}
            for w, d in workers_of(client).items():
                if w in said and d.get("status") in ("closing", "closed", "failed"):
                    return w
            return None

        wait_for(lambda: listed() is not None, f"the worker {name} to fail to start")
        return listed()


def test_a_worker_without_whitted_joining_between_films_never_hangs_the_next(scheduler,
                                                                             tmp_path):
    """A worker that cannot load whitted joins a scheduler that ran a film (the plugins are
    registered there): it fails to start and stays listed, answering nothing. The next film
    names it once and renders on the healthy worker; with only such a worker left, the film
    ends at once with one line and exit status 3."""
    address, worker, _ = scheduler
    good = worker("--name", "good", pythonpath=str(SRC))
    scene = tmp_path / "film.toml"
    scene.write_text(FILM)
    with distributed.Client(address) as client:
        client.wait_for_workers(1)
    first = _animate(scene, tmp_path / "first", address, "--frames", "0:1", "-q")
    assert first.returncode == 0, first.stderr
    bare_path = f"{no_whitted(tmp_path)}{os.pathsep}{SRC}"
    worker("--name", "bare", pythonpath=bare_path)
    bare = _wait_for_bare(address, "bare")

    second = _animate(scene, tmp_path / "second", address, "--frames", "0:1")
    assert second.returncode == 0, second.stderr
    named = second.stderr.splitlines()  # warnings only: status and progress go to stdout
    assert named == [f"farm: worker {bare} (bare) cannot load whitted (ModuleNotFoundError: "
                     "No module named 'whitted'; is whitted[farm] installed there?): it gets "
                     "no tasks (it answers nothing: removed from the scheduler)"], second.stderr
    assert sorted(p.name for p in (tmp_path / "second").glob("*.png")) == ["0000.png",
                                                                          "0001.png"]
    for name in ("0000.png", "0001.png"):  # the same frames as the first film's
        assert ((tmp_path / "second" / name).read_bytes()
                == (tmp_path / "first" / name).read_bytes())

    os.killpg(good.pid, signal.SIGKILL)  # the healthy worker gone; a bare one joins
    with distributed.Client(address) as client:
        wait_for(lambda: not workers_of(client), "the healthy worker to be gone")
    worker("--name", "bare2", pythonpath=bare_path)
    bare2 = _wait_for_bare(address, "bare2")
    third = _animate(scene, tmp_path / "third", address, "--frames", "0:1", "-q",
                     timeout=120)
    assert third.returncode == 3, third.stderr
    assert third.stderr.strip().splitlines() == [
        f"error: no worker can render: worker {bare2} (bare2) cannot load whitted "
        "(ModuleNotFoundError: No module named 'whitted'; is whitted[farm] installed "
        "there?)"]


def test_a_stopped_worker_stalls_nothing_its_tasks_go_elsewhere(scheduler, film_scene,
                                                                 local_frames, tmp_path):
    address, worker, _ = scheduler
    for i in range(2):
        worker("--name", f"w{i}", pythonpath=str(SRC))
    notes: list[str] = []
    stopped: list[str] = []
    pids: dict[str, int] = {}
    try:
        with distributed.Client(address) as client:
            client.wait_for_workers(2)
            ready_cluster(client, WhittedWorker(threads=1), None)
            pids.update(client.run(os.getpid))
            # SIGSTOP before the film: the scheduler still counts the worker and gives it
            # tasks, which it holds without a word (an event, not a race with the frames)
            victim = sorted(pids)[0]
            os.kill(pids[victim], signal.SIGSTOP)
            stopped.append(victim)

            try:
                result = farm_film(client, film_scene, tmp_path / "frames", chunk=1,
                                     note=notes.append, stall_floor=2.0)
            except ClusterLost:
                print(notes)
                raise
    finally:
        for worker_pid in pids.values():
            with contextlib.suppress(ProcessLookupError):
                os.kill(worker_pid, signal.SIGCONT)  # the stopped worker, not its nanny
    assert stopped and sorted(result.rendered) == list(range(8))
    told = [n for n in notes if n.startswith(f"farm: worker {stopped[0]} ")]
    assert told and all("\n" not in n for n in told)  # it is named, in one line each
    for k in range(8):
        assert (tmp_path / "frames" / f"{k:04d}.png").read_bytes() == local_frames[k]


def test_a_killed_lone_worker_costs_retries_not_the_film(film_scene, local_frames, tmp_path):
    from whitted.farm import farm_client

    killed: list[int] = []
    with farm_client("local:1", threads=1) as client:
        pid = client.run(os.getpid)

        def kill_it(done, total, frame) -> None:
            if not killed:  # its nanny starts a new one: it has neither scene nor kernels
                os.kill(next(iter(pid.values())), signal.SIGKILL)
                killed.append(frame)

        result = farm_film(client, film_scene, tmp_path / "frames", chunk=1,
                             progress=kill_it)
        assert next(iter(client.run(os.getpid).values())) != next(iter(pid.values()))
    assert killed and sorted(result.rendered) == list(range(8))
    for k in range(8):
        assert (tmp_path / "frames" / f"{k:04d}.png").read_bytes() == local_frames[k]


def test_a_finished_frame_lost_with_its_worker_before_it_came_is_rendered_again(
        film_scene, local_frames, tmp_path, monkeypatch):
    """The race CI met: Dask says a task finished, then its lone worker dies before the
    result is fetched, and the future turns "lost" (Dask computes it again). That is no
    failed frame: the film waits for the new result."""
    from whitted.farm import farm_client
    from whitted.farm.watch import Watch

    killed: list[str] = []
    wait = Watch.wait

    def wait_then_kill(self, futures):
        done = wait(self, futures)
        if done and not killed:
            os.kill(next(iter(pid.values())), signal.SIGKILL)
            # the event: the client hears that the finished result is gone with its worker
            wait_for(lambda: any(f.status != "finished" for f in done), "a lost result", 60)
            killed.extend(f.status for f in done)
        return done

    monkeypatch.setattr(Watch, "wait", wait_then_kill)
    with farm_client("local:1", threads=1) as client:
        pid = client.run(os.getpid)
        result = farm_film(client, film_scene, tmp_path / "frames", chunk=1)
    assert "lost" in killed and not result.report.failed
    assert sorted(result.rendered) == list(range(8))
    for k in range(8):
        assert (tmp_path / "frames" / f"{k:04d}.png").read_bytes() == local_frames[k]


def test_a_local_worker_restarted_by_its_nanny_ignores_ctrl_c_too():
    """The workers of ``--cluster local:N`` ignore a terminal's Ctrl-C (the client stops
    them); one its nanny starts again after a kill is a new process, and ignores it too."""
    from whitted.farm import farm_client

    def handler() -> tuple[int, bool]:  # (the worker's pid, whether it ignores SIGINT)
        import os
        import signal

        return os.getpid(), signal.getsignal(signal.SIGINT) == signal.SIG_IGN

    with farm_client("local:1", threads=1) as client:
        [(first, ignored)] = client.run(handler).values()
        assert ignored
        os.kill(first, signal.SIGKILL)

        def restarted_and_ready() -> bool:
            try:
                [(pid, _)] = client.run(handler).values()
                [identity] = workers_of(client).values()
            except Exception:  # noqa: BLE001 - the nanny is starting it again
                return False
            return pid != first and identity.get("resources", {}).get("whitted", 0) > 0

        wait_for(restarted_and_ready, "the nanny to start the worker again")
        [(second, ignored)] = client.run(handler).values()
        assert second != first and ignored
        os.kill(second, signal.SIGINT)  # a terminal's Ctrl-C: nothing happens
        [(same, ignored)] = client.run(handler).values()
        assert same == second and ignored


def test_losing_every_worker_ends_in_one_line_keeping_the_frames(scheduler, film_scene,
                                                                 tmp_path):
    address, worker, _ = scheduler
    lone = worker("--name", "lone", "--no-nanny", pythonpath=str(SRC))
    with distributed.Client(address) as client:
        client.wait_for_workers(1)
        ready_cluster(client, WhittedWorker(threads=1), None)

        def kill_it(done, total, frame) -> None:
            if lone.poll() is None:
                lone.kill()
                lone.wait()

        with pytest.raises(ClusterLost) as lost:
            farm_film(client, film_scene, tmp_path / "frames", chunk=1, progress=kill_it,
                        stall_floor=3.0)
    # a task the killed worker had finished but not handed over goes back to any worker
    # (none is left): the watch, not the resubmission, ends it
    assert re.fullmatch(r"every worker was lost \(\d+ s without one\)", str(lost.value)), \
        str(lost.value)
    assert len(list((tmp_path / "frames").glob("*.png"))) >= 1


def test_losing_the_scheduler_ends_in_one_line_keeping_the_frames(scheduler, tmp_path):
    address, worker, scheduler_proc = scheduler
    worker("--name", "w", pythonpath=str(SRC))
    scene = tmp_path / "film.toml"
    scene.write_text(FILM.replace("frames = 8", "frames = 400"))
    with distributed.Client(address) as client:  # the worker ready before the command
        client.wait_for_workers(1)
    command = [sys.executable, "-m", "whitted", "animate", str(scene), "-o",
               str(tmp_path / "frames"), "--scheduler", address, "-q"]
    run = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True, env=env_with())
    try:
        wait_for(lambda: any((tmp_path / "frames").glob("*.png")) or run.poll() is not None,
                 "the first frame")
        scheduler_proc.kill()
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 3, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    # where the scheduler was and what is kept; not Dask's text of the broken connection
    assert re.fullmatch(rf"error: lost the connection to the scheduler at {address} \(\d+ of "
                        rf"400 frames are in {re.escape(str(tmp_path / 'frames'))}\)",
                        lines[0]), lines[0]
    assert len(list((tmp_path / "frames").glob("*.png"))) >= 1


def test_an_unreachable_scheduler_is_one_line_at_once(tmp_path):
    port = free_port()  # nothing listens there: the connection is refused
    result = subprocess.run([sys.executable, "-m", "whitted", "render", "-W", "8", "-H", "8",
                             "-o", str(tmp_path / "x.png"), "--scheduler",
                             f"tcp://127.0.0.1:{port}"], capture_output=True, text=True,
                            timeout=120, env=env_with())
    assert result.returncode == 3
    assert result.stderr.strip().splitlines() == [
        f"error: --scheduler tcp://127.0.0.1:{port}: cannot reach the scheduler "
        "(Connection refused)"]
    assert not (tmp_path / "x.png").exists()
    bad = subprocess.run([sys.executable, "-m", "whitted", "render", "-o",
                          str(tmp_path / "x.png"), "--scheduler", "head-node"],
                         capture_output=True, text=True, timeout=120, env=env_with())
    assert bad.returncode == 2
    assert bad.stderr.strip() == ("error: --scheduler head-node: not an address "
                                  "tcp://HOST:PORT")


# ------------------------------------------------------------------------------ telling


def test_a_cold_worker_says_it_is_compiling_with_progress(scheduler):
    from whitted.farm import Watch
    from whitted.farm.worker import EVENT_TOPIC

    address, _, _ = scheduler
    notes: list[str] = []
    with distributed.Client(address) as client:
        watch = Watch(client, notes.append)
        try:
            def compiling(fraction: float) -> None:  # what a compiling worker's plugin logs
                client.log_event(EVENT_TOPIC, {"worker": "tcp://10.0.0.7:40000",
                                               "status": "compiling", "fraction": fraction})

            # the subscription travels apart from log_event: the first event until it is heard
            wait_for(lambda: compiling(0.05) or notes, "the subscription")
            for fraction in (0.08, 0.35, 0.99):
                compiling(fraction)
            wait_for(lambda: len(notes) == 3, "three notes")
        finally:
            watch.close()
    assert notes == [f"farm: worker tcp://10.0.0.7:40000 is compiling the kernels (a cold "
                     f"cache: first run of this whitted there): {p}%" for p in (0, 30, 90)]


def test_a_still_stopped_part_way_keeps_the_bands_that_arrived(scheduler, film_scene):
    import threading

    import numpy as np

    from whitted.farm import render_still
    from whitted.render.api import RenderJob

    address, worker, _ = scheduler
    worker("--name", "w", pythonpath=str(SRC))
    still = film_scene.at_frame(0).with_settings(width=40, height=64)
    stop = threading.Event()
    with distributed.Client(address) as client:
        client.wait_for_workers(1)
        ready_cluster(client, WhittedWorker(threads=1), None)
        image = render_still(client, still, bands=4, cancel=stop,
                             progress=lambda done, total: stop.set())
    stats = image.meta["stats"]
    local = RenderJob(still, threads=1).run().pixels
    assert stats.tiles_total == 4 and stats.tiles_done >= 1
    assert stats.cancelled == (stats.tiles_done < 4)
    from whitted.farm import band_ranges

    same = 0
    for a, b in band_ranges(64, 4):  # each band is the local rows, or black (not arrived)
        if np.array_equal(image.pixels[a:b], local[a:b]):
            same += 1
        else:
            assert not image.pixels[a:b].any()
    assert same >= stats.tiles_done


@pytest.mark.parametrize("floor", [0, -1.0, float("nan"), float("inf"), "30"])
def test_a_stall_floor_is_a_positive_number_of_seconds(scheduler, floor):
    from whitted.farm import Watch

    address, _, _ = scheduler
    with distributed.Client(address) as client, pytest.raises(ValueError, match="stall_floor"):
        Watch(client, stall_floor=floor)
