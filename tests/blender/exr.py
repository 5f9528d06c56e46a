# Minimal OpenEXR reader for the tests (scanline images, NONE / ZIPS / ZIP compression, HALF /
# FLOAT / UINT channels): enough for what Blender and gdpt-reconstruct write. Blender's Python
# has no OpenImageIO module, and Render Result pixels cannot be read from Python, so the tests
# read the files the renders wrote.
#
# read_exr(path) -> {channel name: float32 array (height, width)}, rows bottom-first (Blender's
# pixel order, the one the gradient convention dy(x, y) = I(x, y+1) - I(x, y) refers to).
import struct
import zlib

import numpy as np

_MAGIC = 20000630
_LINES_PER_BLOCK = {0: 1, 2: 1, 3: 16}
_DTYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}


def _read_header(data, pos):
    header = {}
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        if not name:
            return header, pos
        end = data.index(b"\0", pos)
        kind = data[pos:end].decode()
        pos = end + 1
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        header[name] = (kind, data[pos:pos + size])
        pos += size


def _channels(raw):
    out = []
    pos = 0
    while raw[pos] != 0:
        end = raw.index(b"\0", pos)
        name = raw[pos:end].decode()
        pos = end + 1
        pixel_type, _linear, xs, ys = struct.unpack_from("<iB3xii", raw, pos)
        pos += 16
        if xs != 1 or ys != 1:
            raise ValueError("subsampled channels are not supported")
        out.append((name, pixel_type))
    return out


def _unzip(block, expected):
    raw = np.frombuffer(zlib.decompress(block), dtype=np.uint8)
    # Undo the predictor, then the even/odd byte split of OpenEXR's ZIP codec.
    raw = (np.cumsum(raw.astype(np.int64) - 128) + 128).astype(np.uint8)
    half = (len(raw) + 1) // 2
    out = np.empty(len(raw), dtype=np.uint8)
    out[0::2] = raw[:half]
    out[1::2] = raw[half:]
    if len(out) != expected:
        raise ValueError("EXR block has the wrong size")
    return out.tobytes()


def read_exr(path):
    with open(path, "rb") as f:
        data = f.read()
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != _MAGIC:
        raise ValueError(f"{path}: not an OpenEXR file")
    if version & 0x1600:  # tiled, long names are fine, deep / multipart are not
        if version & 0x200 or version & 0x800 or version & 0x1000:
            raise ValueError(f"{path}: tiled, deep or multi-part EXR not supported")
    header, pos = _read_header(data, 8)
    channels = _channels(header["channels"][1])
    compression = header["compression"][1][0]
    if compression not in _LINES_PER_BLOCK:
        raise ValueError(f"{path}: compression {compression} not supported")
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", header["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    lines = _LINES_PER_BLOCK[compression]
    blocks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{blocks}Q", data, pos)

    planes = {name: np.empty((height, width), dtype=np.float32) for name, _ in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        block = data[offset + 8:offset + 8 + size]
        row0 = y - ymin
        count = min(lines, height - row0)
        expected = sum(_DTYPES[t].itemsize for _, t in channels) * width * count
        if compression != 0 and size < expected:
            block = _unzip(block, expected)
        p = 0
        for r in range(count):
            for name, t in channels:
                n = _DTYPES[t].itemsize * width
                planes[name][row0 + r] = np.frombuffer(block, dtype=_DTYPES[t], count=width,
                                                       offset=p).astype(np.float32)
                p += n
    # EXR rows run top to bottom; Blender's pixel rows bottom to top.
    return {name: plane[::-1].copy() for name, plane in planes.items()}


def rgb(channels, prefix):
    """(height, width, 3) from `prefix` + R/G/B (prefix e.g. 'ViewLayer.Primal.' or '')."""
    return np.stack([channels[prefix + c] for c in "RGB"], axis=-1)


def read_string_attributes(path):
    """The header's string attributes, e.g. {"gdpt.ViewLayer.samples": "687", ...}."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    header, _ = _read_header(data, 8)
    return {k: v.decode(errors="replace") for k, (kind, v) in header.items() if kind == "string"}
