"""Saving a scene into a user's TOML file without rewriting it (tomlkit keeps comments, layout,
inline arrays and the order of keys): only what changed between the scene as loaded and the
scene as edited is written, and new items are written compactly, with only the values that
differ from their defaults.

- :func:`compact_data`: an item (or a whole scene) as plain data with only non-default values
- :func:`compact_toml`: a whole scene as compact TOML (a file that did not exist before)
- :func:`edit_toml`: the text of a TOML scene file with the changes from ``old`` to ``new``
- :func:`edited_toml`: that edit, read back and checked, or None when it cannot be made
- :func:`save_scene_toml`: write a scene, style-preserving when the file's text is known

Every result is read back and compared with the scene before it is written. When a file's own
style cannot carry an edit, :func:`scene_toml` writes the scene compactly (nothing is lost);
the editor asks first (:func:`edited_toml` says None) rather than rewrite a user's file."""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any

import tomlkit
from pydantic import BaseModel
from tomlkit.items import AoT, Array, InlineTable, Table

from ..errors import SceneError
from ..files import atomic_write
from .io import parse_scene_text, scene_from_dict
from .materials import Material
from .scene import Scene
from .writing import rebase_files, scene_to_dict

# ---------------------------------------------------------------------- compact data


def _defaults_for(model: BaseModel) -> dict[str, Any]:
    """What a field of ``model`` is when left out: its class default, or, for a material
    built on a preset, the preset's value."""
    preset = getattr(model, "preset", None) if isinstance(model, Material) else None
    if preset is not None:
        base = Material(preset=preset)
        return {name: getattr(base, name) for name in type(model).model_fields}
    out = {}
    for name, field in type(model).model_fields.items():
        if field.default_factory is not None:
            out[name] = field.default_factory()
        else:
            out[name] = field.default
    return out


def _plain(value: Any) -> Any:
    """A value as TOML-ready plain data (tuples as lists, models compact)."""
    if isinstance(value, BaseModel):
        return compact_data(value)
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if v is not None}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def compact_data(model: BaseModel) -> dict[str, Any]:
    """``model`` as plain data with only the values that differ from their defaults (a
    ``type`` tag is always kept: it says which kind of item this is)."""
    defaults = _defaults_for(model)
    out: dict[str, Any] = {}
    names = list(type(model).model_fields)
    if "type" in names:  # the kind of item first, then its name: how people write them
        names.remove("type")
        names.insert(0, "type")
    for name in names:
        value = getattr(model, name)
        if name == "type" or (name == "preset" and value is not None):
            out[name] = value
            continue
        if value is None or value == defaults.get(name, object()):
            continue
        out[name] = _plain(value)  # {} for a table of defaults (``antialias = {}``)
    return out


def _item(value: Any, *, inline: bool = True) -> Any:
    """A tomlkit item for plain data: tables inline (compact) unless ``inline`` is False."""
    if isinstance(value, dict):
        table = tomlkit.inline_table() if inline else tomlkit.table()
        for k, v in value.items():
            table[k] = _item(v)
        return table
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        array = tomlkit.array()
        for v in value:
            array.append(_item(v))
        return array
    return tomlkit.item(value)


def _table(data: dict[str, Any]) -> Table:
    table = tomlkit.table()
    for k, v in data.items():
        table[k] = _item(v)
    return table


def compact_toml(scene: Scene) -> str:
    """The whole scene as compact TOML: settings, camera and background as tables, named
    materials, then ``[[lights]]`` and ``[[objects]]`` with only their non-default values."""
    doc = tomlkit.document()
    for name in ("render", "camera", "background"):
        data = compact_data(getattr(scene, name))
        if data:
            doc[name] = _table(data)
    if scene.materials:
        mats = tomlkit.table()
        for key, mat in scene.materials.items():
            mats[key] = _table(compact_data(mat))
        doc["materials"] = mats
    for name in ("lights", "objects"):
        items = getattr(scene, name)
        if items:
            doc[name] = _aot(items)
    if scene.animation is not None:
        doc["animation"] = _animation_table(scene.animation)
    return tomlkit.dumps(doc).lstrip("\n")  # a file of only [[objects]] starts with one


# ---------------------------------------------------------------------- editing a file


def _is_table(node: Any) -> bool:
    return isinstance(node, Table | InlineTable)


def _set_field(table: Any, name: str, old: BaseModel, new: BaseModel) -> None:
    """Make ``table[name]`` say the new value of field ``name`` (or drop it: a default)."""
    old_value, new_value = getattr(old, name), getattr(new, name)
    if old_value == new_value:
        return
    node = table.get(name)
    if (isinstance(new_value, BaseModel) and isinstance(old_value, BaseModel)
            and type(new_value) is type(old_value) and _is_table(node)
            and getattr(old_value, "type", None) == getattr(new_value, "type", None)
            and getattr(old_value, "preset", None) == getattr(new_value, "preset", None)):
        _update_table(node, old_value, new_value)
        return
    default = _defaults_for(new).get(name, object())
    if new_value is None or (new_value == default and name not in ("type", "preset")):
        if name in table:
            del table[name]
        return
    plain = _plain(new_value)
    # a sub-table only where the file has one: ``material = "glass"`` becoming an object's
    # own material is written inline, on the line where the name was
    table[name] = _item(plain, inline=not (isinstance(table, Table) and isinstance(
        new_value, BaseModel) and isinstance(node, Table)))


def _update_table(table: Any, old: BaseModel, new: BaseModel) -> None:
    for name in type(new).model_fields:
        _set_field(table, name, old, new)


def _key(item: BaseModel) -> str:
    return item.model_dump_json()


def _update_list(doc: Any, name: str, old: list, new: list) -> None:
    if not new:
        if name in doc:
            del doc[name]
        return
    node = doc.get(name)
    if not isinstance(node, AoT | Array):  # none yet (a file that loads has no other form)
        doc[name] = _aot(new)
        return
    inline = isinstance(node, Array)
    fresh = (lambda it: _item(compact_data(it))) if inline else (
        lambda it: _block(compact_data(it)))
    ops = difflib.SequenceMatcher(None, [_key(i) for i in old], [_key(i) for i in new],
                                  autojunk=False).get_opcodes()
    for tag, i1, i2, j1, j2 in reversed(ops):  # from the end: earlier indices stay valid
        if tag == "equal":
            continue
        paired = min(i2 - i1, j2 - j1) if tag == "replace" else 0
        for k in range(paired):
            o, n = old[i1 + k], new[j1 + k]
            if type(o) is type(n) and getattr(o, "type", None) == getattr(n, "type", None):
                _update_table(node[i1 + k], o, n)
            else:
                node[i1 + k] = fresh(n)
        for index in range(i2 - 1, i1 + paired - 1, -1):  # removed
            del node[index]
        for k in range(j2 - 1, j1 + paired - 1, -1):  # added, in order
            node.insert(i1 + paired, fresh(new[k]))


def _block(data: dict[str, Any]) -> Table:
    """A table of an array of tables (``[[objects]]``) with a blank line before it."""
    table = _table(data)
    table.trivia.indent = "\n"
    return table


def _aot(items: list) -> AoT:
    aot = tomlkit.aot()
    for it in items:
        aot.append(_block(compact_data(it)))
    return aot


def edit_toml(text: str, old: Scene, new: Scene) -> str:
    """``text`` (a TOML file that loads as ``old``) changed so that it loads as ``new``:
    comments, layout and untouched values stay byte for byte."""
    if old == new:
        return text
    doc = tomlkit.parse(text)
    for name in ("render", "camera", "background"):
        o, n = getattr(old, name), getattr(new, name)
        if o == n:
            continue
        node = doc.get(name)
        if _is_table(node):
            _update_table(node, o, n)
        else:  # not in the file: it was the default, so the new value is not
            doc[name] = _table(compact_data(n))
    if old.materials != new.materials:
        node = doc.get("materials")
        if not _is_table(node):
            node = tomlkit.table()
            doc["materials"] = node
        for key in [k for k in old.materials if k not in new.materials]:
            del node[key]
        for key, mat in new.materials.items():
            if key in old.materials and _is_table(node.get(key)):
                _update_table(node[key], old.materials[key], mat)
            elif old.materials.get(key) != mat:
                node[key] = _table(compact_data(mat))
        if not new.materials:
            del doc["materials"]
    for name in ("lights", "objects"):
        o, n = getattr(old, name), getattr(new, name)
        if o != n:
            _update_list(doc, name, list(o), list(n))
    if old.animation != new.animation:
        _update_animation(doc, old.animation, new.animation)
    return tomlkit.dumps(doc)


# ---------------------------------------------------------------------- the [animation] table


def _keys_array(keys: list) -> Array:
    """A track's keys, one ``[frame, value]`` a line (as people write them)."""
    array = tomlkit.array()
    for frame, value in sorted(keys, key=lambda k: k[0]):
        array.append(tomlkit.item([frame, _plain(value)]))
    array.multiline(len(keys) > 1)
    return array


def _track_table(track: Any) -> Table:
    table = tomlkit.table()
    table.trivia.indent = "\n"  # a blank line before each [[animation.tracks]]
    table["path"] = track.path
    if track.interpolation != "linear":
        table["interpolation"] = track.interpolation
    table["keys"] = _keys_array(track.keys)
    return table


def _animation_table(animation: Any) -> Table:
    """``[animation]`` with its non-default values, then one ``[[animation.tracks]]`` each."""
    table = tomlkit.table()
    for name, value in compact_data(animation).items():
        if name != "tracks":
            table[name] = _item(value)
    if animation.tracks:
        aot = tomlkit.aot()
        for track in animation.tracks:
            aot.append(_track_table(track))
        table["tracks"] = aot
    return table


def _update_track(table: Any, old: Any, new: Any) -> None:
    for name in ("path", "interpolation"):
        _set_field(table, name, old, new)
    if old.keys == new.keys:
        return
    array = table.get("keys")
    if not isinstance(array, Array) or (len(new.keys) > 1 and "\n" not in array.as_string()):
        table["keys"] = _keys_array(new.keys)  # a one-line array grows into one key a line
        return
    ops = difflib.SequenceMatcher(None, [repr(k) for k in old.keys],
                                  [repr(k) for k in new.keys], autojunk=False).get_opcodes()
    for tag, i1, i2, j1, j2 in reversed(ops):  # keys not changed keep their spelling
        if tag == "equal":
            continue
        paired = min(i2 - i1, j2 - j1) if tag == "replace" else 0
        for k in range(paired):
            frame, value = new.keys[j1 + k]
            array[i1 + k] = tomlkit.item([frame, _plain(value)])
        for index in range(i2 - 1, i1 + paired - 1, -1):
            del array[index]
        for k in range(j2 - 1, j1 + paired - 1, -1):
            frame, value = new.keys[k]
            array.insert(i1 + paired, tomlkit.item([frame, _plain(value)]))


def _update_animation(doc: Any, old: Any, new: Any) -> None:
    """Write the changes of the ``[animation]`` table: frames and fps in place, tracks
    matched item by item (a new key rewrites that track's keys only)."""
    node = doc.get("animation")
    if new is None:
        if node is not None:
            del doc["animation"]
        return
    if old is None or not isinstance(node, Table):
        doc["animation"] = _animation_table(new)
        return
    for name in ("frames", "fps"):
        _set_field(node, name, old, new)
    tracks = node.get("tracks")
    if not isinstance(tracks, AoT):
        if "tracks" in node:
            del node["tracks"]
        if new.tracks:
            node["tracks"] = _animation_table(new)["tracks"]
        return
    ops = difflib.SequenceMatcher(None, [_key(t) for t in old.tracks],
                                  [_key(t) for t in new.tracks], autojunk=False).get_opcodes()
    for tag, i1, i2, j1, j2 in reversed(ops):
        if tag == "equal":
            continue
        paired = min(i2 - i1, j2 - j1) if tag == "replace" else 0
        for k in range(paired):
            _update_track(tracks[i1 + k], old.tracks[i1 + k], new.tracks[j1 + k])
        for index in range(i2 - 1, i1 + paired - 1, -1):
            del tracks[index]
        for k in range(j2 - 1, j1 + paired - 1, -1):
            tracks.insert(i1 + paired, _track_table(new.tracks[k]))
    if not new.tracks:
        del node["tracks"]


def _loads(text: str, scene: Scene) -> Scene | None:
    try:
        loaded = scene_from_dict(parse_scene_text(text, ".toml"))
    except (SceneError, ValueError):
        return None
    return loaded


def edited_toml(scene: Scene, text: str, loaded: Scene) -> str | None:
    """``text`` (the file as read, which loaded as ``loaded``) with only the edits that make
    it ``scene`` written into it, checked by reading it back; None when the file's own style
    cannot carry them (the caller then asks before writing the whole file afresh)."""
    try:
        edited = edit_toml(text, loaded, scene)
    except (KeyError, TypeError, ValueError, tomlkit.exceptions.TOMLKitError):
        return None
    return edited if _loads(edited, scene) == scene else None


def scene_toml(scene: Scene, *, text: str | None = None, loaded: Scene | None = None) -> str:
    """The TOML to save ``scene`` as: ``text`` (the file as read, which loaded as ``loaded``)
    with only the edits written into it, else the compact form. Checked by reading it back."""
    if text is not None and loaded is not None:
        edited = edited_toml(scene, text, loaded)
        if edited is not None:
            return edited
    compact = compact_toml(scene)
    if _loads(compact, scene) == scene:
        return compact
    import tomli_w

    return tomli_w.dumps(scene_to_dict(scene))  # every value spelt out: always loads back


def save_scene_toml(scene: Scene, path: str | Path, *, text: str | None = None,
                    loaded: Scene | None = None, payload: str | None = None) -> str:
    """Write ``scene`` to the TOML file ``path`` atomically (see :func:`scene_toml`, or
    ``payload`` when the caller has made the text already); relative model and texture names
    are rewritten when the folder changes. Returns the text written."""
    path = Path(path)
    if payload is None:
        if path.parent.resolve() != scene.base_dir.resolve():
            scene = rebase_files(scene, path.parent)
            text = loaded = None  # another folder: file names change, write it afresh
        payload = scene_toml(scene, text=text, loaded=loaded)
    atomic_write(path, lambda tmp: Path(tmp).write_text(payload, encoding="utf-8"))
    return payload
