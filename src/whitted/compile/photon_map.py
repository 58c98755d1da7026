"""The caustics' photon map: targets, emitters, photons shot on all cores, the hashed grid
the render kernel gathers from (docs/caustics.md).

:func:`photon_lights` turns a compiled scene's ``LightArrays`` into the same with a photon
map when ``[render.caustics] photons`` is above 0. Every pass shoots its photons
(kernels/photons.py) and gets its own gather radius, shrinking as progressive photon
mapping prescribes (Hachisuka et al. 2008, in the memoryless form of Knaus and Zwicker
2011: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1)); all passes' photons go into one grid, and
the gather averages the passes' estimates in one render.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError
from ..jit import builder
from ..kernels.caustics import cell_hash, cell_of
from ..kernels.layout import (
    BVH_STACK,
    GRID_BITS,
    GRID_INV_CELL,
    GRID_PASS,
    GRID_PASSES,
    GRID_R2_MAX,
    LIGHT_DIRECTIONAL,
    LIGHT_DIST_SCALE,
    LIGHT_FALLOFF,
    LIGHT_POSITION,
    LIGHT_RADIANCE,
    LIGHT_TYPE,
    MAT_ATTEN,
    MAT_COLOR,
    MAT_KR,
    MAT_KT,
    MAX_MEDIA,
    MESH_TRI_COUNT,
    MESH_TRI_OFFSET,
    PHOTON_POWER,
    PHOTON_WIDTH,
    PRIM_MATERIAL,
    PRIM_OBJECT,
    PRIM_TYPE,
    SHAPE_MESH,
    LightArrays,
    RenderParams,
)
from ..kernels.photons import (
    EMIT_BACK,
    EMIT_CENTRE,
    EMIT_COUNT,
    EMIT_FIRST,
    EMIT_LIGHT,
    EMIT_RADIUS,
    N_EMIT,
    N_SET,
    SET_DEPTH,
    SET_EPSILON,
    SET_PASS,
    SET_SEED,
    SET_SLOTS,
)
from ..scene.scene import CausticsSettings
from .scene import CompiledScene

SLOTS = 6  # records one photon may store: SHADOW_SLOTS shadow photons, caustic photons
#: (diffuse surfaces that also reflect or refract) in the rest
#: the offset (in cells) of the grid the default radius counts photons in
GRID_SHIFT = np.array([0.5, 0.5, 0.5])
DEFAULT_NEIGHBOURS = 256  # photons the default radius gathers where light is not focused
MAX_TARGETS = 64  # more bodies than this are aimed at as one bounding sphere
PHOTON_BYTES = PHOTON_WIDTH * 4
MEMORY_SHARE = 0.5  # of the memory available, what a photon map may take
CHUNK_MIN = 2048  # photons per kernel call: at least this many (calls cost little)...
CHUNK_MAX = 1 << 18  # ...at most this many (a cancel waits for the calls under way)


@dataclass
class Targets:
    """Bounding spheres of the scene's reflecting or refracting bodies (one per object) and
    how much of the light each passes on (its largest kr + kt)."""

    centres: np.ndarray  # (T, 3)
    radii: np.ndarray  # (T,)
    strength: np.ndarray  # (T,)


def _specular(mats: np.ndarray, rows: np.ndarray) -> np.ndarray:
    return mats[rows, MAT_KR] + mats[rows, MAT_KT]


def _specular_primitives(compiled: CompiledScene) -> tuple[np.ndarray, np.ndarray]:
    """(the largest kr + kt of each primitive's materials, whether it is bounded)."""
    geo = compiled.geometry
    mats = compiled.materials
    info = geo.prim_info
    n = len(info)
    strength = np.zeros(n)
    own = info[:, PRIM_MATERIAL]
    has_own = own >= 0
    strength[has_own] = _specular(mats, own[has_own])
    for i in np.flatnonzero(~has_own & (info[:, PRIM_TYPE] == SHAPE_MESH)):
        mesh = int(geo.prim_params[i, 0])
        start = geo.mesh_info[mesh, MESH_TRI_OFFSET]
        rows = geo.tri_material[start:start + geo.mesh_info[mesh, MESH_TRI_COUNT]]
        strength[i] = _specular(mats, rows).max(initial=0.0)
    lo, hi = compiled.prim_lo, compiled.prim_hi
    return strength, np.all(np.isfinite(lo) & np.isfinite(hi), axis=1)


def unbounded_specular_objects(compiled: CompiledScene) -> list[int]:
    """The scene objects (indices) with an unbounded primitive that reflects or refracts:
    an infinite plane. Photons cannot be aimed at all of it: it casts no caustic (a mirror
    plane sends no light on; light passes a transparent one as it passes shadow rays,
    times kt·colour, straight, without Fresnel) and renders say so."""
    strength, bounded = _specular_primitives(compiled)
    info = compiled.geometry.prim_info
    return sorted({int(o) for o in info[(strength > 0.0) & ~bounded, PRIM_OBJECT]})


def caustic_targets(compiled: CompiledScene) -> Targets:
    """The bounded objects with a material that reflects or refracts (kr or kt > 0): the
    bounding sphere of their primitives that do, per scene object."""
    strength, bounded = _specular_primitives(compiled)
    info = compiled.geometry.prim_info
    lo, hi = compiled.prim_lo, compiled.prim_hi
    chosen = np.flatnonzero((strength > 0.0) & bounded)
    objects = info[chosen, PRIM_OBJECT]
    centres, radii, power = [], [], []
    for obj in sorted(set(objects.tolist())):  # (np.unique would import numpy.ma: 10 ms)
        mine = chosen[objects == obj]
        box_lo, box_hi = lo[mine].min(axis=0), hi[mine].max(axis=0)
        centres.append(0.5 * (box_lo + box_hi))
        radii.append(0.5 * float(np.linalg.norm(box_hi - box_lo)))
        power.append(float(strength[mine].max()))
    if len(centres) > MAX_TARGETS:  # one sphere around them all
        box_lo = np.min([c - r for c, r in zip(centres, radii, strict=True)], axis=0)
        box_hi = np.max([c + r for c, r in zip(centres, radii, strict=True)], axis=0)
        centres = [0.5 * (box_lo + box_hi)]
        radii = [0.5 * float(np.linalg.norm(box_hi - box_lo))]
        power = [max(power)]
    return Targets(np.array(centres, np.float64).reshape(-1, 3),
                   np.maximum(np.array(radii, np.float64), 1e-9),
                   np.array(power, np.float64))


def clear_materials(compiled: CompiledScene) -> np.ndarray:
    """Which material rows are *clear* with caustics on (bool per row): the transparent
    ones (kt > 0) of bounded bodies. Shadow rays pass them as if they were not there, and
    their effect on the light arrives as photons: the caustic photons add the light they
    send on, the shadow photons take away what passed straight through them. Materials of
    unbounded shapes are not clear (a transparent infinite plane cannot be aimed at: its
    light keeps passing shadow rays multiplied by kt, and photons crossing it do not count
    it as a specular bounce)."""
    table = compiled.materials
    lo, hi = compiled.prim_lo, compiled.prim_hi
    unbounded = ~np.all(np.isfinite(lo) & np.isfinite(hi), axis=1)
    keep = compiled.geometry.prim_info[unbounded, PRIM_MATERIAL]
    keep = keep[keep >= 0]
    clear = table[:, MAT_KT] > 0.0
    clear[keep] = False
    return clear


def shadow_material_table(compiled: CompiledScene) -> np.ndarray:
    """The material table shadow rays see with caustics on: the clear materials
    (:func:`clear_materials`) pass all the light (kt 1, white, no absorption); the rest
    as they are. The direct term is then the light as if the clear bodies were not there,
    and the photon map corrects it (docs/caustics.md): no double counting, and no rim at
    the shadow's edge, since the shadow photons blur the shadow exactly as the caustic
    photons blur the caustic."""
    table = compiled.materials.copy()
    clear = clear_materials(compiled)
    table[clear, MAT_KT] = 1.0
    table[clear, MAT_COLOR:MAT_COLOR + 3] = 1.0
    table[clear, MAT_ATTEN:MAT_ATTEN + 3] = 0.0
    return table


def _light_power(table: np.ndarray, j: int, centre: np.ndarray, radius: float) -> float:
    """The light's power into a target's bounding sphere (for sharing the photons out)."""
    lum = float(np.mean(table[j, LIGHT_RADIANCE:LIGHT_RADIANCE + 3]))
    if table[j, LIGHT_TYPE] == LIGHT_DIRECTIONAL:
        return lum * math.pi * radius * radius
    dist = float(np.linalg.norm(centre - table[j, LIGHT_POSITION:LIGHT_POSITION + 3]))
    if dist <= radius:
        omega = 4.0 * math.pi
    else:
        omega = 2.0 * math.pi * (1.0 - math.sqrt(1.0 - (radius / dist) ** 2))
    mode = table[j, LIGHT_FALLOFF]
    scale = 1.0 if mode == 2.0 else (table[j, LIGHT_DIST_SCALE] * max(dist, radius)
                                     if mode == 1.0 else max(dist, radius) ** 2)
    return lum * omega * scale


def emitters(compiled: CompiledScene, targets: Targets, photons: int) -> np.ndarray:
    """One row per (light, target) pair (kernels/photons.py's EMIT_* columns): the
    ``photons`` of a pass shared out by the power each pair sends on (largest remainder,
    so they add up exactly)."""
    table = compiled.lights.table
    n_t = len(targets.radii)
    rows = np.zeros((table.shape[0] * n_t, N_EMIT))
    weights = np.zeros(len(rows))
    finite = np.isfinite(compiled.bounds_min).all()
    middle = 0.5 * (compiled.bounds_min + compiled.bounds_max) if finite else np.zeros(3)
    half = 0.5 * float(np.linalg.norm(compiled.bounds_max - compiled.bounds_min)) if finite else 0
    for j in range(table.shape[0]):
        for k in range(n_t):
            row = rows[j * n_t + k]
            c, r = targets.centres[k], float(targets.radii[k])
            row[EMIT_LIGHT] = j
            row[EMIT_CENTRE:EMIT_CENTRE + 3] = c
            row[EMIT_RADIUS] = r
            row[EMIT_BACK] = r + float(np.linalg.norm(c - middle)) + half + 1.0
            weights[j * n_t + k] = _light_power(table, j, c, r) * targets.strength[k]
    total = weights.sum()
    if total > 0 and photons > 0:
        share = weights / total * photons
        counts = np.floor(share)
        left = int(photons - counts.sum())
        counts[np.argsort(-(share - counts), kind="stable")[:left]] += 1
    else:
        counts = np.zeros(len(rows))
    rows[:, EMIT_COUNT] = counts
    rows[:, EMIT_FIRST] = np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(rows) else []
    return rows[counts > 0] if len(rows) else rows


def pass_radii(radius: float, passes: int, alpha: float) -> np.ndarray:
    """Gather radius of each pass: r_1 = radius, r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1)."""
    r2 = np.empty(passes)
    r2[0] = radius * radius
    for i in range(1, passes):
        r2[i] = r2[i - 1] * (i + alpha) / (i + 1)
    return np.sqrt(r2)


def default_radius(targets: Targets, photons: int) -> float:
    """A first guess of the radius gathering DEFAULT_NEIGHBOURS photons: the photons of a
    pass spread over the targets' cross-sections (:func:`fitted_radius` refines it)."""
    area = float(np.sum(math.pi * targets.radii ** 2)) if len(targets.radii) else 1.0
    return math.sqrt(DEFAULT_NEIGHBOURS * area / (math.pi * max(photons, 1)))


def fitted_radius(positions: np.ndarray, guess: float,
                  neighbours: int = DEFAULT_NEIGHBOURS) -> float:
    """The radius at which the typical stored photon of a pass (``positions``) has about
    ``neighbours`` others within it: the photons' density read off a grid of cells twice
    the radius (photons lie on surfaces: a cell holds about (2r)^2 of surface), the median
    over the photons of their cell's count, twice (from ``guess``, kept within 1/8 to 4
    times it)."""
    if len(positions) < neighbours:
        return guess
    r = guess
    pos = positions.astype(np.float64)
    cells = np.empty_like(pos)
    edges = np.empty(len(pos) + 1, bool)  # where a run of equal keys starts or ends
    edges[0] = edges[-1] = True
    for _ in range(2):
        h = 2.0 * r
        # the cells shifted off the origin: a floor at y = 0 would lie on their boundary,
        # its photons split between two rows of cells by their last bits
        np.divide(pos, h, out=cells)
        cells += GRID_SHIFT
        ints = np.floor(cells, out=cells).astype(np.int64)
        keys = (ints[:, 0] * 73856093) ^ (ints[:, 1] * 19349663) ^ (ints[:, 2] * 83492791)
        # each photon's cell count: the lengths of the runs of equal keys, sorted (the
        # median over the photons is that of each run's length repeated by itself)
        keys.sort()
        np.not_equal(keys[1:], keys[:-1], out=edges[1:-1])
        counts = np.diff(np.flatnonzero(edges))
        density = float(np.median(np.repeat(counts, counts))) / (h * h)
        r = min(4.0 * guess, max(guess / 8.0, math.sqrt(neighbours / (math.pi * density))))
    return r


def chunk_bounds(photons: int, threads: int) -> np.ndarray:
    """Where the tracer's calls of a pass start and end: 8 calls a thread (they balance the
    load), each of CHUNK_MIN to CHUNK_MAX photons."""
    chunks = max(1, min(8 * threads, -(-photons // CHUNK_MIN)), -(-photons // CHUNK_MAX))
    return np.linspace(0, photons, chunks + 1).astype(np.int64)


def check_photon_memory(settings: CausticsSettings, threads: int = 1) -> int:
    """The bytes a photon map of these settings may take (each thread's output slots for
    its calls, a pass's counts; the photons stored, one per photon shot on average, three
    copies while the grid is sorted, their cell keys and two hash-table rows each);
    :class:`SceneError` naming the key when that is more than half the memory available."""
    widest = int(np.diff(chunk_bounds(settings.photons, threads)).max())
    need = (threads * widest * SLOTS * PHOTON_BYTES + settings.photons * 4
            + settings.photons * settings.passes * (3 * PHOTON_BYTES + 8 + 8))
    from ..files.memory import memory_room

    room = memory_room()
    if room is not None and need > MEMORY_SHARE * room.bytes:
        raise SceneError(
            f"render.caustics: {settings.photons:,} photons x {settings.passes:,} passes need "
            f"about {need / 2**30:.1f} GiB of memory, more than half of what this process "
            f"may take: {room.describe()} (shoot fewer photons or passes)")
    return need


#: The smallest gather radius, in units in the last place of the photons' float32 positions
#: at the scene's size: below it no two positions differ by less than the radius, and its
#: square would underflow the gather's arithmetic (1e-300 squared is 0).
RADIUS_ULPS = 16


def smallest_radius(compiled: CompiledScene) -> float:
    """The smallest gather radius the scene's size allows (:data:`RADIUS_ULPS`)."""
    lo, hi = compiled.bounds_min, compiled.bounds_max
    size = float(max(np.abs(lo).max(), np.abs(hi).max())) if np.all(np.isfinite(lo)) \
        and np.all(np.isfinite(hi)) else 1.0
    return RADIUS_ULPS * float(np.spacing(np.float32(max(size, 1.0))))


def check_radius(compiled: CompiledScene, settings: CausticsSettings) -> None:
    """:class:`SceneError` naming ``render.caustics.radius`` when it is set below what the
    photons' positions can resolve in this scene (0, the default, chooses one)."""
    if settings.radius == 0.0:
        return
    floor = smallest_radius(compiled)
    if settings.radius < floor:
        raise SceneError(f"{settings.radius:g} is smaller than the photons' positions can "
                         f"resolve in this scene (at least {floor:.2g}; 0 chooses one)",
                         where="render.caustics.radius")


@builder(_nrt=False)
def _fill_grid(photons, inv_cell, bits, keys, cells, fill, out):
    """``out``: ``photons`` sorted by the hash row of their grid cell (stable: the order
    within a row is the order shot); ``cells`` (zeroed, 2^(3 bits) + 1 entries): the hash
    table's row starts. ``keys`` (one int64 a photon) and ``fill`` (one int32 a row) are
    scratch. Every array comes from the caller: no Numba runtime."""
    n = photons.shape[0]
    rows = 1 << (3 * bits)
    for q in range(n):
        h = cell_hash(cell_of(np.float64(photons[q, 0]), inv_cell),
                      cell_of(np.float64(photons[q, 1]), inv_cell),
                      cell_of(np.float64(photons[q, 2]), inv_cell), bits)
        keys[q] = h
        cells[h + 1] += 1
    for h in range(rows):
        cells[h + 1] += cells[h]
    for h in range(rows):
        fill[h] = cells[h]
    for q in range(n):
        h = keys[q]
        for c in range(photons.shape[1]):
            out[fill[h], c] = photons[q, c]
        fill[h] += 1


def build_grid(photons: np.ndarray, inv_cell: float, bits: int) -> tuple[np.ndarray, np.ndarray]:
    """``photons`` sorted by the hash row of their grid cell (stable: the order within a
    row is the order shot) and the hash table's row starts (2^(3 bits) rows)."""
    rows = 1 << (3 * int(bits))
    cells = np.zeros(rows + 1, np.int32)
    out = np.empty_like(photons)
    _fill_grid(photons, inv_cell, bits, np.empty(photons.shape[0], np.int64), cells,
               np.empty(rows, np.int32), out)
    return out, cells


def grid_bits(photons: int) -> int:
    """Bits per cell coordinate: at least two rows per photon, at least 4 cells a side."""
    return max(2, -(-max(1, 2 * photons - 1).bit_length() // 3))


@dataclass
class PhotonStats:
    """What a photon map took: photons shot and stored, radii, seconds."""

    shot: int = 0
    stored: int = 0
    radius: float = 0.0
    last_radius: float = 0.0
    targets: int = 0
    seconds: float = 0.0
    warnings: list[str] = field(default_factory=list)


def shoot_pass(compiled: CompiledScene, rows: np.ndarray, clear: np.ndarray,
               params: RenderParams, photons: int, pass_index: int, threads: int,
               pool: ThreadPoolExecutor | None,
               cancelled: Callable[[], bool] = lambda: False) -> np.ndarray:
    """The records the photons of one pass store, in photon order (chunks of photons not
    started once ``cancelled()`` is true are left out: the render is being cancelled)."""
    from ..kernels.photons import trace_photons
    from ..kernels.strict import strict

    # compiled without fast-math (kernels/strict.py): the same photons on every CPU target,
    # cold compiled or loaded from the cache
    tracer = strict(trace_photons)
    settings = np.zeros(N_SET)
    settings[SET_SEED] = params.seed
    settings[SET_PASS] = pass_index
    settings[SET_DEPTH] = params.max_depth
    settings[SET_EPSILON] = params.epsilon
    settings[SET_SLOTS] = SLOTS
    counts = np.zeros(photons, np.int32)
    bounds = chunk_bounds(photons, threads)
    chunks = len(bounds) - 1
    widest = int(np.diff(bounds).max())
    # each thread's call writes its photons' slots into rows of its own, used again by its
    # next call (not one row block for every photon of the pass: 48 MB to fault in at
    # 200,000 photons), and keeps the records stored, in photon order
    mine = threading.local()
    stored: list[np.ndarray | None] = [None] * chunks
    slot = np.arange(SLOTS)[None, :]

    def run(k: int) -> None:
        if cancelled():
            return
        out = getattr(mine, "out", None)
        if out is None:
            out = mine.out = np.empty((widest * SLOTS, PHOTON_WIDTH), np.float32)
        first, last = int(bounds[k]), int(bounds[k + 1])
        tracer(compiled.geometry, compiled.materials, clear, compiled.lights.table, rows,
               settings, first, last, out, counts, np.empty(BVH_STACK, np.int32),
               np.empty(MAX_MEDIA, np.int32), np.empty(MAX_MEDIA, np.int32))
        keep = slot < counts[first:last, None]
        stored[k] = out[:(last - first) * SLOTS][keep.ravel()]

    if pool is None:
        for k in range(chunks):
            run(k)
    else:
        list(pool.map(run, range(chunks)))
    kept = [part for part in stored if part is not None]
    return np.concatenate(kept) if kept else np.zeros((0, PHOTON_WIDTH), np.float32)


def photon_lights(compiled: CompiledScene, params: RenderParams, settings: CausticsSettings,
                  threads: int = 1, cancelled: Callable[[], bool] = lambda: False,
                  stats: PhotonStats | None = None) -> LightArrays:
    """``compiled.lights`` with the photon map of ``settings`` (which must shoot photons):
    photons traced on ``threads`` threads, the same map on any number."""
    import time

    start = time.perf_counter()
    check_photon_memory(settings, threads)
    check_radius(compiled, settings)
    stats = stats if stats is not None else PhotonStats()
    targets = caustic_targets(compiled)
    stats.warnings = [f"objects[{i}] reflects or refracts but is unbounded: it casts no "
                      "caustic (light passes it as shadow rays do, times kt; "
                      "docs/caustics.md)" for i in unbounded_specular_objects(compiled)]
    rows = emitters(compiled, targets, settings.photons)
    shadow_mats = shadow_material_table(compiled)
    clear = clear_materials(compiled).astype(np.uint8)
    parts = []
    pool = ThreadPoolExecutor(threads, thread_name_prefix="whitted-photons") if threads > 1 \
        else None
    try:
        for p in range(settings.passes):
            if cancelled():
                break
            if len(rows):
                parts.append(shoot_pass(compiled, rows, clear, params, settings.photons,
                                        p, threads, pool, cancelled))
    finally:
        if pool is not None:
            pool.shutdown()
    photons = (np.concatenate(parts) if parts
               else np.zeros((0, PHOTON_WIDTH), np.float32))
    radius = settings.radius
    if radius == 0.0:  # fitted to the first pass's photons (the same on every machine)
        radius = default_radius(targets, settings.photons)
        if parts:
            first = parts[0]  # its caustic photons (the shadow photons carry less than 0)
            radius = fitted_radius(first[first[:, PHOTON_POWER:PHOTON_POWER + 3].sum(axis=1)
                                         > 0.0, :3], radius)
    radii = pass_radii(radius, settings.passes, settings.alpha)
    grid = np.zeros(GRID_PASS + 2 * settings.passes)
    grid[GRID_INV_CELL] = 1.0 / radius
    bits = grid_bits(len(photons))
    grid[GRID_BITS] = bits
    grid[GRID_R2_MAX] = radius * radius
    grid[GRID_PASSES] = settings.passes
    grid[GRID_PASS::2] = (radii * radii)
    grid[GRID_PASS + 1::2] = 2.0 / (math.pi * radii * radii) / settings.passes
    sorted_photons, cells = build_grid(photons, grid[GRID_INV_CELL], bits)
    stats.shot = settings.photons * settings.passes
    stats.stored = len(photons)
    stats.radius = float(radii[0])
    stats.last_radius = float(radii[-1])
    stats.targets = len(targets.radii)
    stats.seconds = time.perf_counter() - start
    return compiled.lights._replace(photons=sorted_photons, photon_cells=cells,
                                    photon_grid=grid, shadow_materials=shadow_mats)


def scene_photon_map(scene, threads: int = 1) -> tuple[CompiledScene, LightArrays, PhotonStats]:
    """Compile ``scene`` and build the photon map of its ``[render.caustics]`` (tests, the
    validation in docs/caustics.md): (compiled scene, lights with the map, stats)."""
    from .params import render_params
    from .scene import compile_scene

    compiled = compile_scene(scene)
    params = render_params(scene, compiled, scene.render)
    stats = PhotonStats()
    return compiled, photon_lights(compiled, params, scene.render.caustics, threads,
                                   stats=stats), stats


def irradiance(lights: LightArrays, points, normals, shadows: bool = False) -> np.ndarray:
    """The caustic irradiance (N, 3) the render kernel's gather finds at ``points`` (N, 3)
    of surfaces with unit ``normals`` (N, 3) facing the side seen: the caustic photons'
    estimate, and with ``shadows`` the shadow photons' (negative) added, as the render adds
    it to the direct term of lights passing the clear bodies."""
    from ..kernels.caustics import irradiance_at

    points = np.ascontiguousarray(points, np.float64).reshape(-1, 3)
    normals = np.ascontiguousarray(np.broadcast_to(normals, points.shape), np.float64)
    out = np.zeros((len(points), 3))
    irradiance_at(lights, points, normals, shadows, out)
    return out
