//! Affine maps of the plane: rotation, reflection, scaling and translation of parts. The
//! linear algebra (products, determinants, inverses) is nalgebra's; the map keeps its plain
//! row-major fields so readers build it from file records and serde writes it as numbers.

use crate::float::Libm;
use nalgebra::{Matrix2, Vector2};
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

    /// Scaling by `sx` along x and `sy` along y about the origin (a DXF block insert's scale).
    /// Unless `|sx| = |sy|` it is not a similarity: circles become ellipses.
    ///
    /// ```
    /// use cutroute_geometry::{Point, Transform};
    /// let map = Transform::axis_scaling(2.0, -3.0);
    /// assert_eq!(map.apply(Point::new(1.0, 1.0)), Point::new(2.0, -3.0));
    /// assert!(map.is_reflection() && !map.is_similarity());
    /// ```
    pub const fn axis_scaling(sx: f64, sy: f64) -> Self {
        Transform {
            matrix: [[sx, 0.0], [0.0, sy]],
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

    /// The linear part as a nalgebra matrix.
    fn linear(&self) -> Matrix2<f64> {
        let m = &self.matrix;
        Matrix2::new(m[0][0], m[0][1], m[1][0], m[1][1])
    }

    /// The map with linear part `linear` and translation `offset`.
    fn from_linear(linear: &Matrix2<f64>, offset: Point) -> Transform {
        Transform {
            matrix: [
                [linear[(0, 0)], linear[(0, 1)]],
                [linear[(1, 0)], linear[(1, 1)]],
            ],
            offset,
        }
    }

    /// Determinant of the matrix; negative for a reflection.
    pub fn determinant(&self) -> f64 {
        self.linear().determinant()
    }

    /// True when the map mirrors the plane (negative determinant), reversing arc orientation.
    pub fn is_reflection(&self) -> bool {
        self.determinant() < 0.0
    }

    /// True when the map keeps circles circles (a rotation, reflection or uniform scale, with
    /// any translation): the matrix's columns are orthogonal and of equal length, within 10⁻⁹
    /// of their squared length. A singular map is not a similarity.
    pub fn is_similarity(&self) -> bool {
        let linear = self.linear();
        let (first, second) = (linear.column(0), linear.column(1));
        let col1 = first.norm_squared();
        let col2 = second.norm_squared();
        let dot = first.dot(&second);
        let scale = col1.max(col2);
        scale > 0.0 && (col1 - col2).abs() <= 1e-9 * scale && dot.abs() <= 1e-9 * scale
    }

    /// The image of a point.
    pub fn apply(&self, p: Point) -> Point {
        self.apply_vector(p) + self.offset
    }

    /// The image of a direction vector (the matrix only, no offset).
    pub fn apply_vector(&self, v: Point) -> Point {
        let image = self.linear() * Vector2::new(v.x, v.y);
        Point::new(image.x, image.y)
    }

    /// The map "first `self`, then `next`".
    pub fn then(&self, next: &Transform) -> Transform {
        Transform::from_linear(&(next.linear() * self.linear()), next.apply(self.offset))
    }

    /// The inverse map, or `None` when the matrix is singular (or not finite).
    pub fn inverse(&self) -> Option<Transform> {
        if !self.determinant().is_finite() {
            return None;
        }
        let inverse = self.linear().try_inverse()?;
        let linear = Transform::from_linear(&inverse, Point::ORIGIN);
        Some(Transform::from_linear(
            &inverse,
            -linear.apply_vector(self.offset),
        ))
    }
}
