//! The rectangle a view shows, kept as a corner and a size (an SVG `viewBox`).

use serde::{Deserialize, Serialize};

use crate::{BoundingBox, Point};

/// The rectangle a view shows: the corner `(x, y)` with the least coordinates and the size
/// `width × height`, as an SVG `viewBox` lists them.
///
/// Unlike [`BoundingBox`] the size is kept as numbers of its own, not as `max − min`: panning
/// moves only the corner, so the zoom (the size) after any number of pans is exactly what it
/// was. A box recomputed from its corners would drift in the last bits.
///
/// ```
/// use cutroute_geometry::{BoundingBox, Point, Viewport};
/// let view = Viewport::new(0.0, 0.0, 100.0, 50.0);
/// // Zoom in ×2 about (20, 10): that point stays where it was in the view.
/// assert_eq!(view.zoomed_about(0.5, Point::new(20.0, 10.0)), Viewport::new(10.0, 5.0, 50.0, 25.0));
/// // A pan moves the corner and keeps the size bit for bit.
/// let panned = view.panned(Point::new(0.1, -0.3));
/// assert_eq!((panned.width, panned.height), (100.0, 50.0));
/// let b = BoundingBox::from_corners(Point::new(1.0, 2.0), Point::new(4.0, 8.0));
/// assert_eq!(Viewport::from_box(&b).to_box(), b);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Viewport {
    /// Least x of the rectangle.
    pub x: f64,
    /// Least y of the rectangle.
    pub y: f64,
    /// Extent along x.
    pub width: f64,
    /// Extent along y.
    pub height: f64,
}

/// The zoom factors [`Viewport::zoomed_about`] accepts; a factor outside is clamped, so one
/// wild wheel event cannot collapse or blow up the view.
const ZOOM_LIMITS: (f64, f64) = (1e-3, 1e3);

impl Viewport {
    /// The rectangle with corner `(x, y)` and size `width × height`.
    pub const fn new(x: f64, y: f64, width: f64, height: f64) -> Self {
        Self {
            x,
            y,
            width,
            height,
        }
    }

    /// The rectangle of a (non-empty) box.
    pub fn from_box(bounds: &BoundingBox) -> Self {
        Self::new(bounds.min.x, bounds.min.y, bounds.width(), bounds.height())
    }

    /// The rectangle as a box.
    pub fn to_box(&self) -> BoundingBox {
        BoundingBox::from_corners(
            Point::new(self.x, self.y),
            Point::new(self.x + self.width, self.y + self.height),
        )
    }

    /// The rectangle that shows `bounds` with `margin` on every side. The size is the box's
    /// plus two margins, computed from the box's size (not from the grown corners).
    pub fn fitting(bounds: &BoundingBox, margin: f64) -> Self {
        Self::new(
            bounds.min.x - margin,
            bounds.min.y - margin,
            bounds.width() + 2.0 * margin,
            bounds.height() + 2.0 * margin,
        )
    }

    /// The centre of the rectangle.
    pub fn centre(&self) -> Point {
        Point::new(self.x + self.width / 2.0, self.y + self.height / 2.0)
    }

    /// The longer side.
    pub fn longer_side(&self) -> f64 {
        self.width.max(self.height)
    }

    /// The rectangle moved by `offset`, its size unchanged.
    pub fn panned(self, offset: Point) -> Self {
        Self::new(
            self.x + offset.x,
            self.y + offset.y,
            self.width,
            self.height,
        )
    }

    /// The rectangle scaled by `factor` (> 1 shows more, i.e. zooms out) keeping `anchor` at
    /// the same relative place. `factor` is clamped to `[1e-3, 1e3]`.
    pub fn zoomed_about(self, factor: f64, anchor: Point) -> Self {
        let factor = factor.clamp(ZOOM_LIMITS.0, ZOOM_LIMITS.1);
        Self::new(
            anchor.x - (anchor.x - self.x) * factor,
            anchor.y - (anchor.y - self.y) * factor,
            self.width * factor,
            self.height * factor,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fitting_keeps_the_margin_on_every_side() {
        let b = BoundingBox::from_corners(Point::new(10.0, -60.0), Point::new(110.0, -10.0));
        let v = Viewport::fitting(&b, 3.0);
        assert_eq!(v, Viewport::new(7.0, -63.0, 106.0, 56.0));
        assert_eq!(v.to_box(), b.expanded(3.0));
        assert_eq!(v.centre(), b.centre());
        assert_eq!(v.longer_side(), 106.0);
    }

    #[test]
    fn the_zoom_factor_is_clamped() {
        let v = Viewport::new(0.0, 0.0, 10.0, 10.0);
        assert_eq!(v.zoomed_about(0.0, Point::ORIGIN).width, 10.0 * 1e-3);
        assert_eq!(v.zoomed_about(1e9, Point::ORIGIN).width, 10.0 * 1e3);
    }

    fn coordinate() -> impl Strategy<Value = f64> {
        -1e5..1e5
    }

    fn size() -> impl Strategy<Value = f64> {
        1e-2..1e5
    }

    proptest! {
        #[test]
        fn pans_never_change_the_size(
            (x, y, w, h) in (coordinate(), coordinate(), size(), size()),
            offsets in prop::collection::vec((coordinate(), coordinate()), 1..20),
        ) {
            let mut v = Viewport::new(x, y, w, h);
            for (dx, dy) in offsets {
                v = v.panned(Point::new(dx, dy));
            }
            prop_assert_eq!((v.width, v.height), (w, h));
        }

        #[test]
        fn zoom_keeps_the_anchor_at_its_relative_place(
            (x, y, w, h) in (coordinate(), coordinate(), size(), size()),
            (u, t) in (0.0..1.0, 0.0..1.0),
            factor in 0.01..100.0,
        ) {
            let v = Viewport::new(x, y, w, h);
            let anchor = Point::new(x + u * w, y + t * h);
            let z = v.zoomed_about(factor, anchor);
            let relative = |v: Viewport| ((anchor.x - v.x) / v.width, (anchor.y - v.y) / v.height);
            let (a, b) = (relative(v), relative(z));
            prop_assert!((a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-6, "{:?} {:?}", a, b);
            prop_assert!((z.width / w - factor).abs() <= 1e-12 * factor);
        }

        #[test]
        fn a_box_round_trips_and_fitting_contains_it(
            (ax, ay, bx, by) in (coordinate(), coordinate(), coordinate(), coordinate()),
            margin in 0.0..100.0,
        ) {
            let b = BoundingBox::from_corners(Point::new(ax, ay), Point::new(bx, by));
            let v = Viewport::from_box(&b);
            let back = v.to_box();
            let close = |p: Point, q: Point| (p.x - q.x).abs() <= 1e-9 && (p.y - q.y).abs() <= 1e-9;
            prop_assert!(close(back.min, b.min) && close(back.max, b.max));
            let fitted = Viewport::fitting(&b, margin).to_box();
            prop_assert!(fitted.expanded(1e-9).contains_box(&b));
            prop_assert!((fitted.width() - b.width() - 2.0 * margin).abs() <= 1e-9);
        }
    }
}
