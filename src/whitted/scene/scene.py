"""The scene: render settings, camera, background, materials, lights and objects. Pure data."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, PrivateAttr, model_validator

from .animation import Animation
from .camera import Camera
from .lights import Light
from .materials import PRESETS, Material
from .shapes import Shape
from .timeline import check_animation, is_sequence, scene_at_frame
from .types import Background, Strict
from .writing import save_scene

MAX_PIXELS = 100_000_000
MAX_DEPTH = 64


class Antialias(Strict):
    """Adaptive anti-aliasing (``[render.antialias]``, POV-Ray's method 2: ``+A0.3 +AM2
    +R3`` is ``threshold = 0.3, max_samples = 81``): a pixel's corners are traced, and a
    pixel (then each of its quarters) whose corners differ by more than ``threshold`` (the
    sum of the red, green and blue differences, 0..3) is split, while a square of it may
    still take (2^k + 1)^2 <= ``max_samples`` samples."""

    threshold: float = Field(default=0.3, ge=0.0, le=3.0)
    max_samples: int = Field(default=81, ge=4, le=1089)

    @property
    def levels(self) -> int:
        """Splits a pixel may take: the most whose grid, (2^levels + 1)^2 points, stays
        within ``max_samples`` (POV-Ray's ``+R``)."""
        levels = 0
        while ((1 << (levels + 1)) + 1) ** 2 <= self.max_samples:
            levels += 1
        return levels
MAX_PHOTONS = 50_000_000  # photons per pass
MAX_PASSES = 4096


class CausticsSettings(Strict):
    """Caustics by (progressive) photon mapping (docs/caustics.md). ``photons``: photons
    shot per pass (0, the default: no caustics, the renderer exactly as without this table);
    ``passes``: progressive passes, each with its own photons and a smaller gather radius;
    ``radius``: the first pass's gather radius in scene units (0: chosen from the size of
    the light's targets and the photon count); ``alpha``: the radius reduction of
    progressive photon mapping (each pass keeps this fraction of the new photons' density,
    Hachisuka et al. 2008)."""

    photons: int = Field(default=0, ge=0, le=MAX_PHOTONS)
    passes: int = Field(default=1, ge=1, le=MAX_PASSES)
    radius: float = Field(default=0.0, ge=0.0, le=1e6)
    alpha: float = Field(default=0.7, gt=0.0, le=1.0)


class RenderSettings(Strict):
    """How to render. ``threads = 0`` uses every core. ``epsilon = 0`` picks the ray offset
    from the scene's size. ``transfer``: ``srgb`` (display images) or ``linear`` (raw values,
    to compare with hand-computed numbers). ``tonemap``: ``clamp``, ``reinhard`` or ``aces``.
    ``mesh_tracer``: who traces the big (instanced) meshes: ``embree`` (Intel's kernels, when
    installed: ``pip install 'whitted[embree]'``), ``whitted`` (its own walk, always there)
    or ``auto`` (Embree when it loads)."""

    width: int = Field(default=640, ge=1, le=100_000)
    height: int = Field(default=480, ge=1, le=100_000)
    samples: int = Field(default=1, ge=1, le=4096)
    max_depth: int = Field(default=5, ge=0, le=MAX_DEPTH)
    min_weight: float = Field(default=0.01, ge=0.0, le=1.0)
    shadow_samples: int = Field(default=16, ge=1, le=4096)
    seed: int = Field(default=0, ge=0, le=2**31 - 1)
    threads: int = Field(default=0, ge=0, le=1024)
    epsilon: float = Field(default=0.0, ge=0.0, le=1.0)
    transfer: Literal["srgb", "linear"] = "srgb"
    tonemap: Literal["clamp", "reinhard", "aces"] = "clamp"
    mesh_tracer: Literal["auto", "whitted", "embree"] = "auto"
    antialias: Antialias | None = None
    caustics: CausticsSettings = Field(default_factory=CausticsSettings)

    @model_validator(mode="after")
    def _size(self) -> RenderSettings:
        if self.antialias is not None and self.samples > 1:
            raise ValueError(f"samples = {self.samples} beside [render.antialias], which "
                             "chooses the samples of each pixel itself: leave samples at 1 "
                             "(antialias.max_samples sets the most)")
        if self.width * self.height > MAX_PIXELS:
            raise ValueError(
                f"{self.width}x{self.height} is over {MAX_PIXELS // 1_000_000} megapixels"
            )
        return self


class Scene(Strict):
    """A whole scene. Build it in Python or load it with :func:`whitted.load_scene`."""

    render: RenderSettings = Field(default_factory=RenderSettings)
    camera: Camera = Field(default_factory=Camera)
    background: Background = Field(default_factory=Background)
    materials: dict[str, Material] = Field(default_factory=dict)
    lights: list[Light] = Field(default_factory=list)
    objects: list[Shape] = Field(default_factory=list)
    #: the time axis (frames, fps, tracks): see :mod:`whitted.animation`; None for a still
    animation: Animation | None = None
    # folder that relative file names (models, textures) are relative to: the scene file's
    # folder when loaded from a file, else the current directory
    _base_dir: Path | None = PrivateAttr(default=None)

    def __eq__(self, other: object) -> bool:
        """Equal content; where relative file names are resolved from does not count."""
        if not isinstance(other, Scene):
            return NotImplemented
        return type(self) is type(other) and self.__dict__ == other.__dict__

    __hash__ = None  # mutable model

    @property
    def base_dir(self) -> Path:
        return self._base_dir if self._base_dir is not None else Path.cwd()

    def with_base_dir(self, folder: str | Path | None) -> Scene:
        """A copy of this scene (shallow: the parts are shared, as they are immutable in use)
        whose relative file names are taken relative to ``folder``."""
        scene = self.model_copy()
        scene._base_dir = None if folder is None else Path(folder).resolve()
        return scene

    def resolve_path(self, name: str | Path) -> Path:
        """The file a scene names: absolute as given, else relative to :attr:`base_dir`."""
        p = Path(name).expanduser()
        return p if p.is_absolute() else self.base_dir / p

    @model_validator(mode="after")
    def _material_names_resolve(self) -> Scene:
        def check(objects, where: str) -> None:
            for i, obj in enumerate(objects):
                name = obj.material
                if isinstance(name, str) and name not in self.materials and name not in PRESETS:
                    known = sorted(set(self.materials) | set(PRESETS))
                    raise ValueError(
                        f"{where}[{i}].material: unknown material {name!r}"
                        f" (known: {', '.join(known)})"
                    )
                if obj.type == "csg":  # the children of a CSG object, to any depth
                    check(obj.objects, f"{where}[{i}].objects")

        check(self.objects, "objects")
        return self

    @model_validator(mode="after")
    def _animation_targets(self) -> Scene:

        check_animation(self)
        return self

    @property
    def frame_count(self) -> int:
        """Frames of the animation (1 for a still scene)."""
        return self.animation.frames if self.animation is not None else 1

    @property
    def is_animated(self) -> bool:
        """Whether frames differ: an animation, or a mesh file naming a numbered sequence."""

        return self.animation is not None or any(
            is_sequence(getattr(obj, "file", None)) for obj in self.objects)

    def at_frame(self, frame: int) -> Scene:
        """The plain still of frame ``frame`` (0 .. frame_count - 1): tracks applied, mesh
        sequences named, the frame's seed derived; this scene is unchanged."""

        return scene_at_frame(self, frame)

    def with_animation(self, frames: int, fps: float = 24.0, tracks: list | None = None) -> Scene:
        """A copy of this scene with an animation (validated against the scene)."""
        scene = self.model_copy()
        scene.animation = Animation(frames=frames, fps=fps, tracks=tracks or [])
        return scene

    def material_of(self, index: int) -> Material:
        """The resolved material of object ``index`` (named, preset, inline or the default)."""
        return self.resolve_material(self.objects[index].material)

    def resolve_material(self, ref: str | Material | None) -> Material:
        """The material a reference names: inline, a name of ``materials``, a preset, or the
        default for None."""
        if ref is None:
            return Material()
        if isinstance(ref, Material):
            return ref
        if ref in self.materials:
            return self.materials[ref]
        return Material(preset=ref)

    def save(self, path: str | Path) -> Path:
        """Write the scene as TOML or JSON (by extension), atomically."""
        return save_scene(self, path)

    def with_settings(self, **overrides: object) -> Scene:
        """A copy with some render settings replaced (validated)."""
        data = self.render.model_dump()
        data.update({k: v for k, v in overrides.items() if v is not None})
        return self.model_copy(update={"render": RenderSettings(**data)})
