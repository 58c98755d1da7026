"""``whitted bench --rays``: the render time by kind of ray. No timing assertions: the
variants trace what they should (ray counts) and the figures add up to the render time."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st
from typer.testing import CliRunner

from whitted.bench.breakdown import KINDS, split_time, variants
from whitted.bench.scenes import load_bench_scene
from whitted.cli.main import app


def test_split_time_worked_numbers():
    rays = {"full": {"primary": 100, "shadow": 50, "reflection": 30, "refraction": 10}}
    out = split_time({"full": 2.0, "dark": 1.2, "primary": 0.4}, 0.3, rays)
    s = out["seconds"]
    assert s["primary"] == pytest.approx(0.4)
    assert s["shadow"] == pytest.approx(2.0 - 0.3 - 1.2)
    assert s["reflection"] == pytest.approx(0.8 * 0.75)
    assert s["refraction"] == pytest.approx(0.8 * 0.25)
    assert s["photon"] == pytest.approx(0.3)
    assert sum(s.values()) == pytest.approx(2.0) and out["noise_s"] == 0.0
    # noise: dark timed slower than full; the shadow share is 0 and the difference kept
    out = split_time({"full": 1.0, "dark": 1.1, "primary": 0.4}, 0.0, rays)
    assert out["seconds"]["shadow"] == 0.0 and out["noise_s"] == pytest.approx(0.1)
    assert sum(out["seconds"].values()) - out["noise_s"] == pytest.approx(1.0)


times = st.floats(min_value=0.0, max_value=1e4, allow_nan=False)
counts = st.integers(min_value=0, max_value=10**12)


@given(times, times, times, times, counts, counts)
def test_split_time_always_adds_up(full, dark, primary, photon, reflection, refraction):
    """Whatever the machine's noise does to the variants' times, the kinds are never negative
    and add up to the render time plus the noise kept aside."""
    rays = {"full": {"primary": 1, "shadow": 1, "reflection": reflection,
                     "refraction": refraction}}
    out = split_time({"full": full, "dark": dark, "primary": primary}, photon, rays)
    seconds = out["seconds"]
    assert all(v >= 0.0 for v in seconds.values()) and out["noise_s"] >= 0.0
    assert sum(seconds.values()) - out["noise_s"] == pytest.approx(full, abs=1e-6)


def test_variants_drop_direct_light_and_depth():
    scene = load_bench_scene("ice", quick=True)
    v = variants(scene)
    assert v["full"] is scene
    assert [light.type for light in v["dark"].lights] == ["ambient"]
    assert len(scene.lights) == 3
    assert v["primary"].render.max_depth == 0 and v["dark"].render.max_depth == 10


def test_bench_rays_table_and_json(tmp_path):
    out = tmp_path / "bench.json"
    result = CliRunner().invoke(app, ["bench", "--quick", "--scene", "ice", "--rays",
                                      "--json", str(out)])
    assert result.exit_code == 0, result.output
    assert "render time by kind of ray" in result.output
    for kind in KINDS:
        assert f"{kind} s" in result.output
    (row,) = json.loads(out.read_text())
    b = row["time_by_kind"]
    rays = b["variant_rays"]
    pixels = row["width"] * row["height"]
    assert rays["full"] == row["rays"]
    assert rays["dark"]["shadow"] == 0 and rays["dark"]["primary"] == pixels
    # without lights every reflected and refracted ray is still traced, and only those
    assert rays["dark"]["reflection"] == rays["full"]["reflection"] > 0
    assert rays["dark"]["refraction"] == rays["full"]["refraction"] > 0
    assert rays["primary"] == {"primary": pixels, "shadow": 0, "reflection": 0,
                               "refraction": 0}
    seconds = b["seconds"]
    assert set(seconds) == set(KINDS) and all(v >= 0 for v in seconds.values())
    assert seconds["photon"] == 0.0  # no caustics in this scene
    assert sum(seconds.values()) - b["noise_s"] == pytest.approx(b["render_s"])
    ratio = seconds["reflection"] / (seconds["reflection"] + seconds["refraction"])
    share = rays["full"]["reflection"] / (rays["full"]["reflection"]
                                          + rays["full"]["refraction"])
    assert ratio == pytest.approx(share)


def test_bench_rays_refuses_study():
    result = CliRunner().invoke(app, ["bench", "--quick", "--rays", "--study", "threads"])
    assert result.exit_code == 2 and "--rays" in result.output
