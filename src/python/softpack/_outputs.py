"""A run's files read back: the CSV logs (pandas DataFrames when pandas is
installed, else numpy structured arrays) and the fields of fields_*.vtu /
.pvtu (VTK XML as src/io/output.c writes it: inline base64 "binary"
arrays, a UInt64 byte count first; FieldData in ASCII)."""

import base64
import glob
import os
import re
import xml.etree.ElementTree as ET

import numpy as np

try:
    import pandas
except ImportError:  # optional
    pandas = None


def read_csv(path):
    """A CSV log as a pandas DataFrame (numpy structured array without
    pandas; empty cells are NaN there)."""
    if pandas is not None:
        return pandas.read_csv(path, float_precision="round_trip")
    with open(path) as f:
        header = f.readline().strip().split(",")
        rows = [line.rstrip("\n").split(",") for line in f if line.strip()]
    cols = []
    for j, name in enumerate(header):
        vals = [r[j] if j < len(r) else "" for r in rows]
        try:
            ints = [int(v) for v in vals]
            cols.append(np.array(ints, dtype=np.int64))
            continue
        except ValueError:
            pass
        try:
            cols.append(np.array([float(v) if v != "" else np.nan for v in vals]))
        except ValueError:
            cols.append(np.array(vals, dtype=object))
    dtype = [(n, c.dtype) for n, c in zip(header, cols)]
    out = np.empty(len(rows), dtype=dtype)
    for n, c in zip(header, cols):
        out[n] = c
    return out


_VTK_TYPES = {"Float64": "<f8", "Float32": "<f4", "Int32": "<i4", "Int64": "<i8",
              "UInt8": "u1", "UInt32": "<u4", "UInt64": "<u8", "Int8": "i1"}


def _array(el, byte_order="LittleEndian"):
    """The values of a <DataArray> element (binary or ascii)."""
    kind = el.get("type")
    fmt = el.get("format", "ascii")
    ncomp = int(el.get("NumberOfComponents", "1"))
    if kind == "String":
        codes = [int(x) for x in (el.text or "").split()]
        out, cur = [], []
        for c in codes:
            if c == 0:
                out.append(bytes(cur).decode())
                cur = []
            else:
                cur.append(c)
        return out
    dt = np.dtype(_VTK_TYPES[kind])
    if byte_order == "BigEndian":
        dt = dt.newbyteorder(">")
    if fmt == "binary":
        raw = base64.b64decode("".join((el.text or "").split()))
        n = int(np.frombuffer(raw[:8], dtype=np.dtype("<u8") if byte_order != "BigEndian"
                              else np.dtype(">u8"))[0])
        vals = np.frombuffer(raw[8:8 + n], dtype=dt).astype(dt.newbyteorder("="))
    elif fmt == "ascii":
        vals = np.array((el.text or "").split(), dtype=dt.newbyteorder("="))
    else:
        raise ValueError(f"DataArray {el.get('Name')}: format {fmt} not read")
    return vals.reshape(-1, ncomp) if ncomp > 1 else vals


class Fields:
    """The fields of one output: ``points`` (n_nodes x 3; z = 0 in 2D),
    ``elements`` (n_elements x nodes per element, 0-based), ``dim``,
    ``time``, ``step``, ``point_data`` (a dict of arrays: c_1, mu_1, ...,
    cell_id), ``cell_data`` (region), ``names`` (the cells' names, or
    None), and ``c(k)`` / ``mu(k)``: cell k's fields (k 1-based, as in the
    files and the CSVs).  A .pvtu's pieces are joined by their node_id
    (the global node number): points in the global numbering."""

    def __init__(self, points, elements, point_data, cell_data, time, step, names):
        self.points, self.elements = points, elements
        self.point_data, self.cell_data = point_data, cell_data
        self.time, self.step, self.names = time, step, names
        self.dim = 3 if elements.shape[1] == 8 else 2

    @property
    def coords(self):
        """The nodes' coordinates, n_nodes x dim."""
        return self.points[:, :self.dim]

    @property
    def n_cells(self):
        return sum(1 for k in self.point_data if re.fullmatch(r"c_\d+", k))

    def c(self, k):
        return self.point_data[f"c_{k}"]

    def mu(self, k):
        return self.point_data[f"mu_{k}"]

    def __repr__(self):
        return (f"<softpack.Fields step {self.step} t={self.time:g}: {len(self.points)} nodes, "
                f"{len(self.elements)} elements, {self.n_cells} cells>")


def _read_piece(path):
    root = ET.parse(path).getroot()
    order = root.get("byte_order", "LittleEndian")
    grid = root.find("UnstructuredGrid")
    fd = {}
    f = grid.find("FieldData")
    if f is not None:
        for el in f.findall("DataArray"):
            fd[el.get("Name")] = _array(el, order)
    piece = grid.find("Piece")
    pd = {el.get("Name"): _array(el, order) for el in piece.find("PointData").findall("DataArray")}
    cd_el = piece.find("CellData")
    cd = {el.get("Name"): _array(el, order) for el in cd_el.findall("DataArray")} \
        if cd_el is not None else {}
    points = _array(piece.find("Points").find("DataArray"), order)
    cells = {el.get("Name"): _array(el, order) for el in piece.find("Cells").findall("DataArray")}
    offsets = cells["offsets"]
    nen = int(offsets[0]) if len(offsets) else 4
    elements = cells["connectivity"].astype(np.int64).reshape(-1, nen)
    return points, elements, pd, cd, fd


def read_vtu(path):
    """The Fields of a fields_<step>.vtu or fields_<step>.pvtu."""
    if path.endswith(".pvtu"):
        root = ET.parse(path).getroot()
        base = os.path.dirname(path)
        pieces = [_read_piece(os.path.join(base, p.get("Source")))
                  for p in root.find("PUnstructuredGrid").findall("Piece")]
        n = 1 + max(int(p[2]["node_id"].max()) for p in pieces)
        points = np.zeros((n, 3))
        pd, cd, elements = {}, {}, []
        for pts, els, ppd, pcd, _ in pieces:
            gid = ppd["node_id"].astype(np.int64)
            points[gid] = pts
            elements.append(gid[els])
            for k, v in ppd.items():
                if k == "node_id":
                    continue
                pd.setdefault(k, np.zeros(n, dtype=v.dtype))[gid] = v
            for k, v in pcd.items():
                cd.setdefault(k, []).append(v)
        elements = np.concatenate(elements)
        cd = {k: np.concatenate(v) for k, v in cd.items()}
        fd = pieces[0][4]
    else:
        points, elements, pd, cd, fd = _read_piece(path)
    time = float(np.ravel(fd["TIME"])[0]) if "TIME" in fd else float("nan")
    step = int(np.ravel(fd["CYCLE"])[0]) if "CYCLE" in fd else -1
    return Fields(points, elements, pd, cd, time, step, fd.get("cell_name"))


def field_files(out):
    """{step: path} of the fields written into the directory @p out."""
    found = {}
    for p in glob.glob(os.path.join(out, "fields_*.vtu")) + \
            glob.glob(os.path.join(out, "fields_*.pvtu")):
        m = re.fullmatch(r"fields_(\d+)\.p?vtu", os.path.basename(p))
        if m:
            s = int(m.group(1))
            if s not in found or p.endswith(".pvtu"):
                found[s] = p
    return dict(sorted(found.items()))
