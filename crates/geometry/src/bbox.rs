//! Axis-aligned bounding boxes.

use serde::{Deserialize, Serialize};

use crate::Point;

/// An axis-aligned rectangle `[min.x, max.x] × [min.y, max.y]`.
///
/// The empty box has `min = +∞` and `max = −∞`, so that including any point yields that point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoundingBox {
    /// Lower-left corner.
    pub min: Point,
    /// Upper-right corner.
    pub max: Point,
}

impl Default for BoundingBox {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl BoundingBox {
    /// The box containing nothing.
    pub const EMPTY: BoundingBox = BoundingBox {
        min: Point::new(f64::INFINITY, f64::INFINITY),
        max: Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    };

    /// The box spanned by two corners (in any order).
    pub fn from_corners(a: Point, b: Point) -> Self {
        Self::EMPTY.including(a).including(b)
    }

    /// The smallest box containing all `points` (empty for no points).
    pub fn from_points(points: impl IntoIterator<Item = Point>) -> Self {
        points.into_iter().fold(Self::EMPTY, Self::including)
    }

    /// True when the box contains no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y)
    }

    /// This box grown to contain `p` (non-finite coordinates are ignored by `min`/`max`).
    pub fn including(self, p: Point) -> Self {
        BoundingBox {
            min: Point::new(self.min.x.min(p.x), self.min.y.min(p.y)),
            max: Point::new(self.max.x.max(p.x), self.max.y.max(p.y)),
        }
    }

    /// The smallest box containing both boxes.
    pub fn union(self, other: BoundingBox) -> Self {
        if other.is_empty() {
            return self;
        }
        self.including(other.min).including(other.max)
    }

    /// This box grown by `margin` on every side.
    pub fn expanded(self, margin: f64) -> Self {
        if self.is_empty() {
            return self;
        }
        BoundingBox {
            min: Point::new(self.min.x - margin, self.min.y - margin),
            max: Point::new(self.max.x + margin, self.max.y + margin),
        }
    }

    /// Width (0 for the empty box).
    pub fn width(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.max.x - self.min.x
        }
    }

    /// Height (0 for the empty box).
    pub fn height(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.max.y - self.min.y
        }
    }

    /// Area (0 for the empty box).
    pub fn area(&self) -> f64 {
        self.width() * self.height()
    }

    /// The centre of the box.
    pub fn centre(&self) -> Point {
        self.min.midpoint(self.max)
    }

    /// `p` lies in the closed box.
    pub fn contains_point(&self, p: Point) -> bool {
        self.min.x <= p.x && p.x <= self.max.x && self.min.y <= p.y && p.y <= self.max.y
    }

    /// `other` lies entirely in this closed box (false for an empty `other`).
    pub fn contains_box(&self, other: &BoundingBox) -> bool {
        !other.is_empty() && self.contains_point(other.min) && self.contains_point(other.max)
    }

    /// The least distance from `p` to a point of the closed box (0 inside; infinite for the
    /// empty box): a lower bound on the distance from `p` to any shape the box contains.
    pub fn distance_to_point(&self, p: Point) -> f64 {
        self.gap_to_point(p).norm()
    }

    /// How far `p` lies outside the box along each axis (0 on an axis where it lies within the
    /// box's extent; infinite for the empty box): the vector whose length is
    /// [`BoundingBox::distance_to_point`], for callers that take the length by
    /// [`Point::fast_norm`] in an inner loop.
    ///
    /// ```
    /// use cutroute_geometry::{BoundingBox, Point};
    /// let b = BoundingBox::from_corners(Point::new(0.0, 0.0), Point::new(2.0, 1.0));
    /// assert_eq!(b.gap_to_point(Point::new(5.0, 0.5)), Point::new(3.0, 0.0));
    /// assert_eq!(b.gap_to_point(Point::new(-3.0, 5.0)).fast_norm(), 5.0);
    /// ```
    #[inline]
    pub fn gap_to_point(&self, p: Point) -> Point {
        Point::new(
            (self.min.x - p.x).max(p.x - self.max.x).max(0.0),
            (self.min.y - p.y).max(p.y - self.max.y).max(0.0),
        )
    }

    /// The least distance between a point of this box and a point of `other` (0 when they
    /// overlap; infinite when either is empty): a lower bound on the distance between any
    /// shapes they contain.
    pub fn distance_to_box(&self, other: &BoundingBox) -> f64 {
        if self.is_empty() || other.is_empty() {
            return f64::INFINITY;
        }
        self.gap_to_box(other).norm()
    }

    /// How far apart the two boxes lie along each axis (0 on an axis where their extents
    /// overlap): the vector whose length is [`BoundingBox::distance_to_box`] for non-empty
    /// boxes, for callers that take the length by [`Point::fast_norm`] in an inner loop.
    ///
    /// ```
    /// use cutroute_geometry::{BoundingBox, Point};
    /// let a = BoundingBox::from_corners(Point::new(0.0, 0.0), Point::new(1.0, 1.0));
    /// let b = BoundingBox::from_corners(Point::new(4.0, 5.0), Point::new(6.0, 6.0));
    /// assert_eq!(a.gap_to_box(&b), Point::new(3.0, 4.0));
    /// assert_eq!(b.gap_to_box(&a).fast_norm(), 5.0);
    /// ```
    #[inline]
    pub fn gap_to_box(&self, other: &BoundingBox) -> Point {
        Point::new(
            (other.min.x - self.max.x)
                .max(self.min.x - other.max.x)
                .max(0.0),
            (other.min.y - self.max.y)
                .max(self.min.y - other.max.y)
                .max(0.0),
        )
    }

    /// The closed boxes share at least one point.
    pub fn intersects(&self, other: &BoundingBox) -> bool {
        self.min.x <= other.max.x
            && other.min.x <= self.max.x
            && self.min.y <= other.max.y
            && other.min.y <= self.max.y
    }
}
