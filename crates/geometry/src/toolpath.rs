//! The machine's motion along a route, move by move: what the animation, the G-code post-processor
//! and the exporters consume.
//!
//! A [`Route`] says *which* contour is cut where; a [`Toolpath`] spells out *how* the head moves:
//! straight idle moves, pierces, tool-on links between chained contours, and every span of
//! every contour from the pierce point round to the pierce point again. [`ToolClock`] puts the moves on the machine's time axis (idle and cut
//! speeds, pierce time) so a viewer can ask where the head is at any moment.

use crate::{
    chain_spans, opened_at, MachineParameters, Nest, PathRoute, Point, Route, RouteError, Span,
};

/// One move of the machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToolMove {
    /// Tool off: a straight air move.
    Idle {
        /// Where the move starts.
        from: Point,
        /// Where it ends.
        to: Point,
    },
    /// The torch pierces the sheet; the head stands still for the pierce time.
    Pierce {
        /// Where.
        at: Point,
        /// Index of the route step this pierce starts.
        step: usize,
    },
    /// Tool on: one span (segment or arc) of the contour of a route step, in cutting direction,
    /// or one straight piece of the tool-on link that enters the step (chain cutting).
    Cut {
        /// Index of the route step.
        step: usize,
        /// The piece of the contour or link.
        span: Span,
        /// A piece of the link between two chained contours rather than of a contour: cut like
        /// any other move (the torch is on), drawn apart by viewers.
        link: bool,
    },
}

impl ToolMove {
    /// Length travelled by the head, mm (0 for a pierce).
    pub fn length(&self) -> f64 {
        match self {
            ToolMove::Idle { from, to } => from.distance(*to),
            ToolMove::Pierce { .. } => 0.0,
            ToolMove::Cut { span, .. } => span.length(),
        }
    }

    /// Machine time of the move, seconds. A zero or invalid speed makes a move of positive
    /// length take no time rather than forever, so a viewer never divides by zero.
    pub fn duration(&self, machine: &MachineParameters) -> f64 {
        let at_speed = |length: f64, speed: f64| {
            if speed > 0.0 && speed.is_finite() {
                length / speed
            } else {
                0.0
            }
        };
        match self {
            ToolMove::Idle { .. } => at_speed(self.length(), machine.idle_speed),
            ToolMove::Pierce { .. } => machine.pierce_time.max(0.0),
            ToolMove::Cut { .. } => at_speed(self.length(), machine.cut_speed),
        }
    }

    /// Where the head is after the fraction `f ∈ [0, 1]` of the move's length.
    pub fn point_at(&self, f: f64) -> Point {
        let f = if f.is_nan() { 0.0 } else { f.clamp(0.0, 1.0) };
        match self {
            ToolMove::Idle { from, to } => from.lerp(*to, f),
            ToolMove::Pierce { at, .. } => *at,
            ToolMove::Cut { span, .. } => span.point_at(f),
        }
    }

    /// Where the move ends.
    pub fn end(&self) -> Point {
        self.point_at(1.0)
    }

    /// The route step the move belongs to: the cut or pierce of that step, or the idle move
    /// leading to it (`None` for the final idle move to the finish point).
    pub fn step(&self) -> Option<usize> {
        match self {
            ToolMove::Idle { .. } => None,
            ToolMove::Pierce { step, .. } | ToolMove::Cut { step, .. } => Some(*step),
        }
    }
}

/// Every move of a route in order: idle to the first pierce point, pierce, cut the contour span by
/// span back to the pierce point, idle to the next (or cut the link to it, for a step entered by
/// a link: no idle move and no pierce), …, idle to the finish point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Toolpath {
    /// Where the head starts.
    pub start: Point,
    /// The moves in order.
    pub moves: Vec<ToolMove>,
}

/// Pieces of a span shorter than this (mm) are dropped when a contour is opened at its pierce
/// point: a pierce at a vertex would otherwise leave a zero-length arc, which G-code rejects.
const MIN_PIECE_LENGTH: f64 = 1e-9;

impl Toolpath {
    /// The toolpath of `route` over `nest`. Each contour is cut from the point of the contour
    /// nearest to the step's pierce point (the pierce point itself for a valid route).
    ///
    /// Fails when a step names a contour the nest does not have.
    pub fn new(route: &Route, nest: &Nest) -> Result<Toolpath, RouteError> {
        let mut moves = Vec::new();
        let mut at = route.start;
        for (step, cut) in route.steps.iter().enumerate() {
            let contour = nest
                .contour(cut.contour)
                .ok_or(RouteError::UnknownContour {
                    step,
                    contour: cut.contour,
                })?;
            match route.link_path(step) {
                Some(link) => {
                    for w in link.windows(2) {
                        if w[0].distance(w[1]) > MIN_PIECE_LENGTH {
                            moves.push(ToolMove::Cut {
                                step,
                                span: Span::line(w[0], w[1]),
                                link: true,
                            });
                        }
                    }
                }
                None => {
                    let on = cut.switch_on_point();
                    if at != on {
                        moves.push(ToolMove::Idle { from: at, to: on });
                    }
                    moves.push(ToolMove::Pierce { at: on, step });
                }
            }
            at = cut.switch_off_point();
            let push = |moves: &mut Vec<ToolMove>, span: Span| {
                if span.length() > MIN_PIECE_LENGTH {
                    moves.push(ToolMove::Cut {
                        step,
                        span,
                        link: false,
                    });
                }
            };
            match &cut.leads {
                None => opened_at(contour, cut.pierce_point, MIN_PIECE_LENGTH)
                    .into_iter()
                    .for_each(|span| push(&mut moves, span)),
                Some(leads) => {
                    // The lead-in, the equidistant from the entry round (and the overcut),
                    // the lead-out; an equidistant that does not exist is reported by the
                    // checker, and the step then cuts its leads only.
                    chain_spans(&leads.lead_in).for_each(|span| push(&mut moves, span));
                    if let Ok(eq) = crate::equidistant(contour, leads.offset) {
                        // Between the pieces, the tabs: torch off across the gap, pierce again.
                        let pieces = leads.equidistant_pieces(&eq, MIN_PIECE_LENGTH);
                        for (k, piece) in pieces.into_iter().enumerate() {
                            if let Some(tab) = k.checked_sub(1).and_then(|t| leads.tabs.get(t)) {
                                moves.push(ToolMove::Idle {
                                    from: tab.from,
                                    to: tab.to,
                                });
                                moves.push(ToolMove::Pierce { at: tab.to, step });
                            }
                            piece.into_iter().for_each(|span| push(&mut moves, span));
                        }
                    }
                    chain_spans(&leads.lead_out).for_each(|span| push(&mut moves, span));
                }
            }
        }
        if let Some(finish) = route.finish {
            if at != finish {
                moves.push(ToolMove::Idle {
                    from: at,
                    to: finish,
                });
            }
        }
        Ok(Toolpath {
            start: route.start,
            moves,
        })
    }

    /// The toolpath of a segment-cutting route: per path an idle move (when the head is not
    /// there already), a pierce, and the path's spans (with leads: lead-in, spans, lead-out)
    /// as cuts; the path's index is the move's
    /// step. Pieces through scrap are cuts like the rest (`link: false`: telling them apart
    /// needs the nest, see [`PathRoute::problems`]).
    pub fn from_path_route(route: &PathRoute) -> Toolpath {
        let mut moves = Vec::new();
        let mut at = route.start;
        for (step, path) in route.paths.iter().enumerate() {
            if at != path.pierce {
                moves.push(ToolMove::Idle {
                    from: at,
                    to: path.pierce,
                });
            }
            moves.push(ToolMove::Pierce {
                at: path.pierce,
                step,
            });
            let push = |moves: &mut Vec<ToolMove>, span: Span| {
                if span.length() > MIN_PIECE_LENGTH {
                    moves.push(ToolMove::Cut {
                        step,
                        span,
                        link: false,
                    });
                }
            };
            // With leads: the lead-in, the spans (torch off across each tab's gap, pierce
            // again after it), the overcut, the lead-out.
            let lead_in = path.leads.iter().flat_map(|l| chain_spans(&l.lead_in));
            lead_in.for_each(|span| push(&mut moves, span));
            let pieces = match &path.leads {
                Some(l) => l.pieces(&path.spans, MIN_PIECE_LENGTH),
                None => vec![path.spans.clone()],
            };
            let tabs = path.tabs();
            for (k, piece) in pieces.into_iter().enumerate() {
                if let Some(tab) = k.checked_sub(1).and_then(|t| tabs.get(t)) {
                    moves.push(ToolMove::Idle {
                        from: tab.from,
                        to: tab.to,
                    });
                    moves.push(ToolMove::Pierce { at: tab.to, step });
                }
                piece.into_iter().for_each(|span| push(&mut moves, span));
            }
            path.overcut_spans()
                .into_iter()
                .for_each(|span| push(&mut moves, span));
            let lead_out = path.leads.iter().flat_map(|l| chain_spans(&l.lead_out));
            lead_out.for_each(|span| push(&mut moves, span));
            at = path.switch_off();
        }
        if let Some(finish) = route.finish {
            if at != finish {
                moves.push(ToolMove::Idle {
                    from: at,
                    to: finish,
                });
            }
        }
        Toolpath {
            start: route.start,
            moves,
        }
    }

    /// Total length of the idle moves, mm.
    pub fn idle_length(&self) -> f64 {
        self.moves
            .iter()
            .filter(|m| matches!(m, ToolMove::Idle { .. }))
            .map(ToolMove::length)
            .sum()
    }

    /// Total length of the tool-on links between chained contours, mm (part of
    /// [`Toolpath::cut_length`]).
    pub fn link_length(&self) -> f64 {
        self.moves
            .iter()
            .filter(|m| matches!(m, ToolMove::Cut { link: true, .. }))
            .map(ToolMove::length)
            .sum()
    }

    /// Total length cut with the tool on (contours and links), mm.
    pub fn cut_length(&self) -> f64 {
        self.moves
            .iter()
            .filter(|m| matches!(m, ToolMove::Cut { .. }))
            .map(ToolMove::length)
            .sum()
    }

    /// Number of pierces.
    pub fn pierce_count(&self) -> usize {
        self.moves
            .iter()
            .filter(|m| matches!(m, ToolMove::Pierce { .. }))
            .count()
    }

    /// Where the head ends.
    pub fn end(&self) -> Point {
        self.moves.last().map_or(self.start, ToolMove::end)
    }
}

/// Where the head is and what it does at some moment of machine time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolState {
    /// Position of the head.
    pub position: Point,
    /// Index of the move under way (the last move once the route is over; `None` for an empty
    /// toolpath).
    pub move_index: Option<usize>,
    /// Fraction of that move done, in `[0, 1]`.
    pub fraction: f64,
    /// The torch is on (cutting or piercing).
    pub tool_on: bool,
}

/// The toolpath on the machine's time axis: when each move starts.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolClock {
    /// `starts[i]` = machine time at which move `i` starts; one more entry for the end.
    starts: Vec<f64>,
}

impl ToolClock {
    /// Times of `toolpath`'s moves under `machine`'s speeds and pierce time.
    pub fn new(toolpath: &Toolpath, machine: &MachineParameters) -> ToolClock {
        let mut starts = Vec::with_capacity(toolpath.moves.len() + 1);
        let mut t = 0.0;
        starts.push(t);
        for m in &toolpath.moves {
            t += m.duration(machine);
            starts.push(t);
        }
        ToolClock { starts }
    }

    /// Machine time of the whole route, seconds.
    pub fn total(&self) -> f64 {
        *self.starts.last().unwrap_or(&0.0)
    }

    /// Machine time at which move `index` starts (`total()` for `index == moves.len()`).
    pub fn start_of(&self, index: usize) -> Option<f64> {
        self.starts.get(index).copied()
    }

    /// The state of the head at machine time `t` (clamped to the route's time span).
    pub fn state_at(&self, toolpath: &Toolpath, t: f64) -> ToolState {
        if toolpath.moves.is_empty() {
            return ToolState {
                position: toolpath.start,
                move_index: None,
                fraction: 0.0,
                tool_on: false,
            };
        }
        let t = if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, self.total())
        };
        // The last move starting at or before t; moves of zero duration are passed over.
        let after = self.starts[1..].partition_point(|&end| end <= t);
        let index = after.min(toolpath.moves.len() - 1);
        let (begin, end) = (self.starts[index], self.starts[index + 1]);
        let fraction = if end > begin {
            ((t - begin) / (end - begin)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let m = &toolpath.moves[index];
        ToolState {
            position: m.point_at(fraction),
            move_index: Some(index),
            fraction,
            tool_on: !matches!(m, ToolMove::Idle { .. }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Contour, ContourRef, CutStep, Entry, Part, Vertex};

    fn plate() -> (Nest, Route) {
        let square = Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, 10.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 0.0),
        ]);
        let hole = Contour::circle(Point::new(5.0, 5.0), 2.0, false);
        let nest = Nest {
            sheet: None,
            parts: vec![Part {
                name: "plate".into(),
                contours: vec![square, hole],
            }],
        };
        let route = Route {
            start: Point::new(0.0, -10.0),
            steps: vec![
                CutStep::pierced(
                    ContourRef {
                        part: 0,
                        contour: 1,
                    },
                    Point::new(7.0, 5.0),
                ),
                CutStep::pierced(
                    ContourRef {
                        part: 0,
                        contour: 0,
                    },
                    Point::new(10.0, 5.0),
                ),
            ],
            finish: Some(Point::new(0.0, -10.0)),
        };
        (nest, route)
    }

    #[test]
    fn lengths_and_time_agree_with_the_route() {
        let (nest, route) = plate();
        let path = Toolpath::new(&route, &nest).unwrap();
        assert!((path.idle_length() - route.idle_length()).abs() < 1e-9);
        assert!((path.cut_length() - route.cut_length(&nest)).abs() < 1e-9);
        assert_eq!(path.pierce_count(), route.pierce_count());
        let machine = MachineParameters::default();
        let clock = ToolClock::new(&path, &machine);
        assert!((clock.total() - route.time(&nest, &machine)).abs() < 1e-9);
        assert_eq!(path.end(), Point::new(0.0, -10.0));
    }

    #[test]
    fn cuts_are_continuous_and_return_to_the_pierce_point() {
        let (nest, route) = plate();
        let path = Toolpath::new(&route, &nest).unwrap();
        let mut at = path.start;
        for m in &path.moves {
            let begin = m.point_at(0.0);
            assert!(begin.distance(at) < 1e-9, "{m:?} starts away from {at:?}");
            at = m.end();
        }
        // The square pierced mid-edge is cut in 5 pieces: half an edge, 3 edges, half an edge.
        let square_cuts = path
            .moves
            .iter()
            .filter(|m| matches!(m, ToolMove::Cut { step: 1, .. }))
            .count();
        assert_eq!(square_cuts, 5);
    }

    #[test]
    fn the_clock_walks_the_route() {
        let (nest, route) = plate();
        let path = Toolpath::new(&route, &nest).unwrap();
        let machine = MachineParameters::default();
        let clock = ToolClock::new(&path, &machine);
        let begin = clock.state_at(&path, -1.0);
        assert_eq!(begin.position, route.start);
        assert!(!begin.tool_on);
        let end = clock.state_at(&path, clock.total() + 5.0);
        assert_eq!(end.position, Point::new(0.0, -10.0));
        // During the first pierce the head stands on the hole's pierce point with the torch on.
        let pierce_start = clock.start_of(1).unwrap();
        let piercing = clock.state_at(&path, pierce_start + 0.5 * machine.pierce_time);
        assert_eq!(piercing.move_index, Some(1));
        assert!(piercing.tool_on);
        assert_eq!(piercing.position, Point::new(7.0, 5.0));
        // Time is monotone along the moves.
        let mut last = 0usize;
        for k in 0..=200 {
            let s = clock.state_at(&path, clock.total() * k as f64 / 200.0);
            let i = s.move_index.unwrap();
            assert!(i >= last);
            last = i;
        }
    }

    #[test]
    fn unknown_contours_are_reported() {
        let (nest, mut route) = plate();
        route.steps[0].contour.contour = 7;
        assert!(matches!(
            Toolpath::new(&route, &nest),
            Err(RouteError::UnknownContour { step: 0, .. })
        ));
    }

    #[test]
    fn a_linked_step_is_cut_from_the_previous_exit_without_idle_or_pierce() {
        let square = |x: f64| {
            Contour::new(vec![
                Vertex::line(x, 0.0),
                Vertex::line(x, 10.0),
                Vertex::line(x + 10.0, 10.0),
                Vertex::line(x + 10.0, 0.0),
            ])
        };
        let nest = Nest {
            sheet: None,
            parts: vec![
                Part {
                    name: "a".into(),
                    contours: vec![square(0.0)],
                },
                Part {
                    name: "b".into(),
                    contours: vec![square(12.0)],
                },
            ],
        };
        let a = ContourRef {
            part: 0,
            contour: 0,
        };
        let b = ContourRef {
            part: 1,
            contour: 0,
        };
        let route = Route {
            start: Point::new(0.0, -10.0),
            steps: vec![
                CutStep::pierced(a, Point::new(10.0, 5.0)),
                CutStep {
                    contour: b,
                    pierce_point: Point::new(12.0, 5.0),
                    entry: Entry::Link(vec![Point::new(11.0, 5.0)]),
                    leads: None,
                },
            ],
            finish: None,
        };
        route.validate(&nest, 1e-9).unwrap();
        let path = Toolpath::new(&route, &nest).unwrap();
        assert_eq!(path.pierce_count(), 1);
        assert_eq!(route.pierce_count(), 1);
        assert!((path.link_length() - 2.0).abs() < 1e-12);
        assert!((path.cut_length() - 82.0).abs() < 1e-9);
        assert!((route.cut_length(&nest) - 82.0).abs() < 1e-9);
        assert!((path.idle_length() - route.idle_length()).abs() < 1e-12);
        let links = path
            .moves
            .iter()
            .filter(|m| {
                matches!(
                    m,
                    ToolMove::Cut {
                        link: true,
                        step: 1,
                        ..
                    }
                )
            })
            .count();
        assert_eq!(links, 2, "one piece per corner-to-corner stretch");
        let machine = MachineParameters::default();
        let clock = ToolClock::new(&path, &machine);
        assert!((clock.total() - route.time(&nest, &machine)).abs() < 1e-9);
        let mut at = path.start;
        for m in &path.moves {
            assert!(
                m.point_at(0.0).distance(at) < 1e-9,
                "{m:?} starts away from {at:?}"
            );
            at = m.end();
        }
    }
}
