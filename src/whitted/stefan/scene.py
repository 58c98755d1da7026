"""A still life that renders one saved time: the piece of ice on a table, lit from behind.

Written as a whitted scene file (TOML text) beside the surfaces it names; the Stefan package
writes it but never renders it (the CLI's ``film`` hands the scenes to the render API). The
outer surface carries ice (ior 1.31); the inner one is a single surface between two media,
water (ior 1.333) inside and ice outside (``outside = "ice"``), so a ray crossing it bends by
n_ice/n_water once, whichever way it goes.
Absorption is measured (``WATER_ABSORPTION_CM``, ``ICE_ABSORPTION_CM``: what a camera sees, a
nearly clear piece); ``absorption_boost`` > 1 exaggerates it, and the scene's comment and the
film's stamp say so. Frames take 4 samples per pixel (stratified: no jagged outlines, no
stair-step moiré in the internal reflections). Lengths are scaled from metres to centimetres
(``transform.scale = 100``), so absorption is per centimetre.
"""

from __future__ import annotations

from pathlib import Path

ABSORPTION_BOOST = 1.0  # the default: measured absorption (>1 exaggerates it, said so)
#: absorption coefficients (1/cm) at 650, 550, 450 nm for the red, green, blue channels: pure
#: water, Pope & Fry (1997), Appl. Opt. 36, 8710: 0.340, 0.0565, 0.0092 1/m. Pure ice's
#: visible spectrum resembles water's (Warren 2019, Phil. Trans. R. Soc. A 377, 20180161;
#: Warren & Brandt 2008, JGR 113, D14220): the same values are used for ice (docs/stefan.md).
WATER_ABSORPTION_CM = (0.00340, 0.000565, 0.000092)
ICE_ABSORPTION_CM = WATER_ABSORPTION_CM
FILM_SAMPLES = 4
#: caustics (docs/caustics.md): photons shot per frame through the ice onto the table, what a
#: photograph shows of the light the piece focuses, per pixel of the frame (200,000 at 400x300):
#: the default gather radius goes as 1/sqrt(photons), so it stays the same number of pixels
#: at any frame size and a thumbnail does not pay for a poster's photons
CAUSTIC_PHOTONS_PER_PIXEL = 5.0 / 3.0


LIFT_CM = 0.005  # the piece is lifted a hair so its base does not coincide with the table
BUBBLE_MIN_CM = 1e-4  # no void yet: a bubble too small to see (a sphere needs a radius)


def void_bubble(top_m: tuple[float, float, float], void_m3: float) -> tuple[tuple[float, ...],
                                                                           float]:
    """The void left by the 9 % density difference as one round bubble of air (scene
    centimetres: centre, radius) just under the top of the cavity's surface ``top_m`` (its
    highest vertex, metres): it has risen in the water. A real bubble flattens against the
    wall; a sphere of the void's volume is what is drawn."""
    import math

    r = max(BUBBLE_MIN_CM, 100.0 * (3.0 * max(0.0, void_m3) / (4.0 * math.pi)) ** (1 / 3))
    x, y, z = (100.0 * c for c in top_m)
    return (x, y + LIFT_CM - 1.02 * r, z), r


#: a puddle wider than water's capillary length (sqrt(gamma / (rho g)) = 2.7 mm) stands at
#: e = 2 l_c sin(theta / 2): 2.7 mm for a contact angle of 60° on varnished wood (de Gennes,
#: Brochard-Wyart & Quéré, *Capillarity and Wetting Phenomena*, 2004, section 2.1.3)
PUDDLE_CM = 0.27
#: the flow's tracer particles: bubbles of air this big (cm), as a film's tracer bubbles are
TRACER_CM = 0.03


def puddle_radius(water_m3: float, block_size_m: tuple[float, float, float]) -> float:
    """The meltwater on the table as a disc of water PUDDLE_CM thick centred under the block
    (scene centimetres): its area beyond the block's inscribed circle holds the water;
    BUBBLE_MIN_CM (nothing to see) while there is none."""
    import math

    if water_m3 <= 0.0:
        return BUBBLE_MIN_CM
    inner = 50.0 * min(block_size_m[0], block_size_m[2])
    return math.sqrt(inner ** 2 + 1e6 * water_m3 / PUDDLE_CM / math.pi)


def still_life_scene(outer: str | None, inner: str | None, time_s: float | None, *,
                     width: int = 480, height: int = 360, samples: int = FILM_SAMPLES,
                     size_cm: float = 4.0, frames: int | None = None, fps: float = 8.0,
                     absorption_boost: float = ABSORPTION_BOOST,
                     caustic_photons: int | None = None,
                     bubbles: list[tuple[tuple[float, ...], float]] | None = None,
                     puddles: list[float] | None = None,
                     tracers: list[list[tuple[float, ...]]] | None = None) -> str:
    """The scene file's text; ``outer``/``inner`` are PLY paths relative to the scene file.
    With ``frames``, an animated scene whose meshes are sequences (``{frame:04d}`` in the
    names): frame k shows saved time k. ``bubbles``: the void's bubble (:func:`void_bubble`)
    in the cavity's water, one per frame (one for a still), keyed per frame in a film;
    ``puddles``: the meltwater's disc radius on the table (:func:`puddle_radius`), likewise;
    ``tracers``: the flow's tracer particles (scene centimetres), one list per frame, drawn as
    small bubbles of air (radius ``TRACER_CM``) that the water carries, likewise;
    ``caustic_photons``: photons per frame for the light the piece focuses (0: none; None:
    CAUSTIC_PHOTONS_PER_PIXEL of the frame)."""
    if caustic_photons is None:
        caustic_photons = round(CAUSTIC_PHOTONS_PER_PIXEL * width * height)
    when = ("one frame per saved time (series.csv has the times)" if time_s is None
            else f"t = {time_s:.0f} s ({time_s / 60:.1f} min)")
    lines = [
        f"# whitted stefan: the melting piece, {when}.",
        ("# Absorption of ice and water: measured (Pope & Fry 1997; docs/stefan.md)."
         if absorption_boost == 1.0 else
         f"# Absorption of ice and water exaggerated x{absorption_boost:g} over measured."),
        "",
        "[render]",
        f"width = {width}",
        f"height = {height}",
        f"samples = {samples}",
        "max_depth = 12",
        *(["", "[render.caustics]  # the light the ice focuses onto the table",
           f"photons = {caustic_photons}"] if caustic_photons > 0 else []),
        "",
        "[camera]",
        f"position = [{0.7 * size_cm:.3f}, {1.2 * size_cm:.3f}, {2.9 * size_cm:.3f}]",
        f"look_at = [0.0, {0.45 * size_cm:.3f}, 0.0]",
        "fov = 36.0",
        "",
        "[background]",
        "gradient = { top = [0.05, 0.05, 0.07], bottom = [0.55, 0.57, 0.62] }",
        "",
        "[materials.ice]",
        'preset = "ice"',
        "ior = 1.31",
        "attenuation = [{:.4g}, {:.4g}, {:.4g}]".format(
            *(a * absorption_boost for a in ICE_ABSORPTION_CM)),
        "",
        "[materials.water]",
        'preset = "water"',
        "ior = 1.333",
        "attenuation = [{:.4g}, {:.4g}, {:.4g}]".format(
            *(a * absorption_boost for a in WATER_ABSORPTION_CM)),
        "",
        "[[lights]]",
        'type = "ambient"',
        "intensity = 0.25",
        "",
        "[[lights]]  # the backlight",
        'type = "point"',
        f"position = [{-0.5 * size_cm:.3f}, {2.0 * size_cm:.3f}, {-2.0 * size_cm:.3f}]",
        "intensity = 0.8",
        "",
        "[[lights]]",
        'type = "point"',
        f"position = [{-3.0 * size_cm:.3f}, {4.0 * size_cm:.3f}, {4.0 * size_cm:.3f}]",
        "intensity = 0.6",
        "",
        "[[objects]]",
        'name = "table"',
        'type = "plane"',
        "material = { color = [0.62, 0.45, 0.3], ka = 0.2, kd = 0.7, ks = 0.25, "
        "shininess = 40.0, kr = 0.12 }",
        "",
        "[[objects]]",
        'name = "back wall"',
        'type = "box"',
        f"min = [{-4 * size_cm:.3f}, 0.0, {-3 * size_cm:.3f}]",
        f"max = [{4 * size_cm:.3f}, {4 * size_cm:.3f}, {-2.9 * size_cm:.3f}]",
        "material = { color = [0.85, 0.85, 0.82], ka = 0.25, kd = 0.75 }",
    ]
    for n, colour in enumerate(("#c03a2b", "#f1c40f", "#2e86c1")):
        x0 = (-1.1 + 0.8 * n) * size_cm
        lines += [
            "",
            "[[objects]]",
            f'name = "stripe {n + 1}"',
            'type = "box"',
            f"min = [{x0:.3f}, 0.0, {-2.9 * size_cm:.3f}]",
            f"max = [{x0 + 0.35 * size_cm:.3f}, {4 * size_cm:.3f}, {-2.85 * size_cm:.3f}]",
            f'material = {{ color = "{colour}", ka = 0.25, kd = 0.75 }}',
        ]
    for name, path, material in (("ice", outer, "ice"), ("water", inner, "water")):
        if path is None:
            continue
        lines += [
            "",
            "[[objects]]",
            f'name = "{name}"',
            'type = "mesh"',
            f'file = "{path}"',
            f'material = "{material}"',
            *(['outside = "ice"'] if name == "water" else []),  # one surface, two media
            "smooth = true",
            # lifted a hair so the piece's base does not coincide with the table plane
            f"transform = {{ scale = 100.0, translate = [0.0, {LIFT_CM:g}, 0.0] }}",
        ]
    if bubbles and inner is not None:  # air (ior 1) inside the water: the media stack
        (cx, cy, cz), r = bubbles[0]
        lines += ["", "[[objects]]", 'name = "void bubble"', 'type = "sphere"',
                  f"center = [{cx:.4f}, {cy:.4f}, {cz:.4f}]", f"radius = {r:.5f}",
                  "material = { color = [1.0, 1.0, 1.0], ka = 0.0, kd = 0.0, ks = 0.0, "
                  "kr = 0.0, kt = 1.0, ior = 1.0, fresnel = true }"]
    shown = tracers[0] if tracers and inner is not None else []
    for k, (tx, ty, tz) in enumerate(shown):  # tracer bubbles in the water, like the void's
        lines += ["", "[[objects]]", f'name = "tracer {k}"', 'type = "sphere"',
                  f"center = [{tx:.4f}, {ty + LIFT_CM:.4f}, {tz:.4f}]",
                  f"radius = {TRACER_CM:g}",
                  "material = { color = [1.0, 1.0, 1.0], ka = 0.0, kd = 0.0, ks = 0.0, "
                  "kr = 0.0, kt = 1.0, ior = 1.0, fresnel = true }"]
    if puddles:
        lines += ["", "[[objects]]", 'name = "meltwater"', 'type = "cylinder"',
                  "base = [0.0, 0.0, 0.0]", f"top = [0.0, {PUDDLE_CM:g}, 0.0]",
                  f"radius = {puddles[0]:.4f}", 'material = "water"']
    if frames is not None:
        lines += ["", "[animation]", f"frames = {frames}", f"fps = {fps:g}"]
        if puddles and len(puddles) > 1:
            keys = ", ".join(f"[{k}, {r:.4f}]" for k, r in enumerate(puddles))
            lines += ["", "[[animation.tracks]]", 'path = "objects[meltwater].radius"',
                      'interpolation = "step"', f"keys = [{keys}]"]
        if bubbles and inner is not None and len(bubbles) > 1:
            centres = ", ".join(f"[{k}, [{c[0]:.4f}, {c[1]:.4f}, {c[2]:.4f}]]"
                                for k, (c, _) in enumerate(bubbles))
            radii = ", ".join(f"[{k}, {r:.5f}]" for k, (_, r) in enumerate(bubbles))
            lines += ["", "[[animation.tracks]]", 'path = "objects[void bubble].center"',
                      'interpolation = "step"', f"keys = [{centres}]",
                      "", "[[animation.tracks]]", 'path = "objects[void bubble].radius"',
                      'interpolation = "step"', f"keys = [{radii}]"]
        if shown and len(tracers) > 1:
            for k in range(len(shown)):
                keys = ", ".join(
                    f"[{n}, [{p[k][0]:.4f}, {p[k][1] + LIFT_CM:.4f}, {p[k][2]:.4f}]]"
                    for n, p in enumerate(tracers) if k < len(p))
                lines += ["", "[[animation.tracks]]", f'path = "objects[tracer {k}].center"',
                          'interpolation = "step"', f"keys = [{keys}]"]
    return "\n".join(lines) + "\n"


def write_scene(path: Path, text: str) -> None:
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
