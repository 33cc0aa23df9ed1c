"""Damage known-good frames for the property-based parser tests."""


def damaged_stream(parts) -> tuple[bytes, int]:
    """Join ``(frame, position, value, truncate)`` parts, each cut short or one byte replaced.

    Truncation keeps at least one byte and ends the line; replacement spares the CR LF.
    Returns the bytes and how many frames were really changed.
    """
    stream, damaged = b'', 0
    for frame, position, value, truncate in parts:
        data = bytearray(frame)
        if truncate:
            data = data[:1 + position % (len(data) - 3)] + b'\r\n'
        else:
            data[position % (len(data) - 2)] = value
        damaged += bytes(data) != frame
        stream += bytes(data)
    return stream, damaged
