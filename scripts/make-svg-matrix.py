#!/usr/bin/env python3
"""Writes the made SVG corpus: data/made/svg-matrix/, one file per drawing case, in the ways
Inkscape, Illustrator, CAD exporters and nesting programs write SVG, with expected.csv measured
by svgelements, not by cutroute.

Every shape meant to be cut has class "cut" (on the shape, or inherited from its <use>); the
oracle measures those after svgelements applies every transform, viewport and unit (at 96 px
per inch), converted to millimetres: the number of closed contours (known from the drawing),
their total length, the x range and the height of their box (SVG's y runs down, CAD's up).
Everything else in a file (hidden, in <defs>, clip paths, masks, markers, text) must be left
out.

    python3 scripts/make-svg-matrix.py          # rewrites the folder
"""
import csv
import os
import sys

import svgelements as se

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "data", "made", "svg-matrix")
MM_PER_PX = 25.4 / 96

HEAD = '<?xml version="1.0" encoding="UTF-8"?>\n'


def svg(attrs, body):
    return (f'{HEAD}<svg xmlns="http://www.w3.org/2000/svg" '
            f'xmlns:xlink="http://www.w3.org/1999/xlink" {attrs}>\n{body}\n</svg>\n')


CASES = {
    # Millimetres through width/height and a matching viewBox (Inkscape 1.x, Boxes.py).
    "units-mm": (3, svg('width="200mm" height="100mm" viewBox="0 0 200 100"', '''
  <rect class="cut" x="10" y="10" width="80" height="40" fill="none" stroke="black"/>
  <circle class="cut" cx="40" cy="30" r="10" fill="none" stroke="black"/>
  <ellipse class="cut" cx="150" cy="50" rx="30" ry="15" fill="none" stroke="black"/>''')),
    # No units: CSS pixels, 96 per inch.
    "units-px": (2, svg('width="400" height="300"', '''
  <rect class="cut" x="20" y="20" width="200" height="100"/>
  <polygon class="cut" points="300,20 380,20 380,120 300,120 340,70"/>''')),
    # Inches and a viewBox in tenths of an inch.
    "units-in": (2, svg('width="4in" height="2in" viewBox="0 0 40 20"', '''
  <rect class="cut" x="1" y="1" width="20" height="10"/>
  <circle class="cut" cx="30" cy="10" r="5"/>''')),
    # Points, as Illustrator writes an A4 page.
    "units-pt": (1, svg('width="595.28pt" height="841.89pt" viewBox="0 0 595.28 841.89"', '''
  <path class="cut" d="M100,100 L300,100 L300,250 L100,250 Z"/>''')),
    # Transforms: translate, rotate about a point, mirror, matrix, nested groups.
    "transforms": (5, svg('width="300mm" height="200mm" viewBox="0 0 300 200"', '''
  <g transform="translate(20,20)">
    <rect class="cut" x="0" y="0" width="40" height="20"/>
    <g transform="rotate(30 100 20)">
      <rect class="cut" x="80" y="10" width="40" height="20"/>
    </g>
  </g>
  <g transform="matrix(-1 0 0 1 300 0)">
    <path class="cut" d="M20,100 h40 a10,10 0 0 1 0,20 h-40 z"/>
  </g>
  <g transform="scale(2) translate(10 70)">
    <circle class="cut" cx="10" cy="10" r="5"/>
  </g>
  <g transform="translate(200 150) rotate(-45) scale(1.5 1.5)">
    <ellipse class="cut" cx="0" cy="0" rx="20" ry="8"/>
  </g>''')),
    # Path syntax as minifiers and exporters write it: relative commands, implicit repeats,
    # numbers run together, arcs with their flags packed (`0 1140 0`), smooth curves, quadratic curves.
    "path-syntax": (5, svg('width="300mm" height="150mm" viewBox="0 0 300 150"', '''
  <path class="cut" d="m10 10h50v30h-50z"/>
  <path class="cut" d="M80,10l40,0 0,30-40,0z"/>
  <path class="cut" d="M140 10h40v30h-20.5-19.5z"/>
  <path class="cut" d="M200,40a20 20 0 1140 0a20 20 0 11-40 0z"/>
  <path class="cut" d="M20 80c20-20 40-20 60 0s40 20 60 0q30 30 0 60t-60 0c-20 0-40-20-60-60z"/>''')),
    # Holes as further subpaths of one path, and a relative move after a close.
    "subpaths": (3, svg('width="200mm" height="100mm" viewBox="0 0 200 100"', '''
  <path class="cut" fill-rule="evenodd" d="M10,10 H110 V90 H10 Z m20,20 h20 v20 h-20 z m40,0 h20 v20 h-20 z"/>''')),
    # Rounded rectangles (rx, ry) and a polyline closed by its coordinates.
    "rounded-and-polyline": (3, svg('width="200mm" height="100mm" viewBox="0 0 200 100"', '''
  <rect class="cut" x="10" y="10" width="60" height="40" rx="8"/>
  <rect class="cut" x="80" y="10" width="60" height="40" rx="10" ry="5"/>
  <polyline class="cut" points="150,10 190,10 190,50 150,50 150,10" fill="none"/>''')),
    # What is not drawn: display:none by attribute, by style and by a class in a <style>
    # sheet, visibility hidden, <defs>, <clipPath>, <mask>, <marker>, <pattern>, a <symbol>
    # never used, text; one <use> of a group in <defs> is drawn.
    "hidden-and-used": (2, svg('width="200mm" height="100mm" viewBox="0 0 200 100"', '''
  <style>.off { display: none }</style>
  <defs>
    <rect id="spare" x="0" y="0" width="5" height="5"/>
    <clipPath id="clip"><rect x="0" y="0" width="200" height="100"/></clipPath>
    <mask id="mask"><rect x="0" y="0" width="50" height="50" fill="white"/></mask>
    <marker id="arrow" markerWidth="4" markerHeight="4"><path d="M0,0 L4,2 L0,4 z"/></marker>
    <pattern id="dots" width="4" height="4"><circle cx="2" cy="2" r="1"/></pattern>
    <g id="washer"><circle class="cut" cx="10" cy="10" r="8"/></g>
  </defs>
  <symbol id="unused"><rect x="0" y="0" width="9" height="9"/></symbol>
  <rect class="cut" x="10" y="10" width="60" height="40" clip-path="url(#clip)"/>
  <use xlink:href="#washer" x="100" y="10"/>
  <rect display="none" x="10" y="60" width="10" height="10"/>
  <rect style="display:none" x="30" y="60" width="10" height="10"/>
  <rect class="off" x="50" y="60" width="10" height="10"/>
  <rect visibility="hidden" x="70" y="60" width="10" height="10"/>
  <text x="10" y="95">PART 7</text>''')),
    # A nested viewport of its own, scaled into its box (preserveAspectRatio default).
    "nested-viewport": (2, svg('width="200mm" height="100mm" viewBox="0 0 200 100"', '''
  <rect class="cut" x="10" y="10" width="40" height="40"/>
  <svg x="100" y="0" width="100" height="100" viewBox="0 0 10 10">
    <rect class="cut" x="1" y="1" width="8" height="8"/>
  </svg>''')),
    # Inkscape: layers with transforms, a hidden layer, sodipodi and inkscape attributes.
    "inkscape-layers": (2, svg(
        'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        'xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd" '
        'width="210mm" height="297mm" viewBox="0 0 210 297"', '''
  <sodipodi:namedview id="base" inkscape:document-units="mm"/>
  <g inkscape:groupmode="layer" inkscape:label="Cut" transform="translate(0,-10)">
    <path class="cut" sodipodi:type="arc" d="M 60,60 A 20,20 0 0 1 40,80 20,20 0 0 1 20,60 20,20 0 0 1 40,40 20,20 0 0 1 60,60 Z"/>
    <rect class="cut" x="80" y="40" width="50" height="30" style="fill:none;stroke:#000000;stroke-width:0.26458"/>
  </g>
  <g inkscape:groupmode="layer" inkscape:label="Notes" style="display:none">
    <rect x="0" y="0" width="30" height="30"/>
  </g>''')),
}


def measure(file, contours):
    doc = se.SVG.parse(file, ppi=96)
    length, xs, ys = 0.0, [], []
    for e in doc.elements():
        if not isinstance(e, se.Shape) or e.values.get("class") != "cut":
            continue
        path = abs(se.Path(e))  # transforms applied
        length += path.length(error=1e-12)
        x0, y0, x1, y1 = path.bbox()
        xs += [x0, x1]
        ys += [y0, y1]
    m = MM_PER_PX
    return (length * m, min(xs) * m, max(xs) * m, (max(ys) - min(ys)) * m)


def main():
    os.makedirs(OUT, exist_ok=True)
    for name in os.listdir(OUT):
        os.remove(os.path.join(OUT, name))
    rows = []
    for case, (contours, text) in CASES.items():
        file = os.path.join(OUT, f"{case}.svg")
        with open(file, "w") as f:
            f.write(text)
        length, x0, x1, height = measure(file, contours)
        rows.append([f"{case}.svg", contours, f"{length:.6f}", f"{x0:.6f} {x1:.6f} {height:.6f}"])
    with open(os.path.join(OUT, "expected.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["file", "contours", "perimeter_mm", "x_range_and_height_mm"])
        w.writerows(rows)
    print(f"{len(rows)} files in {os.path.relpath(OUT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
