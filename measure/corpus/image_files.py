"""Image files: the film's 8-bit sRGB encoding (camera/src/film.rs), PNG,
PPM and PFM written by hand (zlib and struct, no Pillow), and PNG and PFM
read back for other scripts.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np


def encode_8bit(film: np.ndarray, mistakes) -> np.ndarray:
    """camera/src/film.rs `linear_to_srgb8`: NaN -> 0, clamp to [0, 1], the
    exact sRGB curve, then (x * 255 + 0.5) truncated (round half up)."""
    c = np.clip(np.nan_to_num(film, nan=0.0), 0.0, 1.0).astype(np.float32).astype(np.float64)
    if "no-srgb" in mistakes:  # MISTAKE: linear values written as they are
        e = c
    elif "gamma-22" in mistakes:  # MISTAKE: a plain gamma of 2.2
        e = c ** (1 / 2.2)
    else:
        e = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    if "truncate-8bit" in mistakes:  # MISTAKE: floor instead of rounding
        return np.floor(e * 255.0).astype(np.uint8)
    return np.floor(e * 255.0 + 0.5).astype(np.uint8)


def write_png(path: str, rgb8: np.ndarray):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))


def write_ppm(path: str, rgb8: np.ndarray, ascii_: bool):
    h, w, _ = rgb8.shape
    with open(path, "wb") as f:
        if ascii_:
            f.write(f"P3\n{w} {h}\n255\n".encode())
            for y in range(h):
                f.write((" ".join(map(str, rgb8[y].ravel().tolist())) + "\n").encode())
        else:
            f.write(f"P6\n{w} {h}\n255\n".encode())
            f.write(rgb8.tobytes())


def write_pfm(path: str, film: np.ndarray):
    """camera/src/film.rs `write_pfm`: `PF\\nW H\\n-1.0\\n`, little-endian f32,
    bottom row first."""
    h, w, _ = film.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(film[::-1], dtype="<f4").tobytes())


def read_pfm(path: str) -> np.ndarray:
    """A PFM as Glint and write_pfm write it, as an (H, W, 3) array, top row first."""
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(b"\n", 3)
    if parts[0] != b"PF":
        raise ValueError(f"{path}: not an RGB PFM")
    w, h = map(int, parts[1].split())
    scale = float(parts[2])
    dtype = "<f4" if scale < 0 else ">f4"
    img = np.frombuffer(parts[3][: w * h * 12], dtype=dtype).reshape(h, w, 3)
    return img[::-1].astype(np.float64) * abs(scale)


def read_png(path: str) -> np.ndarray:
    """An 8-bit RGB, non-interlaced PNG (as write_png and Glint write them)
    as an (H, W, 3) uint8 array."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat = 8, b""
    w = h = bpp = None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        tag = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if tag == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise ValueError(f"{path}: only 8-bit RGB(A) non-interlaced PNGs are read")
            bpp = 3 if ctype == 2 else 4
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = np.zeros((h, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        else:  # 1 (sub), 3 (average), 4 (Paeth): byte by byte
            cur = np.zeros(stride, dtype=np.int32)
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (line[i] + pred) & 255
        out[y] = cur
        prev = cur
    return out.reshape(h, w, bpp)[..., :3].astype(np.uint8)


def srgb8_to_linear(rgb8: np.ndarray) -> np.ndarray:
    e = rgb8.astype(np.float64) / 255.0
    return np.where(e <= 0.04045, e / 12.92, ((e + 0.055) / 1.055) ** 2.4)
