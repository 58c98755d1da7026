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

from whitted import load_scene  # noqa: E402
from whitted.farm import (  # noqa: E402
    WhittedWorker,
    band_ranges,
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
    assert workers_see(client, manifest)  # same machine: "auto" would ship nothing
    shipment = ship_assets(client, [scene], "ship")
    assert shipment.bytes == sum((textured_copy.parent / p).stat().st_size
                                 for p in manifest.files)
    hidden = textured_copy.parent.with_name("hidden")
    textured_copy.parent.rename(hidden)  # now no process sees the scene's folder
    try:
        assert not workers_see(client, manifest)
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
