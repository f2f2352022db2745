//! Affine maps of the plane: rotation, reflection, scaling and translation of parts.

use crate::float::Libm;
use serde::{Deserialize, Serialize};

use crate::Point;

/// The affine map `p ↦ matrix · p + offset`.
///
/// Arcs stay arcs only under similarity maps (rotations, reflections, uniform scaling): those
/// are the ones nests use. A map with a negative determinant mirrors the plane, so it turns
/// counter-clockwise arcs into clockwise ones and [`Contour::transformed`](crate::Contour::transformed)
/// negates the bulges.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Row-major 2×2 matrix: `x' = m[0][0]·x + m[0][1]·y`, `y' = m[1][0]·x + m[1][1]·y`.
    pub matrix: [[f64; 2]; 2],
    /// Translation added after the matrix.
    pub offset: Point,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The map that changes nothing.
    pub const IDENTITY: Transform = Transform {
        matrix: [[1.0, 0.0], [0.0, 1.0]],
        offset: Point::ORIGIN,
    };

    /// A pure translation by `(dx, dy)`.
    pub const fn translation(dx: f64, dy: f64) -> Self {
        Transform {
            matrix: [[1.0, 0.0], [0.0, 1.0]],
            offset: Point::new(dx, dy),
        }
    }

    /// Rotation by `angle` radians counter-clockwise about the origin.
    pub fn rotation(angle: f64) -> Self {
        let (s, c) = angle.sin_cos_libm();
        Transform {
            matrix: [[c, -s], [s, c]],
            offset: Point::ORIGIN,
        }
    }

    /// Uniform scaling by `factor` about the origin.
    pub const fn scaling(factor: f64) -> Self {
        Transform {
            matrix: [[factor, 0.0], [0.0, factor]],
            offset: Point::ORIGIN,
        }
    }

    /// Reflection in the x axis (`y ↦ −y`).
    pub const fn mirror_x() -> Self {
        Transform {
            matrix: [[1.0, 0.0], [0.0, -1.0]],
            offset: Point::ORIGIN,
        }
    }

    /// Reflection in the y axis (`x ↦ −x`).
    pub const fn mirror_y() -> Self {
        Transform {
            matrix: [[-1.0, 0.0], [0.0, 1.0]],
            offset: Point::ORIGIN,
        }
    }

    /// The map of a DBS contour-copy record (formula В.1):
    /// `x' = cos_xx·x + cos_yx·y + Δx`, `y' = sin_xx·x + sin_yx·y + Δy`.
    pub const fn from_dbs(
        cos_xx: f64,
        sin_xx: f64,
        cos_yx: f64,
        sin_yx: f64,
        dx: f64,
        dy: f64,
    ) -> Self {
        Transform {
            matrix: [[cos_xx, cos_yx], [sin_xx, sin_yx]],
            offset: Point::new(dx, dy),
        }
    }

    /// Determinant of the matrix; negative for a reflection.
    pub fn determinant(&self) -> f64 {
        let m = &self.matrix;
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    }

    /// True when the map mirrors the plane (negative determinant), reversing arc orientation.
    pub fn is_reflection(&self) -> bool {
        self.determinant() < 0.0
    }

    /// True when the map keeps circles circles (a rotation, reflection or uniform scale, with
    /// any translation): the matrix's columns are orthogonal and of equal length, within 10⁻⁹
    /// of their squared length. A singular map is not a similarity.
    pub fn is_similarity(&self) -> bool {
        let m = &self.matrix;
        let col1 = m[0][0] * m[0][0] + m[1][0] * m[1][0];
        let col2 = m[0][1] * m[0][1] + m[1][1] * m[1][1];
        let dot = m[0][0] * m[0][1] + m[1][0] * m[1][1];
        let scale = col1.max(col2);
        scale > 0.0 && (col1 - col2).abs() <= 1e-9 * scale && dot.abs() <= 1e-9 * scale
    }

    /// The image of a point.
    pub fn apply(&self, p: Point) -> Point {
        self.apply_vector(p) + self.offset
    }

    /// The image of a direction vector (the matrix only, no offset).
    pub fn apply_vector(&self, v: Point) -> Point {
        let m = &self.matrix;
        Point::new(m[0][0] * v.x + m[0][1] * v.y, m[1][0] * v.x + m[1][1] * v.y)
    }

    /// The map "first `self`, then `next`".
    pub fn then(&self, next: &Transform) -> Transform {
        let a = &next.matrix;
        let b = &self.matrix;
        let matrix = [
            [
                a[0][0] * b[0][0] + a[0][1] * b[1][0],
                a[0][0] * b[0][1] + a[0][1] * b[1][1],
            ],
            [
                a[1][0] * b[0][0] + a[1][1] * b[1][0],
                a[1][0] * b[0][1] + a[1][1] * b[1][1],
            ],
        ];
        Transform {
            matrix,
            offset: next.apply(self.offset),
        }
    }

    /// The inverse map, or `None` when the matrix is singular (or not finite).
    pub fn inverse(&self) -> Option<Transform> {
        let det = self.determinant();
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let m = &self.matrix;
        let inv = 1.0 / det;
        let matrix = [
            [m[1][1] * inv, -m[0][1] * inv],
            [-m[1][0] * inv, m[0][0] * inv],
        ];
        let linear = Transform {
            matrix,
            offset: Point::ORIGIN,
        };
        Some(Transform {
            matrix,
            offset: -linear.apply_vector(self.offset),
        })
    }
}
