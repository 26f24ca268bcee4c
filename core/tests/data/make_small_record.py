#!/usr/bin/env python3
"""Write small_record.mat (MATLAB level 5, zlib-compressed variables, as MATLAB's -v7 does)
and its twin small_record.csv, independently of the Rust test generator.

t, x, phi are column vectors of doubles; `note` is a char variable (which readers skip).
Run: python3 make_small_record.py   (standard library only)
"""
import math
import struct
import zlib

N = 50
t = [i * 1e-3 for i in range(N)]
x = [0.02 * math.sin(2 * math.pi * 1.3 * ti) + 1e-5 * ((i * 7919) % 13 - 6) for i, ti in enumerate(t)]
phi = [(0.0235 * (50 + ti) ** 2) % (2 * math.pi) for ti in t]


def element(dtype, payload):
    if len(payload) <= 4:
        return struct.pack("<I", dtype | (len(payload) << 16)) + payload + b"\0" * (4 - len(payload))
    pad = (8 - len(payload) % 8) % 8
    return struct.pack("<II", dtype, len(payload)) + payload + b"\0" * pad


def matrix(name, cls, dims, data_type, data):
    body = element(6, struct.pack("<II", cls, 0))
    body += element(5, struct.pack("<%di" % len(dims), *dims))
    body += element(1, name.encode())
    body += element(data_type, data)
    return element(14, body)


def compressed(elem):
    z = zlib.compress(elem)
    return struct.pack("<II", 15, len(z)) + z


header = b"MATLAB 5.0 MAT-file, Platform: stf-core fixture".ljust(116, b" ")
header += b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"
out = header
out += compressed(matrix("note", 4, [1, 5], 4, struct.pack("<5H", *b"hello")))
for name, vals in (("t", t), ("x", x), ("phi", phi)):
    out += compressed(matrix(name, 6, [len(vals), 1], 9, struct.pack("<%dd" % len(vals), *vals)))
with open("small_record.mat", "wb") as f:
    f.write(out)
with open("small_record.csv", "w") as f:
    f.write("t,x,phi\n")
    for row in zip(t, x, phi):
        f.write(",".join(repr(v) for v in row) + "\n")
