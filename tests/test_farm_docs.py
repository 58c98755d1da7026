"""docs/farm.md works when followed: every ``dask scheduler`` / ``dask worker`` command in it
(shell lines, the Dockerfile, the Kubernetes YAML) uses options the installed ``dask`` command
has; every ``whitted`` command uses options whitted has; and the SSH recipe, with 127.0.0.1
for its hosts and free ports for its pinned ones, renders a film (issue 26)."""

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
        if language == "python":
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


def test_the_ssh_recipe_on_one_machine_renders_a_film(tmp_path):
    """The doc's three commands, hosts 127.0.0.1 and free ports for the pinned ones."""
    port, worker_port, nanny_port = free_port(), free_port(), free_port()
    env = dict(os.environ, WHITTED_FARM_CACHE=str(tmp_path / "assets"), NUMBA_NUM_THREADS="1")
    started = []
    try:
        started.append(subprocess.Popen(
            [DASK, "scheduler", "--host", "127.0.0.1", "--port", str(port),
             "--dashboard-address", ":0"], env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL))
        started.append(subprocess.Popen(
            [DASK, "worker", f"tcp://127.0.0.1:{port}", "--host", "127.0.0.1", "--nworkers",
             "1", "--nthreads", "2", "--worker-port", str(worker_port), "--nanny-port",
             str(nanny_port), "--dashboard-address", ":0", "--local-directory",
             str(tmp_path / "dask")], env=env, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL))
        end = time.monotonic() + 120
        while not (listening(worker_port) and listening(nanny_port)):
            assert time.monotonic() < end, "the worker did not start on its pinned ports"
            time.sleep(0.05)
        scene = tmp_path / "film.toml"
        scene.write_text(FILM)
        result = subprocess.run(
            [sys.executable, "-m", "whitted", "animate", str(scene), "-o",
             str(tmp_path / "film_frames"), "--scheduler", f"tcp://127.0.0.1:{port}"],
            capture_output=True, text=True, timeout=300, env=env)
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
    assert f"farm: 1 worker (2 Dask threads) at tcp://127.0.0.1:{port}" in result.stderr
    assert "4 frames (4 rendered" in result.stdout
    assert len(list((tmp_path / "film_frames").glob("*.png"))) == 4


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
