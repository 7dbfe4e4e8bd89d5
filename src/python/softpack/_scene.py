"""Scenes as the library takes them: YAML text (from a dict, a YAML string
or a file), "section.key=value" overrides, and label arrays written as the
PNG / NIfTI-1 files the scene keys initial.label_image and
initial.label_volume read."""

import json
import numbers
import os
import struct
import zlib

import numpy as np

try:
    import yaml
except ImportError:  # optional: a dict is then written as JSON, which is YAML
    yaml = None


def _plain(v):
    """@p v with numpy scalars and arrays, tuples and paths made plain
    Python (for the YAML/JSON emitters)."""
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, numbers.Integral):
        return int(v)
    if isinstance(v, numbers.Real):
        return float(v)
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    return v


def dump(scene):
    """YAML text of the scene dict (PyYAML if present, else JSON: a JSON
    document is YAML, and the library reads every value by its key's type)."""
    plain = _plain(scene)
    if yaml is not None:
        return yaml.safe_dump(plain, default_flow_style=False, sort_keys=False)
    return json.dumps(plain, indent=1) + "\n"


def format_value(v):
    """An override's value as the command's --set takes it."""
    v = _plain(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (list, dict)):
        return json.dumps(v)
    return str(v)


def overrides_list(overrides):
    """["section.key=value", ...] from a dict {"section.key": value} or a
    list of such strings (or of (key, value) pairs)."""
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        items = overrides.items()
    else:
        items = []
        for o in overrides:
            if isinstance(o, str):
                if "=" not in o:
                    raise ValueError(f"override '{o}': expected section.key=value")
                k, v = o.split("=", 1)
                items.append((k, v))
            else:
                items.append(tuple(o))
    return [f"{k}={format_value(v) if not isinstance(v, str) else v}" for k, v in items]


# --------------------------------------------------------------------------
# Label arrays
# --------------------------------------------------------------------------

def _png_chunk(kind, data):
    c = struct.pack(">I", len(data)) + kind + data
    return c + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)


def write_label_png(path, rows):
    """Write the 2D integer array @p rows (row 0 at the top, as an image)
    as an 8-bit RGB PNG whose colour is the label: (R, G, B) = the label's
    bytes, 0 black = background.  Labels in [0, 2^24)."""
    rows = np.asarray(rows)
    h, w = rows.shape
    v = rows.astype(np.uint32)
    rgb = np.stack([(v >> 16) & 255, (v >> 8) & 255, v & 255], axis=-1).astype(np.uint8)
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))
    data = (b"\x89PNG\r\n\x1a\n" +
            _png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            _png_chunk(b"IDAT", zlib.compress(raw, 6)) + _png_chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


_NIFTI_TYPES = {np.dtype(np.uint8): 2, np.dtype(np.int16): 4, np.dtype(np.int32): 8,
                np.dtype(np.float32): 16, np.dtype(np.float64): 64, np.dtype(np.int8): 256,
                np.dtype(np.uint16): 512, np.dtype(np.uint32): 768, np.dtype(np.int64): 1024,
                np.dtype(np.uint64): 1280}


def write_label_nifti(path, labels, affine):
    """Write the 3D array @p labels (indexed [i, j, k], i fastest in the
    file) as an uncompressed NIfTI-1 file (.nii: the 348-byte header, 4
    bytes of no extension, the voxels) with @p affine (3 x 4, voxel ->
    world) as its sform (code 2, aligned) and qform code 0."""
    labels = np.asarray(labels)
    if labels.dtype not in _NIFTI_TYPES:
        labels = labels.astype(np.int32)
    code = _NIFTI_TYPES[labels.dtype]
    a = np.asarray(affine, dtype=float)
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    dim = [3, *labels.shape, 1, 1, 1, 1]
    struct.pack_into("<8h", hdr, 40, *dim)
    struct.pack_into("<hh", hdr, 70, code, labels.dtype.itemsize * 8)
    pixdim = [1.0, *np.sqrt((a[:, :3] ** 2).sum(axis=0)), 1.0, 1.0, 1.0, 1.0]
    struct.pack_into("<8f", hdr, 76, *pixdim)
    struct.pack_into("<f", hdr, 108, 352.0)          # vox_offset
    struct.pack_into("<ff", hdr, 112, 1.0, 0.0)      # scl_slope, scl_inter
    struct.pack_into("<B", hdr, 123, 2)              # xyzt_units: mm (informative)
    hdr[148:148 + 16] = b"softpack labels\x00"
    struct.pack_into("<hh", hdr, 252, 0, 2)          # qform_code, sform_code
    struct.pack_into("<4f", hdr, 280, *a[0])
    struct.pack_into("<4f", hdr, 296, *a[1])
    struct.pack_into("<4f", hdr, 312, *a[2])
    hdr[344:348] = b"n+1\x00"
    with open(path, "wb") as f:
        f.write(bytes(hdr))
        f.write(b"\x00\x00\x00\x00")
        f.write(np.asfortranarray(labels).astype(labels.dtype.newbyteorder("<"))
                .tobytes(order="F"))


def label_initial(labels, spacing, origin=None, **keys):
    """The ``initial`` section of a scene that starts from the label array
    @p labels (2D or 3D integers, indexed [x, y] or [x, y, z]; 0 the
    background, every other value one cell, cells in ascending order of
    their labels), sample (i, j[, k])'s centre at origin + (i, j[, k]) *
    spacing.  @p origin None: the array centred on 0.  Other keys of
    ``initial`` (scale, offset_x, ..., centre for a volume) pass through.
    run() writes the array to a file in a temporary directory (see
    docs/python.md) and points initial.label_image / label_volume at it."""
    out = {"labels": np.asarray(labels), "spacing": spacing}
    if origin is not None:
        out["origin"] = origin
    out.update(keys)
    return out


def _geometry(labels, spacing, origin):
    dim = labels.ndim
    h = np.broadcast_to(np.asarray(spacing, dtype=float), (dim,)).copy()
    if np.any(h <= 0):
        raise ValueError(f"initial.spacing {spacing}: expected positive sizes")
    n = np.array(labels.shape)
    o = (-(n - 1) / 2 * h) if origin is None else np.asarray(origin, dtype=float)
    if o.shape != (dim,):
        raise ValueError(f"initial.origin {origin}: expected {dim} numbers")
    return h, o


def materialise_labels(initial, directory):
    """@p initial with its "labels" array written into @p directory and
    replaced by the scene keys that read that file; other keys kept."""
    initial = dict(initial)
    labels = np.asarray(initial.pop("labels"))
    spacing = initial.pop("spacing", 1.0)
    origin = initial.pop("origin", None)
    if labels.ndim not in (2, 3):
        raise ValueError(f"initial.labels: a {labels.ndim}D array; expected 2D or 3D")
    if not (np.issubdtype(labels.dtype, np.integer) or np.issubdtype(labels.dtype, np.bool_)):
        if not np.all(np.isfinite(labels)) or np.any(labels != np.floor(labels)):
            raise ValueError("initial.labels: expected integer labels")
        labels = labels.astype(np.int64)
    if labels.min() < 0:
        raise ValueError("initial.labels: expected labels >= 0 (0: background)")
    h, o = _geometry(labels, spacing, origin)
    if labels.ndim == 2:
        if labels.max() >= 1 << 24:
            raise ValueError("initial.labels: 2D labels must be below 2^24")
        path = os.path.join(directory, "labels.png")
        # image rows from the top: y descending; columns x ascending
        write_label_png(path, labels[:, ::-1].T)
        initial.update({"label_image": path,
                        "x0": float(o[0] - h[0] / 2), "x1": float(o[0] + (labels.shape[0] - 0.5) * h[0]),
                        "y0": float(o[1] - h[1] / 2), "y1": float(o[1] + (labels.shape[1] - 0.5) * h[1])})
    else:
        path = os.path.join(directory, "labels.nii")
        affine = np.zeros((3, 4))
        affine[:, :3] = np.diag(h)
        affine[:, 3] = o
        write_label_nifti(path, labels, affine)
        initial["label_volume"] = path
    return initial


def _unfilter(raw, h, w, bpp):
    """PNG scanlines un-filtered (filters 0-4) into an h x (w * bpp) array."""
    stride = w * bpp
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    pos = 0
    for y in range(h):
        ftype = raw[pos]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=pos + 1).astype(np.int32)
        pos += 1 + stride
        if ftype == 0:
            cur = line
        elif ftype == 2:
            cur = (line + prev) & 255
        elif ftype in (1, 3, 4):
            cur = np.zeros(stride, dtype=np.int32)
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                b = prev[i]
                if ftype == 1:
                    p = a
                elif ftype == 3:
                    p = (a + b) >> 1
                else:
                    c = prev[i - bpp] if i >= bpp else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[i] = (line[i] + p) & 255
        else:
            raise ValueError(f"PNG: unknown filter {ftype}")
        out[y] = cur
        prev = cur
    return out


def read_label_image(path):
    """The labels of a PNG label image as initial.label_image reads it: an
    integer array indexed [x, y] (x to the right, y up: the image's bottom
    row is y = 0), 0 for black (or transparent) pixels, 1..n for the
    colours in ascending order of 0xRRGGBB (the library's cell order).
    8-bit RGB or RGBA, not interlaced."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, hdr = 8, [], None
    while pos < len(data):
        n, = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    w, h, depth, ctype, _, _, interlace = hdr
    if depth != 8 or ctype not in (2, 6) or interlace:
        raise ValueError(f"{path}: expected an 8-bit RGB or RGBA PNG, not interlaced")
    bpp = 3 if ctype == 2 else 4
    px = _unfilter(zlib.decompress(b"".join(idat)), h, w, bpp).reshape(h, w, bpp).astype(np.uint32)
    rgb = (px[..., 0] << 16) | (px[..., 1] << 8) | px[..., 2]
    if bpp == 4:
        rgb = np.where(px[..., 3] == 0, 0, rgb)
    colours = np.unique(rgb[rgb != 0])
    labels = np.zeros(rgb.shape, dtype=np.int32)
    nz = rgb != 0
    labels[nz] = np.searchsorted(colours, rgb[nz]) + 1
    return labels.T[:, ::-1].copy()
