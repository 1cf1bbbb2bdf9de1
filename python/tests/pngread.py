"""A small PNG and PFM reader for the tests (8- and 16-bit greyscale, RGB and RGBA, not
interlaced): enough to read the `kantele` command's files, including 16-bit id images that
common Python imaging libraries truncate to 8 bits."""

import struct
import zlib
from pathlib import Path

import numpy as np


def _unfilter(raw: bytes, height: int, stride: int, bpp: int) -> np.ndarray:
    out = np.zeros((height, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    pos = 0
    for y in range(height):
        ftype = raw[pos]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=pos + 1).astype(np.int32)
        pos += stride + 1
        if ftype == 0:
            cur = line
        elif ftype == 2:
            cur = (line + prev) & 0xFF
        else:
            cur = line.copy()
            for i in range(stride):
                left = cur[i - bpp] if i >= bpp else 0
                if ftype == 1:
                    cur[i] = (cur[i] + left) & 0xFF
                elif ftype == 3:
                    cur[i] = (cur[i] + ((left + prev[i]) >> 1)) & 0xFF
                elif ftype == 4:
                    up, ul = prev[i], (prev[i - bpp] if i >= bpp else 0)
                    p = left + up - ul
                    pa, pb, pc = abs(p - left), abs(p - up), abs(p - ul)
                    pred = left if pa <= pb and pa <= pc else (up if pb <= pc else ul)
                    cur[i] = (cur[i] + pred) & 0xFF
                else:
                    raise ValueError(f"bad PNG filter {ftype}")
        out[y] = cur
        prev = cur
    return out


def read_png(path) -> np.ndarray:
    """(H, W, C) `uint8` or `uint16` pixels of a PNG file."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    assert interlace == 0
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    bytes_per_sample = depth // 8
    bpp = channels * bytes_per_sample
    rows = _unfilter(zlib.decompress(idat), h, w * bpp, bpp)
    if depth == 16:
        return rows.view(">u2").reshape(h, w, channels).astype(np.uint16)
    return rows.reshape(h, w, channels)


def read_pfm(path) -> np.ndarray:
    """(H, W) `float32` values of a greyscale PFM file, row 0 at the top."""
    data = Path(path).read_bytes()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos : pos + 1].isspace():
            pos += 1
        fields.append(data[start:pos].decode())
    pos += 1
    assert fields[0] == "Pf", f"{path}: not a greyscale PFM"
    w, h, scale = int(fields[1]), int(fields[2]), float(fields[3])
    dtype = "<f4" if scale < 0 else ">f4"
    values = np.frombuffer(data, dtype=dtype, count=w * h, offset=pos).reshape(h, w)
    return values[::-1].astype(np.float32)
