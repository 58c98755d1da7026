"""The render farm on a 2-worker LocalCluster (loopback, worker processes, one render thread
each), shared by the tests of this module: stills split across workers, and scene files
shipped to workers that cannot see them."""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

from farm_film import farm_film  # noqa: E402
from whitted import load_scene  # noqa: E402
from whitted.farm import (  # noqa: E402
    FrameFailed,
    WhittedWorker,
    band_ranges,
    chunk_size,
    collect_assets,
    render_still,
    ship_assets,
)
from whitted.farm.assets import asset_cache_dir, scene_file_names  # noqa: E402
from whitted.farm.transfer import workers_see  # noqa: E402
from whitted.render.api import RenderJob  # noqa: E402

TEXTURED_FILES = ("textures/earth.png", "textures/tiles.png", "models/cow")


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    """The workers' working directory: not the repository, not the scenes' folders."""
    return tmp_path_factory.mktemp("workers")


@pytest.fixture(scope="module")
def client(workdir):
    """Two worker processes started in another working directory, kernels warm."""
    here = os.getcwd()
    os.chdir(workdir)  # spawned workers start where the client is
    try:
        cluster = distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address="127.0.0.1:0", env={"NUMBA_NUM_THREADS": "1"})
    finally:
        os.chdir(here)
    with distributed.Client(cluster) as dask_client:
        dask_client.register_plugin(WhittedWorker(threads=1))
        yield dask_client
    cluster.close()


@pytest.fixture
def textured_copy(tmp_path, examples_dir) -> Path:
    """examples/textured.toml and every file it uses, copied to a folder of their own."""
    folder = tmp_path / "project"
    folder.mkdir()
    shutil.copy(examples_dir / "textured.toml", folder)
    for name in TEXTURED_FILES:
        source = examples_dir / name
        if source.is_dir():
            shutil.copytree(source, folder / name)
        else:
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(source, folder / name)
    return folder / "textured.toml"


def local_pixels(scene) -> np.ndarray:
    return RenderJob(scene, threads=1).run().pixels


def test_the_plugin_readied_every_worker_before_any_task(client):
    def state() -> tuple:
        import numba

        from whitted.farm import worker

        return (numba.get_num_threads(), os.environ.get("NUMBA_NUM_THREADS"),
                worker._threads, worker.warm_seconds() is not None)

    assert list(client.run(state).values()) == [(1, "1", 1, True)] * 2


def test_band_ranges_cover_the_image_in_whole_tile_rows():
    assert band_ranges(90, 4) == [(0, 16), (16, 48), (48, 64), (64, 90)]
    assert band_ranges(90, 100) == [(0, 16), (16, 32), (32, 48), (48, 64), (64, 80), (80, 90)]
    assert band_ranges(10, 3) == [(0, 10)]


def test_rows_of_a_render_job_match_the_whole_render(lecture_scene):
    scene = load_scene(lecture_scene).with_settings(width=64, height=40, samples=4)
    whole = local_pixels(scene)
    job = RenderJob(scene, threads=1, rows=(16, 37))
    job.run()
    assert np.array_equal(job.framebuffer[16:37], whole[16:37])
    assert not job.framebuffer[:16].any() and not job.framebuffer[37:].any()
    with pytest.raises(ValueError, match="rows 30:50"):
        RenderJob(scene, rows=(30, 50))


def test_still_split_across_workers_equals_the_local_render(client, examples_dir):
    # 4 samples a pixel (jittered: the random numbers depend on the pixel), a partial last
    # tile row, more bands than workers: every band boundary is a possible seam
    scene = load_scene(examples_dir / "textured.toml").with_settings(
        width=120, height=75, samples=4)
    image = render_still(client, scene, bands=5)
    assert image.meta["bands"] == 5 and image.meta["workers"] == 2
    reference = local_pixels(scene)
    assert image.pixels.dtype == np.float32
    assert np.array_equal(image.pixels, reference)
    assert image.meta["stats"].rays["primary"] == 120 * 75 * 4


def test_files_are_named_and_found_with_their_own_references(textured_copy):
    scene = load_scene(textured_copy)
    assert scene_file_names(scene) == ["textures/earth.png", "textures/tiles.png",
                                       "models/cow/cow.obj"]
    manifest, blobs, needs = collect_assets([scene])
    # the OBJ's material library and the texture map it names come along
    assert sorted(manifest.files) == ["models/cow/cow.mtl", "models/cow/cow.obj",
                                      "models/cow/cow_texture.png", "textures/earth.png",
                                      "textures/tiles.png"]
    assert manifest.base == "."
    for relpath, digest in manifest.files.items():
        data = (textured_copy.parent / relpath).read_bytes()
        assert hashlib.sha256(data).hexdigest() == digest
        assert blobs[digest] == textured_copy.parent / relpath
    assert sorted(needs[0]) == sorted(manifest.files)


def test_files_reach_workers_that_cannot_see_the_scene_folder(client, textured_copy, workdir):
    scene = load_scene(textured_copy).with_settings(width=96, height=54)
    reference = local_pixels(scene)
    manifest, _, _ = collect_assets([scene])
    assert workers_see(client, manifest.stamps)  # same machine: "auto" would ship nothing
    shipment = ship_assets(client, [scene], "ship")
    assert shipment.bytes == sum((textured_copy.parent / p).stat().st_size
                                 for p in manifest.files)
    hidden = textured_copy.parent.with_name("hidden")
    textured_copy.parent.rename(hidden)  # now no process sees the scene's folder
    try:
        assert not workers_see(client, manifest.stamps)
        image = render_still(client, scene, assets=shipment, bands=4)
        assert np.array_equal(image.pixels, reference)

        def cached(dask_worker) -> dict[str, str]:
            root = asset_cache_dir() if os.environ.get("WHITTED_FARM_CACHE") else (
                Path(dask_worker.local_directory) / "whitted-assets")
            blobs = root / "blobs"
            return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
                    for p in blobs.iterdir()} if blobs.is_dir() else {}

        caches = client.run(cached)
        assert os.getcwd() != str(workdir)
        for blobs_of_worker in caches.values():
            # what a worker holds is addressed by content, and it is the scene's files
            assert all(name == digest for name, digest in blobs_of_worker.items())
        # a worker that rendered a band holds every file of the scene
        every = set(manifest.files.values())
        assert any(every <= set(held) for held in caches.values())
        cwd = client.run(os.getcwd)
        assert set(cwd.values()) == {str(workdir)}
    finally:
        hidden.rename(textured_copy.parent)


# ------------------------------------------------------------------------------ films

FILM = """
[render]
width = 48
height = 32
samples = 2
max_depth = 3

[camera]
position = [0, 1.5, 5]
look_at = [0, 0.5, 0]

[[lights]]
type = "point"
position = [3, 5, 4]

[[objects]]
type = "plane"
material = { kd = 0.8, texture = { type = "image", file = "tex/tiles.png" } }

[[objects]]
name = "ball"
type = "sphere"
center = [-0.8, 0.5, 0]
radius = 0.5
material = "glass"

[[objects]]
name = "blade"
type = "mesh"
file = "seq/blade_{frame:02d}.obj"
"""


def write_film_scene(folder: Path, examples_dir: Path, frames: int) -> Path:
    """A scene file with an image texture and a mesh sequence (one OBJ per frame, a triangle
    that grows); :func:`film_of` adds its tracks."""
    (folder / "seq").mkdir(parents=True)
    (folder / "tex").mkdir()
    shutil.copy(examples_dir / "textures/tiles.png", folder / "tex/tiles.png")
    for k in range(frames):
        x = 0.8 + 0.1 * k
        (folder / f"seq/blade_{k:02d}.obj").write_text(
            f"v {x} 0 0\nv {x + 0.8} 0 0\nv {x} {1.0 + 0.05 * k} 0.2\nf 1 2 3\n")
    path = folder / "film.toml"
    path.write_text(FILM)
    return path


def film_of(path: Path, frames: int):
    """The scene at ``path`` animated: a camera move and a material track over ``frames``."""
    from whitted.animation import Track

    last = frames - 1
    return load_scene(path).with_animation(frames, 12.0, [
        Track("camera.position", [[0, [0, 1.5, 5]], [last, [3, 1.5, 4]]]),
        Track("objects[ball].material.kt", [[0, 1.0], [last, 0.2]]),
    ])


@pytest.fixture(scope="module")
def film_scene(tmp_path_factory, examples_dir):
    folder = tmp_path_factory.mktemp("film")
    return film_of(write_film_scene(folder / "project", examples_dir, 8), 8)


@pytest.fixture(scope="module")
def local_frames(film_scene, tmp_path_factory) -> dict[int, bytes]:
    """Every frame of the film as the local ``whitted animate`` writes it (PNG bytes)."""
    from whitted.animation.frames import render_frame

    folder = tmp_path_factory.mktemp("local-frames")
    frames = {}
    for k in range(film_scene.frame_count):
        path = folder / f"{k:04d}.png"
        render_frame(film_scene, k, path, threads=2)
        frames[k] = path.read_bytes()
    return frames


def png_pixels(data: bytes) -> np.ndarray:
    import io

    from PIL import Image as PILImage

    return np.asarray(PILImage.open(io.BytesIO(data)).convert("RGB"))


def assert_frames_match(folder: Path, local_frames: dict[int, bytes], frames) -> None:
    written = sorted(p.name for p in folder.iterdir())
    assert written == [f"{k:04d}.png" for k in frames]  # no temporary or half files left
    for k in frames:
        data = (folder / f"{k:04d}.png").read_bytes()
        assert np.array_equal(png_pixels(data), png_pixels(local_frames[k])), f"frame {k}"
        assert data == local_frames[k], f"frame {k}: the PNG differs from the local one"


def test_chunk_size_packs_short_frames_and_keeps_every_thread_busy():
    # 0.01 s frames: 200 make the 2 s a task should hold; 1,000 frames on 2 threads allow
    # 1000 // (4 * 2) = 125 a task at most
    assert chunk_size(1000, 2, 0.01) == 125
    assert chunk_size(10_000, 2, 0.01) == 200
    assert chunk_size(8, 2, 0.01) == 1  # 8 frames: 4 rounds for each thread come first
    assert chunk_size(1000, 10, 1.3) == 2  # ceil(2 / 1.3) frames of 1.3 s
    assert chunk_size(1000, 10, 60.0) == 1  # a long frame is a task of its own
    assert chunk_size(1000, 10, None) == 1  # not measured yet: one frame a task
    # 10 nodes x 32 threads: 1,000 frames are 1,000 tasks for the 320 threads
    assert chunk_size(1000, 320, 0.05) == 1


def test_film_on_two_workers_is_the_local_film_frame_by_frame(client, film_scene,
                                                              local_frames, tmp_path):
    folder = tmp_path / "frames"
    arrived = []
    result = farm_film(client, film_scene, folder, assets="ship", chunk=3,
                         progress=lambda done, total, frame: arrived.append((done, frame)))
    assert result.report.tasks == 3 and result.report.chunk == 3  # 8 frames: 3 + 3 + 2
    assert sorted(result.rendered) == list(range(8)) and result.kept == []
    assert [done for done, _ in arrived] == list(range(1, 9))
    assert result.report.asset_bytes > 0
    assert_frames_match(folder, local_frames, range(8))


def test_resume_renders_only_the_missing_frames(client, film_scene, local_frames, tmp_path):
    folder = tmp_path / "frames"

    def stop_after_three(done, total, frame):
        if done == 3:
            raise KeyboardInterrupt  # the user stops the client

    with pytest.raises(KeyboardInterrupt):
        farm_film(client, film_scene, folder, chunk=1, progress=stop_after_three)
    first = sorted(int(p.stem) for p in folder.glob("*.png"))
    assert len(first) >= 3  # and every other frame that had arrived when it was stopped
    again = farm_film(client, film_scene, folder, chunk=1)
    assert sorted(again.kept) == first
    assert sorted(again.rendered) == sorted(set(range(8)) - set(first))
    assert_frames_match(folder, local_frames, range(8))


def test_a_failing_frame_is_named_after_the_others_are_saved(client, examples_dir, tmp_path):
    path = write_film_scene(tmp_path / "project", examples_dir, 5)
    bad = tmp_path / "project/seq/blade_03.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")  # no vertex 7
    scene = film_of(path, 5).with_settings(width=24, height=16, samples=1)
    folder = tmp_path / "frames"
    with pytest.raises(FrameFailed) as failure:
        farm_film(client, scene, folder, assets="ship", chunk=2)
    message = str(failure.value)
    assert message.startswith(f"frame 3: {bad}:4:")  # the client's file name, its line
    assert "\n" not in message
    assert sorted(p.name for p in folder.iterdir()) == [f"{k:04d}.png" for k in (0, 1, 2, 4)]


def test_a_worker_killed_mid_film_costs_only_a_retry(client, film_scene, tmp_path):
    import signal

    from whitted.animation.frames import render_frame

    settings = {"width": 96, "height": 64, "samples": 4}  # frames long enough to be caught
    local = {}
    for k in range(film_scene.frame_count):
        render_frame(film_scene, k, tmp_path / "local.png", threads=2, **settings)
        local[k] = (tmp_path / "local.png").read_bytes()
    folder = tmp_path / "frames"
    pids = client.run(os.getpid)
    victim_address, victim = sorted(pids.items())[0]
    killed = []

    def kill_one_worker(done, total, frame):
        # while it runs one of the film's tasks (the scheduler says so): a loaded machine
        # may have it idle at a given frame's end
        if not killed and client.processing().get(victim_address):
            os.kill(victim, signal.SIGKILL)  # the worker process, without warning
            killed.append(frame)

    result = farm_film(client, film_scene, folder, chunk=1, retries=0,
                         progress=kill_one_worker, **settings)
    assert killed
    assert sorted(result.rendered) == list(range(8))  # each frame written exactly once
    assert len(result.rendered) == 8
    assert_frames_match(folder, local, range(8))
    assert victim not in client.run(os.getpid).values()

    def lost_frame_tasks(dask_scheduler, address=victim_address) -> int:
        """Frame tasks that were running on the killed worker when it went."""
        return sum(1 for key, start, *_, stimulus, _ in dask_scheduler.transition_log
                   if "render_frame_chunk" in str(key) and start == "processing"
                   and "worker" in str(stimulus) and "cleanup" in str(stimulus))

    assert client.run_on_scheduler(lost_frame_tasks) >= 1  # the kill cost a task a rerun
