//! Step 4 (restoring the removed contours at the route's last crossing), the optimality
//! certificates (Conditions 1 and 2) and the machine metrics of a route.

use cutroute_geometry::{BoundingBox, ContourRef, CutStep, MachineParameters, Nest, Point, Route};
use serde::{Deserialize, Serialize};

use crate::geom::{on_segment, ArcCache, PreparedSpan, Shape};
use crate::problem::{Grid, Problem};
use crate::search::Search;
use crate::CcpError;

/// How close an air move must come to a contour to count as touching it (mm): a pierce point
/// placed there lengthens the route by at most twice this. Real nests need more than rounding
/// slack: in Nest03 a square part pokes 5·10⁻⁵ mm out of the round hole it sits in, so the route
/// can cut the square from that corner without ever crossing the hole.
const TOUCH: f64 = 1e-3;

/// The last point (largest position λ along `a b`) where the move `a b` touches `span` within
/// [`TOUCH`]: `(λ, point on the span)`. Candidates are the span's ends, the span points nearest
/// the move's ends, and for an arc the circle point nearest the move's line.
fn last_touch(span: &PreparedSpan, a: Point, b: Point) -> Option<(f64, Point)> {
    let w = b - a;
    let ww = w.dot(w);
    let mut cands = [
        span.a(),
        span.b(),
        span.nearest(a).1,
        span.nearest(b).1,
        span.a(),
    ];
    if let Some(ArcCache { center, radius, .. }) = span.arc {
        if ww > 0.0 {
            let n = w.rotated_quarter() * (1.0 / ww.sqrt());
            let side = if n.dot(a - center) >= 0.0 { 1.0 } else { -1.0 };
            cands[4] = span.nearest(center + n * (side * radius)).1;
        }
    }
    let mut best: Option<(f64, Point)> = None;
    for x in cands {
        let lam = if ww > 0.0 {
            ((x - a).dot(w) / ww).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if (a + w * lam).fast_distance(x) <= TOUCH && best.is_none_or(|b| lam > b.0) {
            best = Some((lam, x));
        }
    }
    best
}

/// Builds the full route from the search state: kept contours in order, the exit chain of an
/// open route, and every removed contour inserted at the last crossing of the air path with it
/// (ties on one air move ordered by position along the move), or at its last contact within
/// [`TOUCH`] when no move crosses it.
pub(crate) fn assemble_route(s: &Search, order: &[u32], pts: &[Point]) -> Route {
    let prob = &s.prob;
    // The air path: start, kept pierce points, exit chain (open routes), finish.
    let mut poly: Vec<Point> = Vec::with_capacity(order.len() + 4);
    let mut poly_step: Vec<Option<usize>> = Vec::with_capacity(order.len() + 4);
    poly.push(s.start);
    poly_step.push(None);
    for &k in order {
        poly.push(pts[k as usize]);
        poly_step.push(Some(prob.kept[k as usize]));
    }
    if s.finish.is_none() {
        if let Some(&last) = order.last() {
            let mut chain = Vec::new();
            s.exit_chain(last as usize, pts[last as usize], Some(&mut chain));
            for x in chain {
                poly.push(x);
                poly_step.push(None);
            }
        }
    }
    if let Some(f) = s.finish {
        poly.push(f);
        poly_step.push(None);
    }
    let moves = poly.len().saturating_sub(1);
    let mut inserted: Vec<Vec<(f64, usize, Point)>> = vec![Vec::new(); moves.max(1)];
    let mut leftovers = Vec::new();
    let mut hits = Vec::new();
    // A grid of the air moves: each removed contour only looks at the moves near it.
    let mut area = prob.bounds;
    for p in &poly {
        area = area.including(*p);
    }
    let mut grid = Grid::new(area, moves.max(1), 2.0);
    for t in 0..moves {
        let bb = BoundingBox::from_corners(poly[t], poly[t + 1]);
        grid.insert(t as u32, &bb);
    }
    let mut candidates: Vec<u32> = Vec::new();
    for &c in &prob.removed {
        let shape = &prob.shapes[c];
        candidates.clear();
        grid.cells_in(&shape.bbox, |cell| candidates.extend_from_slice(cell));
        candidates.sort_unstable_by(|a, b| b.cmp(a));
        candidates.dedup();
        let mut found = None;
        for &t in &candidates {
            let t = t as usize;
            let (a, b) = (poly[t], poly[t + 1]);
            // A cheap conservative test: the move may touch what its box meets.
            let move_box = BoundingBox::from_corners(a, b);
            if !shape.bbox.intersects(&move_box) {
                continue;
            }
            let mut best: Option<(f64, Point)> = None;
            for (span, bb) in shape.spans.iter().zip(&shape.span_boxes) {
                if !bb.intersects(&move_box) {
                    continue;
                }
                hits.clear();
                span.intersect_segment(a, b, &mut hits);
                for &(lam, ts) in &hits {
                    if best.is_none_or(|b| lam > b.0) {
                        best = Some((lam, span.point_at(ts)));
                    }
                }
            }
            if best.is_none() {
                // No proper crossing: the move may run along an edge or touch a vertex or an
                // arc (grid-like nests move along the contours' own lines). Its last contact
                // serves as well: after it the route stays outside the contour.
                for (span, bb) in shape.spans.iter().zip(&shape.span_boxes) {
                    if bb
                        .gap_to_point(a)
                        .fast_norm()
                        .min(bb.gap_to_point(b).fast_norm())
                        > TOUCH
                        && !bb.intersects(&move_box)
                    {
                        continue;
                    }
                    if let Some((lam, x)) = last_touch(span, a, b) {
                        if best.is_none_or(|b| lam > b.0) {
                            best = Some((lam, x));
                        }
                    }
                }
            }
            if let Some((lam, x)) = best {
                found = Some((t, lam, x));
                break;
            }
        }
        match found {
            Some((t, lam, x)) => inserted[t].push((lam, c, x)),
            None => leftovers.push(c),
        }
    }
    // A contour not crossed (only possible through numerical tangency) is cut at the end; so
    // must every contour enclosing it, to keep "inner before outer".
    if !leftovers.is_empty() {
        let mut late = vec![false; prob.shapes.len()];
        for &c in &leftovers {
            let mut p = Some(c);
            while let Some(a) = p {
                late[a] = true;
                p = prob.parent[a];
            }
        }
        for list in &mut inserted {
            list.retain(|e| !late[e.1]);
        }
        leftovers = (0..prob.shapes.len()).filter(|&c| late[c]).collect();
    }
    // The route as (contour, pierce point), in the order the air path meets them.
    let mut seq: Vec<(usize, Point)> = Vec::with_capacity(prob.shapes.len());
    for t in 0..poly.len() {
        if let Some(c) = poly_step[t] {
            seq.push((c, poly[t]));
        }
        if t < moves {
            let list = &mut inserted[t];
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            seq.extend(list.iter().map(|&(_, c, x)| (c, x)));
        }
    }
    let (mut seq, deferred) = inner_first(prob, seq);
    leftovers.extend(deferred);
    // Cut them last, innermost (smallest) first, each from the nearest point: precedence holds at
    // the price of extra idle length (a contour of the forest is larger than the ones inside it).
    leftovers.sort_by(|a, b| {
        prob.shapes[*a]
            .area
            .abs()
            .total_cmp(&prob.shapes[*b].area.abs())
    });
    let mut cur = seq.last().map_or(s.start, |&(_, x)| x);
    for c in leftovers {
        let x = prob.shapes[c].nearest(cur);
        seq.push((c, x));
        cur = x;
    }
    let steps = seq
        .into_iter()
        .map(|(c, x)| CutStep {
            contour: prob.refs[c],
            pierce_point: x,
            entry: Default::default(),
            leads: None,
        })
        .collect();
    Route {
        start: s.start,
        steps,
        finish: s.finish,
    }
}

/// The containment forest's precedence imposed on a sequence of cuts: a contour met before
/// every contour inside it is cut waits until the last of them is cut, and is then cut from
/// its point nearest that one. Returns the sequence and the contours still waiting at its end
/// (those with a child missing from it).
///
/// Crossings place a removed contour where the air path leaves it, which is after the
/// contours inside it only when the route's geometry agrees with the forest. A nest whose
/// contours cross (a vertex moved into a spike through a neighbour) breaks that: the path can
/// leave an outer contour before visiting a contour the forest puts inside it, and the checker
/// (`Route::problems`, on the same forest) rejects the route. The forest is the one authority
/// on "inside"; crossings only choose where, among the places it allows.
fn inner_first(prob: &Problem, seq: Vec<(usize, Point)>) -> (Vec<(usize, Point)>, Vec<usize>) {
    let mut uncut_children = vec![0_usize; prob.shapes.len()];
    for p in prob.parent.iter().flatten() {
        uncut_children[*p] += 1;
    }
    let mut waiting = vec![false; prob.shapes.len()];
    let mut out = Vec::with_capacity(seq.len());
    for (c, x) in seq {
        if uncut_children[c] > 0 {
            waiting[c] = true;
            continue;
        }
        out.push((c, x));
        // Cutting `c` may release its parent, then the parent's parent.
        let mut done = c;
        while let Some(p) = prob.parent[done] {
            uncut_children[p] -= 1;
            if uncut_children[p] > 0 || !waiting[p] {
                break;
            }
            waiting[p] = false;
            let from = out.last().map_or(x, |&(_, at)| at);
            out.push((p, prob.shapes[p].nearest(from)));
            done = p;
        }
    }
    let still: Vec<usize> = (0..prob.shapes.len()).filter(|&c| waiting[c]).collect();
    (out, still)
}

/// Idle (air) length of a route: start → pierce points in order → finish.
pub fn idle_length(route: &Route) -> f64 {
    let mut cur = route.start;
    let mut len = 0.0;
    for st in &route.steps {
        let p = st.pierce_point;
        len += cur.fast_distance(p);
        cur = p;
    }
    if let Some(f) = route.finish {
        len += cur.fast_distance(f);
    }
    len
}

/// Lengths, pierce count and time of a route.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RouteMetrics {
    /// Idle (air) length L_off, mm.
    pub idle_length: f64,
    /// Cut length L_on (sum of the perimeters of the cut contours), mm.
    pub cut_length: f64,
    /// Number of pierces N.
    pub pierce_count: usize,
    /// `L_on/V_on + L_off/V_off + N·t_pierce`.
    pub total_time: f64,
}

fn contour_of(nest: &Nest, r: ContourRef) -> Result<&cutroute_geometry::Contour, CcpError> {
    nest.parts
        .get(r.part)
        .and_then(|p| p.contours.get(r.contour))
        .ok_or(CcpError::UnknownContour {
            part: r.part,
            contour: r.contour,
        })
}

/// Metrics of a route over a nest under a machine model.
pub fn route_metrics(
    nest: &Nest,
    route: &Route,
    machine: &MachineParameters,
) -> Result<RouteMetrics, CcpError> {
    let mut cut_length = 0.0;
    for st in &route.steps {
        cut_length += Shape::new(contour_of(nest, st.contour)?).perimeter;
    }
    let idle = idle_length(route);
    let n = route.steps.len();
    Ok(RouteMetrics {
        idle_length: idle,
        cut_length,
        pierce_count: n,
        total_time: machine.time(cut_length, idle, n),
    })
}

/// Which sufficient optimality conditions hold at one pierce point of a route.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContourCertificate {
    /// The contour.
    pub contour: ContourRef,
    /// Its pierce point.
    pub pierce_point: Point,
    /// The pierce point lies on the chord between its route neighbours (Condition 1.1 = 2.1).
    pub on_chord: bool,
    /// Condition 1: on the chord, or the tangent of the confocal ellipse through the pierce
    /// point separates the ellipse from the contour.
    pub condition1: bool,
    /// Condition 2 (the visual version): on the chord; or inside an edge whose line leaves the
    /// whole contour on one side; or at a vertex whose edge rays enclose the contour; or the
    /// contour bounds a convex region.
    pub condition2: bool,
}

/// Checks Conditions 1 and 2 at every pierce point of a route. If Condition 1 holds everywhere,
/// no shift of pierce points can shorten the route for its order (Proposition 2).
pub fn route_certificates(nest: &Nest, route: &Route) -> Result<Vec<ContourCertificate>, CcpError> {
    let n = route.steps.len();
    let mut out = Vec::with_capacity(n);
    for (i, st) in route.steps.iter().enumerate() {
        let shape = Shape::new(contour_of(nest, st.contour)?);
        let p = if i == 0 {
            route.start
        } else {
            route.steps[i - 1].pierce_point
        };
        let q = if i + 1 < n {
            Some(route.steps[i + 1].pierce_point)
        } else {
            route.finish
        };
        let m = st.pierce_point;
        let (on_chord, c1, c2) = certify(&shape, p, q, m);
        out.push(ContourCertificate {
            contour: st.contour,
            pierce_point: st.pierce_point,
            on_chord,
            condition1: c1,
            condition2: c2,
        });
    }
    Ok(out)
}

/// `(on_chord, condition1, condition2)` at pierce point `m` of `shape` between `p` and `q`.
pub(crate) fn certify(shape: &Shape, p: Point, q: Option<Point>, m: Point) -> (bool, bool, bool) {
    let scale = shape.bbox.max.fast_distance(shape.bbox.min).max(1.0);
    let tol = 1e-7 * scale;
    let on_chord = match q {
        Some(q) => on_segment(p, q, m, tol),
        None => m.fast_distance(p) <= tol,
    };
    let n = (m - p).fast_unit() + q.map_or(Point::ORIGIN, |q| (m - q).fast_unit());
    let c1 = on_chord || n.fast_norm() < 1e-12 || shape.min_dot(n.fast_unit(), m) >= -tol;
    let c2 = on_chord || condition2_shape(shape, m, tol);
    (on_chord, c1, c2)
}

fn condition2_shape(shape: &Shape, m: Point, tol: f64) -> bool {
    let nspan = shape.spans.len();
    for (si, span) in shape.spans.iter().enumerate() {
        if span.arc.is_some() {
            continue;
        }
        let (a, b) = (span.a(), span.b());
        let u = b - a;
        if u.fast_norm() < 1e-12 {
            continue;
        }
        let on = on_segment(a, b, m, tol);
        if !on {
            continue;
        }
        if m.fast_distance(a) > tol && m.fast_distance(b) > tol {
            // Interior of an edge: the contour on one side of its line.
            let nl = u.rotated_quarter().fast_unit();
            if shape.min_dot(nl, m) >= -tol || shape.min_dot(nl * -1.0, m) >= -tol {
                return true;
            }
        } else {
            // At a vertex: both incident spans must be segments; the contour inside their angle.
            let (prev, next) = if m.fast_distance(a) <= tol {
                (shape.spans[(si + nspan - 1) % nspan], *span)
            } else {
                (*span, shape.spans[(si + 1) % nspan])
            };
            if prev.arc.is_none() && next.arc.is_none() {
                let (pa, nb) = (prev.a(), next.b());
                let e1 = (nb - m).fast_unit();
                let e2 = (pa - m).fast_unit();
                let s = e1.cross(e2);
                if s.abs() > 1e-12 {
                    let n1 = e1.rotated_quarter() * s.signum();
                    let n2 = e2.rotated_quarter() * -s.signum();
                    if shape.min_dot(n1, m) >= -tol && shape.min_dot(n2, m) >= -tol {
                        return true;
                    }
                }
            }
        }
    }
    shape.is_convex()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Contour, Vertex};

    /// An L: 0..20 × 0..10 plus 0..10 × 10..20 (counter-clockwise).
    fn ell() -> Shape {
        Shape::new(&Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(20.0, 0.0),
            Vertex::line(20.0, 10.0),
            Vertex::line(10.0, 10.0),
            Vertex::line(10.0, 20.0),
            Vertex::line(0.0, 20.0),
        ]))
    }

    #[test]
    fn conditions_on_an_l_shape() {
        let s = ell();
        // Reflection point on the bottom edge: the bottom line supports the whole contour.
        let (chord, c1, c2) = certify(
            &s,
            Point::new(5.0, -10.0),
            Some(Point::new(15.0, -10.0)),
            Point::new(10.0, 0.0),
        );
        assert!(!chord && c1 && c2);
        // At the convex corner (20, 0) seen from outside: the contour lies in its right angle.
        let (_, c1, c2) = certify(
            &s,
            Point::new(30.0, -5.0),
            Some(Point::new(25.0, -10.0)),
            Point::new(20.0, 0.0),
        );
        assert!(c1 && c2);
        // In the notch, on the edge x = 10: neither condition holds (the contour is on both sides
        // of that edge's line, and the ellipse tangent cuts through the L).
        let (_, c1, c2) = certify(
            &s,
            Point::new(30.0, 25.0),
            Some(Point::new(30.0, 5.0)),
            Point::new(10.0, 15.0),
        );
        assert!(!c1 && !c2);
        // On the chord between the neighbours.
        let (chord, c1, c2) = certify(
            &s,
            Point::new(-5.0, 5.0),
            Some(Point::new(25.0, 5.0)),
            Point::new(0.0, 5.0),
        );
        assert!(chord && c1 && c2);
    }
}
