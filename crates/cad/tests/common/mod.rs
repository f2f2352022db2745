//! Test helpers: reference-data paths and an independent, flattened-polygon geometry check.
#![allow(dead_code)]

use std::path::PathBuf;

use cutroute_geometry::{BoundingBox, Contour, Point};

/// A file of the shared reference data; panics loudly when it is missing.
pub fn shared_file(relative: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    std::fs::read(&path).unwrap_or_else(|e| {
        panic!("reference file {} is missing or unreadable ({e}); the tests need data/ of the repository", path.display())
    })
}

/// Every file of a shared-data folder with the extension, sorted; panics if the folder is missing.
pub fn shared_dir_files(relative: &str, extension: &str) -> Vec<String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let mut names: Vec<String> = std::fs::read_dir(&path)
        .unwrap_or_else(|e| panic!("reference folder {} is missing ({e})", path.display()))
        .map(|e| {
            e.expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.ends_with(extension))
        .collect();
    names.sort();
    names
}

/// The contour as a polygon: arcs cut into chords of at most `step` radians.
pub fn polygon(contour: &Contour) -> Vec<Point> {
    let n = contour.vertices.len();
    let mut out = Vec::new();
    for i in 0..n {
        let a = contour.vertices[i].point;
        let b = contour.vertices[(i + 1) % n].point;
        let bulge = contour.vertices[i].bulge;
        out.push(a);
        if bulge != 0.0 {
            let sweep = 4.0 * bulge.atan();
            let chord = ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt();
            let radius = chord * (1.0 + bulge * bulge) / (4.0 * bulge.abs());
            // The centre sits on the chord's left normal at chord·(1 − b²)/(4b) from its middle.
            let d = chord * (1.0 - bulge * bulge) / (4.0 * bulge);
            let (ux, uy) = ((b.x - a.x) / chord, (b.y - a.y) / chord);
            let c = Point::new((a.x + b.x) / 2.0 - uy * d, (a.y + b.y) / 2.0 + ux * d);
            let a0 = (a.y - c.y).atan2(a.x - c.x);
            let pieces = ((sweep.abs() / 0.05).ceil() as usize).max(2);
            for k in 1..pieces {
                let t = a0 + sweep * k as f64 / pieces as f64;
                out.push(Point::new(c.x + radius * t.cos(), c.y + radius * t.sin()));
            }
        }
    }
    out
}

pub fn area(polygon: &[Point]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        / 2.0
}

pub fn inside(p: Point, polygon: &[Point]) -> bool {
    let n = polygon.len();
    let mut result = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + n - 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            result = !result;
        }
    }
    result
}

pub fn distance_to_boundary(p: Point, polygon: &[Point]) -> f64 {
    let n = polygon.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        let l2 = (b.x - a.x).powi(2) + (b.y - a.y).powi(2);
        let t = if l2 == 0.0 {
            0.0
        } else {
            (((p.x - a.x) * (b.x - a.x) + (p.y - a.y) * (b.y - a.y)) / l2).clamp(0.0, 1.0)
        };
        let q = Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
        best = best.min(((p.x - q.x).powi(2) + (p.y - q.y).powi(2)).sqrt());
    }
    best
}

/// Bounding box of a polygon.
pub fn bounds(polygon: &[Point]) -> BoundingBox {
    BoundingBox::from_points(polygon.iter().copied())
}

/// A flattened part: its material is inside the outer polygon and outside every hole.
pub struct Solid {
    pub outer: Vec<Point>,
    pub holes: Vec<Vec<Point>>,
    pub bounds: BoundingBox,
}

impl Solid {
    pub fn new(contours: &[Contour]) -> Self {
        let outer = polygon(&contours[0]);
        Self {
            bounds: bounds(&outer),
            holes: contours[1..].iter().map(polygon).collect(),
            outer,
        }
    }

    /// Whether `p` lies in the material farther than `tolerance` from every boundary.
    pub fn deeply_contains(&self, p: Point, tolerance: f64) -> bool {
        if !self.bounds.contains_point(p) {
            return false;
        }
        inside(p, &self.outer)
            && distance_to_boundary(p, &self.outer) > tolerance
            && self
                .holes
                .iter()
                .all(|h| !inside(p, h) && distance_to_boundary(p, h) > tolerance)
    }

    /// Points on the outer boundary at most `spacing` apart, plus one point inside the material.
    pub fn probes(&self, spacing: f64) -> Vec<Point> {
        let n = self.outer.len();
        let mut out = Vec::new();
        for i in 0..n {
            let (a, b) = (self.outer[i], self.outer[(i + 1) % n]);
            let len = ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt();
            let k = (len / spacing).ceil().max(1.0) as usize;
            for j in 0..k {
                let t = j as f64 / k as f64;
                out.push(Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t));
            }
        }
        // An interior point: the middle of the first material interval on the horizontal line
        // through the bounding box centre (even-odd over outer and holes).
        let y = (self.bounds.min.y + self.bounds.max.y) / 2.0 + 1e-3;
        let mut xs = Vec::new();
        for poly in std::iter::once(&self.outer).chain(self.holes.iter()) {
            let m = poly.len();
            for i in 0..m {
                let (a, b) = (poly[i], poly[(i + 1) % m]);
                if (a.y > y) != (b.y > y) {
                    xs.push(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        if xs.len() >= 2 {
            out.push(Point::new((xs[0] + xs[1]) / 2.0, y));
        }
        out
    }
}

/// Pairs of solids whose materials overlap deeper than `tolerance`, found with a sweep over
/// bounding boxes sorted by their left edge.
pub fn overlapping_pairs(solids: &[Solid], tolerance: f64) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..solids.len()).collect();
    order.sort_by(|&a, &b| solids[a].bounds.min.x.total_cmp(&solids[b].bounds.min.x));
    let probes: Vec<Vec<Point>> = solids.iter().map(|s| s.probes(2.0)).collect();
    let mut pairs = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            let (a, b) = (&solids[i], &solids[j]);
            if b.bounds.min.x >= a.bounds.max.x - tolerance {
                break;
            }
            if b.bounds.min.y >= a.bounds.max.y - tolerance
                || a.bounds.min.y >= b.bounds.max.y - tolerance
            {
                continue;
            }
            let hit = probes[i].iter().any(|&p| b.deeply_contains(p, tolerance))
                || probes[j].iter().any(|&p| a.deeply_contains(p, tolerance));
            if hit {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs
}

/// Centre, radius, start angle and signed sweep of an arc span (`None` for a straight one).
fn arc_of(a: Point, b: Point, bulge: f64) -> Option<(Point, f64, f64, f64)> {
    if bulge == 0.0 {
        return None;
    }
    let chord = ((b.x - a.x).powi(2) + (b.y - a.y).powi(2)).sqrt();
    let radius = chord * (1.0 + bulge * bulge) / (4.0 * bulge.abs());
    let d = chord * (1.0 - bulge * bulge) / (4.0 * bulge);
    let (ux, uy) = ((b.x - a.x) / chord, (b.y - a.y) / chord);
    let c = Point::new((a.x + b.x) / 2.0 - uy * d, (a.y + b.y) / 2.0 + ux * d);
    Some((c, radius, (a.y - c.y).atan2(a.x - c.x), 4.0 * bulge.atan()))
}

fn on_sweep(angle: f64, start: f64, sweep: f64) -> bool {
    let tau = std::f64::consts::TAU;
    let rel = if sweep >= 0.0 {
        (angle - start).rem_euclid(tau)
    } else {
        (start - angle).rem_euclid(tau)
    };
    rel <= sweep.abs()
}

/// Exact bounding box of a contour, arc extremes included.
pub fn exact_bounds(contour: &Contour) -> BoundingBox {
    let n = contour.vertices.len();
    let mut pts: Vec<Point> = contour.vertices.iter().map(|v| v.point).collect();
    for i in 0..n {
        let (a, b) = (
            contour.vertices[i].point,
            contour.vertices[(i + 1) % n].point,
        );
        if let Some((c, r, start, sweep)) = arc_of(a, b, contour.vertices[i].bulge) {
            for k in 0..4 {
                let t = k as f64 * std::f64::consts::FRAC_PI_2;
                if on_sweep(t, start, sweep) {
                    pts.push(Point::new(c.x + r * t.cos(), c.y + r * t.sin()));
                }
            }
        }
    }
    bounds(&pts)
}

/// Exact distance from `p` to a contour made of segments and arcs.
pub fn distance_to_contour(p: Point, contour: &Contour) -> f64 {
    let n = contour.vertices.len();
    let mut best = f64::INFINITY;
    for i in 0..n {
        let (a, b) = (
            contour.vertices[i].point,
            contour.vertices[(i + 1) % n].point,
        );
        let d = match arc_of(a, b, contour.vertices[i].bulge) {
            None => distance_to_boundary(p, &[a, b]),
            Some((c, r, start, sweep)) => {
                let angle = (p.y - c.y).atan2(p.x - c.x);
                if on_sweep(angle, start, sweep) {
                    (((p.x - c.x).powi(2) + (p.y - c.y).powi(2)).sqrt() - r).abs()
                } else {
                    let da = ((p.x - a.x).powi(2) + (p.y - a.y).powi(2)).sqrt();
                    let db = ((p.x - b.x).powi(2) + (p.y - b.y).powi(2)).sqrt();
                    da.min(db)
                }
            }
        };
        best = best.min(d);
    }
    best
}
pub mod realworld;
pub mod spline_sheet;
