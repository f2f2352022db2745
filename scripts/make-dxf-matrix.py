#!/usr/bin/env python3
"""Writes the made DXF corpus: data/made/dxf-matrix/, one file per drawing case and DXF version
(R12 to R2018), all written by ezdxf, with expected.csv measured by ezdxf, not by cutroute.

Each case draws closed contours only (plus entities a cutting program leaves out: text,
hatch, points), so the expected total perimeter is the sum of every curve's length, measured
by ezdxf after its own expansion of block inserts and polylines: lines, arcs and circles
exactly, ellipses and splines on ezdxf's flattening of the curve; the box is the box of the
flattened curves. Units: $INSUNITS says millimetres except in the
inch case, where the expected numbers are scaled by 25.4 here.

    python3 scripts/make-dxf-matrix.py          # rewrites the folder
"""
import csv
import math
import os
import sys

import ezdxf
from ezdxf.math import Vec3


HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "data", "made", "dxf-matrix")
VERSIONS = ["R12", "R2000", "R2004", "R2007", "R2010", "R2013", "R2018"]
MODERN = VERSIONS[1:]
FLATTEN = 1e-5  # mm: chord error of the oracle's flattening


def rect_lines(msp, x, y, w, h):
    pts = [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]
    for a, b in zip(pts, pts[1:] + pts[:1]):
        msp.add_line(a, b)


def case_lines_and_circle(doc, msp):
    rect_lines(msp, 0, 0, 100, 50)
    msp.add_circle((30, 25), 10)
    return 2


def case_arc_slot(doc, msp):
    # A slot: two half circles joined by lines, drawn as separate ARCs and LINEs.
    msp.add_line((10, 0), (60, 0))
    msp.add_arc((60, 10), 10, -90, 90)
    msp.add_line((60, 20), (10, 20))
    msp.add_arc((10, 10), 10, 90, 270)
    return 1


def case_polyline_bulges(doc, msp):
    # A rounded rectangle as one closed polyline with bulges (quarter arcs: bulge tan(22.5°)).
    b = math.tan(math.radians(22.5))
    pts = [(5, 0, 0, 0, 0), (45, 0, 0, 0, b), (50, 5, 0, 0, 0), (50, 25, 0, 0, b),
           (45, 30, 0, 0, 0), (5, 30, 0, 0, b), (0, 25, 0, 0, 0), (0, 5, 0, 0, b)]
    if doc.dxfversion == "AC1009":
        poly = msp.add_polyline2d([(p[0], p[1]) for p in pts], close=True)
        for v, p in zip(poly.vertices, pts):
            v.dxf.bulge = p[4]
    else:
        msp.add_lwpolyline(pts, format="xyseb", close=True)
    # A hole with a constant width (the width is drawing style, not geometry).
    hole = [(20, 10), (30, 10), (30, 20), (20, 20)]
    if doc.dxfversion == "AC1009":
        p = msp.add_polyline2d(hole, close=True)
        p.dxf.default_start_width = 0.5
        p.dxf.default_end_width = 0.5
    else:
        msp.add_lwpolyline(hole, close=True, dxfattribs={"const_width": 0.5})
    return 2


def case_ellipses(doc, msp):
    msp.add_ellipse((50, 50), major_axis=(40, 20), ratio=0.5)
    # Half an ellipse closed by its major axis.
    e = msp.add_ellipse((150, 50), major_axis=(30, 0), ratio=0.6, start_param=0, end_param=math.pi)
    msp.add_line((120, 50), (180, 50))
    return 2


def case_splines(doc, msp):
    # A closed cubic B-spline by control points (periodic), and an open clamped one closed by
    # a line.
    # (A clamped spline whose last control point is its first: closed, as CAD programs save a
    # closed spline drawn by control points; ezdxf evaluates unclamped periodic knots over
    # their whole range, which no CAD program means.)
    ctrl = [(0, 0), (40, -10), (80, 0), (90, 40), (50, 60), (10, 40), (0, 0)]
    msp.add_open_spline(ctrl, degree=3)
    # A rational one (weights): a quarter circle of radius 20 exactly, closed by two lines.
    w = math.sqrt(0.5)
    msp.add_rational_spline([(250, 0), (270, 0), (270, 20)], [1, w, 1], degree=2)
    msp.add_line((270, 20), (250, 20))
    msp.add_line((250, 20), (250, 0))
    open_ctrl = [(120, 0), (140, 40), (170, 40), (190, 0)]
    msp.add_open_spline(open_ctrl, degree=3)
    msp.add_line((190, 0), (120, 0))
    return 3


def block_part(doc, name="PART"):
    blk = doc.blocks.new(name=name)
    rect_lines(blk, 0, 0, 40, 20)
    blk.add_circle((10, 10), 4)
    blk.add_arc((30, 10), 4, 0, 180)
    blk.add_line((26, 10), (34, 10))
    return blk


def case_inserts(doc, msp):
    block_part(doc)
    msp.add_blockref("PART", (0, 0))
    msp.add_blockref("PART", (100, 0), dxfattribs={"rotation": 30})
    msp.add_blockref("PART", (0, 100), dxfattribs={"xscale": 2, "yscale": 2})
    # Mirrored: a negative x scale turns every arc round.
    msp.add_blockref("PART", (200, 100), dxfattribs={"xscale": -1, "yscale": 1, "rotation": 15})
    return 12


def case_nonuniform_insert(doc, msp):
    # Scaled unevenly a circle is an ellipse and an arc an elliptic arc.
    block_part(doc)
    msp.add_blockref("PART", (0, 0), dxfattribs={"xscale": 2, "yscale": 0.5})
    return 3


def case_nested_blocks(doc, msp):
    block_part(doc)
    pair = doc.blocks.new(name="PAIR")
    pair.add_blockref("PART", (0, 0))
    pair.add_blockref("PART", (70, 0), dxfattribs={"rotation": 90})  # 10 apart
    msp.add_blockref("PAIR", (0, 0))
    msp.add_blockref("PAIR", (0, 100), dxfattribs={"rotation": 180, "xscale": 0.5, "yscale": 0.5})
    return 12


def case_minsert(doc, msp):
    block_part(doc)
    ref = msp.add_blockref("PART", (0, 0))
    ref.dxf.column_count = 3
    ref.dxf.row_count = 2
    ref.dxf.column_spacing = 50
    ref.dxf.row_spacing = 30
    return 18


def case_extrusion(doc, msp):
    # Drawn with the view from below (extrusion 0, 0, −1): x is mirrored in the world.
    down = {"extrusion": (0, 0, -1)}
    msp.add_circle((20, 20), 10, dxfattribs=down)
    msp.add_line((-60, 0), (-100, 0))  # world coordinates: lines have no OCS
    msp.add_arc((100, 10), 10, -90, 90, dxfattribs=down)  # OCS centre (100, 10): world (−100, 10)
    msp.add_line((-100, 20), (-60, 20))
    msp.add_arc((60, 10), 10, 90, 270, dxfattribs=down)
    return 2


def case_leftovers(doc, msp):
    rect_lines(msp, 0, 0, 60, 40)
    msp.add_text("PART 7", dxfattribs={"height": 5}).set_placement((5, 5))
    msp.add_point((30, 20))
    if doc.dxfversion != "AC1009":
        h = msp.add_hatch()
        h.paths.add_polyline_path([(10, 10), (20, 10), (20, 20), (10, 20)], is_closed=True)
    return 1


def case_inches(doc, msp):
    doc.header["$INSUNITS"] = 1
    doc.header["$MEASUREMENT"] = 0
    rect_lines(msp, 0, 0, 4, 2)
    msp.add_circle((1, 1), 0.25)
    return 2


def case_closed_by_coordinates(doc, msp):
    # Closed by repeating the first vertex, not by the closed flag (as many exporters do), and
    # a "lens" of two arcs whose angles cross 0°.
    pts = [(0, 0), (40, 0), (40, 30), (0, 30), (0, 0)]
    if doc.dxfversion == "AC1009":
        msp.add_polyline2d(pts)
    else:
        msp.add_lwpolyline(pts)
    msp.add_arc((100, 15), 15, 300, 60)
    msp.add_arc((100 + 15, 15), 15, 120, 240)
    return 2


def case_polyline_seen_from_below(doc, msp):
    # A polyline with bulges in a plane seen from below: its bulges turn the other way.
    b = math.tan(math.radians(45))  # half circles
    pts = [(0, 0, 0, 0, 0), (40, 0, 0, 0, b), (40, 20, 0, 0, 0), (0, 20, 0, 0, b)]
    down = {"extrusion": (0, 0, -1)}
    if doc.dxfversion == "AC1009":
        poly = msp.add_polyline2d([(p[0], p[1]) for p in pts], close=True, dxfattribs=down)
        for v, p in zip(poly.vertices, pts):
            v.dxf.bulge = p[4]
    else:
        msp.add_lwpolyline(pts, format="xyseb", close=True, dxfattribs=down)
    return 1


def case_dimension_and_attributes(doc, msp):
    # A dimension's own block draws lines and arrows, and an insert carries attribute text:
    # neither is a part to cut.
    rect_lines(msp, 0, 0, 80, 40)
    dim = msp.add_linear_dim(base=(0, -10), p1=(0, 0), p2=(80, 0))
    dim.render()
    blk = doc.blocks.new(name="LABELLED")
    blk.add_circle((0, 0), 5)
    blk.add_attdef("NO", (0, 8), dxfattribs={"height": 2})
    ref = msp.add_blockref("LABELLED", (40, 20))
    ref.add_auto_attribs({"NO": "17"})
    return 2


CASES = [
    ("lines-circle", case_lines_and_circle, VERSIONS),
    ("arc-slot", case_arc_slot, VERSIONS),
    ("polyline-bulges", case_polyline_bulges, VERSIONS),
    ("ellipses", case_ellipses, MODERN),
    ("splines", case_splines, MODERN),
    ("inserts", case_inserts, VERSIONS),
    ("nonuniform-insert", case_nonuniform_insert, VERSIONS),
    ("nested-blocks", case_nested_blocks, VERSIONS),
    ("minsert", case_minsert, VERSIONS),
    ("extrusion", case_extrusion, VERSIONS),
    ("leftovers", case_leftovers, VERSIONS),
    ("inches", case_inches, MODERN),
    ("closed-by-coordinates", case_closed_by_coordinates, VERSIONS),
    ("polyline-seen-from-below", case_polyline_seen_from_below, VERSIONS),
    ("dimension-attributes", case_dimension_and_attributes, VERSIONS),
]

SKIP = {"TEXT", "MTEXT", "POINT", "HATCH", "DIMENSION", "ATTRIB", "ATTDEF"}


def curves(layout):
    """Every curve entity of the layout, block inserts expanded by ezdxf."""
    for e in layout:
        kind = e.dxftype()
        if kind == "INSERT":
            for row in e.multi_insert():
                yield from curves(row.virtual_entities())
        elif kind not in SKIP:
            yield e


def measure(doc):
    """Total length and box of the drawing's curves: lines, arcs and circles exactly, ellipses
    and splines on ezdxf's own flattening of the curve (not its Bézier paths, whose circles
    are 1e-4 too long)."""
    length, xs, ys = 0.0, [], []
    for e in curves(doc.modelspace()):
        kind = e.dxftype()
        if kind in ("LWPOLYLINE", "POLYLINE"):
            parts = list(e.virtual_entities())
        else:
            parts = [e]
        for p in parts:
            t = p.dxftype()
            if t == "LINE":
                points = [Vec3(p.dxf.start), Vec3(p.dxf.end)]
                length += points[0].distance(points[1])
            elif t == "CIRCLE":
                points = list(p.flattening(FLATTEN))
                length += 2 * math.pi * p.dxf.radius
            elif t == "ARC":
                points = list(p.flattening(FLATTEN))
                sweep = (p.dxf.end_angle - p.dxf.start_angle) % 360 or 360
                length += math.radians(sweep) * p.dxf.radius
            elif t in ("ELLIPSE", "SPLINE"):
                points = list(p.construction_tool().flattening(FLATTEN))
                length += sum(a.distance(b) for a, b in zip(points, points[1:]))
            else:
                raise ValueError(f"unmeasured entity {t}")
            xs += [q.x for q in points]
            ys += [q.y for q in points]
    return length, (min(xs), min(ys), max(xs), max(ys))


def main():
    os.makedirs(OUT, exist_ok=True)
    for name in os.listdir(OUT):
        os.remove(os.path.join(OUT, name))
    rows = []
    for version in VERSIONS:
        for case, draw, versions in CASES:
            if version not in versions:
                continue
            doc = ezdxf.new(version)
            if version != "R12":
                doc.header["$INSUNITS"] = 4  # millimetres
            msp = doc.modelspace()
            contours = draw(doc, msp)
            file = f"{version}__{case}.dxf"
            doc.saveas(os.path.join(OUT, file))
            length, box = measure(ezdxf.readfile(os.path.join(OUT, file)))
            scale = 25.4 if case == "inches" else 1.0
            rows.append([file, version, contours, f"{length * scale:.6f}",
                         " ".join(f"{v * scale:.6f}" for v in box)])
    with open(os.path.join(OUT, "expected.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["file", "version", "contours", "perimeter_mm", "bbox"])
        w.writerows(rows)
    print(f"{len(rows)} files in {os.path.relpath(OUT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
