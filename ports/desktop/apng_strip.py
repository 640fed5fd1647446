#!/usr/bin/env python3
"""apng_strip.py APNG OUT.png N [SCALE] -- a frame strip for the docs: N frames
of an APNG written by sinew-play --apng (8-bit RGB, full frames), evenly
spread, side by side, every SCALE-th pixel (default 2). Python standard
library only (zlib, struct)."""
import struct, sys, zlib

def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else b if pb <= pc else c

def unfilter(raw, w, h):
    st, out, prev = 3 * w, [], bytearray(3 * w)
    for y in range(h):
        f, row = raw[y * (st + 1)], bytearray(raw[y * (st + 1) + 1:(y + 1) * (st + 1)])
        for x in range(st):
            a = row[x - 3] if x >= 3 else 0
            b = prev[x]
            c = prev[x - 3] if x >= 3 else 0
            row[x] = (row[x] + (0, a, b, (a + b) // 2, paeth(a, b, c))[f]) & 255
        out.append(bytes(row))
        prev = row
    return out

def frames(path):
    b = open(path, "rb").read()
    o, fr, cur = 8, [], None
    while o < len(b):
        n, t = struct.unpack_from(">I4s", b, o)
        d = b[o + 8:o + 8 + n]
        if t == b"IHDR": w, h = struct.unpack(">II", d[:8])
        elif t == b"fcTL":
            if cur is not None: fr.append(cur)
            cur = b""
        elif t == b"IDAT": cur += d
        elif t == b"fdAT": cur += d[4:]
        o += 12 + n
    fr.append(cur)
    return w, h, fr

def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)

if __name__ == "__main__":
    src, out, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
    s = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    w, h, fr = frames(src)
    pick = [round(i * (len(fr) - 1) / max(1, n - 1)) for i in range(n)]
    rows = [unfilter(zlib.decompress(fr[p]), w, h) for p in pick]
    ow, oh = (w // s) * n, h // s
    raw = bytearray()
    for y in range(oh):
        raw.append(0)
        for r in rows:
            line = r[y * s]
            for x in range(w // s):
                raw += line[3 * x * s:3 * x * s + 3]
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", ow, oh, 8, 2, 0, 0, 0)) + \
          chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    open(out, "wb").write(png)
    print("%s: %d frames of %s (%dx%d) -> %dx%d" % (out, n, src, w, h, ow, oh))
