"""assets/mtl.py: MTL text in any encoding, comments and escaped blanks, texture-map options
wherever they stand, every statement's warning in words, and the MTL-to-Whitted mapping of
the module docstring worked out value by value."""

from __future__ import annotations

from pathlib import Path

import pytest

from whitted.assets.mtl import (
    MtlRecord,
    TextureMap,
    decode_text,
    find_texture,
    parse_mtl,
    parse_texture_map,
    read_mtl_file,
    split_escaped,
    strip_comment,
    to_material,
)


def test_text_in_any_encoding():
    assert decode_text("newmtl é".encode("utf-16")) == "newmtl é"
    assert decode_text(b"\xff\xfe\x00\xd8") == "\xff\xfe\x00\xd8"  # a lone surrogate: Latin-1
    assert decode_text(b"\xef\xbb\xbfnewmtl a") == "newmtl a"
    assert decode_text("newmtl é".encode("latin-1")) == "newmtl é"


def test_comments_and_escaped_blanks():
    assert strip_comment("# all") == ""
    assert strip_comment("1 0 0 # red") == "1 0 0 "
    assert strip_comment("wood#2.png") == "wood#2.png"
    assert split_escaped(r"my\ file.png  -o\ 1  x") == ["my file.png", "-o 1", "x"]
    assert split_escaped("a\\") == ["a\\"]


def test_texture_map_options_before_and_after_the_name():
    m = parse_texture_map("-clamp on -o 0.5 0.25 wood grain.png -s 2 -bm 1.5 -foo 3 -bar")
    assert m == TextureMap(file="wood grain.png", options={
        "-clamp": ["on"], "-o": ["0.5", "0.25"], "-s": ["2"], "-bm": ["1.5"],
        "-foo": ["3"], "-bar": []})
    # a word after -imfchan is its argument; -type takes one word, not two
    assert parse_texture_map("-imfchan r -type sphere env.png") == TextureMap(
        file="env.png", options={"-imfchan": ["r"], "-type": ["sphere"]})
    assert parse_texture_map("-2") == TextureMap(file="-2")  # a number is no option
    assert parse_texture_map("-clamp on") is None


def test_parse_warnings_in_words():
    text = ("Kd 1 0 0\n"  # before any newmtl: ignored
            "newmtl  glass \n"
            "Kd spectral file.spd\nKs xyz 1 1 1\nKa one two three\nKt 1 inf 0\n"
            "Tf 0.5\nNs\nNi nan\nd -halo 0.25\nTr x\nillum\nillum 1e400\nmap_Kd -clamp on\n"
            "map_Kd\twood.png # the grain\nKe 1 1 1\n# a comment\n\n"
            "newmtl\tb\nillum 4.7\nKd\t0 1 0  # tab, then blanks\n")
    warnings: list[str] = []
    records = parse_mtl(text, "lib.mtl", warnings)
    assert warnings == [
        "lib.mtl:3: Kd spectral colours are not supported (ignored)",
        "lib.mtl:4: Ks xyz colours are not supported (ignored)",
        "lib.mtl:5: bad colour 'one two three' (ignored)",
        "lib.mtl:6: bad colour '1 inf 0' (ignored)",
        "lib.mtl:8: bad number '' (ignored)",
        "lib.mtl:9: bad number 'nan' (ignored)",
        "lib.mtl:11: bad number 'x' (ignored)",
        "lib.mtl:12: bad illum '' (ignored)",
        "lib.mtl:13: bad illum '1e400' (ignored)",
        "lib.mtl:14: map_Kd without a file name (ignored)",
    ]
    glass = records["glass"]
    assert glass.line == 2 and glass.colours == {"tf": (0.5, 0.5, 0.5)}
    assert glass.scalars == {"d": 0.25}
    assert glass.diffuse_map == TextureMap(file="wood.png") and glass.diffuse_map_line == 15
    assert records["b"].illum == 4
    assert records["b"].colours == {"kd": (0.0, 1.0, 0.0)}


def _material(folder: Path, **record):
    warnings: list[str] = []
    textures: list[str] = []
    mat = to_material(MtlRecord(name="m", line=1, **record), folder, "lib.mtl", warnings,
                      textures)
    return mat, warnings, textures


def test_the_mapping_value_by_value(tmp_path):
    mat, warnings, _ = _material(tmp_path, colours={
        "kd": (1.5, 0.5, -1.0), "ka": (0.1, 0.2, 0.3), "ks": (0.4, 0.8, 0.2)},
        scalars={"ns": 2e6, "ni": 20.0, "tr": 0.25}, illum=3)
    assert warnings == []
    assert mat.color == (1.0, 0.5, 0.0) and mat.ambient_color == (0.1, 0.2, 0.3)
    assert mat.ks == 0.8 and mat.specular_color == pytest.approx((0.5, 1.0, 0.25))
    assert mat.shininess == 100000.0 and mat.ior == 10.0
    assert mat.kr == 0.8 and not mat.fresnel
    assert mat.kt == 0.25 and mat.kd == pytest.approx(0.8 * 0.75)  # Tr is 1 - d
    # d wins over Tr; black Ka is no ambient colour; Ni 0 leaves the ior
    mat, _, _ = _material(tmp_path, colours={"ka": (0, 0, 0)},
                          scalars={"d": 0.75, "tr": 0.9, "ni": 0.0})
    assert mat.kt == 0.25 and mat.ambient_color is None and mat.ior == 1.0
    # glass-like without d: kt from the filter colour's largest; Fresnel on
    mat, _, _ = _material(tmp_path, colours={"tf": (0.2, 0.9, 0.4), "ks": (0.5, 0.5, 0.5)},
                          illum=7)
    assert (mat.kt, mat.kr, mat.fresnel) == (0.9, 0.5, True)
    mat, _, _ = _material(tmp_path, colours={"kt": (0.3, 0.1, 0.2)}, illum=6)
    assert mat.kt == 0.3 and mat.kr == 0.0 and mat.fresnel
    mat, _, _ = _material(tmp_path, illum=4)
    assert mat.kt == 0.0 and mat.fresnel  # nothing says how much passes


def test_texture_maps_found_placed_or_missing(tmp_path):
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "wood.png").write_bytes(b"")
    mat, warnings, textures = _material(
        tmp_path, diffuse_map=TextureMap("maps\\wood.png", {"-o": ["0.5"], "-s": ["2", "3"],
                                                            "-clamp": ["ON"]}),
        diffuse_map_line=7)
    path = str((tmp_path / "maps" / "wood.png").resolve())
    assert warnings == [] and textures == [path]
    assert mat.texture.file == path and mat.texture.wrap == "clamp"
    assert mat.texture.offset == (0.5, 0.0) and mat.texture.scale == (2.0, 3.0)
    mat, warnings, _ = _material(
        tmp_path, diffuse_map=TextureMap("maps/wood.png", {"-o": ["x"], "-s": [],
                                                           "-clamp": ["off"]}),
        diffuse_map_line=7)
    assert warnings == ["lib.mtl:7: bad -o values ['x'] (ignored)",
                        "lib.mtl:7: bad -s values [] (ignored)"]
    assert mat.texture.wrap == "repeat" and mat.texture.offset == (0.0, 0.0)
    mat, warnings, textures = _material(tmp_path, colours={"kd": (1, 0, 0)},
                                        diffuse_map=TextureMap("gone.png"), diffuse_map_line=9)
    assert mat.texture is None and mat.color == (1.0, 0.0, 0.0) and textures == []
    assert warnings == ["lib.mtl:9: texture image 'gone.png' not found (material 'm' uses its "
                        "plain Kd colour)"]


def test_finding_texture_files(tmp_path):
    (tmp_path / "wood.png").write_bytes(b"")
    found = (tmp_path / "wood.png").resolve()
    assert find_texture(str(tmp_path / "wood.png"), Path("/nowhere")) == found  # absolute
    assert find_texture("C:\\textures\\wood.png", tmp_path) == found  # its base name here
    assert find_texture("elsewhere/wood.jpg", tmp_path) is None
    assert find_texture("", tmp_path) is None


def test_a_library_that_cannot_be_read_is_a_warning(tmp_path):
    warnings: list[str] = []
    assert read_mtl_file(tmp_path / "none.mtl", warnings) is None
    assert warnings == [f"{tmp_path / 'none.mtl'}: no such file"]
    (tmp_path / "ok.mtl").write_bytes("newmtl a\nKd 0 1 0\n".encode("utf-16"))
    records = read_mtl_file(tmp_path / "ok.mtl", warnings)
    assert records["a"].colours == {"kd": (0.0, 1.0, 0.0)}
