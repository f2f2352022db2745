//! Vector arithmetic on [`Point`]: the plane is treated as ℝ² (and, in the arc formulas of
//! Appendix Б, as the complex plane, where `rotated_quarter` is multiplication by `i`).

use crate::float::Libm;
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use crate::Point;

impl Point {
    /// The origin.
    pub const ORIGIN: Point = Point::new(0.0, 0.0);

    /// Dot product with `other`.
    #[inline]
    pub fn dot(self, other: Point) -> f64 {
        self.x * other.x + self.y * other.y
    }

    /// z-component of the cross product `self × other` (positive when `other` is to the left).
    #[inline]
    pub fn cross(self, other: Point) -> f64 {
        self.x * other.y - self.y * other.x
    }

    /// Euclidean length of the vector.
    pub fn norm(self) -> f64 {
        self.x.hypot_libm(self.y)
    }

    /// Squared Euclidean length of the vector.
    pub fn norm_squared(self) -> f64 {
        self.dot(self)
    }

    /// Euclidean distance to `other`.
    pub fn distance(self, other: Point) -> f64 {
        (other - self).norm()
    }

    /// Euclidean length by one `sqrt` of `x² + y²`: several times faster than [`Point::norm`]'s
    /// `hypot`, and as deterministic (IEEE 754 rounds `sqrt` exactly on every platform). For
    /// inner loops on coordinates of the numeric domain, whose squares are far from overflow;
    /// it may differ from `norm` in the last bit.
    ///
    /// ```
    /// use cutroute_geometry::Point;
    /// assert_eq!(Point::new(3.0, 4.0).fast_norm(), 5.0);
    /// ```
    #[inline]
    pub fn fast_norm(self) -> f64 {
        (self.x * self.x + self.y * self.y).sqrt()
    }

    /// Euclidean distance to `other` by one `sqrt`, as [`Point::fast_norm`].
    ///
    /// ```
    /// use cutroute_geometry::Point;
    /// assert_eq!(Point::new(1.0, 1.0).fast_distance(Point::new(4.0, 5.0)), 5.0);
    /// ```
    #[inline]
    pub fn fast_distance(self, other: Point) -> f64 {
        let (dx, dy) = (self.x - other.x, self.y - other.y);
        (dx * dx + dy * dy).sqrt()
    }

    /// The unit vector in the same direction by [`Point::fast_norm`] (each coordinate divided
    /// by it), or the zero vector for the zero vector.
    ///
    /// ```
    /// use cutroute_geometry::Point;
    /// assert_eq!(Point::new(0.0, -2.0).fast_unit(), Point::new(0.0, -1.0));
    /// assert_eq!(Point::ORIGIN.fast_unit(), Point::ORIGIN);
    /// ```
    #[inline]
    pub fn fast_unit(self) -> Point {
        let n = self.fast_norm();
        if n > 0.0 {
            Point::new(self.x / n, self.y / n)
        } else {
            Point::ORIGIN
        }
    }

    /// The point `(1 − t)·self + t·other`.
    pub fn lerp(self, other: Point, t: f64) -> Point {
        self + (other - self) * t
    }

    /// The midpoint of `self` and `other`.
    pub fn midpoint(self, other: Point) -> Point {
        Point::new(0.5 * (self.x + other.x), 0.5 * (self.y + other.y))
    }

    /// The vector turned 90° counter-clockwise (multiplication by `i`).
    #[inline]
    pub fn rotated_quarter(self) -> Point {
        Point::new(-self.y, self.x)
    }

    /// The vector turned by `angle` radians counter-clockwise.
    pub fn rotated(self, angle: f64) -> Point {
        let (sin, cos) = angle.sin_cos_libm();
        Point::new(self.x * cos - self.y * sin, self.x * sin + self.y * cos)
    }

    /// The unit vector in the same direction, or the zero vector for a zero (or non-finite) one.
    pub fn normalized(self) -> Point {
        let n = self.norm();
        if n > 0.0 && n.is_finite() {
            self * (1.0 / n)
        } else {
            Point::ORIGIN
        }
    }

    /// Both coordinates are finite (neither NaN nor infinite).
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl Add for Point {
    type Output = Point;
    #[inline]
    fn add(self, rhs: Point) -> Point {
        Point::new(self.x + rhs.x, self.y + rhs.y)
    }
}

impl AddAssign for Point {
    #[inline]
    fn add_assign(&mut self, rhs: Point) {
        *self = *self + rhs;
    }
}

impl Sub for Point {
    type Output = Point;
    #[inline]
    fn sub(self, rhs: Point) -> Point {
        Point::new(self.x - rhs.x, self.y - rhs.y)
    }
}

impl SubAssign for Point {
    #[inline]
    fn sub_assign(&mut self, rhs: Point) {
        *self = *self - rhs;
    }
}

impl Mul<f64> for Point {
    type Output = Point;
    #[inline]
    fn mul(self, rhs: f64) -> Point {
        Point::new(self.x * rhs, self.y * rhs)
    }
}

impl Neg for Point {
    type Output = Point;
    #[inline]
    fn neg(self) -> Point {
        Point::new(-self.x, -self.y)
    }
}
