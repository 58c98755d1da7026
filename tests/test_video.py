"""Films from frames: MP4 (H.264 through imageio-ffmpeg) and GIF."""

from __future__ import annotations

import imageio.v2 as imageio
import numpy as np
import pytest
from PIL import Image as PILImage

from whitted.output.video import encode_film, even_size, pad_to_even, video_format


def _frames(width: int, height: int, count: int) -> list[np.ndarray]:
    """Frames of flat grey levels 20, 50, 80, ... with a white left column."""
    out = []
    for k in range(count):
        f = np.full((height, width, 3), 20 + 30 * k, np.uint8)
        f[:, 0] = 255
        out.append(f)
    return out


def _decode(path) -> tuple[list[np.ndarray], dict]:
    reader = imageio.get_reader(path, format="FFMPEG")
    try:
        return [np.asarray(f) for f in reader], reader.get_meta_data()
    finally:
        reader.close()


@pytest.mark.parametrize(("width", "height"), [(32, 18), (31, 17), (20, 15)])
def test_mp4_decodes_with_frame_count_size_and_fps(tmp_path, width, height):
    frames = _frames(width, height, 7)
    path = encode_film(frames, tmp_path / "film.mp4", fps=12)
    decoded, meta = _decode(path)
    assert len(decoded) == 7
    assert meta["fps"] == 12.0
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    w, h = even_size(width, height)  # odd sides get one more column/row, nothing is scaled
    assert meta["size"] == (w, h) and decoded[0].shape == (h, w, 3)
    for k, frame in enumerate(decoded):  # CRF 18: within a few levels of the input
        assert abs(int(frame[h // 2, w // 2, 1]) - (20 + 30 * k)) <= 3
        assert frame[h // 2, 0, 1] >= 245  # the white column is still at the left edge


def test_mp4_puts_its_index_first(tmp_path):
    path = encode_film(_frames(16, 16, 3), tmp_path / "film.mp4", fps=24)
    data = path.read_bytes()
    assert 0 < data.find(b"moov") < data.find(b"mdat")  # +faststart: playable while loading


def test_pad_to_even_copies_the_last_row_and_column():
    f = np.arange(3 * 5 * 3, dtype=np.uint8).reshape(3, 5, 3)
    p = pad_to_even(f)
    assert p.shape == (4, 6, 3)
    assert np.array_equal(p[:3, :5], f)
    assert np.array_equal(p[3, :5], f[2]) and np.array_equal(p[:3, 5], f[:, 4])
    even = np.zeros((4, 6, 3), np.uint8)
    assert pad_to_even(even) is even


def test_gif_has_every_frame_and_the_delay(tmp_path):
    frames = _frames(21, 13, 5)
    path = encode_film(frames, tmp_path / "film.gif", fps=10)
    with PILImage.open(path) as im:
        assert im.n_frames == 5 and im.size == (21, 13)
        assert im.info["duration"] == 100 and im.info["loop"] == 0
        im.seek(3)
        assert abs(int(np.asarray(im.convert("RGB"))[6, 10, 0]) - 110) <= 2


def test_frames_from_png_files_and_bad_input(tmp_path):
    names = []
    for k, f in enumerate(_frames(10, 8, 3)):
        name = tmp_path / f"{k:04d}.png"
        PILImage.fromarray(f).save(name)
        names.append(name)
    decoded, _ = _decode(encode_film(names, tmp_path / "f.mp4", fps=5))
    assert len(decoded) == 3
    with pytest.raises(ValueError, match="unsupported film format '.avi'"):
        video_format(tmp_path / "f.avi")
    with pytest.raises(ValueError, match="the first was 10x8"):
        encode_film([*_frames(10, 8, 1), *_frames(12, 8, 1)], tmp_path / "g.mp4", fps=5)
    assert not (tmp_path / "g.mp4").exists()  # a failed encode leaves nothing behind
