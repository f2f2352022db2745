//! Loose pieces of a drawing → closed contours → parts.
//!
//! Pieces (lines, arcs, open polylines, approximated splines) are joined end to end when their
//! end points lie within the join tolerance. End points live in a uniform grid whose cells are
//! as wide as the tolerance, so a neighbour search looks at 3 × 3 cells and the whole join is
//! linear in the number of pieces for real drawings. Where more than two ends meet, the nearest
//! wins; what cannot be closed is reported as an open chain. Closed contours are then nested by
//! containment: even depth (not inside anything, or inside a hole) starts a part, odd depth is a
//! hole of its container's part. Outer contours are made clockwise, holes counter-clockwise.

use std::collections::HashMap;

use cutroute_geometry::{
    flatten_spans, BoundingBox, Contour, ContourFault, Nest, Part, Point, ReadWarning, Span,
    Transform, Vertex, WarningKind,
};

use crate::CadError;

/// Where a piece of geometry came from in the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EntityRef {
    /// Entity type (`LINE`, `ARC`, `SPLINE`, …).
    pub entity: String,
    /// 1-based line of the entity's `0` group (of the entity inside its block for inserts).
    pub line: usize,
    /// Layer name, decoded.
    pub layer: String,
}

pub(crate) type SourceRef = EntityRef;

/// A chain of spans from one entity, in world coordinates.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub spans: Vec<Span>,
    /// Closed by construction (circle, closed polyline): the last span ends at the first start.
    pub closed: bool,
    pub source: SourceRef,
}

/// A chain of entities that does not close within the join tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct OpenChain {
    /// Where the chain starts.
    pub start: Point,
    /// Where the chain ends.
    pub end: Point,
    /// Length along the chain, mm.
    pub length: f64,
    /// The entities of the chain, in chain order.
    pub entities: Vec<EntityRef>,
    /// The chain flattened (arcs within the flattening tolerance), from `start` to `end`.
    pub polyline: Vec<Point>,
}

impl std::fmt::Display for OpenChain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "open chain of {} entit", self.entities.len())?;
        f.write_str(if self.entities.len() == 1 { "y" } else { "ies" })?;
        write!(
            f,
            " from ({:.4}, {:.4}) to ({:.4}, {:.4})",
            self.start.x, self.start.y, self.end.x, self.end.y
        )?;
        write!(f, ", {:.3} mm long:", self.length)?;
        for (i, e) in self.entities.iter().take(5).enumerate() {
            let sep = if i == 0 { " " } else { ", " };
            write!(
                f,
                "{sep}{} at line {} (layer {})",
                e.entity, e.line, e.layer
            )?;
        }
        if self.entities.len() > 5 {
            write!(f, ", …")?;
        }
        Ok(())
    }
}

/// Tolerances of the assembly.
pub(crate) struct AssembleLimits {
    pub join_tolerance: f64,
    /// Chord deviation used when flattening arcs for containment tests.
    pub flatten_tolerance: f64,
}

/// Geometry left out during assembly (an open chain, a duplicate entity, a contour that is not
/// cuttable), with why: [`ReadWarning::from`] makes it the reader's warning, with its kind,
/// line, length and the left-out geometry as polylines.
pub(crate) struct Dropped {
    pub kind: WarningKind,
    /// 1-based line of the (first) entity.
    pub line: usize,
    /// A sentence without the line.
    pub message: String,
    /// What was left out, flattened, in millimetres with y up.
    pub left_out: Vec<Vec<Point>>,
}

impl From<Dropped> for ReadWarning {
    fn from(d: Dropped) -> Self {
        ReadWarning::new(d.kind, d.message)
            .at_line(d.line, None)
            .leaving_out(d.left_out)
    }
}

/// A closed contour as a polyline whose last point repeats the first (so its length is the
/// perimeter, within the flattening).
fn closed_polyline(contour: &Contour, tolerance: f64) -> Vec<Point> {
    let mut points = contour.flatten(tolerance);
    if let Some(&first) = points.first() {
        points.push(first);
    }
    points
}

pub(crate) struct Assembled {
    pub parts: Vec<Part>,
    pub open_chains: Vec<OpenChain>,
    pub dropped: Vec<Dropped>,
}

/// The result of a drawing import (DXF, SVG), with the reader's own kind of warning.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawingImport<W> {
    /// The closed parts found, and the sheet when the drawing marks one. Outer contours run
    /// clockwise, holes counter-clockwise, in millimetres with y up; a contour inside a hole
    /// starts a new part.
    pub nest: Nest,
    /// Chains of pieces that did not close within the join tolerance, with their end points.
    pub open_chains: Vec<OpenChain>,
    /// What was skipped or approximated without failing.
    pub warnings: Vec<W>,
}

/// The last step of every drawing import: assembles the parts' pieces into a nest with
/// `sheet`, appending the contours dropped on the way to `warnings` (made by `warning`). With
/// no closed contour the error describes the first open chain, or — without one —
/// `nothing_drawn` says why from the warnings.
pub(crate) fn finish_import<W>(
    pieces: Vec<Piece>,
    sheet: Option<Part>,
    limits: &AssembleLimits,
    mut warnings: Vec<W>,
    warning: impl Fn(Dropped) -> W,
    nothing_drawn: impl FnOnce(&[W]) -> String,
) -> Result<DrawingImport<W>, CadError> {
    let assembled = assemble(pieces, limits);
    // Without a contour or an open chain, what assembly left out is why nothing was drawn.
    let first_dropped = assembled.dropped.first().map(|d| {
        ReadWarning::new(d.kind, d.message.clone())
            .at_line(d.line, None)
            .to_string()
    });
    warnings.extend(assembled.dropped.into_iter().map(&warning));
    // One warning per open chain, so that nothing is left out in silence wherever the
    // warnings go (the CLI, the reports, the page).
    warnings.extend(assembled.open_chains.iter().map(|chain| {
        warning(Dropped {
            kind: WarningKind::OpenChain,
            line: chain.entities.first().map_or(0, |e| e.line),
            message: format!("{chain}; left out"),
            left_out: vec![chain.polyline.clone()],
        })
    }));
    if assembled.parts.is_empty() {
        let first = match assembled.open_chains.first() {
            Some(chain) => chain.to_string(),
            None => match first_dropped {
                Some(dropped) => format!("nothing drawn; {dropped}"),
                None => nothing_drawn(&warnings),
            },
        };
        return Err(CadError::NothingClosed {
            open: assembled.open_chains.len(),
            first,
        });
    }
    Ok(DrawingImport {
        nest: Nest {
            sheet,
            parts: assembled.parts,
        },
        open_chains: assembled.open_chains,
        warnings,
    })
}

/// Most live candidates examined per end-point search: bounds the work on hostile piles of
/// coincident ends without changing the result for real drawings (which have 1–3 per node).
const MAX_CANDIDATES: usize = 64;

struct EndGrid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl EndGrid {
    fn key(&self, p: Point) -> (i64, i64) {
        (
            (p.x / self.cell).floor() as i64,
            (p.y / self.cell).floor() as i64,
        )
    }

    /// The nearest end within `tolerance` of `p` whose piece is unused. End id = piece·2 + side
    /// (0 = start, 1 = end). Entries of used pieces are removed as they are met.
    fn nearest(
        &mut self,
        p: Point,
        tolerance: f64,
        ends: &[Point],
        used: &[bool],
    ) -> Option<(u32, f64)> {
        let (kx, ky) = self.key(p);
        let mut best: Option<(u32, f64)> = None;
        let mut examined = 0;
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(cell) = self
                    .cells
                    .get_mut(&(kx.saturating_add(dx), ky.saturating_add(dy)))
                else {
                    continue;
                };
                let mut i = 0;
                while i < cell.len() {
                    let id = cell[i];
                    if used[(id / 2) as usize] {
                        cell.swap_remove(i);
                        continue;
                    }
                    i += 1;
                    examined += 1;
                    let d = p.distance(ends[id as usize]);
                    if d <= tolerance && best.is_none_or(|(_, bd)| d < bd) {
                        best = Some((id, d));
                    }
                    if examined >= MAX_CANDIDATES {
                        return best;
                    }
                }
            }
        }
        best
    }
}

/// Drops pieces drawn twice (same spans, either direction, equal up to the tolerance grid):
/// CAD drawings often hold overlapping copies, which would otherwise pair up with each other
/// into zero-area "contours" and leave the real outline open.
fn without_duplicates(
    pieces: Vec<Piece>,
    limits: &AssembleLimits,
    dropped: &mut Vec<Dropped>,
) -> Vec<Piece> {
    let tolerance = limits.join_tolerance;
    let quantize = |p: Point| {
        (
            (p.x / tolerance).round() as i64,
            (p.y / tolerance).round() as i64,
        )
    };
    let key = |spans: &mut dyn Iterator<Item = Span>| -> Vec<(i64, i64, i64)> {
        let mut out = Vec::new();
        let mut last = None;
        for s in spans {
            let (x, y) = quantize(s.start);
            out.push((x, y, (s.bulge * 1e6).round() as i64));
            last = Some(s.end);
        }
        if let Some(end) = last {
            let (x, y) = quantize(end);
            out.push((x, y, 0));
        }
        out
    };
    let mut seen: HashMap<Vec<(i64, i64, i64)>, usize> = HashMap::new();
    let mut kept = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let forward = key(&mut piece.spans.iter().copied());
        let backward = key(&mut piece.spans.iter().rev().map(|s| s.reversed()));
        let canonical = if forward <= backward {
            forward
        } else {
            backward
        };
        if let Some(&line) = seen.get(&canonical) {
            dropped.push(Dropped {
                kind: WarningKind::Duplicate,
                line: piece.source.line,
                message: format!(
                    "{} duplicates the entity at line {line}; ignored",
                    piece.source.entity
                ),
                left_out: vec![flatten_spans(&piece.spans, limits.flatten_tolerance)],
            });
            continue;
        }
        seen.insert(canonical, piece.source.line);
        kept.push(piece);
    }
    kept
}

/// Joins, orients and groups the pieces.
pub(crate) fn assemble(pieces: Vec<Piece>, limits: &AssembleLimits) -> Assembled {
    let tolerance = limits.join_tolerance;
    let mut contours: Vec<(Contour, SourceRef)> = Vec::new();
    let mut open_chains = Vec::new();
    let mut dropped = Vec::new();
    let pieces = without_duplicates(pieces, limits, &mut dropped);

    let ends: Vec<Point> = pieces
        .iter()
        .flat_map(|p| [p.spans[0].start, p.spans[p.spans.len() - 1].end])
        .collect();
    let mut used: Vec<bool> = pieces.iter().map(|p| p.closed).collect();
    let mut grid = EndGrid {
        cell: tolerance,
        cells: HashMap::new(),
    };
    for (i, p) in pieces.iter().enumerate() {
        if p.closed {
            contours.push((chain_contour(&[(i, false)], &pieces), p.source.clone()));
            continue;
        }
        for side in 0..2u32 {
            let id = i as u32 * 2 + side;
            let key = grid.key(ends[id as usize]);
            grid.cells.entry(key).or_default().push(id);
        }
    }

    for first in 0..pieces.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        // Chain of (piece, reversed) in order.
        let mut chain: std::collections::VecDeque<(usize, bool)> = [(first, false)].into();
        let mut closed = false;
        for forward in [true, false] {
            loop {
                let (head, tail) = chain_ends(&chain, &ends);
                let (from, to_close) = if forward { (tail, head) } else { (head, tail) };
                let candidate = grid.nearest(from, tolerance, &ends, &used);
                let closing = from.distance(to_close);
                if closing <= tolerance && candidate.is_none_or(|(_, d)| closing <= d) {
                    // A chain of one straight span cannot close on itself.
                    closed = chain.len() > 1
                        || pieces[first].spans.len() > 1
                        || pieces[first].spans[0].bulge != 0.0;
                    if closed {
                        break;
                    }
                }
                let Some((id, _)) = candidate else { break };
                let piece = (id / 2) as usize;
                let at_start = id % 2 == 0;
                used[piece] = true;
                if forward {
                    chain.push_back((piece, !at_start));
                } else {
                    chain.push_front((piece, at_start));
                }
            }
            if closed {
                break;
            }
        }
        let links: Vec<(usize, bool)> = chain.into_iter().collect();
        if closed {
            contours.push((
                chain_contour(&links, &pieces),
                pieces[links[0].0].source.clone(),
            ));
        } else {
            let spans: Vec<Span> = chain_spans(&links, &pieces).collect();
            let length = spans.iter().map(Span::length).sum();
            open_chains.push(OpenChain {
                polyline: flatten_spans(&spans, limits.flatten_tolerance),
                start: spans[0].start,
                end: spans[spans.len() - 1].end,
                length,
                entities: links
                    .iter()
                    .map(|&(p, _)| pieces[p].source.clone())
                    .collect(),
            });
        }
    }

    let parts = group_into_parts(contours, limits, &mut dropped);
    Assembled {
        parts,
        open_chains,
        dropped,
    }
}

fn chain_ends(chain: &std::collections::VecDeque<(usize, bool)>, ends: &[Point]) -> (Point, Point) {
    let &(p, rev) = chain.front().expect("chains are never empty");
    let head = ends[p * 2 + usize::from(rev)];
    let &(q, rev) = chain.back().expect("chains are never empty");
    let tail = ends[q * 2 + usize::from(!rev)];
    (head, tail)
}

fn chain_spans<'a>(
    links: &'a [(usize, bool)],
    pieces: &'a [Piece],
) -> impl Iterator<Item = Span> + 'a {
    links.iter().flat_map(move |&(p, rev)| {
        let spans = &pieces[p].spans;
        let n = spans.len();
        (0..n).map(move |k| {
            if rev {
                spans[n - 1 - k].reversed()
            } else {
                spans[k]
            }
        })
    })
}

/// A span shorter than this (mm) is rounding, not geometry.
const NO_LENGTH_MM: f64 = 1e-6;

fn chain_contour(links: &[(usize, bool)], pieces: &[Piece]) -> Contour {
    // Each span starts at its own start point: gaps within the tolerance close implicitly.
    let vertices: Vec<Vertex> = chain_spans(links, pieces)
        .map(|s| Vertex {
            point: s.start,
            bulge: s.bulge,
        })
        .collect();
    // Spans of no length (an SVG `z` after a path came back to its start, up to the rounding
    // of computed arc ends) would keep the spans on either side from sharing their vertex, and
    // their meeting there would count as a crossing.
    Contour::from_closed_vertices(&vertices, NO_LENGTH_MM)
        .unwrap_or_else(|_| Contour::new(vertices))
}

/// The warning for the loops [`Contour::without_small_loops`] removed from a contour, if any.
fn loops_removed(
    repair: &cutroute_geometry::LoopRepair,
    source: &SourceRef,
    limits: &AssembleLimits,
) -> Option<Dropped> {
    let what = repair.describe()?;
    Some(Dropped {
        kind: repair.warning_kind(),
        line: source.line,
        message: format!("closed contour starting with {}: {what}", source.entity),
        left_out: repair.left_out(limits.flatten_tolerance),
    })
}

struct Placed {
    contour: Contour,
    source: SourceRef,
    area: f64,
    bbox: BoundingBox,
    /// The contour flattened within the flattening tolerance: where containment samples it
    /// when this contour is the inner one.
    polygon: Vec<Point>,
}

fn group_into_parts(
    contours: Vec<(Contour, SourceRef)>,
    limits: &AssembleLimits,
    dropped: &mut Vec<Dropped>,
) -> Vec<Part> {
    let tolerance = limits.join_tolerance;
    let mut placed: Vec<Placed> = Vec::with_capacity(contours.len());
    for (contour, source) in contours {
        // The one repair first: loops too small to cut where an outline touches or crosses
        // itself are removed, said, and the rest of the outline kept.
        let (contour, fault) = match contour.without_small_loops(tolerance) {
            Ok(repair) => {
                dropped.extend(loops_removed(&repair, &source, limits));
                (repair.contour, None)
            }
            Err(fault) => (contour, Some(fault)),
        };
        let area = contour.signed_area();
        // The one meaning of a contour: a drawing commonly carries lines drawn twice (which
        // join into loops enclosing nothing) and crossing outlines; they are left out, said.
        if let Some(fault) = fault {
            let (kind, why) = match &fault {
                ContourFault::SelfIntersecting { x, y, .. } => (
                    WarningKind::SelfIntersecting,
                    format!("crosses itself at ({x:.4}, {y:.4})"),
                ),
                f if f.is_zero_area() => (
                    WarningKind::ZeroArea,
                    "encloses no area (lines drawn twice, or a sliver narrower than the join \
                     tolerance)"
                        .to_string(),
                ),
                other => (WarningKind::Other, other.to_string()),
            };
            dropped.push(Dropped {
                kind,
                line: source.line,
                message: format!(
                    "closed contour starting with {} {why}; left out",
                    source.entity
                ),
                left_out: vec![closed_polyline(&contour, limits.flatten_tolerance)],
            });
            continue;
        }
        let bbox = contour.bounding_box();
        let polygon = contour.flatten(limits.flatten_tolerance.min(tolerance));
        placed.push(Placed {
            contour,
            source,
            area,
            bbox,
            polygon,
        });
    }
    // Largest first: every container comes before what it contains.
    placed.sort_by(|a, b| b.area.abs().total_cmp(&a.area.abs()));

    let mut parent: Vec<Option<usize>> = vec![None; placed.len()];
    let mut depth: Vec<usize> = vec![0; placed.len()];
    let mut duplicate = vec![false; placed.len()];
    // Candidate containers come from an R-tree of the boxes: checking every larger contour
    // was quadratic (a 224-byte MINSERT of 400 × 400 circles ran for minutes).
    let boxes = rstar::RTree::bulk_load(
        placed
            .iter()
            .enumerate()
            .map(|(j, p)| {
                rstar::primitives::GeomWithData::new(
                    rstar::primitives::Rectangle::from_corners(
                        [p.bbox.min.x, p.bbox.min.y],
                        [p.bbox.max.x, p.bbox.max.y],
                    ),
                    j,
                )
            })
            .collect(),
    );
    for i in 0..placed.len() {
        let reach = placed[i].bbox.expanded(tolerance);
        let query =
            rstar::AABB::from_corners([reach.min.x, reach.min.y], [reach.max.x, reach.max.y]);
        // Same order as the scan they replace: the nearest larger contour first.
        let mut candidates: Vec<usize> = boxes
            .locate_in_envelope_intersecting(&query)
            .map(|g| g.data)
            .filter(|&j| j < i)
            .collect();
        candidates.sort_unstable_by(|a, b| b.cmp(a));
        for j in candidates {
            if duplicate[j] {
                continue;
            }
            let (inner, outer) = (&placed[i], &placed[j]);
            if !outer.bbox.expanded(tolerance).contains_box(&inner.bbox) {
                continue;
            }
            match containment(inner, outer, tolerance) {
                Containment::Inside => {
                    parent[i] = Some(j);
                    depth[i] = depth[j] + 1;
                    break;
                }
                Containment::Same => {
                    duplicate[i] = true;
                    dropped.push(Dropped {
                        kind: WarningKind::Duplicate,
                        line: inner.source.line,
                        message: format!(
                            "closed contour starting with {} duplicates the one at line {}; dropped",
                            inner.source.entity, outer.source.line
                        ),
                        left_out: vec![closed_polyline(
                            &inner.contour,
                            limits.flatten_tolerance,
                        )],
                    });
                    break;
                }
                Containment::Outside => {}
            }
        }
    }

    // Parts in file order of their outer contours; holes in file order too.
    let mut part_of: Vec<Option<usize>> = vec![None; placed.len()];
    let mut outers: Vec<usize> = (0..placed.len())
        .filter(|&i| !duplicate[i] && depth[i].is_multiple_of(2))
        .collect();
    outers.sort_by_key(|&i| placed[i].source.line);
    for (k, &i) in outers.iter().enumerate() {
        part_of[i] = Some(k);
    }
    let mut holes: Vec<usize> = (0..placed.len())
        .filter(|&i| !duplicate[i] && depth[i] % 2 == 1)
        .collect();
    holes.sort_by_key(|&i| placed[i].source.line);

    let mut parts: Vec<Part> = outers
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let p = &placed[i];
            let contour = if p.area > 0.0 {
                p.contour.reversed()
            } else {
                p.contour.clone()
            };
            Part {
                name: format!("{}#{}", p.source.layer, k + 1),
                contours: vec![contour],
            }
        })
        .collect();
    for i in holes {
        let p = &placed[i];
        let Some(owner) = parent[i].and_then(|j| part_of[j]) else {
            continue;
        };
        let contour = if p.area < 0.0 {
            p.contour.reversed()
        } else {
            p.contour.clone()
        };
        parts[owner].contours.push(contour);
    }
    parts
}

enum Containment {
    Inside,
    Outside,
    /// Every sample lies on the other's boundary: the same contour twice.
    Same,
}

/// Votes over samples of the inner contour (its flattened outline's vertices and chord
/// midpoints), tested against the outer contour's true arcs and ignoring samples on the outer
/// boundary: contours that touch stay decidable, identical ones are recognised.
fn containment(inner: &Placed, outer: &Placed, tolerance: f64) -> Containment {
    let n = inner.polygon.len();
    let stride = (n / 32).max(1);
    let (mut inside, mut outside) = (0usize, 0usize);
    let mut k = 0;
    while k < n {
        let a = inner.polygon[k];
        let b = inner.polygon[(k + 1) % n];
        for p in [a, a.midpoint(b)] {
            if outer.contour.distance_to(p) <= tolerance {
                continue;
            }
            if outer.contour.contains(p) {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        k += stride;
    }
    if inside == 0 && outside == 0 {
        if (inner.area.abs() - outer.area.abs()).abs()
            <= tolerance * (inner.polygon.len() as f64).max(1.0) * 10.0
        {
            Containment::Same
        } else {
            Containment::Outside
        }
    } else if inside > outside {
        Containment::Inside
    } else {
        Containment::Outside
    }
}

/// The curve and joining settings DXF and SVG import share, checked once for both: the
/// approximation tolerance at least 1e-6 mm, the join tolerance positive, a span budget.
pub(crate) fn check_curve_options(
    approximation_tolerance: f64,
    join_tolerance: f64,
    max_spans: usize,
) -> Result<(), String> {
    let ok = |t: f64| t.is_finite() && t > 0.0;
    if !ok(approximation_tolerance) || approximation_tolerance < 1e-6 {
        return Err(format!(
            "approximation tolerance {approximation_tolerance} must be at least 1e-6 mm"
        ));
    }
    if !ok(join_tolerance) || join_tolerance < 1e-9 {
        return Err(format!("join tolerance {join_tolerance} must be positive"));
    }
    if max_spans == 0 {
        return Err("max_spans must be positive".into());
    }
    Ok(())
}

/// Whether scales stay within 1e6 and offsets within 1e12 mm: with input coordinates bounded
/// by 1e9, every transformed point is then finite with room to spare, so nested inserts (DXF)
/// and nested transforms (SVG) cannot overflow to infinity or NaN.
pub(crate) fn is_bounded(t: &Transform) -> bool {
    t.matrix.iter().flatten().all(|v| v.abs() <= 1e6)
        && t.offset.x.abs() <= 1e12
        && t.offset.y.abs() <= 1e12
}
