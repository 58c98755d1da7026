"""Materials -> the material table (one row each, stored once) and the textures they use."""

from __future__ import annotations

import numpy as np

from ..kernels.layout import (
    MAT_AMBIENT,
    MAT_ATTEN,
    MAT_BLINN,
    MAT_COLOR,
    MAT_FRESNEL,
    MAT_IOR,
    MAT_KA,
    MAT_KD,
    MAT_KR,
    MAT_KS,
    MAT_KT,
    MAT_OUTSIDE,
    MAT_SHININESS,
    MAT_SPECULAR,
    MAT_TEXTURE,
    N_MAT_PARAMS,
)
from ..scene.materials import Material


def material_row(mat: Material, texture: int = -1, outside: int = -1) -> np.ndarray:
    """The material table row of ``mat``; ``texture`` is its row in the texture table,
    ``outside`` the row of the medium outside the surface (-1: none named)."""
    row = np.zeros(N_MAT_PARAMS)
    row[MAT_COLOR : MAT_COLOR + 3] = mat.color
    row[MAT_AMBIENT : MAT_AMBIENT + 3] = mat.ambient_color or mat.color
    row[MAT_SPECULAR : MAT_SPECULAR + 3] = mat.specular_color or (1.0, 1.0, 1.0)
    row[MAT_KA] = mat.ka
    row[MAT_KD] = mat.kd
    row[MAT_KS] = mat.ks
    row[MAT_SHININESS] = mat.shininess
    row[MAT_BLINN] = 1.0 if mat.specular_model == "blinn" else 0.0
    row[MAT_KR] = mat.kr
    row[MAT_KT] = mat.kt
    row[MAT_IOR] = mat.ior
    row[MAT_ATTEN : MAT_ATTEN + 3] = mat.attenuation_rgb()
    row[MAT_FRESNEL] = 1.0 if mat.fresnel else 0.0
    row[MAT_TEXTURE] = texture
    row[MAT_OUTSIDE] = outside
    return row


class MaterialTable:
    """Material rows and the textures they use, each stored once."""

    def __init__(self) -> None:
        self.rows: list[np.ndarray] = []
        self.index: dict[bytes, int] = {}
        self.textures: list = []
        self.texture_index: dict[str, int] = {}

    def add(self, mat: Material, outside: int = -1) -> int:
        """The row of ``mat`` (with ``outside``, the row of the medium outside it)."""
        tex = -1
        if mat.texture is not None:
            key = mat.texture.model_dump_json()
            if key not in self.texture_index:
                self.texture_index[key] = len(self.textures)
                self.textures.append(mat.texture)
            tex = self.texture_index[key]
        row = material_row(mat, tex, outside)
        key = row.tobytes()
        if key not in self.index:
            self.index[key] = len(self.rows)
            self.rows.append(row)
        return self.index[key]
