"""Saving a scene into a user's TOML file without rewriting it (tomlkit keeps comments, layout,
inline arrays and the order of keys): only what changed between the scene as loaded and the
scene as edited is written, and new items are written compactly, with only the values that
differ from their defaults.

- :func:`compact_data`: an item (or a whole scene) as plain data with only non-default values
- :func:`compact_toml`: a whole scene as compact TOML (a file that did not exist before)
- :func:`edit_toml`: the text of a TOML scene file with the changes from ``old`` to ``new``
- :func:`edited_toml`: that edit, read back and checked, or None when it cannot be made
- :func:`scene_toml`: the TOML to save a scene as, style-preserving when the file's text is
  known (``whitted.save_scene`` and the editor both write through it)

An edit touches the file's text only where a value changed: one number of a vector, one key
of a CSG child inside a multi-line array; new numbers are rounded to the decimals the file
uses. Earlier versions of the same file (``history``) lend their spelling: a value set back
to what a version said is written as that version wrote it, and an object deleted and then
restored comes back as it was written, with its comments (a comment block right above an
``[[objects]]`` header belongs to that object).

Every result is read back and compared with the scene before it is written. When a file's own
style cannot carry an edit, :func:`scene_toml` writes the scene compactly (nothing is lost);
the editor asks first (:func:`edited_toml` says None) rather than rewrite a user's file."""

from __future__ import annotations

import contextvars
import copy
import difflib
import math
import re
import tomllib
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import tomlkit
from pydantic import BaseModel, ValidationError
from tomlkit.items import AoT, Array, Comment, InlineTable, Table, Whitespace

from .materials import Material
from .shapes import ArrayData

if TYPE_CHECKING:
    from .scene import Scene

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
    """A value as TOML-ready plain data (tuples as lists, models compact, a mesh's inline
    arrays as lists of rows)."""
    if isinstance(value, ArrayData):
        return value.array.tolist()
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


class _Style:
    """How an edit writes into one file: new numbers rounded to ``decimals`` (None: exact,
    for a file written afresh), and the spellings of the file's earlier versions."""

    def __init__(self, decimals: int | None = None, memory: _Memory | None = None) -> None:
        self.decimals = decimals
        self.memory = memory


_STYLE: contextvars.ContextVar[_Style | None] = contextvars.ContextVar("toml_style", default=None)


def _style() -> _Style:
    return _STYLE.get() or _Style()

#: a float literal in TOML text (its fraction's digits counted for the file's rounding)
_FLOAT = re.compile(r"(?<![\w.\"'#-])[-+]?\d+\.(\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def file_decimals(text: str) -> int:
    """The decimals new numbers get in ``text``: as many as its most precise number shows
    (3 to 6; 4 in a file of whole numbers only)."""
    found = [len(m.group(1)) for m in _FLOAT.finditer(text)]
    return min(max(max(found), 3), 6) if found else 4


def _rounded(value: float, decimals: int | None) -> float:
    """``value`` rounded to ``decimals``; a small one (under a tenth of a unit of the file's
    precision's hundreds) keeps ``decimals`` significant digits instead."""
    if decimals is None or not math.isfinite(value):
        return value
    if abs(value) >= 10.0 ** (2 - decimals):
        return round(value, decimals) + 0.0  # (no -0.0)
    return float(f"{value:.{decimals}g}") + 0.0


def _item(value: Any, *, inline: bool = True) -> Any:
    """A tomlkit item for plain data: tables inline (compact) unless ``inline`` is False;
    floats rounded as the file being edited rounds them."""
    if isinstance(value, dict):
        table = tomlkit.inline_table() if inline else tomlkit.table()
        for k, v in value.items():
            table[k] = _item(v)
        return table
    if isinstance(value, list | tuple):
        array = tomlkit.array()
        for v in value:
            array.append(_item(v))
        return array
    if isinstance(value, float):
        return tomlkit.item(_rounded(value, _style().decimals))
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


def _key(item: BaseModel) -> str:
    return item.model_dump_json()


def _ident(kind: str, item: BaseModel) -> tuple:
    """Which item of a file's earlier versions may lend ``item`` its spellings."""
    return (kind, getattr(item, "type", None), getattr(item, "name", None))


def _is_models(value: Any) -> bool:
    return isinstance(value, list | tuple) and bool(value) and all(
        isinstance(v, BaseModel) for v in value)


def _set_elements(array: Array, old: Any, new: Any) -> None:
    """Write into ``array`` only the elements of a vector (or a list of them) that changed."""
    for k, (o, n) in enumerate(zip(old, new, strict=True)):
        if o == n:
            continue
        node = array[k]
        if isinstance(node, Array) and isinstance(n, list | tuple) and \
                isinstance(o, list | tuple) and len(o) == len(n) == len(node):
            _set_elements(node, o, n)
        else:
            array[k] = _item(_plain(n))


def _set_field(table: Any, name: str, old: BaseModel, new: BaseModel,
               ident: tuple | None = None) -> None:
    """Make ``table[name]`` say the new value of field ``name`` (or drop it: a default),
    changing as little of its text as it can."""
    old_value, new_value = getattr(old, name), getattr(new, name)
    if old_value == new_value:
        return
    node = table.get(name)
    if (isinstance(new_value, BaseModel) and isinstance(old_value, BaseModel)
            and type(new_value) is type(old_value) and _is_table(node)
            and getattr(old_value, "type", None) == getattr(new_value, "type", None)
            and getattr(old_value, "preset", None) == getattr(new_value, "preset", None)):
        _update_table(node, old_value, new_value, None if ident is None else (*ident, name))
        return
    default = _defaults_for(new).get(name, object())
    if new_value is None or (new_value == default and name not in ("type", "preset")):
        if name in table:
            del table[name]
        return
    memory = _style().memory
    spelt = memory.spelling(ident, name, new_value, node) if memory and ident else None
    if spelt is not None:  # as an earlier version of the file wrote it
        table[name] = spelt
        return
    if _is_models(new_value) and _is_models(old_value) and isinstance(node, AoT | Array):
        _update_items(node, list(old_value), list(new_value), "objects")  # CSG children
        return
    if isinstance(node, Array) and isinstance(new_value, list | tuple) and \
            isinstance(old_value, list | tuple) and len(old_value) == len(new_value) == \
            len(node) and not _is_models(new_value):
        _set_elements(node, old_value, new_value)  # one number of a vector
        return
    plain = _plain(new_value)
    # a sub-table only where the file has one: ``material = "glass"`` becoming an object's
    # own material is written inline, on the line where the name was
    table[name] = _item(plain, inline=not (isinstance(table, Table) and isinstance(
        new_value, BaseModel) and isinstance(node, Table)))


def _update_table(table: Any, old: BaseModel, new: BaseModel, ident: tuple | None = None) -> None:
    for name in type(new).model_fields:
        _set_field(table, name, old, new, ident)


def _update_items(node: AoT | Array, old: list, new: list, kind: str) -> None:
    """The items of a ``[[lights]]``/``[[objects]]`` list or a CSG object's ``objects``
    array: items matched one to one, each edited in place; removed ones go with their
    comments, added ones come back as an earlier version wrote them or compactly."""
    inline = isinstance(node, Array)
    memory = _style().memory

    def fresh(item: BaseModel) -> Any:
        kept = memory.item(kind, item, InlineTable if inline else Table) if memory else None
        if kept is not None:
            return kept
        return _item(compact_data(item)) if inline else _block(compact_data(item))

    ops = difflib.SequenceMatcher(None, [_key(i) for i in old], [_key(i) for i in new],
                                  autojunk=False).get_opcodes()
    for tag, i1, i2, j1, j2 in reversed(ops):  # from the end: earlier indices stay valid
        if tag == "equal":
            continue
        paired = min(i2 - i1, j2 - j1) if tag == "replace" else 0
        for k in range(paired):
            o, n = old[i1 + k], new[j1 + k]
            if type(o) is type(n) and getattr(o, "type", None) == getattr(n, "type", None):
                _update_table(node[i1 + k], o, n, _ident(kind, n))
            else:
                node[i1 + k] = fresh(n)
        for index in range(i2 - 1, i1 + paired - 1, -1):  # removed
            gap = _take_gap(node, index) if index == len(node) - 1 > 0 else []
            del node[index]
            _give_gap(node, len(node) - 1, gap)  # the last one's blank line stays
        for k in range(j2 - 1, j1 + paired - 1, -1):  # added, in order
            at = i1 + paired
            item = fresh(new[k])
            gap = _take_gap(node, at - 1) if at == len(node) > 0 and isinstance(
                item, Table) and not _gap(item.value.body) else []
            node.insert(at, item)
            _give_gap(node, at, gap)  # the blank line after the last one moves after it


def _gap(body: list) -> int:
    """How many blank-line items end ``body`` (a table's items)."""
    n = 0
    while n < len(body) and body[-1 - n][0] is None and isinstance(body[-1 - n][1], Whitespace):
        n += 1
    return n


def _take_gap(node: Any, index: int) -> list:
    """Take the blank lines that end table ``index`` of an array of tables (what keeps the
    next section apart from the last table)."""
    if not isinstance(node, AoT) or not 0 <= index < len(node):
        return []
    body = node[index].value.body
    n = _gap(body)
    if not n:
        return []
    taken = [item for _, item in body[-n:]]
    del body[-n:]
    return taken


def _give_gap(node: Any, index: int, gap: list) -> None:
    if gap and isinstance(node, AoT) and 0 <= index < len(node) and \
            not _gap(node[index].value.body):
        for item in gap:
            node[index].add(item)


def _update_list(doc: Any, name: str, old: list, new: list) -> None:
    if not new:
        if name in doc:
            del doc[name]
        return
    node = doc.get(name)
    if not isinstance(node, AoT | Array):  # none yet (a file that loads has no other form)
        doc[name] = _aot(new)
        return
    _update_items(node, old, new, name)


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


# ---------------------------------------------------------------------- a file's comments


def _trailing(body: list) -> int:
    """Where the comment block that ends ``body`` (a table's items) and belongs to what
    follows starts: the comments after its last blank line, right above the next header."""
    end = len(body)
    start = end
    while start > 0 and body[start - 1][0] is None and isinstance(body[start - 1][1], Comment):
        start -= 1
    return start


def _last_body(node: Any) -> list | None:
    """The items at the end of a table as the file shows them (the last sub-table's)."""
    while True:
        if isinstance(node, AoT):
            if not len(node):
                return None
            node = node[-1]
            continue
        if not isinstance(node, Table):
            return None
        body = node.value.body
        if body and isinstance(body[-1][1], Table | AoT) and body[-1][0] is not None:
            node = body[-1][1]
            continue
        return body


def _own_comments(doc: Any) -> None:
    """Give each ``[[lights]]``/``[[objects]]`` table the comment lines right above its
    header (tomlkit keeps them at the end of the table before): deleting an object takes its
    comments with it, and restoring it brings them back. The text stays the same."""
    keys = [k.key if k is not None else None for k, _ in doc.body]
    for name in ("lights", "objects"):
        aot = doc.get(name)
        if not isinstance(aot, AoT) or not len(aot) or name not in keys:
            continue
        at = keys.index(name)
        before = [item for k, item in doc.body[:at] if k is not None]
        tables = [before[-1] if before else None, *aot]
        for prev, table in zip(tables, list(aot), strict=False):
            body = _last_body(prev) if prev is not None else None
            if not body:
                continue
            start = _trailing(body)
            if start == len(body):
                continue
            lead = "".join(item.as_string() for _, item in body[start:])
            del body[start:]
            table.trivia.indent = lead + table.trivia.indent


class _Memory:
    """The items and values of a file's earlier versions (its text and the scene it held),
    to write something set back as that version wrote it."""

    def __init__(self, versions: Iterable[tuple[str, Scene]]) -> None:
        self.whole: dict[tuple, Any] = {}
        self.tables: dict[tuple, list[tuple[BaseModel, Any]]] = {}
        for text, scene in versions:
            try:
                doc = tomlkit.parse(text)
                _own_comments(doc)
            except (tomlkit.exceptions.TOMLKitError, ValueError, TypeError):
                continue
            for name in ("render", "camera", "background"):
                if _is_table(doc.get(name)):
                    self._table((name,), getattr(scene, name), doc[name])
            for kind in ("lights", "objects"):
                node = doc.get(kind)
                if isinstance(node, AoT | Array) and len(node) == len(getattr(scene, kind)):
                    self._items(kind, list(getattr(scene, kind)), node)

    def _table(self, ident: tuple, model: BaseModel, node: Any) -> None:
        self.tables.setdefault(ident, []).append((model, node))
        for name in type(model).model_fields:
            value, sub = getattr(model, name), node.get(name)
            if isinstance(value, BaseModel) and _is_table(sub):
                self._table((*ident, name), value, sub)
            elif _is_models(value) and isinstance(sub, AoT | Array) and len(sub) == len(value):
                self._items("objects", list(value), sub)

    def _items(self, kind: str, items: list, node: Any) -> None:
        for item, table in zip(items, node, strict=True):
            if _is_table(table):
                self.whole.setdefault((kind, _key(item)), table)
                self._table(_ident(kind, item), item, table)

    def item(self, kind: str, item: BaseModel, form: type) -> Any:
        """A copy of ``item`` as an earlier version wrote it (a table of ``form``), or None."""
        node = self.whole.get((kind, _key(item)))
        return copy.deepcopy(node) if isinstance(node, form) else None

    def spelling(self, ident: tuple, name: str, value: Any, node: Any) -> Any:
        """A copy of field ``name`` = ``value`` as an earlier version of the item wrote it,
        or None (also when the file now writes it in another form)."""
        for model, table in reversed(self.tables.get(ident, [])):
            if getattr(model, name, object()) == value and name in table:
                kept = table[name]
                if node is None or type(kept) is type(node) or not isinstance(
                        kept, Table | AoT):
                    if isinstance(kept, Table | AoT):
                        return None  # a sub-table is written field by field
                    return copy.deepcopy(kept)
        return None


def edit_toml(text: str, old: Scene, new: Scene, *,
              history: Iterable[tuple[str, Scene]] = ()) -> str:
    """``text`` (a TOML file that loads as ``old``) changed so that it loads as ``new``:
    comments, layout and untouched values stay byte for byte; new numbers are rounded as
    the file's are; ``history`` (earlier versions: text and scene) lends its spellings."""
    if old == new:
        return text
    history = list(history)
    for version_text, version in reversed(history):
        if version == new:  # everything set back to what a version said: its very text
            return version_text
    doc = tomlkit.parse(text)
    _own_comments(doc)
    memory = _Memory([*history, (text, old)])
    token = _STYLE.set(_Style(file_decimals(text), memory))
    try:
        _edit_doc(doc, old, new)
    finally:
        _STYLE.reset(token)
    return tomlkit.dumps(doc)


def _edit_doc(doc: Any, old: Scene, new: Scene) -> None:
    for name in ("render", "camera", "background"):
        o, n = getattr(old, name), getattr(new, name)
        if o == n:
            continue
        node = doc.get(name)
        if _is_table(node):
            _update_table(node, o, n, (name,))
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
                _update_table(node[key], old.materials[key], mat, ("materials", key))
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


# ---------------------------------------------------------------------- the [animation] table


def _keys_array(keys: list) -> Array:
    """A track's keys, one ``[frame, value]`` a line (as people write them)."""
    array = tomlkit.array()
    for frame, value in sorted(keys, key=lambda k: k[0]):
        array.append(_item([frame, _plain(value)]))
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
            array[i1 + k] = _item([frame, _plain(value)])
        for index in range(i2 - 1, i1 + paired - 1, -1):
            del array[index]
        for k in range(j2 - 1, j1 + paired - 1, -1):
            frame, value = new.keys[k]
            array.insert(i1 + paired, _item([frame, _plain(value)]))


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


def _close(a: Any, b: Any, tolerance: float) -> bool:
    """Plain data ``a`` equal to ``b`` but for numbers rounded to ``tolerance``."""
    if isinstance(a, float | int) and isinstance(b, float | int) and not isinstance(
            a, bool) and not isinstance(b, bool):
        return a == b or abs(a - b) <= tolerance or math.isclose(a, b, rel_tol=1e-5)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k], tolerance) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y, tolerance) for x, y in zip(a, b, strict=True))
    return a == b


def _loads(text: str, like: Scene) -> Scene | None:
    """The scene the TOML ``text`` holds (read as ``whitted.load_scene`` reads it), or None."""
    try:
        return type(like).model_validate(tomllib.loads(text), strict=True)
    except (tomllib.TOMLDecodeError, ValidationError, ValueError, RecursionError):
        return None


def read_toml(text: str, scene: Scene) -> Scene:
    """The scene the TOML ``text`` (just written for ``scene``) holds: ``scene`` with the
    numbers as the file rounded them."""
    loaded = _loads(text, scene)
    return scene if loaded is None or loaded == scene else loaded.with_base_dir(
        getattr(scene, "_base_dir", None))


def same_scene(loaded: Scene | None, scene: Scene, decimals: int | None = None) -> bool:
    """Whether a file that loads as ``loaded`` says ``scene`` (its new numbers rounded to
    ``decimals``)."""
    if loaded is None:
        return False
    if loaded == scene or decimals is None:
        return loaded == scene
    return _close(loaded.model_dump(mode="json"), scene.model_dump(mode="json"),
                  0.5001 * 10.0 ** -decimals)


def edited_toml(scene: Scene, text: str, loaded: Scene, *,
                history: Iterable[tuple[str, Scene]] = ()) -> str | None:
    """``text`` (the file as read, which loaded as ``loaded``) with only the edits that make
    it ``scene`` written into it, checked by reading it back; None when the file's own style
    cannot carry them (the caller then asks before writing the whole file afresh)."""
    try:
        edited = edit_toml(text, loaded, scene, history=history)
    except (KeyError, TypeError, ValueError, tomlkit.exceptions.TOMLKitError):
        return None
    return edited if same_scene(_loads(edited, scene), scene, file_decimals(text)) else None


def scene_toml(scene: Scene, *, text: str | None = None, loaded: Scene | None = None,
               history: Iterable[tuple[str, Scene]] = ()) -> str:
    """The TOML to save ``scene`` as: ``text`` (the file as read, which loaded as ``loaded``)
    with only the edits written into it, else the compact form. Checked by reading it back."""
    if text is not None and loaded is not None:
        edited = edited_toml(scene, text, loaded, history=history)
        if edited is not None:
            return edited
    compact = compact_toml(scene)
    if _loads(compact, scene) == scene:
        return compact
    return tomlkit.dumps(scene.model_dump(mode="json", exclude_none=True))  # every value
