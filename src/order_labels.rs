//! The cut-order numbers over the drawing: a fixed size on screen, and only where they fit.
//!
//! A number is drawn beside its pierce point when its box lies in the view and overlaps no
//! number drawn before it; numbers are placed in cutting order, so the first cuts always
//! show, and zooming in frees room for the rest. The layout is redone for each committed view
//! (a gesture only moves the picture drawn for the last one).

use cutroute_geometry::{Point, Viewport};
use leptos::prelude::*;
use std::collections::HashMap;

use crate::state::Shown;

/// Height of an order number on screen, CSS pixels: read from the back of a lecture room on a
/// projector at 1280×720.
pub const LABEL_PX: f64 = 18.0;

/// Most numbers drawn at once: past this the drawing is one of numbers, not of parts.
const MOST_LABELS: usize = 400;

/// Width of a digit in em (a little above the widths of common sans-serif digits, so that
/// estimated boxes never undercut the drawn ones).
const DIGIT_EM: f64 = 0.62;

/// The text's offset from its pierce point in em (the `dx`, `dy` of the `<text>`).
pub const OFFSET_EM: (f64, f64) = (0.4, -0.3);

/// Room left around each number's box, in em (the text's halo is drawn there).
const PAD_EM: f64 = 0.12;

/// A number's box in view-box units (y down): `[x0, y0, x1, y1]`.
type LabelBox = [f64; 4];

/// The box of number `k + 1` at pierce point `p` (model frame, y up), `em` view-box units high.
fn label_box(k: usize, p: Point, em: f64) -> LabelBox {
    let digits = (k + 1).to_string().len() as f64;
    let x = p.x + OFFSET_EM.0 * em;
    let baseline = -p.y + OFFSET_EM.1 * em;
    [
        x - PAD_EM * em,
        baseline - (0.75 + PAD_EM) * em,
        x + (digits * DIGIT_EM + PAD_EM) * em,
        baseline + (0.2 + PAD_EM) * em,
    ]
}

fn overlap(a: &LabelBox, b: &LabelBox) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Which of the order numbers of `pierces` (model frame, in cutting order) to draw in `view`
/// (the SVG's view box, y down), each `em` view-box units high: in cutting order, every number
/// whose box lies inside the view and overlaps no number kept before it, at most
/// [`MOST_LABELS`]. Indices into `pierces`, ascending.
pub fn placed_labels(pierces: &[Point], view: Viewport, em: f64) -> Vec<usize> {
    if !(em > 0.0 && em.is_finite()) {
        return Vec::new();
    }
    let inside = |b: &LabelBox| {
        b[0] >= view.x
            && b[1] >= view.y
            && b[2] <= view.x + view.width
            && b[3] <= view.y + view.height
    };
    // Kept boxes by grid cell: a cell is wider than any number, so a box meets few cells.
    let cell = 4.0 * em;
    let cells = |b: &LabelBox| {
        let (i0, i1) = ((b[0] / cell).floor() as i64, (b[2] / cell).floor() as i64);
        let (j0, j1) = ((b[1] / cell).floor() as i64, (b[3] / cell).floor() as i64);
        (i0..=i1).flat_map(move |i| (j0..=j1).map(move |j| (i, j)))
    };
    let mut grid: HashMap<(i64, i64), Vec<LabelBox>> = HashMap::new();
    let mut kept = Vec::new();
    for (k, &p) in pierces.iter().enumerate() {
        if kept.len() >= MOST_LABELS {
            break;
        }
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let b = label_box(k, p, em);
        if !inside(&b) {
            continue;
        }
        let free = cells(&b).all(|c| {
            grid.get(&c)
                .is_none_or(|boxes| boxes.iter().all(|other| !overlap(&b, other)))
        });
        if free {
            for c in cells(&b) {
                grid.entry(c).or_default().push(b);
            }
            kept.push(k);
        }
    }
    kept
}

/// The order numbers of the route shown, laid out for `view` at `px_per_unit` screen pixels per
/// view-box unit. They live outside the drawing's flipped group (text must not be mirrored),
/// at (x, −y); numbered by step (contour) or by tool-on path.
#[component]
pub fn OrderLabels(view: Signal<Option<Viewport>>, px_per_unit: Signal<f64>) -> impl IntoView {
    let Shown { route, paths, .. } = expect_context::<Shown>();
    let pierces = Memo::new(move |_| {
        route
            .with(|r| {
                r.as_ref()
                    .map(|r| r.steps.iter().map(|s| s.pierce_point).collect::<Vec<_>>())
            })
            .or_else(|| {
                paths.with(|p| {
                    p.as_ref()
                        .map(|p| p.paths.iter().map(|p| p.pierce).collect())
                })
            })
            .unwrap_or_default()
    });
    let em = Signal::derive(move || LABEL_PX / px_per_unit.get());
    let labels = move || {
        let view = view.get()?;
        let em = em.get();
        pierces.with(|points| {
            Some(
                placed_labels(points, view, em)
                    .into_iter()
                    .map(|k| {
                        let p = points[k];
                        view! {
                            <text x=p.x y=-p.y dx=format!("{}em", OFFSET_EM.0) dy=format!("{}em", OFFSET_EM.1)>
                                {(k + 1).to_string()}
                            </text>
                        }
                    })
                    .collect_view(),
            )
        })
    };
    view! {
        <g class="order" font-size=move || em.get()>{labels}</g>
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(x: f64, y: f64, side: f64) -> Viewport {
        Viewport {
            x,
            y,
            width: side,
            height: side,
        }
    }

    /// Every pair of kept boxes is apart, every kept box is in the view, and a number is left
    /// out only for a reason: outside the view, or overlapping a number kept before it.
    fn check(pierces: &[Point], v: Viewport, em: f64) -> Vec<usize> {
        let kept = placed_labels(pierces, v, em);
        let boxes: Vec<LabelBox> = kept.iter().map(|&k| label_box(k, pierces[k], em)).collect();
        for (i, a) in boxes.iter().enumerate() {
            assert!(a[0] >= v.x && a[2] <= v.x + v.width && a[1] >= v.y && a[3] <= v.y + v.height);
            for b in &boxes[i + 1..] {
                assert!(!overlap(a, b), "{a:?} overlaps {b:?}");
            }
        }
        if kept.len() < MOST_LABELS {
            for k in (0..pierces.len()).filter(|k| !kept.contains(k)) {
                let b = label_box(k, pierces[k], em);
                let outside =
                    b[0] < v.x || b[2] > v.x + v.width || b[1] < v.y || b[3] > v.y + v.height;
                let blocked = kept
                    .iter()
                    .filter(|&&j| j < k)
                    .any(|&j| overlap(&b, &label_box(j, pierces[j], em)));
                assert!(
                    outside || blocked,
                    "number {} left out for no reason",
                    k + 1
                );
            }
        }
        kept
    }

    #[test]
    fn numbers_far_apart_are_all_drawn_and_close_ones_only_first_come() {
        // Two clusters: three points 100 apart, and three within a number's width.
        let pierces = [
            Point::new(0.0, 0.0),
            Point::new(100.0, 0.0),
            Point::new(200.0, 0.0),
            Point::new(300.0, 0.0),
            Point::new(300.5, 0.0),
            Point::new(300.0, 0.5),
        ];
        let v = view(-50.0, -100.0, 400.0);
        assert_eq!(check(&pierces, v, 10.0), vec![0, 1, 2, 3]);
        // Zoomed in on the cluster, where the numbers are small against their spacing: all
        // three fit, and the others are outside the view.
        let close = view(299.0, -3.0, 4.0);
        assert_eq!(check(&pierces, close, 0.2), vec![3, 4, 5]);
    }

    #[test]
    fn a_dense_random_nest_keeps_no_overlap_and_at_most_the_cap() {
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let pierces: Vec<Point> = (0..5000)
            .map(|_| Point::new(1000.0 * next(), 1000.0 * next()))
            .collect();
        let whole = view(-10.0, -1010.0, 1020.0);
        let kept = check(&pierces, whole, 15.0);
        assert!(!kept.is_empty() && kept.len() <= MOST_LABELS);
        assert_eq!(kept[0], 0, "the first cut is always numbered");
        let zoomed = check(&pierces, view(100.0, -400.0, 100.0), 1.5);
        assert!(!zoomed.is_empty());
    }

    #[test]
    fn no_size_no_numbers() {
        let pierces = [Point::new(0.0, 0.0)];
        assert!(placed_labels(&pierces, view(-10.0, -10.0, 20.0), 0.0).is_empty());
        assert!(placed_labels(&pierces, view(-10.0, -10.0, 20.0), f64::NAN).is_empty());
    }
}
