"""The POV-Ray exporter, branch by branch: each material, texture, camera, background, light,
shape, CSG and mesh form is written as the SDL text that POV-Ray reads as ours (the worked
values are in each assertion)."""

from __future__ import annotations

import re

import pytest

from whitted.errors import OutputError
from whitted.export.pov import export_pov, povray_antialias_options, scene_to_pov
from whitted.scene import (
    CSG,
    Box,
    Camera,
    DiskLight,
    ImageTexture,
    Material,
    Mesh,
    Scene,
    Sphere,
    Torus,
    Transform,
)


def _block(sdl: str, opening: str) -> str:
    """The text of the top-level block that starts with ``opening``, up to its closing line."""
    start = sdl.index(opening)
    return sdl[start:sdl.index("\n}", start) + 2]


def _declared(sdl: str, name: str) -> str:
    m = re.search(r"#declare " + name + r" = (.*?)\n(?=\n|#|//|$)", sdl + "\n", re.S)
    assert m, name
    return m.group(1)


def test_image_texture_options_and_placement(tmp_path):
    for name in ("a.jpg", "b.weird"):
        (tmp_path / name).write_bytes(b"")
    tex = ImageTexture(file="a.jpg", colorspace="linear", filter="bilinear", wrap="clamp",
                       offset=(0.25, 0.5), rotation=30, scale=(2, 4))
    plain = ImageTexture(file="b.weird", filter="nearest")
    scene = Scene(objects=[
        Sphere(radius=1, material=Material(texture=tex, kt=0.5)),
        Box(min=(2, 0, 0), max=(3, 1, 1), material=Material(texture=plain)),
    ]).with_base_dir(tmp_path)
    sdl = scene_to_pov(scene)
    first = _declared(sdl, "WhittedTexture1")
    assert (f'pigment {{ uv_mapping image_map {{ jpeg "{tmp_path}/a.jpg" gamma 1.0 '
            "interpolate 2 once filter all 0.5 } translate <-0.25, -0.5, 0> "
            "rotate <0, 0, -30> scale <0.5, 0.25, 1> }") in first
    second = _declared(sdl, "WhittedTexture2")
    # an unknown suffix is read as PNG; nearest, repeat and sRGB need no options
    assert (f'pigment {{ uv_mapping image_map {{ png "{tmp_path}/b.weird" }} '
            "translate <0, 0, 0> rotate <0, 0, 0> scale <1, 1, 1> }") in second


def test_finishes_blinn_coloured_specular_plain_reflection_and_no_interior():
    scene = Scene(objects=[
        Sphere(radius=1, material=Material(ks=0.5, shininess=4, specular_color=(0.2, 0.4, 0.6),
                                           kr=0.3)),
        Sphere(center=(3, 0, 0), radius=1, material=Material(ks=0.5, shininess=0)),
        Sphere(center=(6, 0, 0), radius=1, material=Material(kt=0.5, ior=1.2, fresnel=True,
                                                             kr=0.7)),
    ])
    sdl = scene_to_pov(scene)
    # blinn: specular ks·mean(Cs) = 0.5·0.4, roughness 1/shininess; kr without Fresnel
    assert _declared(sdl, "WhittedTexture1") == (
        "texture {\n  pigment { rgb <0.8, 0.8, 0.8> }\n"
        "  finish { ambient 0.2 diffuse 0.8 specular 0.2 roughness 0.25 reflection { 0.3 } }\n}")
    # shininess 0: roughness capped at 1/1e-3
    assert "specular 0.5 roughness 1000 }" in _declared(sdl, "WhittedTexture2")
    # Fresnel: reflection from kr to min(1, kr + kt)
    assert "reflection { 0.7, 1 fresnel on } conserve_energy" in _declared(sdl,
                                                                          "WhittedTexture3")
    assert "rgbf <0.8, 0.8, 0.8, 0.5>" in _declared(sdl, "WhittedTexture3")
    # opaque spheres (kt 0, no absorption, ior 1) get no interior; the third gets one
    assert _block(sdl, "sphere { <0, 0, 0>").count("interior") == 0
    assert "#declare WhittedInterior1 = interior { ior 1.2 }" in sdl
    assert "interior { WhittedInterior1 }" in _block(sdl, "sphere { <6, 0, 0>")


def test_orthographic_camera_with_focal_blur_plain_background_and_settings():
    scene = Scene(
        camera=Camera(position=(0, 0, 5), look_at=(0, 0, 0), projection="orthographic",
                      ortho_height=4, aperture=0.2, focal_distance=3),
        background={"color": [0.1, 0.2, 0.3]},
        render={"width": 40, "height": 20, "transfer": "linear",
                "antialias": {"threshold": 0.2, "max_samples": 25}},
        objects=[Sphere(radius=1)],
    )
    sdl = scene_to_pov(scene, source="scene.toml")
    assert sdl.startswith("// POV-Ray 3.7 scene written by whitted from scene.toml\n"
                          "// render: povray +I<this file> +W40 +H20 +A0.2 +AM2 +R2 +FN "
                          "File_Gamma=1.0  (adaptive anti-aliasing, as whitted's)\n")
    # an orthographic view 4 high and 8 wide; the eye moves by up to twice our aperture;
    # the focal point 3 units ahead, mirrored in z
    assert _block(sdl, "camera {") == (
        "camera {\n  orthographic\n  location <0, 0, -5>\n  direction <0, 0, 1>\n"
        "  right <8, 0, 0>\n  up <0, 4, 0>\n  aperture 0.4\n  blur_samples 19\n"
        "  focal_point <0, 0, -2>\n  variance 0\n}")
    assert "background { rgb <0.1, 0.2, 0.3> }" in sdl
    assert "sky_sphere" not in sdl


def test_antialias_options():
    assert povray_antialias_options(Scene()) == "-A"
    scene = Scene(render={"antialias": {"threshold": 0.3, "max_samples": 81}})
    assert povray_antialias_options(scene) == "+A0.3 +AM2 +R3"
    scene = Scene(render={"antialias": {"threshold": 0.0, "max_samples": 4}})
    assert povray_antialias_options(scene) == "+A0 +AM2 +R1"  # POV-Ray's least depth


def test_a_disk_light_without_samples_uses_the_scenes_shadow_samples():
    scene = Scene(render={"shadow_samples": 9},
                  lights=[DiskLight(center=(0, 5, 0), normal=(1, 0, 0), radius=0.5)])
    sdl = scene_to_pov(scene)
    # 9 samples: a 3 x 3 array; a normal along x takes the helper axis y: u = n x y = z
    assert ("light_source { <0, 5, 0> rgb <1, 1, 1>\n  area_light <0, 0, -1>, <0, -1, 0>, "
            "3, 3 circular jitter area_illumination on }") in sdl


def test_torus_and_csg_with_children_materials_and_transforms():
    inner = CSG(operation="union", objects=[
        Sphere(radius=0.5, material="mirror"),
        Box(min=(-1, -1, -1), max=(1, 1, 1), transform=Transform(scale=0.5)),
    ])
    body = CSG(operation="difference", name="cut\nblock", material="glass",
               transform=Transform(translate=(1, 2, 3)),
               objects=[Box(min=(-1, -1, -1), max=(1, 1, 1), name="cube"), inner])
    scene = Scene(objects=[Torus(major_radius=2, minor_radius=0.5, material="matte"), body])
    sdl = scene_to_pov(scene)
    assert "// objects[0] torus\ntorus { 2, 0.5\n  texture { WhittedTexture1 }\n}" in sdl
    # the label stays one line; glass is the body's medium: one interior for the whole
    glass, mirror = "WhittedTexture2", "WhittedTexture3"
    assert (
        "// objects[1] csg 'cut block'\ndifference {\n"
        f"  box {{ <-1, -1, 1>, <1, 1, -1>\n    texture {{ {glass} }}\n  }}\n"
        "  union {\n"
        f"    sphere {{ <0, 0, 0>, 0.5\n      texture {{ {mirror} }}\n    }}\n"
        f"    box {{ <-1, -1, 1>, <1, 1, -1>\n      texture {{ {glass} }}\n"
        "      matrix <0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5, 0, 0, 0>\n    }\n  }\n"
        "  interior { WhittedInterior1 }\n"
        "  matrix <1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 2, -3>\n}") in sdl
    assert "#declare WhittedInterior1 = interior { ior 1.5 }" in sdl


def test_a_csg_object_without_material_takes_its_first_solids_medium():
    water = Material(preset="water")
    body = CSG(operation="intersection", objects=[
        CSG(operation="merge", objects=[Sphere(radius=1, material=water),
                                        Sphere(center=(0.5, 0, 0), radius=1)]),
        Box(min=(-2, -2, -2), max=(2, 0, 2), material="matte"),
    ])
    sdl = scene_to_pov(Scene(objects=[body]))
    # water's absorption (0.25, 0.06, 0.03): the strongest sets fade_distance 1/0.25
    assert ("interior { ior 1.333 fade_distance 4 fade_power 1001 fade_color <0, 0.76, 0.88> }"
            in sdl)
    assert "merge {" in sdl and sdl.count("interior { WhittedInterior1 }") == 1


def test_caustics_photons_blocks():
    scene = Scene(render={"caustics": {"photons": 1000, "passes": 3, "radius": 0.2},
                          "max_depth": 4},
                  objects=[Sphere(radius=1, material="glass"),
                           Sphere(center=(2, 0, 0), radius=1, material="mirror"),
                           Sphere(center=(4, 0, 0), radius=1, material="matte"),
                           CSG(operation="union", material="glass",
                               objects=[Sphere(radius=1), Sphere(center=(1, 0, 0), radius=1)]),
                           Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                                material="mirror", solid=False)])
    sdl = scene_to_pov(scene)
    assert ("  photons { count 3000 autostop 0 jitter 0.4 max_trace_level 5 gather 20, 100 "
            "radius 0.2 }\n}") in sdl
    glass = "photons { target reflection on refraction on collect off }"
    mirror = "photons { target reflection on refraction off collect off }"
    assert glass in _block(sdl, "sphere { <0, 0, 0>, 1")
    assert mirror in _block(sdl, "sphere { <2, 0, 0>, 1")
    assert "photons" not in _block(sdl, "sphere { <4, 0, 0>, 1")
    assert glass in _block(sdl, "union {")
    assert mirror in _block(sdl, "mesh2 {")
    scene = scene.model_copy(update={"render": scene.render.model_copy(
        update={"caustics": scene.render.caustics.model_copy(update={"radius": 0.0})})})
    assert "gather 20, 100 }" in scene_to_pov(scene)


def test_meshes_flat_given_normals_and_one_texture_per_face(tmp_path):
    flat = Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                normals=[[0, 0, 1]] * 3, smooth=False)
    given = Mesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]],
                 normals=[[0, 0, 1], [0, 1, 0], [1, 0, 0]], solid=False)
    sdl = scene_to_pov(Scene(objects=[flat, given]))
    first, second = sdl.split("// objects[1] mesh\n")
    assert "normal_vectors" not in first  # smooth = false shades flat
    assert "  normal_vectors { 3,\n<0,0,-1>,\n<0,1,-0>,\n<1,0,-0>\n  }" in second
    assert "face_indices { 1,\n<0,1,2>\n  }" in second
    (tmp_path / "two.mtl").write_text(
        "newmtl red\nKd 1 0 0\nnewmtl glassy\nKd 1 1 1\nd 0.4\nNi 1.5\n", encoding="utf-8")
    (tmp_path / "two.obj").write_text(
        "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "usemtl red\nf 1 2 3\nusemtl glassy\nf 1 3 4\n", encoding="utf-8")
    scene = Scene(objects=[Mesh(file="two.obj"), Mesh(file="two.obj", material="matte",
                                                      transform=Transform(scale=2))])
    sdl = scene_to_pov(scene.with_base_dir(tmp_path))
    per_face, overridden = sdl.split("// objects[1] mesh\n")
    assert ("  texture_list { 2, texture { WhittedTexture1 }, texture { WhittedTexture2 } }\n"
            "  face_indices { 2,\n<0,1,2>,0,\n<0,2,3>,1\n  }\n  inside_vector <0, 0, 1>\n"
            "  interior { WhittedInterior1 }\n}") in per_face
    assert "rgbf <1, 1, 1, 0.6>" in _declared(sdl, "WhittedTexture2")  # d 0.4: kt 0.6
    assert "#declare WhittedInterior1 = interior { ior 1.5 }" in sdl  # the transparent one's
    assert "texture_list" not in overridden
    assert "  texture { WhittedTexture3 }" in overridden
    assert "  matrix <2, 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0>\n}" in overridden


def test_export_refuses_to_write_over_the_scene_or_its_inputs(tmp_path):
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text("[[objects]]\ntype = 'sphere'\nradius = 1\n", encoding="utf-8")
    (tmp_path / "tex.png").write_bytes(b"")
    scene = Scene(objects=[Sphere(radius=1, material=Material(
        texture=ImageTexture(file="tex.png")))]).with_base_dir(tmp_path)
    with pytest.raises(OutputError) as info:
        export_pov(scene, scene_file, source=str(scene_file))
    assert str(info.value) == (f"{scene_file}: is an input of this job ({scene_file}): "
                               "choose another output name")
    with pytest.raises(OutputError, match=r"tex.png: is an input of this job"):
        export_pov(scene, tmp_path / "tex.png", source="not a scene file")
    assert scene_file.read_text().startswith("[[objects]]")
    out = export_pov(scene, tmp_path / "out.pov", width=10, height=5, source=str(scene_file))
    assert "+W10 +H5 -A +FN  (whitted's samples per pixel: 1; -A: one ray per pixel)" in \
        out.read_text()


def test_a_model_that_cannot_be_read_is_one_line(tmp_path):
    from whitted.errors import SceneError

    (tmp_path / "bad.obj").write_text("v 0 0\nf 1 2 3\n", encoding="utf-8")
    scene = Scene(objects=[Mesh(file="bad.obj")]).with_base_dir(tmp_path)
    with pytest.raises(SceneError) as info:
        scene_to_pov(scene)
    assert str(info.value) == f"{tmp_path}/bad.obj:1: 'v' has 2 values, needs at least 3"
