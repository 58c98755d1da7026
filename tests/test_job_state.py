"""RenderJob says how it ended (finished, cancelled, failed and with what), and its picture so
far is one call away as display values."""

from __future__ import annotations

import numpy as np
import pytest

import whitted
from whitted.errors import JobStateError
from whitted.render import JobState, RenderJob


@pytest.fixture(scope="module")
def scene():
    return whitted.default_scene().with_settings(width=48, height=32, threads=1)


def test_finished_job_says_so_and_its_srgb_is_the_image(scene):
    job = RenderJob(scene, tile_size=8)
    assert job.state is JobState.READY and job.state == "ready"
    assert job.fraction == 0.0
    assert not job.srgb().any()  # nothing rendered yet: black
    image = job.run()
    assert job.state is JobState.FINISHED and job.finished
    assert not job.cancelled and not job.failed and job.error is None
    assert job.tiles_done == job.tiles_total == 24 and job.fraction == 1.0
    srgb = job.srgb()
    assert srgb.dtype == np.uint8 and srgb.shape == (32, 48, 3)
    np.testing.assert_array_equal(srgb, image.to_srgb8())
    assert srgb.any()
    assert "finished, 24/24 tiles" in repr(job)
    import io

    from PIL import Image as PILImage

    shown = np.asarray(PILImage.open(io.BytesIO(job._repr_png_())).convert("RGB"))
    np.testing.assert_array_equal(shown, srgb)  # a job in a notebook shows its picture


def test_cancelled_job_keeps_the_tiles_it_finished(scene):
    full = RenderJob(scene, tile_size=8).run().to_srgb8()
    job = RenderJob(scene, tile_size=8, progress=lambda p: job.cancel())
    image = job.run()
    assert job.state is JobState.CANCELLED and job.cancelled and not job.finished
    assert image.meta["stats"].cancelled
    assert 0 < job.tiles_done < job.tiles_total
    partial = job.srgb()
    np.testing.assert_array_equal(partial, image.to_srgb8())
    # tiles go in image order: the first tiles are the full render's pixels, the rest black
    rows = 8 * (job.tiles_done // 6)  # six 8-pixel tiles a row of tiles
    if rows:
        np.testing.assert_array_equal(partial[:rows], full[:rows])
    assert not partial[-8:].any()
    copy = job.partial_image()
    assert copy.pixels is not job.framebuffer  # a copy: later tiles do not change it
    assert copy.transfer == scene.render.transfer


def test_failed_job_keeps_its_error(scene):
    def broken(_progress):
        raise ValueError("the progress callback broke")

    job = RenderJob(scene, tile_size=8, progress=broken)
    with pytest.raises(ValueError, match="callback broke"):
        job.run()
    assert job.state is JobState.FAILED and job.failed
    assert isinstance(job.error, ValueError)
    assert "failed: ValueError" in repr(job)


def test_failed_background_job_raises_on_wait(scene):
    def broken(_progress):
        raise ValueError("broke on the thread")

    job = RenderJob(scene, tile_size=8, progress=broken)
    job.start()
    assert job.join(60)
    assert job.failed and str(job.error) == "broke on the thread"
    with pytest.raises(ValueError, match="broke on the thread"):
        job.wait()


def test_cancelled_before_start_renders_nothing(scene):
    job = RenderJob(scene, tile_size=8)
    job.cancel()
    image = job.run()
    assert job.cancelled and job.tiles_done == 0
    assert not image.to_srgb8().any()


def test_a_job_runs_once(scene):
    job = RenderJob(scene, tile_size=16)
    job.run()
    with pytest.raises(JobStateError):
        job.run()
    with pytest.raises(JobStateError):
        job.start()
    started = RenderJob(scene, tile_size=16)
    started.start()
    with pytest.raises(JobStateError):
        started.start()
    assert started.wait(60) is not None and started.finished
