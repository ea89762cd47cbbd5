#!/usr/bin/env python3
"""Writes an N x N quad grid (2 N^2 triangles) with texture coordinates as grid.obj, its
grid.mtl and a 256x256 checker texture grid.png, for measuring large-mesh frames:

    python3 scripts/grid_obj.py 708 /tmp/big   # 1,002,528 triangles
    texsim render /tmp/big/grid.obj --width 1024 --height 1024 --no-reference
"""
import math
import os
import struct
import sys
import zlib

n = int(sys.argv[1]) if len(sys.argv) > 1 else 708
out = sys.argv[2] if len(sys.argv) > 2 else "grid"
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "grid.obj"), "w") as f:
    f.write("mtllib grid.mtl\nusemtl grid\n")
    lines = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = i / n, j / n
            z = 0.1 * math.sin(x * 12.0) * math.cos(y * 9.0)
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}\nvt {4 * x:.6f} {4 * y:.6f}\n")
    f.write("".join(lines))
    lines = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            b, c, e = a + 1, a + n + 2, a + n + 1
            lines.append(f"f {a}/{a} {b}/{b} {c}/{c} {e}/{e}\n")
    f.write("".join(lines))
with open(os.path.join(out, "grid.mtl"), "w") as f:
    f.write("newmtl grid\nKd 0.9 0.8 0.7\nmap_Kd grid.png\n")


def chunk(kind, data):
    c = kind + data
    return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c))


rows = b"".join(
    b"\0" + bytes(
        v for x in range(256)
        for v in ((230 if (x // 32 + y // 32) % 2 == 0 else 40), x, y)
    )
    for y in range(256)
)
with open(os.path.join(out, "grid.png"), "wb") as f:
    f.write(b"\x89PNG\r\n\x1a\n")
    f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", 256, 256, 8, 2, 0, 0, 0)))
    f.write(chunk(b"IDAT", zlib.compress(rows)))
    f.write(chunk(b"IEND", b""))
