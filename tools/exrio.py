"""exrio.py — a small OpenEXR reader and writer in plain Python (numpy, zlib), for murk's tools and bench
scripts: scanline images of R, G, B (or Y) channels, HALF or FLOAT, compression NONE, ZIPS or ZIP.

    read(path)  -> numpy float32 array (h, w, 3), row 0 at the top
    meta(path)  -> dict of the string attributes (murk:nonfinite_samples, murk:seed, ...)
    write(path, rgb, half=True, zip=True)   writes R, G, B; ZIP (16 lines a chunk), deterministic bytes

The format (OpenEXR's "Technical Introduction" and file layout document): magic 20000630, version 2,
a header of (name, type, size, value) attributes ended by a 0 byte, a table of chunk offsets, then chunks
(y, size, data); a chunk holds its lines one after another, each line its channels in alphabetical order.
ZIP data is zlib over the bytes split into even and odd halves, each byte stored as the difference from
the one before plus 128.
"""
import struct
import zlib

import numpy as np

MAGIC = 20000630
NONE, ZIPS, ZIP = 0, 2, 3
LINES = {NONE: 1, ZIPS: 1, ZIP: 16}
HALF, FLOAT = 1, 2


def _undo_zip(data, size):
    raw = np.frombuffer(zlib.decompress(data), dtype=np.uint8).astype(np.int32)
    if raw.size != size:
        raise ValueError("EXR chunk decompresses to %d bytes, expected %d" % (raw.size, size))
    # undo the predictor: t[0] = d[0], t[i] = t[i - 1] + d[i] - 128 (mod 256)
    t = (np.cumsum(np.concatenate(([raw[0]], raw[1:] - 128))) & 0xFF).astype(np.uint8)
    half = (size + 1) // 2
    out = np.empty(size, dtype=np.uint8)
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def _do_zip(raw):
    b = np.frombuffer(raw, dtype=np.uint8)
    t = np.concatenate((b[0::2], b[1::2])).astype(np.int32)
    d = t.copy()
    d[1:] = (t[1:] - t[:-1] + 128) & 0xFF
    return zlib.compress(d.astype(np.uint8).tobytes(), 9)


def _attrs(buf, pos):
    attrs = {}
    while buf[pos] != 0:
        end = buf.index(b"\0", pos)
        name = buf[pos:end].decode()
        end2 = buf.index(b"\0", end + 1)
        typ = buf[end + 1:end2].decode()
        size = struct.unpack_from("<i", buf, end2 + 1)[0]
        attrs[name] = (typ, buf[end2 + 5:end2 + 5 + size])
        pos = end2 + 5 + size
    return attrs, pos + 1


def _channels(value):
    chans, pos = [], 0
    while value[pos] != 0:
        end = value.index(b"\0", pos)
        name = value[pos:end].decode()
        ptype, _, _, xs, ys = struct.unpack_from("<iB3sii", value, end + 1)
        chans.append((name, ptype))
        pos = end + 1 + 16
    return chans


def _header(path):
    buf = open(path, "rb").read()
    magic, version = struct.unpack_from("<ii", buf, 0)
    if magic != MAGIC or version & 0x200 or version & 0x1000:
        raise ValueError("%s: not a single-part scanline EXR" % path)
    attrs, pos = _attrs(buf, 8)
    return buf, attrs, pos


def meta(path):
    """A scanline EXR's string attributes as a dict of str (murk's murk:* metadata among them)."""
    _, attrs, _ = _header(path)
    return {k: v.decode(errors="replace") for k, (t, v) in attrs.items() if t == "string"}


def read(path):
    """An (h, w, 3) float32 array of a scanline EXR's R, G, B (or Y copied to all three)."""
    buf, attrs, pos = _header(path)
    chans = _channels(attrs["channels"][1])
    comp = attrs["compression"][1][0]
    if comp not in LINES:
        raise ValueError("%s: compression %d not supported" % (path, comp))
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    nchunks = (h + LINES[comp] - 1) // LINES[comp]
    offsets = struct.unpack_from("<%dQ" % nchunks, buf, pos)
    sizes = [2 if t == HALF else 4 for _, t in chans]
    planes = {name: np.zeros((h, w), np.float32) for name, _ in chans}
    for off in offsets:
        y, n = struct.unpack_from("<ii", buf, off)
        data = buf[off + 8:off + 8 + n]
        lines = min(LINES[comp], y1 - y + 1)
        size = lines * w * sum(sizes)
        if comp != NONE and n < size:
            data = _undo_zip(data, size)
        p = 0
        for line in range(lines):
            for (name, t), s in zip(chans, sizes):
                arr = np.frombuffer(data, dtype="<f2" if t == HALF else "<f4", count=w, offset=p)
                planes[name][y - y0 + line] = arr
                p += w * s
    if all(c in planes for c in "RGB"):
        return np.stack([planes["R"], planes["G"], planes["B"]], axis=-1)
    return np.repeat(planes["Y"][:, :, None], 3, axis=2)


def _attr(name, typ, value):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(value)) + value


def write(path, rgb, half=True, zip=True):
    """Writes rgb (h, w, 3) as R, G, B channels (HALF or FLOAT), ZIP or uncompressed."""
    rgb = np.asarray(rgb, dtype=np.float32)
    h, w, _ = rgb.shape
    ptype, dt = (HALF, "<f2") if half else (FLOAT, "<f4")
    comp = ZIP if zip else NONE
    chl = b"".join(c.encode() + b"\0" + struct.pack("<iB3sii", ptype, 0, b"\0\0\0", 1, 1) for c in "BGR") + b"\0"
    head = struct.pack("<ii", MAGIC, 2)
    head += _attr("channels", "chlist", chl)
    head += _attr("compression", "compression", bytes([comp]))
    head += _attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    head += _attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    head += _attr("lineOrder", "lineOrder", b"\0")
    head += _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    head += _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    head += _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    head += b"\0"
    lines = LINES[comp]
    chunks = []
    for y in range(0, h, lines):
        raw = b"".join(rgb[yy, :, c].astype(dt).tobytes() for yy in range(y, min(h, y + lines)) for c in (2, 1, 0))
        data = raw
        if comp != NONE:
            z = _do_zip(raw)
            data = z if len(z) < len(raw) else raw
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    pos = len(head) + 8 * len(chunks)
    table = b""
    for c in chunks:
        table += struct.pack("<Q", pos)
        pos += len(c)
    with open(path, "wb") as f:
        f.write(head + table + b"".join(chunks))
