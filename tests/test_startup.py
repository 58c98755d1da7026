"""Start-up: what ``import whitted``, the CLI and a plain render import, and kernels loaded
from the on-disk cache without Numba's compiler registries.

Each check runs in a fresh interpreter (``sys.modules`` of this test process holds whatever
the other tests imported). Times are not asserted here: they live in ``whitted bench`` and
docs/performance.md.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import whitted

REPO_ROOT = Path(__file__).resolve().parents[1]
HEAVY_EXTRAS = ("PySide6", "matplotlib", "dask", "distributed", "embreex")


def _modules_after(code: str, tmp_path: Path, **settings: str) -> set[str]:
    """The top-level packages imported once ``code`` has run in a fresh interpreter (with
    these environment ``settings``)."""
    script = textwrap.dedent(code) + textwrap.dedent("""
        import json, sys
        print("MODULES=" + json.dumps(sorted({m.split(".")[0] for m in sys.modules})))
    """)
    env = {**os.environ, **settings}
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO_ROOT / "src"), *filter(None, [env.get("PYTHONPATH")])])
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            cwd=tmp_path, env=env, timeout=600)
    assert result.returncode == 0, result.stderr
    line = next(x for x in result.stdout.splitlines() if x.startswith("MODULES="))
    return set(json.loads(line.removeprefix("MODULES=")))


def test_import_whitted_imports_no_numba_no_pydantic(tmp_path):
    loaded = _modules_after("import whitted", tmp_path)
    assert "whitted" in loaded
    for heavy in ("numba", "numpy", "pydantic", "rich", "typer", *HEAVY_EXTRAS):
        assert heavy not in loaded, f"import whitted imported {heavy}"


def test_cli_module_imports_no_numba_pydantic_or_rich(tmp_path):
    loaded = _modules_after("import whitted.cli.main", tmp_path)
    assert "typer" in loaded
    for heavy in ("numba", "numpy", "pydantic", "rich", "PIL", "trimesh", *HEAVY_EXTRAS):
        assert heavy not in loaded, f"import whitted.cli.main imported {heavy}"


def test_plain_render_imports_no_gui_plots_or_farm(tmp_path):
    out = tmp_path / "x.png"
    loaded = _modules_after(f"""
        from whitted.cli.main import app
        app(["render", {str(REPO_ROOT / "examples" / "glass_cube.toml")!r}, "-W", "24",
             "-H", "16", "-q", "-o", {str(out)!r}], standalone_mode=False)
    """, tmp_path)
    assert out.stat().st_size > 0
    for heavy in HEAVY_EXTRAS:
        assert heavy not in loaded, f"whitted render imported {heavy}"


def test_warm_render_to_a_pipe_imports_no_rich(tmp_path):
    """A render whose output is not a terminal prints its summary line without rich
    (cli/console.py). The first run may compile."""
    out = tmp_path / "x.png"
    code = f"""
        import sys
        from whitted.cli.main import app
        app(["render", {str(REPO_ROOT / "benchmarks" / "seed000.toml")!r}, "-W", "40",
             "-H", "30", "-o", {str(out)!r}], standalone_mode=False)
    """
    _modules_after(code, tmp_path)  # may compile
    loaded = _modules_after(code, tmp_path)
    assert out.stat().st_size > 0
    assert "rich" not in loaded


def _run_main(argv: list[str]) -> str:
    """``whitted ARGV`` run by the command's own entry point, in the checking process."""
    return f"""
        import sys
        import whitted.cli.main as main
        main.EXIT_AT_ONCE_WHEN_ABANDONED = False  # back here, to list what was imported
        sys.argv = ["whitted", *{argv!r}]
        try:
            main.main()
        except SystemExit as exc:
            assert exc.code in (0, None), exc.code
    """


def test_a_render_looks_for_no_pydantic_plugins(tmp_path):
    """``whitted render`` validates its scene without pydantic's search of every installed
    distribution for plugins (cli/main.py); a user's own setting is kept."""
    out = tmp_path / "x.png"
    code = _run_main(["render", str(REPO_ROOT / "examples" / "glass_cube.toml"), "-W", "24",
                      "-H", "16", "-q", "-o", str(out)]) + """
        from pydantic.plugin import _loader
        assert _loader._plugins is None, "searched for plugins"
        import os
        print("SETTING=" + os.environ["PYDANTIC_DISABLE_PLUGINS"])
    """
    loaded = _modules_after(code, tmp_path)
    assert out.stat().st_size > 0 and "pydantic" in loaded
    script = textwrap.dedent(code).replace('assert _loader._plugins is None, "searched for '
                                           'plugins"', "")
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT / "src"), "PYDANTIC_DISABLE_PLUGINS": ""}
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=tmp_path, env=env, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "SETTING=\n" in run.stdout


def test_a_warm_render_imports_no_file_lock_library(tmp_path):
    """A render whose kernels are all in the cache, as sealed, checks the cache without its
    lock (jit/cache.py): filelock is not imported (21 modules). The first run may compile;
    a copy of the warm cache keeps other processes' compiles out of the check."""
    import shutil

    from whitted.jit.cache import prepare

    warm = Path(prepare().folder)
    cache = tmp_path / "cache"
    if warm.is_dir():
        shutil.copytree(warm, cache / warm.name, ignore=shutil.ignore_patterns("whitted.lock"))
    out = tmp_path / "x.png"
    code = _run_main(["render", str(REPO_ROOT / "benchmarks" / "seed000.toml"), "-W", "24",
                      "-H", "16", "-q", "-o", str(out)])
    settings = {"WHITTED_CACHE_DIR": str(cache), "NUMBA_CACHE_DIR": ""}
    _modules_after(code, tmp_path, **settings)  # may compile
    loaded = _modules_after(code, tmp_path, **settings)
    assert out.stat().st_size > 0 and "numba" in loaded
    assert "filelock" not in loaded


def test_a_warm_render_needs_neither_numbas_runtime_nor_its_array_code(tmp_path):
    """The render kernels and the builders of a warm render (BVH, wide BVH, OBJ reader,
    light buffers) are compiled without Numba's runtime and allocate nothing: loading them
    neither compiles the runtime's functions (``rtsys.library`` is not made) nor imports
    Numba's NumPy array code (``numba.np.arrayobj``, with its string and hashing code)."""
    import shutil

    from whitted.jit.cache import prepare

    warm = Path(prepare().folder)
    cache = tmp_path / "cache"
    if warm.is_dir():
        shutil.copytree(warm, cache / warm.name, ignore=shutil.ignore_patterns("whitted.lock"))
    out = tmp_path / "x.png"
    code = textwrap.dedent(_run_main(["render", str(REPO_ROOT / "benchmarks" / "seed000.toml"),
                                      "-W", "24", "-H", "16", "-q", "-o", str(out)]))
    code += textwrap.dedent("""
        from numba.core.runtime.nrt import rtsys
        try:
            rtsys.library
            print("RUNTIME=made")
        except RuntimeError:
            print("RUNTIME=none")
        print("ARRAYOBJ=" + str("numba.np.arrayobj" in sys.modules))
    """)
    settings = {"WHITTED_CACHE_DIR": str(cache), "NUMBA_CACHE_DIR": ""}
    env = {**os.environ, **settings}
    env["PYTHONPATH"] = os.pathsep.join(
        [str(REPO_ROOT / "src"), *filter(None, [env.get("PYTHONPATH")])])
    for _ in range(2):  # the first run may compile
        result = subprocess.run([sys.executable, "-c", code],
                                capture_output=True, text=True, cwd=tmp_path, env=env,
                                timeout=600)
        assert result.returncode == 0, result.stderr
    assert out.stat().st_size > 0
    assert "RUNTIME=none" in result.stdout and "ARRAYOBJ=False" in result.stdout, result.stdout


@pytest.mark.parametrize("scene, options", [
    ("seed000", []), ("caustics", ["--set", "render.caustics.photons=3000"])])
def test_a_warm_render_imports_no_masked_arrays(tmp_path, scene, options):
    """Numba types array arguments without importing NumPy's masked arrays
    (jit/dispatcher.py), and the photon map's set-up uses nothing that imports them:
    ``numpy.ma`` (8-13 ms) is no part of a warm render, with caustics or without."""
    import shutil

    from whitted.jit.cache import prepare

    warm = Path(prepare().folder)
    cache = tmp_path / "cache"
    if warm.is_dir():
        shutil.copytree(warm, cache / warm.name, ignore=shutil.ignore_patterns("whitted.lock"))
    out = tmp_path / "x.png"
    code = textwrap.dedent(_run_main([
        "render", str(REPO_ROOT / "benchmarks" / f"{scene}.toml"), "-W", "24", "-H", "16",
        "-q", "-o", str(out), *options]))
    settings = {"WHITTED_CACHE_DIR": str(cache), "NUMBA_CACHE_DIR": ""}
    _modules_after(code, tmp_path, **settings)  # may compile
    loaded = _modules_after(code + "\nassert 'numpy.ma' not in sys.modules, 'numpy.ma'\n",
                            tmp_path, **settings)
    assert out.stat().st_size > 0 and "numba" in loaded


def test_plain_line_is_what_rich_prints_and_needs_no_rich(tmp_path, monkeypatch):
    """cli/console.py writes a plain line to a file that is not a terminal itself: the same
    bytes rich writes for it (markup and emoji codes stay literal)."""
    import io

    # as in a command's process (a Jupyter kernel started by another test imports ipykernel
    # here, and in a kernel the answer is left to rich)
    monkeypatch.delitem(sys.modules, "ipykernel", raising=False)

    from rich.console import Console
    from rich.text import Text

    from whitted.cli.console import LazyConsole

    for text in ("809x817: wall 0.38 s -> out.png", "[bold]not markup[/bold] :100:",
                 "warning: \u00e9t\u00e9 \u2192 \u6f22\u5b57", "x" * 300, "", "a\tb",
                 "cr\rhere \x07\x0b\x0c"):
        ours, theirs = io.StringIO(), io.StringIO()
        LazyConsole(file=ours, highlight=False, soft_wrap=True, emoji=False).echo(text)
        Console(file=theirs, highlight=False, soft_wrap=True, emoji=False).print(
            Text(text), soft_wrap=True)
        assert ours.getvalue() == theirs.getvalue()
        assert ours.getvalue() == text + "\n" or not text.isprintable()
    console = LazyConsole(file=io.StringIO())
    assert console.is_terminal is False and console._made is None  # rich not needed
    loaded = _modules_after("""
        from whitted.cli.console import out, err
        out.echo("plain")
        assert not err.is_terminal
    """, tmp_path)
    assert "rich" not in loaded


def test_numba_imported_through_whitted_skips_its_scipy_and_yaml_probes(tmp_path):
    """Numba imports SciPy and PyYAML only to probe for them (jit/lean_numba.py): after
    ``import whitted`` they are skipped, and both still import afterwards."""
    loaded = _modules_after("""
        import whitted, sys
        import numba
        assert "scipy" not in sys.modules and "yaml" not in sys.modules, "probed"
        import scipy, yaml  # still importable, for scikit-image and Dask
        assert scipy.__version__ and yaml.safe_load("a: 1") == {"a": 1}
        from whitted.jit import lean_numba as _lean_numba
        assert _lean_numba._finder not in sys.meta_path  # one-shot: gone once numba is in
    """, tmp_path)
    assert {"numba", "scipy", "yaml"} <= loaded


def test_numba_imported_through_whitted_skips_its_coverage_probe(tmp_path):
    """Numba imports coverage.py to report compiled lines to a running measurement: through
    whitted it is skipped when coverage.py is not imported (no measurement can be running),
    and still importable afterwards; with coverage.py imported first (``coverage run``,
    pytest-cov), Numba sees it as without whitted."""
    pytest.importorskip("coverage")
    loaded = _modules_after("""
        import whitted, sys
        import numba
        from numba.misc import coverage_support
        assert "coverage" not in sys.modules, "probed"
        assert coverage_support.coverage_available is False
        import coverage
        assert coverage.Coverage
    """, tmp_path, COVERAGE_PROCESS_START="", COVERAGE_PROCESS_CONFIG="")  # not measured
    assert {"numba", "coverage"} <= loaded
    _modules_after("""
        import coverage
        import whitted
        import numba
        from numba.misc import coverage_support
        assert coverage_support.coverage_available is True
    """, tmp_path)


def test_numba_config_file_still_read_through_whitted(tmp_path):
    """With a ``.numba_config.yaml`` in the working folder PyYAML is imported, so Numba reads
    the user's settings as it would without whitted."""
    (tmp_path / ".numba_config.yaml").write_text("boundscheck: 1\n")
    loaded = _modules_after("""
        import whitted
        import numba
        assert numba.config.BOUNDSCHECK == 1, numba.config.BOUNDSCHECK
    """, tmp_path)
    assert "yaml" in loaded


def test_slp_vectoriser_stays_on_when_numba_was_imported_before_whitted(tmp_path):
    """Loading Numba through whitted (jit/decorators.py) turns LLVM's SLP vectoriser on. Numba
    reads its settings from the environment again before a compile once the environment has
    changed (whitted sets
    NUMBA_CACHE_DIR when Numba is already imported): the setting must survive that, or the
    kernels compiled then (and cached) run some 50 % slower."""
    _modules_after("""
        import os
        import numba
        from numba.core import config
        from whitted.jit import load_numba
        load_numba()
        assert config.SLP_VECTORIZE == 1
        os.environ["WHITTED_TEST_CHANGE"] = "1"  # any change: Numba re-reads everything
        config.reload_config()
        assert config.SLP_VECTORIZE == 1, "lost on re-reading the environment"
        assert numba.config.CACHE_DIR  # whitted's cache folder survives it too
    """, tmp_path)
    env = dict(os.environ, NUMBA_SLP_VECTORIZE="0")  # a user's own choice wins
    result = subprocess.run([sys.executable, "-c", "import numba, whitted.jit as j; "
                             "j.load_numba(); assert numba.config.SLP_VECTORIZE == 0"], env=env,
                            capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert result.returncode == 0, result.stderr


def test_public_api_resolves_every_name():
    for name in whitted.__all__:
        assert getattr(whitted, name) is not None, name
    assert set(whitted.__all__) <= set(dir(whitted))
    from whitted.scene.shapes import Sphere

    assert whitted.Sphere is Sphere
    importlib.import_module("whitted.render.warm_up")  # binds the subpackage to the name

    assert callable(whitted.render) and whitted.render.__name__ == "render"
    with pytest.raises(AttributeError, match="no attribute 'Spheer'"):
        _ = whitted.Spheer


def test_kernels_loaded_from_cache_then_a_new_kernel_compiles(tmp_path):
    """A render loads its kernels without Numba's compiler registries (with the tuned
    dispatcher: jit/dispatcher.py ``KernelCache``); a kernel compiled afterwards in the
    same process, using NumPy and math functions and calling a loaded kernel, must still
    compile and give the right value."""
    loaded = _modules_after("""
        import math
        import numpy as np
        import whitted
        from whitted.jit import kernel
        from whitted.kernels.vec import dot

        whitted.render(whitted.Scene(), width=8, height=8, threads=1)

        @kernel(cache=False)
        def fresh(a):
            s = 0.0
            for i in range(a.shape[0]):
                s += math.sqrt(a[i]) + np.sin(0.0)
            return s + dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))

        assert fresh(np.array([4.0, 9.0])) == 5.0 + 32.0
    """, tmp_path)
    assert "numba" in loaded


@pytest.mark.parametrize(("blocked", "args", "extra"), [
    ("PySide6", ["gui"], "gui"),
    ("matplotlib", ["bench", "--study", "threads", "--quick"], "plots"),
    ("embreex", ["bench", "--quick", "--scene", "sphere1m", "--compare", "embree"], "bench"),
])
def test_a_missing_extra_is_one_line_naming_it(tmp_path, blocked, args, extra):
    """Without an optional dependency the command says which extra to install (one line,
    status 2), instead of a traceback."""
    script = textwrap.dedent(f"""
        import sys
        sys.modules[{blocked!r}] = None  # as if it were not installed
        import importlib.util
        real_find_spec = importlib.util.find_spec
        importlib.util.find_spec = lambda name, *a: (
            None if name.split(".")[0] == {blocked!r} else real_find_spec(name, *a))
        sys.argv = ["whitted", *{args!r}]
        from whitted.program import main
        main()
    """)
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"))
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            cwd=tmp_path, env=env, timeout=120)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and f"pip install 'whitted[{extra}]'" in lines[0], result.stderr


@pytest.mark.timing  # "at once" is seconds, and a loaded machine may finish the compile
def test_cold_compile_reports_progress_and_stops_at_once_on_ctrl_c(tmp_path):
    """A first render on an empty cache: compile_progress() climbs from 0 while it runs, and
    Ctrl-C (SIGINT, here sent by the process to itself once the progress is above 0) ends
    the compile at once and the helper process with it."""
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"),
               WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    script = textwrap.dedent("""
        import os, signal, threading, time, json
        # Ctrl-C as in a terminal, whatever this test's parents ignore (a job started in the
        # background of a shell inherits SIGINT ignored)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        import whitted
        from whitted.render import warm_up

        seen = []
        sent = []
        def watch():  # Ctrl-C once the compile has visibly progressed
            while not sent:
                fraction = warm_up.compile_progress()
                seen.append(fraction)
                if fraction is not None and fraction > 0.0:
                    sent.append(time.perf_counter())
                    os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.1)
        threading.Thread(target=watch, daemon=True).start()
        try:
            whitted.render(whitted.Scene(), width=4, height=4, threads=1)
            print("RESULT=" + json.dumps({"finished": True}))
        except KeyboardInterrupt:
            stopped = time.perf_counter() - sent[0]
            helpers = []
            for p in os.listdir("/proc"):
                try:
                    with open(f"/proc/{p}/stat") as f:
                        parent = int(f.read().rsplit(")", 1)[1].split()[1])
                except (OSError, ValueError, IndexError):
                    continue
                if parent == os.getpid():
                    helpers.append(p)  # a child of this process still there
            fractions = [f for f in seen if f is not None]
            print("RESULT=" + json.dumps({"stopped_s": stopped, "helpers": helpers,
                                          "progress": max(fractions, default=None),
                                          "after": warm_up.compile_progress()}))
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            cwd=tmp_path, env=env, timeout=600)
    lines = [x for x in result.stdout.splitlines() if x.startswith("RESULT=")]
    assert lines, result.stderr[-2000:]
    line = lines[0]
    outcome = json.loads(line.removeprefix("RESULT="))
    assert "finished" not in outcome, "the compile ended before the interrupt"
    assert outcome["stopped_s"] < 3.0  # at once (Numba checks for signals between steps)
    assert outcome["helpers"] == []  # the helper was stopped, not waited for
    assert 0.0 < outcome["progress"] < 1.0 and outcome["after"] is None


def test_compile_helper_ends_when_its_parent_is_gone(tmp_path):
    """A helper started by a process that then vanishes stops instead of compiling on."""
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"),
               WHITTED_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    # the shell starts the helper (naming itself as the parent) and exits at once
    shell = subprocess.run(
        ["sh", "-c", f'"{sys.executable}" -m whitted.render.warm_up plain $$ '
                     '>/dev/null 2>&1 & echo $!'],
        capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    pid = int(shell.stdout.strip())
    import time

    deadline = time.monotonic() + 15.0  # Python, NumPy and Numba start first
    while time.monotonic() < deadline and Path(f"/proc/{pid}").exists():
        status = Path(f"/proc/{pid}/status").read_text() if Path(f"/proc/{pid}").exists() else ""
        if "State:\tZ" in status:
            break
        time.sleep(0.2)
    alive = Path(f"/proc/{pid}").exists() and "State:\tZ" not in Path(
        f"/proc/{pid}/status").read_text()
    assert not alive, "the orphaned helper is still compiling"


def test_render_in_a_terminal_draws_its_bar(tmp_path):
    """``whitted render`` with a terminal on stderr draws the rich progress bar (the lazy
    console must work inside rich's live display) and writes the image."""
    import pty

    out = tmp_path / "x.png"
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"), COLUMNS="100", TERM="xterm",
               WHITTED_PROGRESS_DELAY="0")  # the bar at once, however fast the render
    pid, fd = pty.fork()
    if pid == 0:  # the child: the CLI with the pseudo-terminal as its terminal
        os.chdir(tmp_path)
        os.execvpe(sys.executable, [sys.executable, "-m", "whitted", "render", "-W", "24",
                                    "-H", "16", "-o", str(out)], env)
    captured = b""
    while True:
        try:
            chunk = os.read(fd, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        captured += chunk
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, captured.decode(errors="replace")[-800:]
    assert b"rendering" in captured and b"24x16" in captured
    assert out.stat().st_size > 0


def _cli_process(tmp_path: Path, args: list[str], env_extra: dict | None = None):
    """``whitted ARGS`` in a fresh interpreter that also registers an atexit handler (printing
    TEARDOWN) and reports its OPENBLAS_NUM_THREADS from one (so a test sees whether the
    process went through the interpreter's teardown)."""
    script = textwrap.dedent(f"""
        import atexit, os, sys
        atexit.register(lambda: print("TEARDOWN " + os.environ.get("OPENBLAS_NUM_THREADS",
                                                                    "unset"), flush=True))
        sys.argv = ["whitted", *{args!r}]
        from whitted.cli.main import main
        main()
    """)
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT / "src"))
    env.pop("OPENBLAS_NUM_THREADS", None)
    env.update(env_extra or {})
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=tmp_path, env=env, timeout=600)


def test_a_local_render_ends_without_teardown_and_keeps_its_output(tmp_path):
    """After the image is written the process ends at once (no atexit, no interpreter
    teardown), yet its summary line reaches a pipe and the file holds the same pixels as
    an in-process render of the same scene."""
    import numpy as np
    from PIL import Image as PILImage

    scene_file = REPO_ROOT / "examples" / "glass_cube.toml"
    out = tmp_path / "x.png"
    result = _cli_process(tmp_path, ["render", str(scene_file), "-W", "24", "-H", "16",
                                     "-t", "2", "-o", str(out)])
    assert result.returncode == 0, result.stderr
    assert "TEARDOWN" not in result.stdout
    summary = [line for line in result.stdout.splitlines() if line.startswith("24x16:")]
    assert len(summary) == 1 and summary[0].endswith(f"-> {out}"), result.stdout
    written = np.asarray(PILImage.open(out))
    expected = whitted.render(str(scene_file), width=24, height=16, threads=1).to_srgb8()
    assert written.shape == (16, 24, 3)
    assert np.array_equal(written, expected)


def test_other_commands_and_user_mistakes_end_normally(tmp_path):
    """Only a local render skips the teardown: a command that failed before rendering, and
    other commands, end through it (their atexit handlers run)."""
    failed = _cli_process(tmp_path, ["render", str(tmp_path / "missing.toml"), "-o",
                                     str(tmp_path / "x.png")])
    assert failed.returncode == 2
    assert "TEARDOWN" in failed.stdout
    version = _cli_process(tmp_path, ["--version"])
    assert version.returncode == 0 and "TEARDOWN" in version.stdout


def test_the_command_starts_no_blas_thread_pool_unless_asked(tmp_path):
    """The command's process runs NumPy with one OpenBLAS thread (its pool made importing
    NumPy 0.05 s slower); a user's own OPENBLAS_NUM_THREADS is kept."""
    assert "TEARDOWN 1" in _cli_process(tmp_path, ["--version"]).stdout
    kept = _cli_process(tmp_path, ["--version"], {"OPENBLAS_NUM_THREADS": "2"})
    assert "TEARDOWN 2" in kept.stdout


def test_progress_bar_appears_only_for_a_render_still_running_after_the_delay(tmp_path,
                                                                               monkeypatch):
    """On a terminal the bar appears once a render has run PROGRESS_DELAY seconds (cli/render.py):
    a render that ends sooner never shows it (nor imports rich's progress display)."""
    import io

    from rich.console import Console

    from whitted.cli import main as cli
    from whitted.cli import render as render_command
    from whitted.cli.console import err

    shown = {}
    for delay in (0.0, 600.0):
        screen = io.StringIO()
        monkeypatch.setattr(err, "_made", Console(file=screen, force_terminal=True,
                                                  width=100))
        monkeypatch.setattr(render_command, "PROGRESS_DELAY", delay)
        out = tmp_path / f"delay{delay:g}.png"
        cli.app(["render", str(REPO_ROOT / "examples" / "glass_cube.toml"), "-W", "32",
                 "-H", "24", "-o", str(out)], standalone_mode=False)
        assert out.stat().st_size > 0
        shown[delay] = screen.getvalue()
    assert "rendering" in shown[0.0]
    assert shown[600.0] == ""


def test_terminal_check_without_rich_agrees_with_rich(monkeypatch):
    """cli/console.py answers ``is_terminal`` by rich's rules without making the console:
    the same answer as rich's for every combination of TTY_COMPATIBLE, FORCE_COLOR and a file
    that is or is not a terminal."""
    import io
    import pty

    monkeypatch.delitem(sys.modules, "ipykernel", raising=False)  # as in a command's process

    from rich.console import Console

    from whitted.cli.console import LazyConsole

    master, slave = pty.openpty()
    tty = os.fdopen(slave, "w")
    try:
        for compatible in (None, "0", "1", "2"):
            for force_color in (None, "", "1"):
                for file in (io.StringIO(), tty):
                    for name, value in (("TTY_COMPATIBLE", compatible),
                                        ("FORCE_COLOR", force_color)):
                        if value is None:
                            monkeypatch.delenv(name, raising=False)
                        else:
                            monkeypatch.setenv(name, value)
                    ours = LazyConsole(file=file)
                    assert ours.is_terminal == Console(file=file).is_terminal, (
                        compatible, force_color, file)
                    assert ours._made is None
    finally:
        tty.close()
        os.close(master)


def test_render_pauses_the_garbage_collector_only_for_its_set_up(tmp_path):
    """``whitted render`` runs its imports and scene reading with the cyclic collector paused
    (cli/app.py ``resume_collector``), and the job with it on, the set-up's objects frozen;
    a render that ends in a usage error leaves it on too, and other commands never touch it."""
    out = tmp_path / "x.png"
    _modules_after(f"""
        import gc, sys
        import whitted.cli.main as cli
        import whitted.cli.render as render_command
        cli.EXIT_AT_ONCE_WHEN_ABANDONED = False
        seen = []
        job_run = render_command._render_and_write
        def watched(*args, **kwargs):
            seen.append((gc.isenabled(), gc.get_freeze_count() > 0))
            return job_run(*args, **kwargs)
        render_command._render_and_write = watched
        for argv in (["render", "-W", "16", "-H", "12", "-o", {str(out)!r}],
                     ["render", "-W", "-5", "-o", {str(out)!r}], ["--version"]):
            sys.argv = ["whitted", *argv]
            gc.unfreeze()
            try:
                cli.main()
            except SystemExit:
                pass
            assert gc.isenabled(), argv
        assert seen == [(True, True)], seen
    """, tmp_path)
    assert out.stat().st_size > 0
