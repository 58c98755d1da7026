"""output/: where an output cannot be written (a device, a folder that is a file, a name over
255 bytes), the inputs of a scene whose files cannot be resolved, memory that cannot be read,
frames a film cannot take, and an Image's pixels replaced and converted."""

from __future__ import annotations

import numpy as np
import pytest

from whitted.errors import OutputError
from whitted.output.image import Image
from whitted.output.safety import available_memory, check_output_place, input_files
from whitted.output.video import encode_film


def test_places_that_cannot_take_a_file(tmp_path):
    with pytest.raises(OutputError) as info:
        check_output_place("/dev/null")
    assert str(info.value) == "/dev/null: is a character device, not a file that can be written"
    (tmp_path / "plain").write_text("")
    with pytest.raises(OutputError) as info:
        check_output_place(tmp_path / "plain" / "x.png")
    assert str(info.value) == (f"{tmp_path / 'plain' / 'x.png'}: cannot write: "
                               "Not a directory")
    long = tmp_path / ("x" * 256 + ".png")
    with pytest.raises(OutputError) as info:
        check_output_place(long)
    assert str(info.value) == f"{long}: cannot write: File name too long"
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "plain")
    with pytest.raises(OutputError) as info:
        check_output_place(link / "x.png")
    assert str(info.value) == f"{link / 'x.png'}: cannot write: Not a directory"


def test_inputs_whose_names_cannot_be_resolved_are_skipped(tmp_path):
    from whitted.scene import ImageTexture, Material, Scene, Sphere

    scene = Scene(objects=[Sphere(radius=1, material=Material(
        texture=ImageTexture(file="~no_such_user_cov2/t.png")))]).with_base_dir(tmp_path)
    # "~user" of no such user cannot be expanded: that name is left out, not an error
    assert input_files(scene, tmp_path / "s.toml") == [tmp_path / "s.toml"]


def test_memory_that_cannot_be_read(monkeypatch):
    def no_proc(*args, **kwargs):
        raise OSError("no /proc")

    monkeypatch.setattr("builtins.open", no_proc)
    assert available_memory() is None


def test_memory_without_the_line(monkeypatch, tmp_path):
    import builtins

    fake = tmp_path / "meminfo"
    fake.write_text("MemTotal: 100 kB\n")
    real_open = builtins.open
    monkeypatch.setattr("builtins.open", lambda path, *a, **k: real_open(
        fake if path == "/proc/meminfo" else path, *a, **k))
    assert available_memory() is None
    fake.write_text("MemAvailable: 2048 kB\n")
    assert available_memory() == 2048 * 1024


def test_frames_a_film_cannot_take(tmp_path):
    with pytest.raises(ValueError, match="^no frames to encode$"):
        encode_film([], tmp_path / "f.mp4", 24)
    with pytest.raises(ValueError) as info:
        encode_film([np.zeros((4, 4, 3), np.float32)], tmp_path / "f.gif", 10)
    assert str(info.value) == "frames must be (H, W, 3) uint8 images, got float32 (4, 4, 3)"
    assert not (tmp_path / "f.gif").exists() and list(tmp_path.iterdir()) == []


def test_image_pixels_replaced_and_converted():
    image = Image(np.zeros((2, 3, 3), np.float32))
    image.pixels = np.ones((1, 2, 3), np.float64)
    assert (image.width, image.height) == (2, 1) and image.pixels.dtype == np.float32
    assert np.asarray(image, dtype=np.float64).dtype == np.float64
    with pytest.raises(ValueError) as info:
        image.__array__(np.float64, copy=False)
    assert str(info.value) == "cannot convert Image pixels to float64 without a copy"
    with pytest.raises(ValueError):
        image.pixels = np.zeros((2, 2), np.float32)  # not (H, W, 3)


def test_a_name_with_a_nul_byte_is_one_line():
    with pytest.raises(OutputError) as info:
        check_output_place("out\0.png")
    assert str(info.value) == "out\0.png: cannot write: embedded null byte"
