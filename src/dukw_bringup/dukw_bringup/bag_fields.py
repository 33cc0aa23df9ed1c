"""Chosen fields of many CDR messages of one type at once: the offline replay's decoding.

rosbags decodes one message into nested message objects (2-7 us each, numpy arrays for
the covariances); a replay that reads a few numbers of each of thousands of messages of a
topic does better to read them as columns. The messages of one topic in a bag almost
always share one CDR layout (the same frame_id, no or the same sequences), so one numpy
structured dtype, laid out from rosbags' message definition (its fields, in order, with
CDR's alignment), views all of them at once. The layout is taken from the first message
and checked against every other one (size, encapsulation, every string length and
sequence count); where they differ, rosbags decodes each message and the fields are read
from its objects. Both paths give the same values: Python numbers for the scalars, fixed
arrays as lists on the numpy path and as rosbags' numpy arrays on the other.
"""
from __future__ import annotations

from operator import attrgetter
from typing import Any, Sequence

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys.store import Typestore

#: CDR primitive -> (numpy format, size in bytes) for the types read as numbers
_PRIMITIVES = {'bool': ('?', 1), 'byte': ('i1', 1), 'char': ('u1', 1), 'int8': ('i1', 1),
               'uint8': ('u1', 1), 'int16': ('<i2', 2), 'uint16': ('<u2', 2),
               'int32': ('<i4', 4), 'uint32': ('<u4', 4), 'int64': ('<i8', 8),
               'uint64': ('<u8', 8), 'float32': ('<f4', 4), 'float64': ('<f8', 8)}
#: bytes before the CDR payload (encapsulation kind and options); alignment counts after them
_ENCAPSULATION_BYTES = 4
#: the encapsulation's first two bytes for little-endian CDR (00 01), read as '<u2'
_CDR_LE = 0x0100


class _NotShared(Exception):
    """The wanted fields cannot be read through one numpy layout."""


class _Layout:
    """Where each wanted field of one message sits, and the length words to check."""

    def __init__(self, store: Typestore, raw: bytes, wanted: Sequence[str]) -> None:
        self.store, self.raw, self.wanted = store, raw, set(wanted)
        self.pos = 0                                 # in the payload (CDR aligns on it)
        self.fields: dict[str, tuple[Any, int]] = {}  # path -> (numpy format, byte offset)
        self.empty: set[str] = set()                 # wanted sequences that are empty
        self.checks: list[tuple[int, int]] = []      # (byte offset, uint32 every one has)

    def message(self, msgtype: str, prefix: str) -> None:
        for name, desc in self.store.get_msgdef(msgtype).fields:
            self.field(prefix + name, desc)

    def field(self, path: str, desc: tuple) -> None:
        kind, detail = desc
        if kind == Nodetype.NAME:
            self._not_wanted(path)
            self.message(detail, path + '.')
        elif kind == Nodetype.BASE:
            self.base(path, detail[0])
        elif kind == Nodetype.ARRAY:
            self.array(path, *detail)
        else:
            self.sequence(path, detail[0])

    def base(self, path: str, typename: str) -> None:
        if typename == 'string':
            self._not_wanted(path)
            length = self._length_word()      # (aligns pos: read it before adding)
            self.pos += 4 + length
            return
        fmt, size = _PRIMITIVES[typename]
        self._align(size)
        if path in self.wanted:
            self.fields[path] = (fmt, _ENCAPSULATION_BYTES + self.pos)
        self.pos += size

    def array(self, path: str, element: tuple, count: int) -> None:
        if element[0] == Nodetype.BASE and element[1][0] in _PRIMITIVES:
            fmt, size = _PRIMITIVES[element[1][0]]
            self._align(size)
            if path in self.wanted:
                self.fields[path] = ((fmt, (count,)), _ENCAPSULATION_BYTES + self.pos)
            self.pos += count * size
            return
        self._not_wanted(path)
        for index in range(count):
            self.field(f'{path}[{index}]', element)

    def sequence(self, path: str, element: tuple) -> None:
        count = self._length_word()
        self.pos += 4
        numeric = element[0] == Nodetype.BASE and element[1][0] in _PRIMITIVES
        if path in self.wanted:
            if count or numeric:      # rosbags gives numeric ones as arrays: not here
                raise _NotShared(path)
            self.empty.add(path)
            return
        if numeric:
            size = _PRIMITIVES[element[1][0]][1]
            if count:                 # (an empty one does not align: rosbags, CDR)
                self._align(size)
            self.pos += count * size
            return
        for index in range(count):
            self.field(f'{path}[{index}]', element)

    def _length_word(self) -> int:
        """The uint32 (string length or sequence count) at the aligned position, recorded
        as a check: every message must have the same one to share the layout."""
        self._align(4)
        offset = _ENCAPSULATION_BYTES + self.pos
        if offset + 4 > len(self.raw):
            raise _NotShared('truncated')
        value = int.from_bytes(self.raw[offset:offset + 4], 'little')
        self.checks.append((offset, value))
        return value

    def _align(self, size: int) -> None:
        self.pos = (self.pos + size - 1) & -size

    def _not_wanted(self, path: str) -> None:
        if path in self.wanted:
            raise _NotShared(path)


def _dtype(layout: _Layout, itemsize: int) -> np.dtype:
    names, formats, offsets = ['#cdr'], ['<u2'], [0]
    for path, (fmt, offset) in layout.fields.items():
        names.append(path), formats.append(fmt), offsets.append(offset)
    for k, (offset, _) in enumerate(layout.checks):
        names.append(f'#{k}'), formats.append('<u4'), offsets.append(offset)
    return np.dtype({'names': names, 'formats': formats, 'offsets': offsets,
                     'itemsize': itemsize})


def _columns(store: Typestore, msgtype: str, raws: Sequence[bytes],
             paths: Sequence[str]) -> list[list] | None:
    """Each wanted field over all ``raws`` through one numpy view, or None when the
    messages do not share the first one's layout (or a field is not a number)."""
    first = raws[0]
    layout = _Layout(store, first, paths)
    try:
        layout.message(msgtype, '')
    except _NotShared:
        return None
    size = len(first)
    # the payload ends at the layout's end, up to 3 bytes of padding after it
    if not layout.pos + _ENCAPSULATION_BYTES <= size <= layout.pos + _ENCAPSULATION_BYTES + 3 \
            or len(set(map(len, raws))) != 1:
        return None
    view = np.frombuffer(b''.join(raws), _dtype(layout, size))
    if (view['#cdr'] != _CDR_LE).any() or any(
            (view[f'#{k}'] != value).any() for k, (_, value) in enumerate(layout.checks)):
        return None
    return [[[] for _ in raws] if path in layout.empty else view[path].tolist()
            for path in paths]


def _check_paths(store: Typestore, msgtype: str, paths: Sequence[str]) -> None:
    """A path that names no field of ``msgtype`` is an error on either path."""
    for path in paths:
        typename = msgtype
        for name in path.split('.'):
            fields = dict(store.get_msgdef(typename).fields) if typename else {}
            if name not in fields:
                raise ValueError(f'{msgtype} has no field {path!r}')
            kind, detail = fields[name]
            typename = detail if kind == Nodetype.NAME else None


def read_fields(store: Typestore, msgtype: str, raws: Sequence[bytes],
                paths: Sequence[str]) -> list[tuple]:
    """The fields ``paths`` (dotted: 'pose.pose.position.x') of each CDR message in ``raws``
    (all of type ``msgtype``), one tuple per message in the order of ``paths``."""
    if not paths:
        raise ValueError('read_fields: no field asked for')
    _check_paths(store, msgtype, paths)
    if not raws:
        return []
    columns = _columns(store, msgtype, raws, paths)
    if columns is not None:
        return list(zip(*columns, strict=True))
    get, decode = attrgetter(*paths), store.deserialize_cdr
    if len(paths) == 1:
        return [(get(decode(raw, msgtype)),) for raw in raws]
    return [get(decode(raw, msgtype)) for raw in raws]
