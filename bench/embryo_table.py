#!/usr/bin/env python3
"""The tables of docs/embryo.md ("The C. elegans 8-cell scene") from a run
of inputs/embryo/celegans_8.yaml or celegans_8_2d.yaml.

usage: bench/embryo_table.py OUT_DIR

Reads OUT_DIR's divisions.csv, cells.csv, contacts.csv and units.csv (the
units the scene names: um, min) and prints, in Markdown:
  - every division: its time, the parent and daughters, the table's share
    and the first daughter's share of the parent's mass right after the cut;
  - the 4-cell stage (the last step with 4 cells) and the 8-cell stage (the
    last step): each cell's volume (c >= 1/2; an area in 2D) in the scene's
    unit and as a fraction of the stage's cells, its mass (in the scene's
    unit) and the ratio of the two, its mass fraction, and the
    CShaper atlas's volume and fraction (Cao et al. 2020, as quoted in
    docs/embryo.md);
  - the contacts of those stages: each pair's contact (contacts.csv) in the
    scene's unit and as a fraction of each of the two cells' surfaces (their
    membranes under the default output.contact_measure; docs/model.md,
    "Contacts"), beside the published ones: PUBLISHED holds the contact
    fractions that can be cited (none found: docs/embryo.md, "The C. elegans 8-cell scene", says what was searched; the column prints "-"),
    and TOUCHES whether the pair touches in the embryo where a source says
    so (the 4-cell "diamond": ABa does not touch P2, the other five pairs
    do; Giammona and Campas 2021, PLoS Comput Biol 17:e1007994, Fig 1A);
  - the arrangement of those stages: each cell's centre (cells.csv) and, for
    every pair, the distance between the centres and, when the run wrote
    that step's fields (OUT_DIR/fields_<step>.vtu, one process), the gap:
    the smallest distance between a mesh node where c_k >= 1/2 and one where
    c_l >= 1/2. Two cells pressed together have a gap of about one element
    (their c = 1/2 surfaces meet between nodes); cells with a third one
    between them, its width. A test of touching from the nodes alone, beside
    contacts.csv's (docs/model.md, "Contacts"; docs/embryo.md, "The C.
    elegans 8-cell scene").
"""
import base64
import csv
import math
import re
import struct
import sys
from collections import defaultdict

ATLAS = {"P0": 20769, "AB": 12304, "P1": 8465, "ABa": 6195, "ABp": 6109, "EMS": 4856,
         "P2": 3609, "ABal": 2930, "ABar": 3162, "ABpl": 3156, "ABpr": 2857, "MS": 2550,
         "E": 2249, "C": 2368, "P3": 1157}

# Published contact fractions by pair (frozenset of names): none could be
# cited after two searches (docs/embryo.md, "The C. elegans 8-cell scene",
# which also quotes an unpublished one-embryo reading that is not put here).
PUBLISHED = {}

# Whether a pair touches in the embryo, where a source says so: the 4-cell
# stage's diamond (Giammona and Campas 2021, Fig 1A).
TOUCHES = {frozenset(p): "yes" for p in (("ABa", "ABp"), ("ABa", "EMS"), ("ABp", "EMS"),
                                          ("ABp", "P2"), ("EMS", "P2"))}
TOUCHES[frozenset(("ABa", "P2"))] = "no"


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def main(out):
    units = {(r["file"], r["column"]): (r["unit"], float(r["scale"]))
             for r in read(f"{out}/units.csv")} if _exists(f"{out}/units.csv") else {}

    def conv(file, column, value):
        unit, scale = units.get((file, column), ("model", 1.0))
        return value * scale, unit

    divisions = read(f"{out}/divisions.csv")
    print("| t | parent | first, second | table's share | first daughter's share |")
    print("|---|---|---|---|---|")
    for d in divisions:
        t, unit = conv("divisions.csv", "t", float(d["t"]))
        share = float(d["parent_mass_after"]) / float(d["parent_mass_before"])
        print(f"| {t:.2f} {unit} | {d['parent_name']} | {d['first_name']}, {d['second_name']} "
              f"| {float(d['fraction']):.6f} | {share:.9f} |")

    cells = read(f"{out}/cells.csv")
    by_step = defaultdict(list)
    for r in cells:
        by_step[int(r["step"])].append(r)
    volume_column = "volume" if "volume" in cells[0] else "area"
    last = max(by_step)
    four = max(s for s, rows in by_step.items() if len(rows) == 4)
    contacts = defaultdict(list)
    for r in read(f"{out}/contacts.csv"):
        if int(r["step"]) in (four, last):
            contacts[int(r["step"])].append(r)
    for name, step in (("4-cell", four), ("8-cell", last)):
        rows = by_step[step]
        t, tunit = conv("cells.csv", "t", float(rows[0]["t"]))
        total_v = sum(float(r[volume_column]) for r in rows)
        total_m = sum(float(r["mass"]) for r in rows)
        total_a = sum(ATLAS[r["name"]] for r in rows)
        print(f"\n{name} stage (step {step}, t = {t:.2f} {tunit}):\n")
        print(f"| cell | {volume_column} | fraction | mass | {volume_column} / mass "
              "| mass fraction | atlas um^3 | atlas fraction |")
        print("|---|---|---|---|---|---|---|---|")
        for r in sorted(rows, key=lambda r: r["name"]):
            v, vunit = conv("cells.csv", volume_column, float(r[volume_column]))
            m, munit = conv("cells.csv", "mass", float(r["mass"]))
            print(f"| {r['name']} | {v:.1f} {vunit} | {float(r[volume_column]) / total_v:.4f} "
                  f"| {m:.0f} {munit} | {float(r[volume_column]) / float(r['mass']):.2f} "
                  f"| {float(r['mass']) / total_m:.4f} | {ATLAS[r['name']]} "
                  f"| {ATLAS[r['name']] / total_a:.4f} |")
        print(f"\n(the {volume_column}s add up to {total_v / total_m:.2f} of the masses)")
        names = {int(r["cell"]): r["name"] for r in rows}
        surface = {int(r["cell"]): float(r["surface"]) for r in contacts[step]
                   if int(r["other"]) == 0}
        print("\n| pair | contact | of the first's surface | of the second's "
              "| published | touches in the embryo |")
        print("|---|---|---|---|---|---|")
        for r in contacts[step]:
            k, l = int(r["cell"]), int(r["other"])
            if l == 0:
                continue
            a = float(r["contact"])
            c, cunit = conv("contacts.csv", "contact", a)
            pair = frozenset((names[k], names[l]))
            published = PUBLISHED.get(pair)
            print(f"| {names[k]}-{names[l]} | {c:.1f} {cunit} | {a / surface[k]:.3f} "
                  f"| {a / surface[l]:.3f} | {'-' if published is None else published} "
                  f"| {TOUCHES.get(pair, '-')} |")
        arrangement(out, step, rows, conv)


def arrangement(out, step, rows, conv):
    """The stage's centres, and each pair's centre distance and gap."""
    axes = [a for a in ("xc", "yc", "zc") if a in rows[0]]
    centre = {}
    print(f"\n| cell | {' | '.join(a[0] for a in axes)} |")
    print("|---|" + "---|" * len(axes))
    for r in sorted(rows, key=lambda r: r["name"]):
        centre[r["name"]] = [conv("cells.csv", a, float(r[a]))[0] for a in axes]
        unit = conv("cells.csv", axes[0], 0.0)[1]
        print(f"| {r['name']} | " + " | ".join(f"{v:.2f} {unit}" for v in centre[r["name"]])
              + " |")
    fields = read_vtu_fields(f"{out}/fields_{step:06d}.vtu")
    print("\n| pair | centre distance | gap (c >= 1/2) |")
    print("|---|---|---|")
    ordered = sorted(rows, key=lambda r: r["name"])
    inside = {}
    if fields is not None:
        points, c = fields
        scale = conv("cells.csv", axes[0], 1.0)[0]
        for r in ordered:
            inside[r["name"]] = [points[i] for i, v in enumerate(c[f"c_{r['cell']}"]) if v >= 0.5]
    for i, p in enumerate(ordered):
        for q in ordered[i + 1:]:
            d = math.dist(centre[p["name"]], centre[q["name"]])
            gap = "-"
            if inside.get(p["name"]) and inside.get(q["name"]):
                g = min(math.dist(a, b) for a in inside[p["name"]] for b in inside[q["name"]])
                gap = f"{g * scale:.1f} {unit}"
            print(f"| {p['name']}-{q['name']} | {d:.1f} {unit} | {gap} |")


def read_vtu_fields(path):
    """The points and the Float64 point arrays c_<k> (by name) of a .vtu
    softpack wrote (inline base64 with a UInt64 byte count); None when the
    file is not there."""
    if not _exists(path):
        return None
    with open(path) as f:
        text = f.read()
    c = {name: _binary_array(text, name, "d") for name in
         re.findall(r'<DataArray type="Float64" Name="(c_\d+)" format="binary">', text)}
    xyz = _binary_array(text, "Points", "d")
    return [xyz[i:i + 3] for i in range(0, len(xyz), 3)], c


def read_vtu_elements(path):
    """The elements of a .vtu softpack wrote, each a tuple of its points'
    indices (the connectivity cut at the offsets)."""
    with open(path) as f:
        text = f.read()
    connectivity = _binary_array(text, "connectivity", "i")
    ends = _binary_array(text, "offsets", "q")
    return [connectivity[a:b] for a, b in zip((0,) + ends[:-1], ends)]


def pieces(elements, inside):
    """The connected pieces of the points in the set @p inside, two points
    being connected when an element holds both: a list of sets of point
    indices, the largest first."""
    parent = {i: i for i in inside}

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for element in elements:
        held = [i for i in element if i in parent]
        for i in held[1:]:
            parent[root(i)] = root(held[0])
    found = defaultdict(set)
    for i in inside:
        found[root(i)].add(i)
    return sorted(found.values(), key=len, reverse=True)


def _binary_array(text, name, kind):
    """The values of the inline binary DataArray @p name (struct format
    character @p kind: "d", "i", "q")."""
    data = re.search(rf'<DataArray type="\w+" Name="{name}"[^>]*format="binary">\s*([^<]*)<',
                     text).group(1)
    raw = base64.b64decode("".join(data.split()))
    n = struct.unpack_from("<Q", raw)[0] // struct.calcsize(kind)
    return struct.unpack_from(f"<{n}{kind}", raw, 8)


def _exists(path):
    try:
        open(path).close()
        return True
    except OSError:
        return False


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
