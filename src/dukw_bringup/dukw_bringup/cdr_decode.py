"""CDR decoders per message type, generated from the rosbags type store, for bag replay.

rosbags' own decoder (``Typestore.deserialize_cdr``) is generated per type too but
unpacks each primitive with its own ``struct`` call, appends it to a list and looks up
every nested type's decoder in the store on each message: 2-7 us for the stack's
messages, a fifth of a replay through the cores. The decoders here read the same bytes
into the same rosbags message classes (same field values, numpy arrays as rosbags makes
them) with one ``struct`` call per run of fixed-size fields and nested types inlined.
Types with arrays or sequences of messages (or arrays of strings) and big-endian data are
left to rosbags. ``tests/test_cdr_decode.py`` checks every message of the golden bags against
rosbags, field by field and bit for bit.
"""
from __future__ import annotations

import struct
import sys
from typing import Any, Callable

import numpy
from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError
from rosbags.serde.utils import check_sequence, check_string
from rosbags.typesys.store import Typestore

#: struct codes and sizes of the CDR primitives (as rosbags.serde.primitives)
_CODES = {'bool': '?', 'byte': 'b', 'char': 'B', 'int8': 'b', 'int16': 'h', 'int32': 'i',
          'int64': 'q', 'uint8': 'B', 'uint16': 'H', 'uint32': 'I', 'uint64': 'Q',
          'float32': 'f', 'float64': 'd'}
_SIZES = {name: struct.calcsize('<' + code) for name, code in _CODES.items()}
_NDTYPES = {'bool': 'bool_', 'byte': 'int8', 'char': 'uint8', 'int8': 'int8', 'int16': 'int16',
            'int32': 'int32', 'int64': 'int64', 'uint8': 'uint8', 'uint16': 'uint16',
            'uint32': 'uint32', 'uint64': 'uint64', 'float32': 'float32', 'float64': 'float64'}
_UINT32 = struct.Struct('<I').unpack_from


class _Unsupported(Exception):
    """A field this generator leaves to rosbags."""


class _Generator:
    """Emits one type's decoder: the position is ``pos + off`` with ``off`` known here and
    ``pos`` a runtime value aligned to ``known`` (it moves only after a string)."""

    def __init__(self, store: Typestore) -> None:
        self.store = store
        self.lines: list[str] = []
        self.names: dict[str, Any] = {
            'frombuffer': numpy.frombuffer, 'check_string': check_string,
            'check_sequence': check_sequence, 'unpack_uint32': _UINT32,
            'max_sequence_length': store.max_sequence_length}
        self.off, self.known = 0, 8
        self.run: list[str] = []            # pending struct codes ('x' for padding)
        self.run_off = 0
        self.run_vars: list[str] = []
        self.count = 0

    def _new(self, prefix: str, value: Any = None) -> str:
        self.count += 1
        name = f'{prefix}{self.count}'
        if value is not None:
            self.names[name] = value
        return name

    def _flush(self) -> None:
        if self.run_vars:
            unpack = self._new('S', struct.Struct('<' + ''.join(self.run)).unpack_from)
            values = ', '.join(self.run_vars)
            self.lines.append(f'  {values}, = {unpack}(raw, pos + {self.run_off})')
        self.run, self.run_vars = [], []

    def _align(self, alignment: int) -> None:
        if alignment <= self.known:
            pad = -self.off % alignment
        else:                                # depends on where the last string ended
            self._flush()
            self.lines.append(f'  pos = (pos + {self.off} + {alignment - 1}) & -{alignment}')
            self.off, self.known, pad = 0, alignment, 0
        if pad:
            if self.run_vars:
                self.run.append('x' * pad)
            self.off += pad

    def _primitive(self, base: str) -> str:
        self._align(_SIZES[base])
        if not self.run_vars:
            self.run_off = self.off
        self.run.append(_CODES[base])
        var = self._new('v')
        self.run_vars.append(var)
        self.off += _SIZES[base]
        return var

    def _string(self) -> str:
        self._align(4)
        self._flush()
        length, var = self._new('n'), self._new('s')
        self.lines += [f'  pos += {self.off}',
                       f'  {length} = unpack_uint32(raw, pos)[0]',
                       f'  check_string(raw, pos, {length}, cdr=True)',
                       f'  {var} = bytes(raw[pos + 4:pos + 3 + {length}]).decode()',
                       f'  pos += 4 + {length}']
        self.off, self.known = 0, 1
        return var

    def _array(self, base: str, length: int) -> str:
        if base == 'string':
            raise _Unsupported('array of strings')
        self._align(_SIZES[base])
        var, dtype = self._new('a'), self._new('D', numpy.dtype(_NDTYPES[base]))
        # positional, with the dtype made once: half the cost of rosbags' keyword call
        self.lines.append(f'  {var} = frombuffer(raw, {dtype}, {length}, pos + {self.off})')
        if self.run_vars:                    # the pending run skips over the array
            self.run.append('x' * (length * _SIZES[base]))
        self.off += length * _SIZES[base]
        return var

    def _sequence(self, base: str) -> str:
        """A sequence of primitives or strings (checked as rosbags checks them)."""
        self._align(4)
        self._flush()
        size, var = self._new('n'), self._new('q')
        minimum = 5 if base == 'string' else _SIZES[base]
        self.lines += [f'  pos += {self.off}',
                       f'  {size} = unpack_uint32(raw, pos)[0]',
                       '  pos += 4',
                       f'  check_sequence(raw, pos, {size}, {minimum}, max_sequence_length)']
        if base == 'string':
            self.lines += [f'  {var} = []',
                           f'  for _ in range({size}):',
                           '    pos = (pos + 3) & -4',
                           '    length = unpack_uint32(raw, pos)[0]',
                           '    check_string(raw, pos, length, cdr=True)',
                           f'    {var}.append(bytes(raw[pos + 4:pos + 3 + length]).decode())',
                           '    pos += 4 + length']
            self.off, self.known = 0, 1
            return var
        item = _SIZES[base]
        dtype = self._new('D', numpy.dtype(_NDTYPES[base]))
        if item > 4:
            self.lines.append(f'  if {size}:\n    pos = (pos + {item - 1}) & -{item}')
        self.lines += [f'  {var} = frombuffer(raw, {dtype}, {size}, pos)',
                       f'  pos += {size} * {item}']
        self.off, self.known = 0, min(4, item)
        return var

    def message(self, typename: str) -> str:
        """The expression building ``typename`` from the fields that follow."""
        msgdef = self.store.get_msgdef(typename)
        args = []
        for _, desc in msgdef.fields:
            kind, detail = desc
            if kind == Nodetype.NAME:
                args.append(self.message(detail))
            elif kind == Nodetype.BASE:
                args.append(self._string() if detail[0] == 'string' else
                            self._primitive(detail[0]))
            elif kind == Nodetype.ARRAY and detail[0][0] == Nodetype.BASE:
                args.append(self._array(detail[0][1][0], detail[1]))
            elif kind == Nodetype.SEQUENCE and detail[0][0] == Nodetype.BASE:
                args.append(self._sequence(detail[0][1][0]))
            else:
                raise _Unsupported(f'{typename}: array or sequence of messages')
        cls = self._new('C', msgdef.cls)
        return f'{cls}({", ".join(args)})'

    def source(self, typename: str) -> str:
        """The decoder's source: ``decode(raw)`` for the payload after the 4-byte header."""
        expression = self.message(typename)
        self._flush()
        body, self.lines = self.lines, []
        return '\n'.join(['def decode(raw):', '  pos = 0', *body,
                          f'  return {expression}, pos + {self.off}'])


def _compile(store: Typestore, typename: str) -> Callable[[memoryview], tuple[Any, int]] | None:
    generator = _Generator(store)
    try:
        source = generator.source(typename)
    except _Unsupported:
        return None
    namespace = dict(generator.names)
    exec(compile(source, f'<cdr_decode {typename}>', 'exec'), namespace)  # noqa: S102
    return namespace['decode']


def decoder(store: Typestore, typename: str) -> Callable[[bytes], Any]:
    """``raw CDR bytes -> message`` for ``typename``, as ``store.deserialize_cdr`` decodes
    them (the same classes, values and errors); rosbags' own for the types left to it."""
    fast = _compile(store, typename) if sys.byteorder == 'little' else None
    if fast is None:
        return lambda raw: store.deserialize_cdr(raw, typename)

    def decode(raw: bytes) -> Any:
        if raw[:2] != b'\x00\x01':           # big-endian or not CDR: rosbags decides
            return store.deserialize_cdr(raw, typename)
        payload = memoryview(raw)[4:]
        try:
            message, end = fast(payload)
        except (struct.error, UnicodeDecodeError, ValueError) as exc:
            raise SerdeError(f'Could not deserialize {typename!r}: {exc}') from exc
        if end + 4 + 3 < len(raw):
            raise SerdeError(f'CDR message size mismatch for {typename!r}.')
        return message

    return decode
