"""The strict Wavefront OBJ reader: one Numba routine over the file's bytes.

:func:`scan_obj` walks the bytes twice with the same code. The first walk (``fill=False``)
is the validator: it checks every statement the renderer uses, counts the ``v``/``vt``/``vn``
records and the fan triangles, and stops at the first problem with its 1-based line number.
The second walk (``fill=True``) runs only on a valid file and writes the numbers into arrays
sized by the first walk's counts. Sharing one routine keeps the check and the parse from ever
disagreeing about what a file contains.

Numbers: ``[+-]digits[.digits][(e|E)[+-]digits]`` (``.5`` and ``2.`` included). The decimal
significand and exponent are gathered as integers; when the significand has at most 15 digits
and the power of ten is at most 22 both are exact doubles, so one multiplication or division
gives the correctly rounded value (the same bits as ``float()``). Other numbers ("hard" ones:
many digits, large exponents) are listed with their byte span and converted by Python's
``float`` afterwards, so every value is exactly what a correct decimal parser gives.

Faces: every corner is ``v``, ``v/vt``, ``v//vn``, ``v/vt/vn`` (empty ``vt``/``vn`` fields and a
trailing slash allowed); indices are 1-based, negative ones count back from the records defined
so far. A polygon with corners ``c0 .. ck`` becomes the fan ``(c0, ci, ci+1)`` in file order.

Nothing here knows about materials: ``usemtl`` and ``mtllib`` statements are reported as byte
spans of their (trimmed) argument, with the triangle count at which each ``usemtl`` appeared.
"""

from __future__ import annotations

import numpy as np

from ..jit import builder
from ..jit.python_twins import for_size

# Result codes (``info[INFO_CODE]``); the Python side turns them into messages.
OK = 0
ERR_INVALID_NUMBER = 1
ERR_NOT_FINITE = 2
ERR_TOO_FEW_VALUES = 3  # aux1 = record kind, aux2 = how many values were given
ERR_FACE_TOO_FEW_CORNERS = 4  # aux2 = corner count
ERR_INDEX_ZERO = 5  # aux1 = index kind
ERR_INDEX_OUT_OF_RANGE = 6  # aux1 = index kind, aux2 = index, aux3 = records defined so far
ERR_INVALID_CORNER = 7
ERR_MISSING_VERTEX_INDEX = 8
ERR_CONTROL_BYTE = 9  # aux2 = the byte

# Record / index kinds (aux1).
KIND_POSITION = 0
KIND_TEXCOORD = 1
KIND_NORMAL = 2

# Layout of the ``info`` array.
INFO_CODE = 0
INFO_LINE = 1
INFO_TOKEN_START = 2
INFO_TOKEN_END = 3
INFO_AUX1 = 4
INFO_AUX2 = 5
INFO_AUX3 = 6
INFO_POSITIONS = 7
INFO_TEXCOORDS = 8
INFO_NORMALS = 9
INFO_TRIANGLES = 10
INFO_USEMTL = 11
INFO_MTLLIB = 12
INFO_HARD_NUMBERS = 13
INFO_LINES = 14
INFO_SIZE = 16

# Until the builders are compiled, files of at most this many bytes are read by the same
# routines run as Python (jit/python_twins.py): about 0.06 s for the default scene's 37 kB
# model, against 3 s of CPU to compile the reader.
PYTHON_LIMIT_BYTES = 1 << 16
PYTHON_LIMIT_TRIANGLES = 1 << 13

# parse_number statuses
_NUMBER_EXACT = 0
_NUMBER_HARD = 1
_NUMBER_INVALID = 2
_NUMBER_NOT_FINITE = 3

# Compiled without the Numba runtime: arrays pass between these functions without atomic
# reference counting (several times faster here); none of them allocates.
_scanner = builder(_nrt=False)

_EXACT_POWERS_OF_TEN = np.array([float(f"1e{k}") for k in range(23)])
_INDEX_LIMIT = 10**15  # larger indices saturate (and are out of range)
_EXPONENT_LIMIT = 100000


@_scanner
def _is_line_end(data, i, n):
    b = data[i]
    return b == 10 or (b == 13 and (i + 1 >= n or data[i + 1] != 10))


@_scanner
def _is_blank(data, i, n):
    """Whitespace inside a line: space, tab, VT, FF, the \\x1c-\\x1f separators (blanks for
    Python's str.split too) and the CR of a CRLF pair."""
    b = data[i]
    if b == 32 or b == 9 or b == 11 or b == 12 or (b >= 28 and b <= 31):
        return True
    return b == 13 and i + 1 < n and data[i + 1] == 10


@_scanner
def _continuation_length(data, i, n):
    """Length of a backslash line continuation (``\\`` then LF, CRLF or CR) at i, else 0."""
    if data[i] != 92 or i + 1 >= n:
        return 0
    if data[i + 1] == 10:
        return 2
    if data[i + 1] == 13:
        if i + 2 < n and data[i + 2] == 10:
            return 3
        return 2
    return 0


@_scanner
def _is_control(b):
    return b == 0 or b == 127 or (b < 32 and b != 9 and b != 10 and b != 11 and b != 12
                                  and b != 13 and b < 28)


@_scanner
def _skip_blanks(data, i, n, line):
    while i < n:
        b = data[i]
        if b == 32 or b == 9 or (b < 32 and _is_blank(data, i, n)):
            i += 1
            continue
        step = _continuation_length(data, i, n) if b == 92 else 0
        if step == 0:
            break
        i += step
        line += 1
    return i, line


@_scanner
def _token_end(data, i, n):
    while i < n:
        b = data[i]
        if b > 32 and b != 92:  # the common case: a plain character
            i += 1
            continue
        if b == 92:
            if _continuation_length(data, i, n) > 0:
                break
        elif _is_line_end(data, i, n) or _is_blank(data, i, n):
            break
        i += 1
    return i


@_scanner
def _line_end(data, i, n):
    """The index of the end of the line that contains i (or n)."""
    while i < n:
        b = data[i]
        if b == 10 or (b == 13 and _is_line_end(data, i, n)):
            break
        i += 1
    return i


@_scanner
def _rest_of_line(data, i, n):
    """(end of the line's text, last non-blank + 1) from i."""
    last = i
    while i < n:
        b = data[i]
        if b == 10 or (b == 13 and _is_line_end(data, i, n)):
            break
        if b > 32 or not _is_blank(data, i, n):
            last = i + 1
        i += 1
    return i, last


@_scanner
def _lower(b):
    if b >= 65 and b <= 90:
        return b + 32
    return b


@_scanner
def _is_non_finite_word(data, s, e):
    """``nan``, ``inf``, ``infinity`` (any case, optional sign, ``nan(...)`` payload)."""
    if s < e and (data[s] == 43 or data[s] == 45):
        s += 1
    if e - s < 3:
        return False
    a, b, c = _lower(data[s]), _lower(data[s + 1]), _lower(data[s + 2])
    if a == 110 and b == 97 and c == 110:  # nan
        return True
    return a == 105 and b == 110 and c == 102  # inf...


@_scanner
def parse_number(data, s, e):
    """(status, value) of the decimal number in data[s:e]; see the module docstring."""
    i = s
    negative = False
    if i < e and (data[i] == 43 or data[i] == 45):
        negative = data[i] == 45
        i += 1
    significand = 0
    digits = 0  # significant digits kept in `significand`
    exponent = 0  # decimal exponent applied to `significand`
    inexact = False
    seen_digit = False
    while i < e and data[i] >= 48 and data[i] <= 57:
        d = int(data[i]) - 48
        seen_digit = True
        if significand == 0 and d == 0:
            pass
        elif digits < 19:
            significand = significand * 10 + d
            digits += 1
        else:
            exponent += 1
            if d != 0:
                inexact = True
        i += 1
    if i < e and data[i] == 46:
        i += 1
        while i < e and data[i] >= 48 and data[i] <= 57:
            d = int(data[i]) - 48
            seen_digit = True
            if significand == 0 and d == 0:
                exponent -= 1
            elif digits < 19:
                significand = significand * 10 + d
                digits += 1
                exponent -= 1
            elif d != 0:
                inexact = True
            i += 1
    if not seen_digit:
        if _is_non_finite_word(data, s, e):
            return _NUMBER_NOT_FINITE, 0.0
        return _NUMBER_INVALID, 0.0
    if i < e and (data[i] == 101 or data[i] == 69):
        i += 1
        exponent_negative = False
        if i < e and (data[i] == 43 or data[i] == 45):
            exponent_negative = data[i] == 45
            i += 1
        if i >= e or data[i] < 48 or data[i] > 57:
            return _NUMBER_INVALID, 0.0
        written = 0
        while i < e and data[i] >= 48 and data[i] <= 57:
            if written < _EXPONENT_LIMIT:
                written = written * 10 + (int(data[i]) - 48)
            i += 1
        exponent += -written if exponent_negative else written
    if i != e:
        return _NUMBER_INVALID, 0.0
    if significand == 0:
        return _NUMBER_EXACT, -0.0 if negative else 0.0
    if digits - 1 + exponent > 308:  # at least 1e309: no double holds it
        return _NUMBER_NOT_FINITE, 0.0
    if inexact or digits > 15 or exponent > 22 or exponent < -22:
        return _NUMBER_HARD, 0.0
    if exponent >= 0:
        value = float(significand) * _EXACT_POWERS_OF_TEN[exponent]
    else:
        value = float(significand) / _EXACT_POWERS_OF_TEN[-exponent]
    return _NUMBER_EXACT, -value if negative else value


@_scanner
def _parse_index_field(data, s, e):
    """(status, value): 0 = a signed integer, 1 = empty, 2 = not an integer."""
    if s == e:
        return 1, 0
    i = s
    negative = False
    if data[i] == 43 or data[i] == 45:
        negative = data[i] == 45
        i += 1
    if i == e:
        return 2, 0
    value = 0
    while i < e:
        b = data[i]
        if b < 48 or b > 57:
            return 2, 0
        if value < _INDEX_LIMIT:
            value = value * 10 + (int(b) - 48)
        i += 1
    return 0, -value if negative else value


@_scanner
def _resolve_index(index, defined):
    """(error code, 0-based index) for a 1-based or negative OBJ index."""
    if index == 0:
        return ERR_INDEX_ZERO, -1
    if index > 0:
        if index > defined:
            return ERR_INDEX_OUT_OF_RANGE, -1
        return OK, index - 1
    if -index > defined:
        return ERR_INDEX_OUT_OF_RANGE, -1
    return OK, defined + index


@_scanner
def _fail(info, code, line, s, e, aux1, aux2, aux3):
    info[INFO_CODE] = code
    info[INFO_LINE] = line
    info[INFO_TOKEN_START] = s
    info[INFO_TOKEN_END] = e
    info[INFO_AUX1] = aux1
    info[INFO_AUX2] = aux2
    info[INFO_AUX3] = aux3


@_scanner
def _keyword_is(data, s, e, c0, c1, c2, c3, c4, c5):
    """Whether data[s:e] spells the six-letter keyword given as its byte codes."""
    codes = (c0, c1, c2, c3, c4, c5)
    if e - s != 6:
        return False
    for k in range(6):  # noqa: SIM110 - a loop Numba compiles
        if data[s + k] != codes[k]:
            return False
    return True


@_scanner
def scan_obj(data, fill, info, positions, texcoords, normals, corner_v, corner_vt, corner_vn,
             usemtl_spans, mtllib_spans, hard_numbers):
    """Validate (``fill=False``) or read (``fill=True``) the OBJ text in ``data`` (uint8).

    ``info`` (int64, INFO_SIZE) receives the result code, the error's line/token/aux values and
    the counts. With ``fill`` the arrays must be sized from a successful validating walk:
    positions (V, 3), texcoords (VT, 2), normals (VN, 3) float64; corner_v/vt/vn (T, 3) int32
    (-1 where a corner has no vt/vn); usemtl_spans (U, 4) int64 = name start, name end,
    triangles before it, line; mtllib_spans (L, 3) = start, end, line; hard_numbers (H, 5) =
    token start, end, line, kind, flat index into that kind's array.
    """
    n = data.shape[0]
    for k in range(INFO_SIZE):
        info[k] = 0
    position_count = 0
    texcoord_count = 0
    normal_count = 0
    triangle_count = 0
    usemtl_count = 0
    mtllib_count = 0
    hard_count = 0
    line = 1
    i = 0
    while i < n:
        i, line = _skip_blanks(data, i, n, line)
        if i >= n:
            break
        if data[i] == 10 or _is_line_end(data, i, n):
            i += 1
            line += 1
            continue
        statement_line = line
        keyword_start = i
        i = _token_end(data, i, n)
        keyword_end = i
        first = data[keyword_start]
        length = keyword_end - keyword_start
        if first == 35:  # '#': a comment, whatever follows
            i = _line_end(data, i, n)
        elif first == 118 and (length == 1 or (length == 2 and (
                data[keyword_start + 1] == 116 or data[keyword_start + 1] == 110))):
            # v, vt, vn
            if length == 1:
                kind = KIND_POSITION
                needed = 3
                stored = 3
                record = position_count
            elif data[keyword_start + 1] == 116:
                kind = KIND_TEXCOORD
                needed = 1
                stored = 2
                record = texcoord_count
            else:
                kind = KIND_NORMAL
                needed = 3
                stored = 3
                record = normal_count
            values = 0
            while True:
                i, line = _skip_blanks(data, i, n, line)
                if i >= n or _is_line_end(data, i, n):
                    break
                if data[i] == 35:  # an end-of-line comment
                    i = _line_end(data, i, n)
                    break
                token_start = i
                i = _token_end(data, i, n)
                status, value = parse_number(data, token_start, i)
                if status == _NUMBER_INVALID:
                    _fail(info, ERR_INVALID_NUMBER, line, token_start, i, kind, 0, 0)
                    return
                if status == _NUMBER_NOT_FINITE:
                    _fail(info, ERR_NOT_FINITE, line, token_start, i, kind, 0, 0)
                    return
                if values < stored:
                    if status == _NUMBER_HARD:
                        if fill:
                            hard = hard_numbers[hard_count]
                            hard[0] = token_start
                            hard[1] = i
                            hard[2] = line
                            hard[3] = kind
                            hard[4] = record * stored + values
                        hard_count += 1
                    elif fill:
                        if kind == KIND_POSITION:
                            positions[record, values] = value
                        elif kind == KIND_TEXCOORD:
                            texcoords[record, values] = value
                        else:
                            normals[record, values] = value
                values += 1
            if values < needed:
                _fail(info, ERR_TOO_FEW_VALUES, statement_line, keyword_start, i, kind, values,
                      0)
                return
            if kind == KIND_POSITION:
                position_count += 1
            elif kind == KIND_TEXCOORD:
                if fill and values < 2:
                    texcoords[record, 1] = 0.0
                texcoord_count += 1
            else:
                normal_count += 1
        elif first == 102 and length == 1:  # f
            corners = 0
            first_v = first_vt = first_vn = -1
            previous_v = previous_vt = previous_vn = -1
            while True:
                i, line = _skip_blanks(data, i, n, line)
                if i >= n or _is_line_end(data, i, n):
                    break
                if data[i] == 35:
                    i = _line_end(data, i, n)
                    break
                token_start = i
                i = _token_end(data, i, n)
                slashes = 0
                for k in range(token_start, i):
                    if data[k] == 47:
                        slashes += 1
                if slashes > 2:
                    _fail(info, ERR_INVALID_CORNER, line, token_start, i, 0, 0, 0)
                    return
                # split the corner at '/' into up to three fields
                field_start = token_start
                field = 0
                v = vt = vn = -1
                while True:
                    field_end = field_start
                    while field_end < i and data[field_end] != 47:
                        field_end += 1
                    status, index = _parse_index_field(data, field_start, field_end)
                    if status == 2:
                        _fail(info, ERR_INVALID_CORNER, line, token_start, i, 0, 0, 0)
                        return
                    if status == 1:
                        if field == 0:
                            _fail(info, ERR_MISSING_VERTEX_INDEX, line, token_start, i, 0, 0, 0)
                            return
                    else:
                        if field == 0:
                            defined = position_count
                        elif field == 1:
                            defined = texcoord_count
                        else:
                            defined = normal_count
                        code, resolved = _resolve_index(index, defined)
                        if code != OK:
                            _fail(info, code, line, token_start, i, field, index, defined)
                            return
                        if field == 0:
                            v = resolved
                        elif field == 1:
                            vt = resolved
                        else:
                            vn = resolved
                    if field_end >= i:
                        break
                    field_start = field_end + 1
                    field += 1
                if corners == 0:
                    first_v, first_vt, first_vn = v, vt, vn
                elif corners >= 2:
                    if fill:
                        corner_v[triangle_count, 0] = first_v
                        corner_v[triangle_count, 1] = previous_v
                        corner_v[triangle_count, 2] = v
                        corner_vt[triangle_count, 0] = first_vt
                        corner_vt[triangle_count, 1] = previous_vt
                        corner_vt[triangle_count, 2] = vt
                        corner_vn[triangle_count, 0] = first_vn
                        corner_vn[triangle_count, 1] = previous_vn
                        corner_vn[triangle_count, 2] = vn
                    triangle_count += 1
                previous_v, previous_vt, previous_vn = v, vt, vn
                corners += 1
            if corners < 3:
                _fail(info, ERR_FACE_TOO_FEW_CORNERS, statement_line, keyword_start, i, 0,
                      corners, 0)
                return
        elif _keyword_is(data, keyword_start, keyword_end, 117, 115, 101, 109, 116, 108) or \
                _keyword_is(data, keyword_start, keyword_end, 109, 116, 108, 108, 105, 98):
            # usemtl / mtllib: the rest of the line, trimmed
            is_usemtl = first == 117
            i, line = _skip_blanks(data, i, n, line)
            name_start = i
            i, name_end = _rest_of_line(data, i, n)  # (name_end >= name_start)
            for k in range(name_start, name_end):
                if _is_control(data[k]):
                    _fail(info, ERR_CONTROL_BYTE, line, name_start, name_end, 0, np.int64(data[k]),
                          0)
                    return
            if is_usemtl:
                if fill:
                    span = usemtl_spans[usemtl_count]
                    span[0] = name_start
                    span[1] = name_end
                    span[2] = triangle_count
                    span[3] = statement_line
                usemtl_count += 1
            else:
                if fill:
                    span = mtllib_spans[mtllib_count]
                    span[0] = name_start
                    span[1] = name_end
                    span[2] = statement_line
                mtllib_count += 1
        else:
            # any other statement (o, g, s, l, p, vp, vendor ones) is skipped, but binary
            # bytes in it mean the file is not text
            k = keyword_start
            while k < n and not _is_line_end(data, k, n):
                step = _continuation_length(data, k, n)
                if step > 0:
                    k += step
                    line += 1
                    continue
                if _is_control(data[k]):
                    _fail(info, ERR_CONTROL_BYTE, line, keyword_start, k + 1, 0, data[k], 0)
                    return
                k += 1
            i = k
        # now at the end of the line (or of the data)
        if i < n:
            i += 1
            line += 1
    info[INFO_POSITIONS] = position_count
    info[INFO_TEXCOORDS] = texcoord_count
    info[INFO_NORMALS] = normal_count
    info[INFO_TRIANGLES] = triangle_count
    info[INFO_USEMTL] = usemtl_count
    info[INFO_MTLLIB] = mtllib_count
    info[INFO_HARD_NUMBERS] = hard_count
    info[INFO_LINES] = line


def split_corners(vertex_count, corner_v, corner_vt, corner_vn):
    """Per-vertex attributes from per-corner indices, without moving any vertex.

    A position keeps its own index for the first (vt, vn) pair it is used with; each further
    pair gets a new vertex appended after the file's ones (a copy of the same position).

    Returns (faces (T, 3) int32, source_position (V',) int64, texcoord_index (V',) int64,
    normal_index (V',) int64); the index arrays hold -1 where a corner had no vt / vn and -2
    for vertices that no face uses.
    """
    triangles = corner_v.shape[0]
    capacity = int(vertex_count) + 3 * triangles  # every corner a vertex of its own at most
    source_position = np.empty(capacity, np.int64)
    texcoord_index = np.empty(capacity, np.int64)
    normal_index = np.empty(capacity, np.int64)
    faces = np.empty((triangles, 3), np.int32)
    split = for_size(_split_corners, triangles, PYTHON_LIMIT_TRIANGLES)
    used = split(vertex_count, corner_v, corner_vt, corner_vn, faces, source_position,
                  texcoord_index, normal_index, np.empty(capacity, np.int64))
    return faces, source_position[:used], texcoord_index[:used], normal_index[:used]


@_scanner
def _split_corners(vertex_count, corner_v, corner_vt, corner_vn, faces, source_position,
                   texcoord_index, normal_index, next_copy):
    """split_corners' work in the caller's arrays (each of vertex_count + 3 T entries;
    ``next_copy``: the chain of copies made of one position); returns the vertices used."""
    triangles = corner_v.shape[0]
    for k in range(vertex_count):
        source_position[k] = k
        texcoord_index[k] = -2
        normal_index[k] = -2
        next_copy[k] = -1
    used = vertex_count
    for t in range(triangles):
        for c in range(3):
            v = corner_v[t, c]
            vt = corner_vt[t, c]
            vn = corner_vn[t, c]
            if texcoord_index[v] == -2:
                texcoord_index[v] = vt
                normal_index[v] = vn
                faces[t, c] = v
                continue
            slot = v
            while True:
                if texcoord_index[slot] == vt and normal_index[slot] == vn:
                    break
                if next_copy[slot] < 0:
                    new = used
                    used += 1
                    source_position[new] = v
                    texcoord_index[new] = vt
                    normal_index[new] = vn
                    next_copy[new] = -1
                    next_copy[slot] = new
                    slot = new
                    break
                slot = next_copy[slot]
            faces[t, c] = slot
    return used


@_scanner
def gather_tokens(data, spans, out):
    """Copy the tokens data[spans[k, 0]:spans[k, 1]] into out, one blank after each."""
    position = 0
    for k in range(spans.shape[0]):
        for j in range(spans[k, 0], spans[k, 1]):
            out[position] = data[j]
            position += 1
        out[position] = 32
        position += 1
