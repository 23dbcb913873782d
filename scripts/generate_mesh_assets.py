#!/usr/bin/env python3
"""Writes test assets for the mesh importer's timing (docs/assets.md, "Measured"): a UV sphere
of about TRIS triangles as glTF 2.0 (.gltf + .bin + PNG base colour, normal and
metallic-roughness maps of SIZE^2 texels), binary glTF (.glb, textures embedded), OBJ + MTL
(centimetres, y up, base colour map), binary STL and binary PLY, plus a world file placing
them all. Standard library only (PNG through zlib).

    python3 scripts/generate_mesh_assets.py /tmp/assets --triangles 200000 --texture 2048
    penumbra run /tmp/assets/world.yaml --duration 0.01 --out /tmp/assets/out   # logs import times
"""
import argparse
import json
import math
import os
import struct
import zlib


def png(width, height, pixel):
    rows = bytearray()
    for y in range(height):
        rows.append(0)
        for x in range(width):
            rows.extend(pixel(x, y))
    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(bytes(rows), 6)) + chunk(b"IEND", b""))


def sphere(tris):
    # lat-long grid: 2 * n * (2n) triangles
    n = max(4, int(math.sqrt(tris / 4)))
    m = 2 * n
    pos, nrm, uv, idx = [], [], [], []
    for i in range(n + 1):
        th = math.pi * i / n
        for j in range(m + 1):
            ph = 2 * math.pi * j / m
            p = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))  # y up
            pos.append(p)
            nrm.append(p)
            uv.append((j / m, i / n))
    for i in range(n):
        for j in range(m):
            a = i * (m + 1) + j
            b, c, d = a + 1, a + m + 1, a + m + 2
            idx += [a, b, c, b, d, c]
    return pos, nrm, uv, idx


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--triangles", type=int, default=200000)
    ap.add_argument("--texture", type=int, default=2048)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    pos, nrm, uv, idx = sphere(a.triangles)
    s = a.texture
    base = png(s, s, lambda x, y: (200 if (x // 64 + y // 64) % 2 else 60, (x * 255) // s, (y * 255) // s))
    normal = png(s, s, lambda x, y: (128 + int(60 * math.sin(x / 8.0)), 128, 230))
    mr = png(s // 2, s // 2, lambda x, y: (0, 64 + (x * 191) // (s // 2), 0))
    for name, data in (("base.png", base), ("normal.png", normal), ("mr.png", mr)):
        open(os.path.join(a.out, name), "wb").write(data)

    binary = bytearray()
    views = []
    def view(data):
        while len(binary) % 4:
            binary.append(0)
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
        binary.extend(data)
        return len(views) - 1
    vp = view(b"".join(struct.pack("<3f", *p) for p in pos))
    vn = view(b"".join(struct.pack("<3f", *p) for p in nrm))
    vt = view(b"".join(struct.pack("<2f", *t) for t in uv))
    vi = view(b"".join(struct.pack("<I", i) for i in idx))
    nv = len(pos)
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "sphere"}],
        "meshes": [{"name": "sphere", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"name": "painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 2}, "metallicFactor": 0, "roughnessFactor": 1}, "normalTexture": {"index": 1}}],
        "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
        "accessors": [
            {"bufferView": vp, "componentType": 5126, "count": nv, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": vn, "componentType": 5126, "count": nv, "type": "VEC3"},
            {"bufferView": vt, "componentType": 5126, "count": nv, "type": "VEC2"},
            {"bufferView": vi, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
    }
    g = dict(doc, images=[{"uri": "base.png"}, {"uri": "normal.png"}, {"uri": "mr.png"}],
             bufferViews=list(views), buffers=[{"uri": "sphere.bin", "byteLength": len(binary)}])
    open(os.path.join(a.out, "sphere.bin"), "wb").write(binary)
    open(os.path.join(a.out, "sphere.gltf"), "w").write(json.dumps(g))
    # .glb: the images embedded as buffer views
    images = []
    for data in (base, normal, mr):
        images.append({"bufferView": view(data), "mimeType": "image/png"})
    while len(binary) % 4:
        binary.append(0)
    gb = dict(doc, images=images, bufferViews=views, buffers=[{"byteLength": len(binary)}])
    js = json.dumps(gb).encode()
    js += b" " * (-len(js) % 4)
    glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(binary))
    glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(binary), b"BIN\x00") + bytes(binary)
    open(os.path.join(a.out, "sphere.glb"), "wb").write(glb)
    # OBJ in centimetres (radius 50 cm), y up
    with open(os.path.join(a.out, "sphere.mtl"), "w") as f:
        f.write("newmtl painted\nKd 1 1 1\nNs 20\nmap_Kd base.png\n")
    with open(os.path.join(a.out, "sphere.obj"), "w") as f:
        f.write("mtllib sphere.mtl\nusemtl painted\n")
        f.writelines("v %.6f %.6f %.6f\n" % (50 * p[0], 50 * p[1], 50 * p[2]) for p in pos)
        f.writelines("vt %.6f %.6f\n" % (t[0], 1 - t[1]) for t in uv)
        f.writelines("vn %.6f %.6f %.6f\n" % p for p in nrm)
        f.writelines("f %d/%d/%d %d/%d/%d %d/%d/%d\n" % tuple(k + 1 for k in (idx[t], idx[t], idx[t], idx[t + 1], idx[t + 1], idx[t + 1], idx[t + 2], idx[t + 2], idx[t + 2])) for t in range(0, len(idx), 3))
    # binary STL and PLY (z up: the y-up sphere is symmetric anyway)
    with open(os.path.join(a.out, "sphere.stl"), "wb") as f:
        f.write(b"penumbra sphere".ljust(80, b"\0") + struct.pack("<I", len(idx) // 3))
        for t in range(0, len(idx), 3):
            f.write(struct.pack("<3f", 0, 0, 0))
            for k in idx[t:t + 3]:
                f.write(struct.pack("<3f", *pos[k]))
            f.write(b"\0\0")
    with open(os.path.join(a.out, "sphere.ply"), "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (nv, len(idx) // 3)).encode())
        for p in pos:
            f.write(struct.pack("<3f", *p))
        for t in range(0, len(idx), 3):
            f.write(struct.pack("<B3i", 3, *idx[t:t + 3]))
    with open(os.path.join(a.out, "world.yaml"), "w") as f:
        f.write("duration_sec: 0.01\nmodels:\n")
        for i, (name, extra) in enumerate((("sphere.gltf", ""), ("sphere.glb", ""), ("sphere.obj", ", units: cm"),
                                          ("sphere.stl", ""), ("sphere.ply", ""))):
            f.write("  - {name: m%d, file: %s, pose: {xyz: [%d, 0, 1]}%s}\n" % (i, name, 3 * i, extra))
    print("wrote %s: %d triangles, %d^2 textures" % (a.out, len(idx) // 3, s))


if __name__ == "__main__":
    main()
