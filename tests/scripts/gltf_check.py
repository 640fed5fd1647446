#!/usr/bin/env python3
"""gltf_check.py -- independent checks of sinew-play's outputs (issue 17 item 4),
with the Python standard library only (struct, json, zlib):
  gltf_check.py glb OUT.glb FRAMES [SOURCE.gltf]   structure of a --out-gltf file
  gltf_check.py apng OUT.png FRAMES NUM DEN          an --apng file, decoded
Prints one 'ok: ...' line or 'FAIL: ...' lines; exit 1 on failure."""
import json, struct, sys, zlib, os

fails = []
def fail(msg):
    fails.append(msg)

SIZES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
FMT = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}

def read_acc(j, bins, i):
    a = j["accessors"][i]
    v = j["bufferViews"][a["bufferView"]]
    buf = bins[v["buffer"]]
    ct, n, nc = a["componentType"], a["count"], NCOMP[a["type"]]
    es = SIZES[ct] * nc
    stride = v.get("byteStride", es)
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    if a.get("byteOffset", 0) + (n - 1) * stride + es > v["byteLength"]:
        fail("accessors[%d]: runs past bufferViews[%d]" % (i, a["bufferView"]))
        return []
    if v.get("byteOffset", 0) + v["byteLength"] > len(buf):
        fail("bufferViews[%d]: runs past its buffer" % a["bufferView"])
        return []
    out = []
    for k in range(n):
        out.append(struct.unpack_from("<%d%s" % (nc, FMT[ct]), buf, start + k * stride))
    return out

def check_glb(path, frames, source=None):
    b = open(path, "rb").read()
    magic, ver, total = struct.unpack_from("<4sII", b, 0)
    if magic != b"glTF" or ver != 2: fail("header: magic %r version %d" % (magic, ver))
    if total != len(b): fail("header.length %d, file %d bytes" % (total, len(b)))
    jl, jt = struct.unpack_from("<I4s", b, 12)
    if jt != b"JSON" or jl % 4: fail("chunk 0: type %r length %d" % (jt, jl))
    j = json.loads(b[20:20 + jl])
    bl, bt = struct.unpack_from("<I4s", b, 20 + jl)
    if bt != b"BIN\0" or bl % 4 or 28 + jl + bl != len(b): fail("chunk 1: type %r length %d" % (bt, bl))
    binc = b[28 + jl:28 + jl + bl]
    if j["buffers"][0]["byteLength"] > len(binc): fail("buffers[0].byteLength past the BIN chunk")
    prim = j["meshes"][0]["primitives"][0]
    pos = read_acc(j, [binc], prim["attributes"]["POSITION"])
    idx = read_acc(j, [binc], prim["indices"])
    nv = len(pos)
    if any(i[0] >= nv for i in idx): fail("indices: a vertex index >= %d" % nv)
    tg = prim.get("targets", [])
    if len(tg) != frames: fail("%d morph targets, want %d" % (len(tg), frames))
    for a in [prim["attributes"]["POSITION"]] + [t["POSITION"] for t in tg]:
        vals = read_acc(j, [binc], a)
        acc = j["accessors"][a]
        lo = [min(v[c] for v in vals) for c in range(3)]
        hi = [max(v[c] for v in vals) for c in range(3)]
        if "min" not in acc or "max" not in acc: fail("accessors[%d]: POSITION without min/max" % a)
        elif any(abs(acc["min"][c] - lo[c]) > 1e-6 * (1 + abs(lo[c])) or abs(acc["max"][c] - hi[c]) > 1e-6 * (1 + abs(hi[c])) for c in range(3)):
            fail("accessors[%d]: min/max %s %s, data %s %s" % (a, acc["min"], acc["max"], lo, hi))
    an = j["animations"][0]
    s = an["samplers"][an["channels"][0]["sampler"]]
    ti, wo = read_acc(j, [binc], s["input"]), read_acc(j, [binc], s["output"])
    if an["channels"][0]["target"]["path"] != "weights": fail("animation does not drive weights")
    if len(wo) != len(ti) * frames: fail("weights: %d values for %d times x %d targets" % (len(wo), len(ti), frames))
    if any(ti[k][0] >= ti[k + 1][0] for k in range(len(ti) - 1)): fail("animation times not increasing")
    msg = "%s: %d bytes, %d vertices, %d triangles, %d morph targets, %d keys" % (path, len(b), nv, len(idx) // 3, len(tg), len(ti))
    if source:   # the base frame (the state before the first step) against the source glTF's POSITION
        sj = json.load(open(source))
        d = os.path.dirname(source)
        sb = [open(os.path.join(d, bu["uri"]), "rb").read() for bu in sj["buffers"]]
        src = []
        for p in sj["meshes"][0]["primitives"]:
            src += read_acc(sj, sb, p["attributes"]["POSITION"])
        if len(src) != nv: fail("%d vertices, the source has %d" % (nv, len(src)))
        else:
            dev = max(abs(src[k][c] - pos[k][c]) for k in range(nv) for c in range(3))
            msg += ", base vs source POSITION %.3g" % dev
            if dev > 1e-3: fail("base positions differ from the source glTF's by %.3g" % dev)
    return msg

def check_apng(path, frames, num, den):
    b = open(path, "rb").read()
    if b[:8] != b"\x89PNG\r\n\x1a\n": fail("signature")
    o, seq, nfc, ndata, w = 8, 0, 0, 0, None
    actl, types = None, []
    while o < len(b):
        n, t = struct.unpack_from(">I4s", b, o)
        data = b[o + 8:o + 8 + n]
        crc, = struct.unpack_from(">I", b, o + 8 + n)
        if zlib.crc32(t + data) & 0xffffffff != crc: fail("chunk %s at %d: bad CRC" % (t, o))
        types.append(t)
        if t == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", data[:10])
        elif t == b"acTL":
            actl = struct.unpack(">II", data)
        elif t == b"fcTL":
            s, fw, fh, x, y, dn, dd, dop, bop = struct.unpack(">IIIIIHHBB", data)
            if s != seq: fail("fcTL sequence %d, want %d" % (s, seq))
            seq += 1
            nfc += 1
            if (fw, fh, x, y) != (w, h, 0, 0): fail("fcTL %d: region %dx%d at %d,%d" % (nfc, fw, fh, x, y))
            if (dn, dd) != (num, den): fail("fcTL %d: delay %d/%d, want %d/%d" % (nfc, dn, dd, num, den))
            cur = b""
        elif t in (b"IDAT", b"fdAT"):
            if t == b"fdAT":
                s, = struct.unpack(">I", data[:4])
                if s != seq: fail("fdAT sequence %d, want %d" % (s, seq))
                seq += 1
                data = data[4:]
            raw = zlib.decompress(data)
            if len(raw) != h * (1 + 3 * w): fail("frame %d: %d bytes inflated, want %d" % (nfc, len(raw), h * (1 + 3 * w)))
            ndata += 1
        o += 12 + n
    if types[0] != b"IHDR" or types[1] != b"acTL" or types[-1] != b"IEND": fail("chunk order %s" % types[:3])
    if not actl or actl[0] != frames: fail("acTL frames %s, want %d" % (actl, frames))
    if nfc != frames or ndata != frames: fail("%d fcTL, %d image chunks, want %d" % (nfc, ndata, frames))
    return "%s: %d bytes, %dx%d, %d frames of %d/%d s, sequence 0..%d" % (path, len(b), w, h, nfc, num, den, seq - 1)

if __name__ == "__main__":
    try:
        if sys.argv[1] == "glb":
            m = check_glb(sys.argv[2], int(sys.argv[3]), sys.argv[4] if len(sys.argv) > 4 else None)
        else:
            m = check_apng(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]))
    except Exception as e:   # a file too broken to walk
        fail("%s: %r" % (sys.argv[2], e))
        m = ""
    for f in fails:
        print("FAIL:", f)
    if not fails:
        print("ok:", m)
    sys.exit(1 if fails else 0)
