//! A generated DXF of many closed SPLINEs, the shape of drawing that nesting programs and CAD
//! exports of organic parts write: a grid of blobs, each a clamped cubic B-spline whose first
//! and last control points coincide. Deterministic (a fixed linear congruential sequence), so
//! the test and the read-time benchmark read the same bytes.

use std::fmt::Write;

/// The drawing: `columns × rows` closed splines of `points` control points each (the last
/// repeats the first), 50 mm apart, as an R2000 ASCII DXF in millimetres.
pub fn spline_sheet(columns: usize, rows: usize, points: usize) -> String {
    let mut seed: u64 = 0x2545_F491_4F6C_DD1D;
    let mut random = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = String::new();
    out.push_str("  0\nSECTION\n  2\nHEADER\n  9\n$ACADVER\n  1\nAC1015\n  9\n$INSUNITS\n 70\n4\n");
    out.push_str("  0\nENDSEC\n  0\nSECTION\n  2\nENTITIES\n");
    let degree = 3;
    let mut handle = 0x100;
    for row in 0..rows {
        for column in 0..columns {
            let (cx, cy) = (column as f64 * 50.0, row as f64 * 50.0);
            let n = points - 1;
            let radii: Vec<f64> = (0..n).map(|_| 14.0 + 8.0 * random()).collect();
            let knot_count = points + degree + 1;
            write!(
                out,
                "  0\nSPLINE\n  5\n{handle:X}\n100\nAcDbEntity\n  8\nPARTS\n100\nAcDbSpline\n\
                 210\n0.0\n220\n0.0\n230\n1.0\n 70\n8\n 71\n{degree}\n 72\n{knot_count}\n\
                 73\n{points}\n 74\n0\n 42\n0.0000000001\n 43\n0.0000000001\n"
            )
            .unwrap();
            handle += 1;
            // Clamped uniform knots: the curve starts and ends on the (shared) end point.
            let inner = knot_count - 2 * (degree + 1);
            for k in 0..knot_count {
                let u = if k <= degree {
                    0.0
                } else if k >= knot_count - degree - 1 {
                    1.0
                } else {
                    (k - degree) as f64 / (inner + 1) as f64
                };
                writeln!(out, " 40\n{u:.12}").unwrap();
            }
            for i in 0..points {
                let j = i % n;
                let angle = -std::f64::consts::TAU * j as f64 / n as f64;
                let (x, y) = (cx + radii[j] * angle.cos(), cy + radii[j] * angle.sin());
                writeln!(out, " 10\n{x:.12}\n 20\n{y:.12}\n 30\n0.0").unwrap();
            }
        }
    }
    out.push_str("  0\nENDSEC\n  0\nEOF\n");
    out
}
