"""Deterministic encoders of frames (PNG, OpenEXR, NPY) and the two decoders
the CLI backend needs. Pure Python + numpy + zlib: the same arrays always give
the same bytes, which is what makes a distributed render comparable byte for
byte with a single-process one.
"""

from __future__ import annotations

import io
import struct
import zlib

import numpy as np

#: OpenEXR channel names of each AOV (alphabetical order is the file's order).
EXR_CHANNELS = {
    "hdr": ("R", "G", "B", "A"),
    "depth": ("Z",),
    "distance": ("distance",),
    "normal": ("N.X", "N.Y", "N.Z"),
    "class": ("class",),
    "instance": ("instance",),
    "motion": ("motion.X", "motion.Y"),
}


def _chunk(kind: bytes, data: bytes) -> bytes:
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def encode_png(rgba: np.ndarray) -> bytes:
    """An 8-bit RGBA PNG of an (H, W, 4) uint8 array, row 0 at the top."""
    if rgba.dtype != np.uint8 or rgba.ndim != 3 or rgba.shape[2] != 4:
        raise ValueError(f"png: expected an (H, W, 4) uint8 array, got {rgba.dtype} {rgba.shape}")
    h, w, _ = rgba.shape
    raw = np.zeros((h, w * 4 + 1), np.uint8)
    raw[:, 1:] = rgba.reshape(h, w * 4)
    header = struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)) + _chunk(b"IEND", b"")


def decode_png(data: bytes) -> np.ndarray:
    """An (H, W, 4) uint8 array of an 8-bit RGB/RGBA non-interlaced PNG."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("png: not a PNG file")
    pos, idat, header = 8, [], None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        pos += 12 + length
    w, h, depth, color, _, _, interlace = header
    channels = {6: 4, 2: 3}.get(color)
    if depth != 8 or channels is None or interlace:
        raise ValueError(f"png: only 8-bit RGB/RGBA non-interlaced PNGs are read (depth {depth}, colour type {color})")
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8).reshape(h, w * channels + 1)
    out = np.zeros((h, w * channels), np.int32)
    bpp = channels
    prev = np.zeros(w * channels, np.int32)
    for y in range(h):
        f, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 0xFF
        else:  # Sub, Average, Paeth depend on the pixel to the left: sequential
            cur = np.zeros_like(line)
            for x in range(len(line)):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) >> 1
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + p) & 0xFF
        out[y] = cur
        prev = cur
    img = out.astype(np.uint8).reshape(h, w, channels)
    if channels == 3:
        img = np.concatenate([img, np.full((h, w, 1), 255, np.uint8)], axis=2)
    return img


def encode_npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(array), allow_pickle=False)
    return buf.getvalue()


def _attr(name: str, kind: str, value: bytes) -> bytes:
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def encode_exr(aov: str, array: np.ndarray) -> bytes:
    """A scanline OpenEXR file (no compression) of one AOV.

    Float AOVs become FLOAT channels, `class`/`instance` UINT channels, named
    as the CLI names them (R,G,B,A; Z; distance; N.X/Y/Z; motion.X/Y; ...).
    """
    names = EXR_CHANNELS[aov]
    a = array if array.ndim == 3 else array[:, :, None]
    h, w, n = a.shape
    if n != len(names):
        raise ValueError(f"exr: {aov} needs {len(names)} channels, got shape {array.shape}")
    uint = aov in ("class", "instance")
    a = a.astype(np.uint32 if uint else np.float32)
    pixel_type = 0 if uint else 2
    order = sorted(range(n), key=lambda k: names[k])
    chlist = b"".join(names[k].encode() + b"\0" + struct.pack("<iB3xii", pixel_type, 0, 1, 1) for k in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (
        struct.pack("<ii", 20000630, 2)
        + _attr("channels", "chlist", chlist)
        + _attr("compression", "compression", b"\0")
        + _attr("dataWindow", "box2i", box)
        + _attr("displayWindow", "box2i", box)
        + _attr("lineOrder", "lineOrder", b"\0")
        + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
        + _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
        + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
        + b"\0"
    )
    planar = np.ascontiguousarray(a[:, :, order].transpose(0, 2, 1)).astype("<u4" if uint else "<f4")
    line_bytes = n * w * 4
    table_end = len(header) + 8 * h
    offsets = struct.pack(f"<{h}Q", *(table_end + y * (8 + line_bytes) for y in range(h)))
    body = b"".join(struct.pack("<ii", y, line_bytes) + planar[y].tobytes() for y in range(h))
    return header + offsets + body


def decode_exr(data: bytes) -> dict[str, np.ndarray]:
    """Channels of a scanline OpenEXR file (NONE, ZIPS or ZIP compression)."""
    magic, _ = struct.unpack("<ii", data[:8])
    if magic != 20000630:
        raise ValueError("exr: not an OpenEXR file")
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        kend = data.index(b"\0", end + 1)
        (size,) = struct.unpack("<i", data[kend + 1 : kend + 5])
        attrs[name] = data[kend + 5 : kend + 5 + size]
        pos = kend + 5 + size
    pos += 1
    channels, cpos, chl = [], 0, attrs["channels"]
    while chl[cpos] != 0:
        end = chl.index(b"\0", cpos)
        (ptype,) = struct.unpack("<i", chl[end + 1 : end + 5])
        channels.append((chl[cpos:end].decode(), ptype))
        cpos = end + 17
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    compression = attrs["compression"][0]
    lines = {0: 1, 2: 1, 3: 16}.get(compression)
    if lines is None:
        raise ValueError(f"exr: compression {compression} is not read (NONE, ZIPS, ZIP are)")
    chunks = (h + lines - 1) // lines
    offsets = struct.unpack(f"<{chunks}Q", data[pos : pos + 8 * chunks])
    sizes = [2 if t == 1 else 4 for _, t in channels]
    dtypes = {0: "<u4", 1: "<f2", 2: "<f4"}
    out = {name: np.zeros((h, w), np.uint32 if t == 0 else np.float32) for name, t in channels}
    for off in offsets:
        y, size = struct.unpack("<ii", data[off : off + 8])
        block = data[off + 8 : off + 8 + size]
        n_lines = min(lines, y1 + 1 - y)
        expected = n_lines * w * sum(sizes)
        if compression != 0 and size < expected:
            # Undo the predictor exactly: d[0] kept, t[i] = (t[i-1] + d[i] - 128) mod 256.
            d = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int64)
            t = (np.cumsum(d - 128) + 128) & 0xFF
            t = t.astype(np.uint8)
            half = (len(t) + 1) // 2
            inter = np.empty(len(t), np.uint8)
            inter[0::2], inter[1::2] = t[:half], t[half:]
            block = inter.tobytes()
        p = 0
        for ly in range(n_lines):
            for (name, t), s in zip(channels, sizes):
                row = np.frombuffer(block[p : p + w * s], dtypes[t])
                out[name][y - y0 + ly] = row
                p += w * s
    return out
