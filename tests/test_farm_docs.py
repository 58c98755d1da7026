"""docs/farm.md works when followed: every ``dask scheduler`` / ``dask worker`` command in it
(shell lines, the Dockerfile, the Kubernetes YAML) uses options the installed ``dask`` command
has; every ``whitted`` command uses options whitted has; and the SSH recipe, with 127.0.0.1
for its hosts and free ports for its pinned ones, renders a film."""

from __future__ import annotations

import json
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import time
from functools import cache
from pathlib import Path

import pytest

pytest.importorskip("distributed")

DOC = Path(__file__).resolve().parents[1] / "docs" / "farm.md"
DASK = str(Path(sys.executable).parent / "dask")


def blocks() -> list[tuple[str, str]]:
    """(language, text) of every fenced block of the doc."""
    return re.findall(r"^```(\w*)\n(.*?)^```", DOC.read_text(), flags=re.S | re.M)


def commands() -> list[list[str]]:
    """Every command line of the doc's blocks, as words: shell lines (continuations joined,
    ``ssh host '...'`` unwrapped), Dockerfile RUN/CMD, and the YAML ``args:`` lists."""
    found = []
    for language, text in blocks():
        text = text.replace("\\\n", " ")
        if language == "yaml":
            for args in re.findall(r"args: \[(.*?)\]", text, flags=re.S):
                found.append([w.strip().strip('"') for w in args.replace("\n", " ").split(",")])
            continue
        if language in ("python", "text"):  # code; what a program prints
            continue
        for line in text.splitlines():
            line = line.split(" #")[0].strip()
            if line.startswith("CMD ["):
                found.append(json.loads(line[4:]))
                continue
            line = re.sub(r"^RUN ", "", line)
            if not re.match(r"(\w+=\S+ )*(dask|whitted|ssh) ", line):
                continue  # output shown, other tools
            for part in re.split(r"&&|;", line):
                words = shlex.split(part.replace("$(nproc)", "4"), comments=True)
                if words[:1] == ["ssh"]:
                    words = shlex.split(words[2])
                while words and "=" in words[0]:  # VAR=value before the command
                    words = words[1:]
                if words:
                    found.append(words)
    return found


@cache
def help_text(*command: str) -> str:
    result = subprocess.run([*command, "--help"], capture_output=True, text=True, timeout=120,
                            env=dict(os.environ, COLUMNS="200"))
    assert result.returncode == 0, result.stderr
    return result.stdout


def options(words: list[str]) -> list[str]:
    return [w.split("=")[0] for w in words if w.startswith("--")]


def test_the_doc_has_its_cluster_commands():
    found = [c[:2] for c in commands()]
    assert ["dask", "scheduler"] in found and ["dask", "worker"] in found
    assert not [c for c in commands() if c[0] in ("dask-worker", "dask-scheduler")]
    assert sum(1 for c in commands() if c[:2] == ["dask", "worker"]) >= 3  # ssh, image, k8s


@pytest.mark.parametrize("sub", ["scheduler", "worker"])
def test_every_dask_command_in_the_doc_uses_options_dask_has(sub):
    text = help_text(DASK, sub)
    for words in commands():
        if words[:2] == ["dask", sub]:
            for option in options(words):
                assert re.search(rf"(^|[\s/]){re.escape(option)}\b", text, flags=re.M), (
                    f"docs/farm.md: dask {sub} has no option {option}")


def test_every_whitted_command_in_the_doc_uses_options_whitted_has():
    seen = 0
    for words in commands():
        if words[0] != "whitted":
            continue
        text = help_text(sys.executable, "-m", "whitted", words[1])
        for option in options(words):
            assert option in text, f"docs/farm.md: whitted {words[1]} has no option {option}"
        seen += 1
    assert seen >= 5


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=1):
            return True
    except OSError:
        return False


def certificates(folder: Path) -> dict[str, Path]:
    """The doc's openssl commands, run in ``folder``: the farm's certificate authority and one
    certificate for its machines (``ca.pem``, ``farm.pem``, ``farm.key``); and an intruder's
    certificate that no one signed (``intruder.pem``, ``intruder.key``)."""
    import shutil

    if shutil.which("openssl") is None:
        pytest.skip("needs the openssl command")
    [script] = [text for language, text in blocks() if language == "sh"
                and "openssl req" in text]
    lines = [line for line in script.replace("\\\n", " ").splitlines()
             if line.strip() and not line.startswith("#")]
    lines.append("openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes "
                 "-days 2 -subj /CN=intruder -keyout intruder.key -out intruder.pem")
    for line in lines:
        subprocess.run(shlex.split(line), cwd=folder, check=True, capture_output=True,
                       timeout=60)
    return {name: folder / name for name in ("ca.pem", "farm.pem", "farm.key",
                                            "intruder.pem", "intruder.key")}


def tls_client(certs: dict[str, Path], cert: str = "farm") -> dict[str, str]:
    """The doc's client settings (Dask's environment variables)."""
    return {"DASK_DISTRIBUTED__COMM__TLS__CA_FILE": str(certs["ca.pem"]),
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": str(certs[f"{cert}.pem"]),
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": str(certs[f"{cert}.key"])}


def test_the_ssh_recipe_on_one_machine_renders_a_film_over_tls(tmp_path):
    """The doc's commands (scheduler, worker, client, all over TLS with the doc's
    certificates), hosts 127.0.0.1 and free ports for the pinned ones: the film renders; a
    client with a certificate the farm did not sign is refused in one line, and so is one
    with no certificate at all."""
    certs = certificates(tmp_path)
    tls = ["--tls-ca-file", str(certs["ca.pem"]), "--tls-cert", str(certs["farm.pem"]),
           "--tls-key", str(certs["farm.key"])]
    port, worker_port, nanny_port = free_port(), free_port(), free_port()
    env = dict(os.environ, WHITTED_FARM_CACHE=str(tmp_path / "assets"), NUMBA_NUM_THREADS="1")
    address = f"tls://127.0.0.1:{port}"
    started = []
    try:
        started.append(subprocess.Popen(
            [DASK, "scheduler", "--protocol", "tls", "--host", "127.0.0.1", "--port",
             str(port), "--no-dashboard", *tls], env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL))
        started.append(subprocess.Popen(
            [DASK, "worker", address, "--host", "127.0.0.1", "--nworkers",
             "1", "--nthreads", "2", "--worker-port", str(worker_port), "--nanny-port",
             str(nanny_port), "--no-dashboard", "--local-directory",
             str(tmp_path / "dask"), *tls], env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL))
        end = time.monotonic() + 120
        while not (listening(worker_port) and listening(nanny_port)):
            assert time.monotonic() < end, "the worker did not start on its pinned ports"
            time.sleep(0.05)
        scene = tmp_path / "film.toml"
        scene.write_text(FILM)

        def animate(client_env: dict[str, str], output: str) -> subprocess.CompletedProcess:
            return subprocess.run(
                [sys.executable, "-m", "whitted", "animate", str(scene), "-o",
                 str(tmp_path / output), "--scheduler", address], capture_output=True,
                text=True, timeout=300, env=dict(env, **client_env))

        result = animate(tls_client(certs), "film_frames")
        intruder = animate(tls_client(certs, "intruder"), "intruder_frames")
        bare = animate({}, "bare_frames")
    finally:
        for proc in reversed(started):
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
    assert result.returncode == 0, result.stderr
    # one worker process with 2 Dask threads, on the pinned port
    assert f"farm: 1 worker (2 Dask threads) at {address}" in result.stdout
    assert "4 frames (4 rendered" in result.stdout
    assert len(list((tmp_path / "film_frames").glob("*.png"))) == 4
    assert intruder.returncode == 3
    assert intruder.stderr.strip().splitlines() == [
        f"error: --scheduler {address}: the scheduler refused this client's TLS connection "
        "(its certificate must be signed by the farm's certificate authority; docs/farm.md)"]
    assert bare.returncode == 2
    assert bare.stderr.strip().splitlines() == [
        f"error: --scheduler {address}: a TLS scheduler needs this client's certificate: set "
        "DASK_DISTRIBUTED__COMM__TLS__CA_FILE, DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT and "
        "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY (Dask's distributed.comm.tls settings; "
        "docs/farm.md)"]
    for refused in ("intruder_frames", "bare_frames"):
        assert not any((tmp_path / refused).glob("*.png"))


FILM = """
[render]
width = 16
height = 12
samples = 1

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
type = "sphere"
center = [0, 0.5, 0]
radius = 0.5

[animation]
frames = 4
fps = 12

[[animation.tracks]]
path = "camera.position"
keys = [[0, [0, 1.5, 5]], [3, [3, 1.5, 4]]]
"""


def test_the_python_local_cluster_recipe_renders_the_local_film(tmp_path):
    """The doc's Python block, as written but for a small film and no poster: a LocalCluster
    on loopback, readied, the film pipeline with the farm's executor; its frames are the
    frames a local render writes, byte for byte."""
    from whitted import load_scene
    from whitted.animation.film import render_film

    [code] = [text for language, text in blocks() if language == "python"
              and "LocalCluster(" in text]
    assert "with_settings(width=1920, height=1080)" in code
    code = code.replace("with_settings(width=1920, height=1080)", "with_settings()")
    code = "\n".join(line for line in code.splitlines() if "poster" not in line)
    (tmp_path / "film.toml").write_text(FILM)
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600, env=dict(os.environ, NUMBA_NUM_THREADS="1"))
    assert run.returncode == 0, run.stderr
    import ast

    # print(result.rendered, result.kept, result.report.tasks, result.report.workers)
    match = re.fullmatch(r"(\[[^\]]*\]) \[\] (\d+) (\{.*\})", run.stdout.splitlines()[-1])
    assert match, run.stdout
    rendered, workers = ast.literal_eval(match[1]), ast.literal_eval(match[3])
    assert sorted(rendered) == [0, 1, 2, 3] and int(match[2]) >= 1
    assert sorted(workers) == [0, 1, 2, 3]
    assert all(w.startswith("tcp://127.0.0.1:") for w in workers.values())
    assert (tmp_path / "film.mp4").stat().st_size > 0
    local = render_film(load_scene(tmp_path / "film.toml"), tmp_path / "local", threads=1)
    assert local.rendered == [0, 1, 2, 3]
    for path in local.files:
        assert (tmp_path / "film_frames" / path.name).read_bytes() == path.read_bytes()


# ------------------------------------------------------------------ the container recipe

NOBODY = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"]  # uid/gid nobody
SRC = Path(__file__).resolve().parents[1] / "src"
#: runs the command line with a listener of Numba's compile events: one line ``COMPILE
#: <kernel>`` on stdout for each kernel compiled (a kernel loaded from the cache is not)
COUNTING = """
import sys
from numba.core import event

class Seen(event.Listener):
    def on_start(self, ev):
        print("COMPILE", ev.data["dispatcher"].py_func.__qualname__, flush=True)
    def on_end(self, ev):
        pass

event.register("numba:compile", Seen())
from whitted.cli.main import main
sys.argv[0] = "whitted"
main()
"""


def dockerfile() -> str:
    [text] = [text for language, text in blocks() if language == "dockerfile"]
    return text.replace("\\\n", " ")


def as_nobody(args: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*NOBODY, sys.executable, *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=600)


def _snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*"))}


@pytest.fixture
def open_folder():
    """A folder in /tmp that the user nobody can enter (pytest's tmp_path is root's only)."""
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="whitted-image-"))
    folder.chmod(0o755)
    try:
        yield folder
    finally:
        shutil.rmtree(folder)


def test_the_container_recipe_renders_from_its_read_only_cache_as_another_user(open_folder):
    """The Dockerfile's build steps as written (its warm-up render, its chmod; the image's
    paths moved into a temporary folder), then renders as another user (nobody, through
    setpriv) with that cache read-only: the kernels load from it (no compile), nothing is
    written there, no warning; a kernel the image did not warm (the AOV kernel) is compiled
    in memory with one warning line, and the render still succeeds."""
    import shutil

    from whitted.jit import cache as _cache
    from whitted.render.warm_up import warm_up_kernels

    if os.geteuid() != 0 or shutil.which("setpriv") is None:
        pytest.skip("needs root and setpriv to run as another user")
    base = open_folder
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "WHITTED_CACHE_DIR")}
    env.update(PYTHONPATH=str(SRC), HOME="/nonexistent")  # nobody's home: no cache to fall to
    probe = as_nobody(["-c", "import numba, whitted"], env, base)
    if probe.returncode != 0:
        pytest.skip(f"user nobody cannot run this Python: {probe.stderr.strip()[-200:]}")

    text = dockerfile()
    [cache_dir] = re.findall(r"^ENV WHITTED_CACHE_DIR=(\S+)$", text, flags=re.M)
    [build] = [line[4:] for line in text.splitlines()
               if line.startswith("RUN ") and "whitted render" in line]
    steps = [shlex.split(step.replace(cache_dir, str(base / "cache"))
                         .replace("/tmp/warm.png", str(base / "warm.png")))
             for step in build.split("&&")]
    assert [s[0] for s in steps] == ["whitted", "rm", "chmod"]  # warm, tidy, read-only
    # the build's warm-up starts from this session's warm folder (a copy: no cold compile
    # here), less the AOV kernel, which the recipe's warm-up does not compile
    warm_up_kernels()
    session = Path(_cache.prepare().folder)
    shutil.copytree(session, base / "cache" / session.name,
                    ignore=shutil.ignore_patterns("whitted.lock", "*render_aovs*"))
    build_env = dict(env, WHITTED_CACHE_DIR=str(base / "cache"), HOME=os.environ["HOME"])
    warm = subprocess.run([sys.executable, "-m", *steps[0]], capture_output=True, text=True,
                          env=build_env, timeout=600)
    assert warm.returncode == 0 and warm.stderr == "", warm.stderr
    reference = (base / "warm.png").read_bytes()
    subprocess.run(steps[2], check=True)  # the recipe's chmod (rm: the next render's -o)
    folder = base / "cache" / session.name
    assert not any(p.stat().st_mode & 0o222 for p in folder.rglob("*"))
    before = _snapshot(folder)
    out = base / "out"
    out.mkdir()
    out.chmod(0o777)
    run_env = dict(env, WHITTED_CACHE_DIR=str(base / "cache"))
    args = ["-c", COUNTING, *steps[0][1:]]
    args[args.index(str(base / "warm.png"))] = str(out / "frame.png")

    run = as_nobody(args, run_env, out)
    assert run.returncode == 0, run.stderr
    assert run.stdout == "" and run.stderr == ""  # nothing compiled, no warning
    assert (out / "frame.png").read_bytes() == reference
    assert _snapshot(folder) == before

    aov = as_nobody([*args, "--aov", "depth"], run_env, out)  # a kernel the image lacks
    assert aov.returncode == 0, aov.stderr
    assert "COMPILE render_aovs" in aov.stdout.splitlines()
    lines = aov.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        f"warning: kernel cache folder {folder} cannot be written"), aov.stderr
    assert _snapshot(folder) == before
