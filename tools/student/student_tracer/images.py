"""Reading image files: PNG (8/16-bit, sRGB decoded to linear) and Radiance .hdr,
into an Image of linear (r, g, b) texels.
"""

import math
import struct
import zlib

from .vectors import INF


class Image:
    """width x height texels, row 0 at the top; data[y*width + x] = (r, g, b) linear."""

    def __init__(self, width, height, data):
        self.width = width
        self.height = height
        self.data = data

    def texel(self, x, y):
        return self.data[y * self.width + x]


def srgb_to_linear(c):
    # IEC 61966-2-1 decoding (scene-format.md: 8- and 16-bit files are decoded
    # from sRGB to linear once at load)
    if c <= 0.04045:
        return c / 12.92
    return ((c + 0.055) / 1.055) ** 2.4


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    if pb <= pc:
        return b
    return c


def read_png(path):
    raw = open(path, "rb").read()
    if raw[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos = 8
    idat = []
    palette = None
    while pos < len(raw):
        (n,) = struct.unpack(">I", raw[pos:pos + 4])
        kind = raw[pos + 4:pos + 8]
        body = raw[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif kind == b"PLTE":
            palette = [tuple(body[i:i + 3]) for i in range(0, len(body), 3)]
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if interlace:
        raise ValueError(f"{path}: interlaced PNGs are not supported")
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ctype]
    data = zlib.decompress(b"".join(idat))
    bpp = max(1, channels * depth // 8)
    stride = (width * channels * depth + 7) // 8
    prev = bytearray(stride)
    rows = []
    p = 0
    for _ in range(height):
        ftype = data[p]
        line = bytearray(data[p + 1:p + 1 + stride])
        p += 1 + stride
        if ftype == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 255
        elif ftype == 2:
            line = bytearray((a + b) & 255 for a, b in zip(line, prev))
        elif ftype == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 255
        elif ftype == 4:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                upleft = prev[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + _paeth(left, prev[i], upleft)) & 255
        rows.append(line)
        prev = line
    if depth == 8:
        lut = [srgb_to_linear(i / 255.0) for i in range(256)]
    texels = []
    for line in rows:
        if depth == 16:
            vals = [(line[2 * i] << 8 | line[2 * i + 1]) for i in range(width * channels)]
            conv = [srgb_to_linear(v / 65535.0) for v in vals]
        elif depth == 8:
            vals = line
            conv = None
        else:
            raise ValueError(f"{path}: bit depth {depth} not supported")
        for x in range(width):
            if ctype == 3:
                r, g, b = palette[line[x]]
                texels.append((lut[r], lut[g], lut[b]))
                continue
            base = x * channels
            if conv is None:
                if channels >= 3:
                    texels.append((lut[vals[base]], lut[vals[base + 1]], lut[vals[base + 2]]))
                else:
                    gv = lut[vals[base]]
                    texels.append((gv, gv, gv))
            else:
                if channels >= 3:
                    texels.append((conv[base], conv[base + 1], conv[base + 2]))
                else:
                    texels.append((conv[base], conv[base], conv[base]))
    return Image(width, height, texels)


def read_hdr(path):
    raw = open(path, "rb").read()
    pos = 0
    while True:  # header lines up to a blank line
        end = raw.index(b"\n", pos)
        line = raw[pos:end]
        pos = end + 1
        if line == b"":
            break
    end = raw.index(b"\n", pos)
    res = raw[pos:end].split()
    pos = end + 1
    if res[0] != b"-Y" or res[2] != b"+X":
        raise ValueError(f"{path}: unsupported orientation {res}")
    height, width = int(res[1]), int(res[3])
    texels = []

    def rgbe(r, g, b, e):
        if e == 0:
            return (0.0, 0.0, 0.0)
        f = math.ldexp(1.0, e - 136)
        return (r * f, g * f, b * f)

    for _ in range(height):
        if 8 <= width < 32768 and raw[pos] == 2 and raw[pos + 1] == 2 and raw[pos + 2] < 128:
            pos += 4  # new-style run-length encoded scanline
            comps = []
            for _c in range(4):
                out = bytearray()
                while len(out) < width:
                    count = raw[pos]
                    pos += 1
                    if count > 128:
                        out.extend(bytes([raw[pos]]) * (count - 128))
                        pos += 1
                    else:
                        out.extend(raw[pos:pos + count])
                        pos += count
                comps.append(out)
            for x in range(width):
                texels.append(rgbe(comps[0][x], comps[1][x], comps[2][x], comps[3][x]))
        else:
            for x in range(width):
                r, g, b, e = raw[pos:pos + 4]
                pos += 4
                texels.append(rgbe(r, g, b, e))
    out = []
    for t in texels:  # NaN, infinite and negative values read as 0
        out.append(tuple(c if (c == c and 0 <= c < INF) else 0.0 for c in t))
    return Image(width, height, out)


def read_image(path):
    if path.lower().endswith(".png"):
        return read_png(path)
    if path.lower().endswith(".hdr"):
        return read_hdr(path)
    raise ValueError(f"{path}: only PNG and Radiance HDR are read by this tracer")
