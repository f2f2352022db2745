//! Where a tool-on path closes a loop.

use cutroute_geometry::Span;

/// The loop that the last of `spans` (a tool-on path, in cutting order) closes: the index of
/// the span it began with, or `None`. A loop is a stretch of the path that returns to its own
/// start: it ends within `tolerance` of where it began and went farther than twice the
/// tolerance from there on the way, so a run of spans shorter than the tolerance (the 1–3 µm
/// lines real drawings carry) never closes one on its own. Of the loops the last span closes,
/// the longest (the earliest start) is taken: what comes before it is the lead-in or the link
/// from the previous loop. The stretch must be continuous: a gap wider than the tolerance
/// between two spans (a jump the program made) ends the search.
pub fn closed_loop_start(spans: &[Span], tolerance: f64) -> Option<usize> {
    let end = spans.last()?.end;
    let mut farthest = 0.0_f64;
    let mut start = None;
    for (j, span) in spans.iter().enumerate().rev() {
        farthest = farthest
            .max(span.end.distance(end))
            .max(span.midpoint().distance(end));
        if span.start.distance(end) <= tolerance && farthest > 2.0 * tolerance {
            start = Some(j);
        }
        farthest = farthest.max(span.start.distance(end));
        if j > 0 && spans[j - 1].end.distance(span.start) > tolerance {
            break;
        }
    }
    start
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::Point;

    fn path(points: &[(f64, f64)]) -> Vec<Span> {
        points
            .windows(2)
            .map(|w| Span::line(Point::new(w[0].0, w[0].1), Point::new(w[1].0, w[1].1)))
            .collect()
    }

    #[test]
    fn a_square_closes_at_its_own_start_after_its_lead_in() {
        let spans = path(&[
            (-2.0, 0.0),
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 10.0),
            (0.0, 10.0),
        ]);
        assert_eq!(closed_loop_start(&spans, 0.01), None);
        let mut closed = spans.clone();
        closed.extend(path(&[(0.0, 10.0), (0.0, 0.0)]));
        assert_eq!(closed_loop_start(&closed, 0.01), Some(1));
    }

    #[test]
    fn micrometre_steps_close_no_loop() {
        // Each step ends within the tolerance of the starts before it.
        let steps = path(&[
            (0.0, 0.0),
            (0.002, 0.0),
            (0.004, 0.001),
            (0.003, 0.003),
            (0.0, 0.0),
        ]);
        for n in 1..=steps.len() {
            assert_eq!(closed_loop_start(&steps[..n], 0.01), None, "{n}");
        }
        // A real contour made of such steps and long sides closes once, at its end.
        let mut contour = path(&[(0.0, 0.0), (0.002, 0.0), (20.0, 0.0), (20.0, 20.0)]);
        contour.extend(path(&[(20.0, 20.0), (0.001, 0.002), (0.0, 0.0)]));
        let closes: Vec<usize> = (1..=contour.len())
            .filter(|&n| closed_loop_start(&contour[..n], 0.01).is_some())
            .collect();
        assert_eq!(closes, vec![contour.len() - 1, contour.len()]);
        assert_eq!(closed_loop_start(&contour, 0.01), Some(0));
    }

    #[test]
    fn a_jump_ends_the_search() {
        let mut spans = path(&[(0.0, 0.0), (5.0, 0.0)]);
        spans.extend(path(&[(50.0, 0.0), (60.0, 0.0), (60.0, 5.0), (0.0, 0.0)]));
        assert_eq!(closed_loop_start(&spans, 0.01), None);
    }
}
