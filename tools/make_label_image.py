#!/usr/bin/env python3
"""Make inputs/labels/embryo_4.png, the example label image of
inputs/label_image.yaml (docs/restart.md): a four-cell embryo in the
paper's egg, as a segmentation of a microscope image would label it, one
colour a cell on black. 200 x 100 pixels cover the box [-0.5, 0.5] x
[-0.25, 0.25] (the scene's initial.x0 ... y1 defaults). Standard library
only (zlib, struct): run it to remake the file, byte for byte.

    tools/make_label_image.py [OUT.png]
"""
import struct
import sys
import zlib

W, H = 200, 100
X0, Y0, X1, Y1 = -0.5, -0.25, 0.5, 0.25
# (centre x, centre y, semi-axis x, semi-axis y, colour): the AB and P1
# daughters of an early embryo, with gaps of a few pixels between them
CELLS = [(-0.235, 0.000, 0.150, 0.160, (230, 60, 60)),
         (0.015, 0.095, 0.100, 0.090, (60, 200, 80)),
         (0.015, -0.095, 0.100, 0.090, (70, 90, 230)),
         (0.245, 0.000, 0.125, 0.140, (240, 200, 50))]


def pixel(px, py):
    x = X0 + (px + 0.5) * (X1 - X0) / W
    y = Y1 - (py + 0.5) * (Y1 - Y0) / H
    for cx, cy, ax, ay, rgb in CELLS:
        if ((x - cx) / ax) ** 2 + ((y - cy) / ay) ** 2 <= 1.0:
            return rgb
    return (0, 0, 0)


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xffffffff)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "inputs/labels/embryo_4.png"
    rows = b"".join(b"\x00" + bytes(c for px in range(W) for c in pixel(px, py))
                    for py in range(H))
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))
    with open(out, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
