"""Materials: the Whitted/Phong surface description, plus named presets."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from .textures import Texture
from .types import Colour, Finite, Strict, Unit


class Material(Strict):
    """How a surface shades.

    The Whitted model (lecture eq. 9): ``I = ka·Ia·Ca + Σ_j Ij·(kd·Cd·(n·l) + ks·Cs·spec) +
    kr·Ir + kt·Cd·It`` where ``spec`` is ``(r·v)^shininess`` (phong) or ``(n·h)^shininess`` (blinn).
    ``attenuation`` is the Beer–Lambert absorption coefficient per unit length inside the body
    (``exp(-attenuation·distance)``), a number or a colour-wise triple.

    ``texture`` multiplies ``color`` by a texture's value at the hit's (u, v); when a texture
    is given and ``color`` is not, ``color`` is white, so the texture shows as it is.
    """

    preset: str | None = None
    color: Colour = (0.8, 0.8, 0.8)
    ambient_color: Colour | None = None
    specular_color: Colour | None = None
    ka: Unit = 0.2
    kd: Unit = 0.8
    ks: Unit = 0.0
    shininess: float = Field(default=32.0, ge=0.0, le=100000.0)
    specular_model: Literal["phong", "blinn"] = "blinn"
    kr: Unit = 0.0
    kt: Unit = 0.0
    ior: float = Field(default=1.0, gt=0.0, le=10.0)
    attenuation: Finite | tuple[Finite, Finite, Finite] = 0.0
    fresnel: bool = False
    texture: Texture | None = None

    @model_validator(mode="before")
    @classmethod
    def _apply_preset(cls, data: object) -> object:
        if isinstance(data, dict) and data.get("preset") is not None:
            name = data["preset"]
            if not isinstance(name, str):
                raise ValueError(f"preset must be a preset's name (one of {', '.join(PRESETS)})")
            if name not in PRESETS:
                raise ValueError(f"unknown material preset {name!r} (known: {', '.join(PRESETS)})")
            merged = dict(PRESETS[name])
            merged.update(data)
            return merged
        return data

    @model_validator(mode="after")
    def _check_attenuation(self) -> Material:
        values = self.attenuation if isinstance(self.attenuation, tuple) else (self.attenuation,)
        if any(v < 0 for v in values):
            raise ValueError("attenuation must be >= 0")
        return self

    @model_validator(mode="after")
    def _white_under_texture(self) -> Material:
        if self.texture is not None and "color" not in self.model_fields_set:
            object.__setattr__(self, "color", (1.0, 1.0, 1.0))
        return self

    def attenuation_rgb(self) -> tuple[float, float, float]:
        a = self.attenuation
        return a if isinstance(a, tuple) else (a, a, a)


# Linear colours. Values chosen to look right at scene scales of a few units.
PRESETS: dict[str, dict[str, object]] = {
    "matte": {"color": (0.8, 0.8, 0.8), "ka": 0.2, "kd": 0.9, "ks": 0.0},
    "plastic": {
        "color": (0.8, 0.1, 0.1), "ka": 0.15, "kd": 0.8, "ks": 0.5, "shininess": 64.0,
        "specular_model": "blinn", "kr": 0.05,
    },
    "mirror": {
        "color": (0.95, 0.95, 0.95), "ka": 0.0, "kd": 0.05, "ks": 0.6, "shininess": 500.0,
        "kr": 0.9,
    },
    "chrome": {
        "color": (0.55, 0.56, 0.58), "ka": 0.05, "kd": 0.15, "ks": 0.8, "shininess": 200.0,
        "specular_color": (0.9, 0.9, 0.95), "kr": 0.7,
    },
    "glass": {
        "color": (1.0, 1.0, 1.0), "ka": 0.0, "kd": 0.0, "ks": 0.6, "shininess": 300.0,
        "kr": 0.05, "kt": 0.95, "ior": 1.5, "fresnel": True,
    },
    "water": {
        "color": (1.0, 1.0, 1.0), "ka": 0.0, "kd": 0.0, "ks": 0.5, "shininess": 300.0,
        "kr": 0.02, "kt": 0.98, "ior": 1.333, "fresnel": True, "attenuation": (0.25, 0.06, 0.03),
    },
    "ice": {
        "color": (0.95, 0.98, 1.0), "ka": 0.02, "kd": 0.05, "ks": 0.4, "shininess": 120.0,
        "kr": 0.03, "kt": 0.9, "ior": 1.309, "fresnel": True, "attenuation": (0.08, 0.03, 0.02),
    },
}
