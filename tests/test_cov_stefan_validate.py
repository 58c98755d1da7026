"""stefan/validate.py: the similarity constants beside the quoted values, and the plot of the
computed front beside the exact one."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from whitted.stefan import validate


def test_lambda_rows_match_the_quoted_values():
    rows = {r["case"]: r for r in validate.lambda_rows()}
    assert list(rows) == ["one phase, St = 0.1", "one phase, St = 1",
                          "two phase, +10 / -10 °C", "two phase front after 1 h (mm)"]
    # the one-phase constants are quoted to 6 digits; the two-phase ones (0.2089, 9.14 mm)
    # differ from the root, 0.20908, within the rounding of the quoted properties
    assert rows["one phase, St = 0.1"]["lambda"] == pytest.approx(0.220016, abs=1e-6)
    assert rows["one phase, St = 1"]["lambda"] == pytest.approx(0.620063, abs=1e-6)
    assert rows["two phase, +10 / -10 °C"]["lambda"] == pytest.approx(0.2089, abs=2e-4)
    assert rows["two phase front after 1 h (mm)"]["lambda"] == pytest.approx(9.14, abs=0.01)
    for r in rows.values():
        assert r["difference"] == pytest.approx(r["lambda"] - r["quoted"], abs=1e-15)


def test_plot_front_writes_the_figure(tmp_path):
    path = tmp_path / "front.png"
    validate.plot_front(path, dx=2e-3, t_end=600.0, samples=3)
    with Image.open(path) as image:
        assert image.size == (660, 396)  # 6 x 3.6 inches at 110 dpi
        # not a blank canvas: the exact curve and the computed points are drawn
        colours = np.unique(np.asarray(image.convert("RGB")).reshape(-1, 3), axis=0)
        assert len(colours) > 10
