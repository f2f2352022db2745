//! Loose pieces of a drawing → closed contours → parts.
//!
//! Pieces (lines, arcs, open polylines, approximated splines) are joined end to end when their
//! end points lie within the join tolerance. End points live in a uniform grid whose cells are
//! as wide as the tolerance, so a neighbour search looks at 3 × 3 cells and the whole join is
//! linear in the number of pieces for real drawings; what cannot be closed is reported as an
//! open chain.
//!
//! Where more than two ends meet (pieces sharing edges, branches, T-junctions at end points),
//! joining end to end would close an arbitrary loop. Such a group of pieces is read as the
//! plane graph it draws, and every bounded face of it is a contour of its own: a cutting
//! machine cuts every line drawn, so each region enclosed by lines falls out as a piece of its
//! own, and an edge two regions share is one common edge of two parts (which common-edge
//! cutting cuts once). Reading only the outline would drop the inner lines, and reading the
//! inner faces as holes would cut the whole part away. The unbounded face of each connected
//! piece is no contour (its bounded faces draw it); branches that enclose nothing (dangling
//! pieces, bridges between regions) are reported as open chains. Closed contours are then nested by
//! containment: even depth (not inside anything, or inside a hole) starts a part, odd depth is a
//! hole of its container's part. Outer contours are made clockwise, holes counter-clockwise.

use std::cell::OnceCell;
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
    // Pieces of a group with a node where more than two ends meet are not joined end to end
    // (which loop closes there would be arbitrary) but split into the faces of their plane
    // graph, after the joiner.
    let nodes = Nodes::cluster(&pieces, &ends, tolerance);
    let branched = nodes.branched(&pieces, tolerance);
    let mut used: Vec<bool> = pieces
        .iter()
        .zip(&branched)
        .map(|(p, &b)| p.closed || b)
        .collect();
    let mut grid = EndGrid {
        cell: tolerance,
        cells: HashMap::new(),
    };
    for (i, p) in pieces.iter().enumerate() {
        if p.closed {
            contours.push((chain_contour(&[(i, false)], &pieces), p.source.clone()));
            continue;
        }
        if branched[i] {
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

    let members: Vec<usize> = (0..pieces.len()).filter(|&i| branched[i]).collect();
    if !members.is_empty() {
        let (faces, chains, left_out) = faces_of(&pieces, &members, &nodes, limits);
        contours.extend(faces);
        open_chains.extend(chains);
        dropped.extend(left_out);
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
    /// The contour flattened within `flatten_tolerance`, where containment samples it when
    /// this contour is the inner one: made only then, since most contours of a big drawing
    /// (an array insert) have no box around them to test against.
    polygon: OnceCell<Vec<Point>>,
    flatten_tolerance: f64,
}

impl Placed {
    fn polygon(&self) -> &[Point] {
        self.polygon
            .get_or_init(|| self.contour.flatten(self.flatten_tolerance))
    }
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
        placed.push(Placed {
            contour,
            source,
            area,
            bbox,
            polygon: OnceCell::new(),
            flatten_tolerance: limits.flatten_tolerance.min(tolerance),
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
    let polygon = inner.polygon();
    let n = polygon.len();
    let stride = (n / 32).max(1);
    let (mut inside, mut outside) = (0usize, 0usize);
    let mut k = 0;
    while k < n {
        let a = polygon[k];
        let b = polygon[(k + 1) % n];
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
        if (inner.area.abs() - outer.area.abs()).abs() <= tolerance * (n as f64).max(1.0) * 10.0 {
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

/// End points of the open pieces merged into nodes: each end joins the nearest node within the
/// join tolerance (found in a grid of tolerance-wide cells), or starts one.
struct Nodes {
    /// Node of each end (piece·2 + side); `u32::MAX` for the ends of closed pieces.
    of_end: Vec<u32>,
    /// Where each node is: the first end that started it.
    at: Vec<Point>,
}

impl Nodes {
    fn cluster(pieces: &[Piece], ends: &[Point], tolerance: f64) -> Nodes {
        let mut of_end = vec![u32::MAX; ends.len()];
        let mut at: Vec<Point> = Vec::new();
        let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        let key = |p: Point| {
            (
                (p.x / tolerance).floor() as i64,
                (p.y / tolerance).floor() as i64,
            )
        };
        for (id, &p) in ends.iter().enumerate() {
            if pieces[id / 2].closed {
                continue;
            }
            let (kx, ky) = key(p);
            let mut best: Option<(u32, f64)> = None;
            let mut examined = 0;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    let Some(cell) = cells.get(&(kx.saturating_add(dx), ky.saturating_add(dy)))
                    else {
                        continue;
                    };
                    for &n in cell {
                        let d = p.distance(at[n as usize]);
                        if d <= tolerance && best.is_none_or(|(_, bd)| d < bd) {
                            best = Some((n, d));
                        }
                        examined += 1;
                        if examined >= MAX_CANDIDATES {
                            break 'search;
                        }
                    }
                }
            }
            of_end[id] = match best {
                Some((n, _)) => n,
                None => {
                    let n = at.len() as u32;
                    at.push(p);
                    cells.entry((kx, ky)).or_default().push(n);
                    n
                }
            };
        }
        Nodes { of_end, at }
    }

    /// Whether the open piece `i` has both ends at one node and cannot enclose anything there:
    /// a single straight span, or a piece no longer than twice the join tolerance (a closed
    /// curve of length L fits in a disc of diameter L/2, so it would be narrower than the
    /// tolerance).
    fn collapsed(&self, pieces: &[Piece], i: usize, tolerance: f64) -> bool {
        let spans = &pieces[i].spans;
        self.of_end[2 * i] == self.of_end[2 * i + 1]
            && ((spans.len() == 1 && spans[0].bulge == 0.0)
                || spans.iter().map(Span::length).sum::<f64>() <= 2.0 * tolerance)
    }

    /// The open pieces whose connected group of pieces has a node where more than two ends
    /// meet: shared edges and branches, where end-to-end joining is ambiguous.
    fn branched(&self, pieces: &[Piece], tolerance: f64) -> Vec<bool> {
        let mut degree = vec![0u32; self.at.len()];
        let mut sets = UnionFind::new(self.at.len());
        for i in 0..pieces.len() {
            if pieces[i].closed || self.collapsed(pieces, i, tolerance) {
                continue;
            }
            let (a, b) = (self.of_end[2 * i], self.of_end[2 * i + 1]);
            degree[a as usize] += 1;
            degree[b as usize] += 1;
            sets.union(a as usize, b as usize);
        }
        let mut branching = vec![false; self.at.len()];
        for (n, &d) in degree.iter().enumerate() {
            if d > 2 {
                let root = sets.find(n);
                branching[root] = true;
            }
        }
        (0..pieces.len())
            .map(|i| !pieces[i].closed && branching[sets.find(self.of_end[2 * i] as usize)])
            .collect()
    }
}

struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.parent[a] = b;
        }
    }
}

/// The point `s` mm along the spans from their start (their end when they are shorter).
fn point_along(spans: impl Iterator<Item = Span>, mut s: f64) -> Option<Point> {
    let mut last = None;
    for span in spans {
        let length = span.length();
        if length >= s && length > 0.0 {
            return Some(span.point_at(s / length));
        }
        s -= length;
        last = Some(span.end);
    }
    last
}

/// The faces of the plane graph of the branched pieces (see [`assemble`]): closed contours of
/// every bounded face, and the pieces that bound none as open chains.
fn faces_of(
    pieces: &[Piece],
    members: &[usize],
    nodes: &Nodes,
    limits: &AssembleLimits,
) -> (Vec<(Contour, SourceRef)>, Vec<OpenChain>, Vec<Dropped>) {
    let tolerance = limits.join_tolerance;
    let mut leftover: Vec<usize> = Vec::new();
    // Edge e runs over piece edges[e] from node ends[2e] to node ends[2e+1]; half-edge h is
    // edge h/2 forwards when h is even, backwards when odd.
    let mut edges: Vec<usize> = Vec::new();
    for &i in members {
        if nodes.collapsed(pieces, i, tolerance) {
            leftover.push(i);
        } else {
            edges.push(i);
        }
    }
    let origin = |h: usize| nodes.of_end[2 * edges[h / 2] + (h % 2)] as usize;
    // Direction in which each half-edge leaves its node: towards a point a little way along
    // it, measured from the node (not from the piece's own end), so that pieces meeting within
    // the tolerance but offset from each other are ordered as drawn, and tangent pieces by
    // their curvature.
    let reach = 10.0 * tolerance;
    let angle: Vec<f64> = (0..2 * edges.len())
        .map(|h| {
            let piece = &pieces[edges[h / 2]];
            let length: f64 = piece.spans.iter().map(Span::length).sum();
            let s = (0.5 * length).min(reach);
            let along = if h % 2 == 0 {
                point_along(piece.spans.iter().copied(), s)
            } else {
                point_along(piece.spans.iter().rev().map(|sp| sp.reversed()), s)
            };
            let from = nodes.at[origin(h)];
            let d = along.unwrap_or(from) - from;
            d.y.atan2(d.x)
        })
        .collect();

    let mut alive = vec![true; edges.len()];
    let mut dropped = Vec::new();
    let mut duplicate = vec![false; edges.len()];
    // Two pieces between the same two nodes that enclose a sliver narrower than the tolerance
    // (as `check_cuttable` measures thinness) are one edge drawn twice: a hatch line whose
    // ends touch an outline's corners, an edge redrawn a little off. The first is kept.
    let mut between: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for e in 0..edges.len() {
        let (a, b) = (origin(2 * e), origin(2 * e + 1));
        if a == b {
            continue;
        }
        let list = between.entry((a.min(b), a.max(b))).or_default();
        let twin = list.iter().copied().find(|&k| {
            let links = [
                (edges[k], false),
                (edges[e], origin(2 * e) == origin(2 * k)),
            ];
            let loop_ = chain_contour(&links, pieces);
            loop_.area() < tolerance * loop_.perimeter() / 2.0
        });
        match twin {
            Some(k) => {
                alive[e] = false;
                duplicate[e] = true;
                let (this, kept) = (&pieces[edges[e]].source, &pieces[edges[k]].source);
                dropped.push(Dropped {
                    kind: WarningKind::Duplicate,
                    line: this.line,
                    message: format!(
                        "{} runs along the {} at line {} within the join tolerance, between the \
                         same end points; ignored",
                        this.entity, kept.entity, kept.line
                    ),
                    left_out: vec![flatten_spans(
                        &pieces[edges[e]].spans,
                        limits.flatten_tolerance,
                    )],
                });
            }
            None => list.push(e),
        }
    }
    // A piece that ends on the inside of another piece of its group (a T-junction away from
    // the other's ends) makes a plane graph that only splitting that piece would complete;
    // its faces read without the split would not be the regions drawn, so such a group is
    // left open, every piece said.
    let unsplit = t_junction_groups(pieces, &edges, &alive, &origin, nodes, tolerance);
    for e in 0..edges.len() {
        if unsplit[e] {
            alive[e] = false;
        }
    }
    prune_branches(&mut alive, &origin, nodes.at.len());
    let mut faces = trace_faces(&alive, &origin, &angle, nodes.at.len());
    // An edge with one face on both sides is a bridge between two pieces (or a branch into a
    // face): it bounds no region, so it is left out and the faces traced again without it.
    let mut bridged = false;
    for (e, live) in alive.iter_mut().enumerate() {
        if *live && faces.face_of[2 * e] == faces.face_of[2 * e + 1] {
            *live = false;
            bridged = true;
        }
    }
    if bridged {
        prune_branches(&mut alive, &origin, nodes.at.len());
        faces = trace_faces(&alive, &origin, &angle, nodes.at.len());
    }

    // Each connected piece of the graph has one unbounded face, the one of least signed area
    // (clockwise, as the bounded faces come out counter-clockwise): it is that piece's outline
    // seen from outside, drawn by the bounded faces already, so it is not a contour of its own.
    let mut sets = UnionFind::new(nodes.at.len());
    for (e, _) in alive.iter().enumerate().filter(|(_, &live)| live) {
        sets.union(origin(2 * e), origin(2 * e + 1));
    }
    let link = |h: usize| (edges[h / 2], h % 2 == 1);
    let mut traced: Vec<(usize, Contour, f64)> = Vec::with_capacity(faces.walks.len());
    let mut outer: HashMap<usize, (usize, f64)> = HashMap::new();
    for (f, walk) in faces.walks.iter().enumerate() {
        // Start at the piece that comes first in the file, as the joiner does.
        let first = (0..walk.len())
            .min_by_key(|&k| edges[walk[k] / 2])
            .unwrap_or(0);
        let links: Vec<(usize, bool)> = walk[first..]
            .iter()
            .chain(&walk[..first])
            .map(|&h| link(h))
            .collect();
        let contour = chain_contour(&links, pieces);
        let area = contour.signed_area();
        let component = sets.find(origin(walk[0]));
        let entry = outer.entry(component).or_insert((f, area));
        if area < entry.1 {
            *entry = (f, area);
        }
        traced.push((links[0].0, contour, area));
    }
    let mut covered = duplicate;
    let mut contours = Vec::new();
    for (f, (start, contour, _)) in traced.into_iter().enumerate() {
        let component = sets.find(origin(faces.walks[f][0]));
        if outer.get(&component).is_some_and(|&(o, _)| o == f) {
            continue;
        }
        for &h in &faces.walks[f] {
            covered[h / 2] = true;
        }
        contours.push((contour, pieces[start].source.clone()));
    }
    // Said, never silent: every piece that bounds no face.
    let mut left: Vec<usize> = (0..edges.len()).filter(|&e| !covered[e]).collect();
    left.sort_unstable();
    let open_chains = chain_leftovers(pieces, nodes, &left, &edges, &leftover, limits);
    (contours, open_chains, dropped)
}

/// The edges of every connected group in which a node of one live end lies on the inside of
/// another piece of the group (farther than the tolerance from that piece's ends).
fn t_junction_groups(
    pieces: &[Piece],
    edges: &[usize],
    alive: &[bool],
    origin: &impl Fn(usize) -> usize,
    nodes: &Nodes,
    tolerance: f64,
) -> Vec<bool> {
    let mut degree: HashMap<usize, u32> = HashMap::new();
    let mut sets = UnionFind::new(nodes.at.len());
    for e in (0..edges.len()).filter(|&e| alive[e]) {
        *degree.entry(origin(2 * e)).or_default() += 1;
        *degree.entry(origin(2 * e + 1)).or_default() += 1;
        sets.union(origin(2 * e), origin(2 * e + 1));
    }
    let spans = rstar::RTree::bulk_load(
        (0..edges.len())
            .filter(|&e| alive[e])
            .flat_map(|e| {
                pieces[edges[e]]
                    .spans
                    .iter()
                    .enumerate()
                    .map(move |(k, s)| {
                        let b = s.bounding_box().expanded(tolerance);
                        rstar::primitives::GeomWithData::new(
                            rstar::primitives::Rectangle::from_corners(
                                [b.min.x, b.min.y],
                                [b.max.x, b.max.y],
                            ),
                            (e, k),
                        )
                    })
            })
            .collect(),
    );
    let mut open_group: HashMap<usize, bool> = HashMap::new();
    for (&n, _) in degree.iter().filter(|(_, &d)| d == 1) {
        let p = nodes.at[n];
        let query = rstar::AABB::from_corners([p.x, p.y], [p.x, p.y]);
        let on_inside = spans.locate_in_envelope_intersecting(&query).any(|g| {
            let (e, k) = g.data;
            let (a, b) = (origin(2 * e), origin(2 * e + 1));
            a != n
                && b != n
                && nodes.at[a].distance(p) > tolerance
                && nodes.at[b].distance(p) > tolerance
                && pieces[edges[e]].spans[k].distance_to(p) <= tolerance
        });
        if on_inside {
            open_group.insert(sets.find(n), true);
        }
    }
    (0..edges.len())
        .map(|e| alive[e] && open_group.contains_key(&sets.find(origin(2 * e))))
        .collect()
}

/// Marks dead every edge on a branch that ends in a node of one end: such a branch encloses
/// nothing, however far it reaches.
fn prune_branches(alive: &mut [bool], origin: &impl Fn(usize) -> usize, node_count: usize) {
    let mut degree = vec![0u32; node_count];
    let mut at: HashMap<usize, Vec<usize>> = HashMap::new();
    for (e, _) in alive.iter().enumerate().filter(|(_, &live)| live) {
        for h in [2 * e, 2 * e + 1] {
            degree[origin(h)] += 1;
            at.entry(origin(h)).or_default().push(h);
        }
    }
    let mut queue: Vec<usize> = (0..node_count).filter(|&n| degree[n] == 1).collect();
    while let Some(n) = queue.pop() {
        if degree[n] != 1 {
            continue;
        }
        let Some(&h) = at[&n].iter().find(|&&h| alive[h / 2]) else {
            continue;
        };
        alive[h / 2] = false;
        degree[n] -= 1;
        let other = origin(h ^ 1);
        degree[other] -= 1;
        if degree[other] == 1 {
            queue.push(other);
        }
    }
}

struct Faces {
    /// The face on the left of each half-edge (`usize::MAX` for dead edges).
    face_of: Vec<usize>,
    /// Each face's boundary walk, as half-edges.
    walks: Vec<Vec<usize>>,
}

/// Faces of the live edges, each to the left of its walk: at every node the half-edges are
/// ordered by angle, and a walk arriving at a node leaves by the half-edge next clockwise from
/// the one it arrived by, so bounded faces run counter-clockwise.
fn trace_faces(
    alive: &[bool],
    origin: &impl Fn(usize) -> usize,
    angle: &[f64],
    node_count: usize,
) -> Faces {
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); node_count];
    for e in 0..alive.len() {
        if alive[e] {
            out[origin(2 * e)].push(2 * e);
            out[origin(2 * e + 1)].push(2 * e + 1);
        }
    }
    let mut position = vec![0usize; 2 * alive.len()];
    for list in &mut out {
        list.sort_by(|&a, &b| angle[a].total_cmp(&angle[b]).then(a.cmp(&b)));
        for (k, &h) in list.iter().enumerate() {
            position[h] = k;
        }
    }
    let mut face_of = vec![usize::MAX; 2 * alive.len()];
    let mut walks = Vec::new();
    for start in 0..2 * alive.len() {
        if !alive[start / 2] || face_of[start] != usize::MAX {
            continue;
        }
        let face = walks.len();
        let mut walk = Vec::new();
        let mut h = start;
        while face_of[h] == usize::MAX {
            face_of[h] = face;
            walk.push(h);
            let twin = h ^ 1;
            let list = &out[origin(twin)];
            h = list[(position[twin] + list.len() - 1) % list.len()];
        }
        walks.push(walk);
    }
    Faces { face_of, walks }
}

/// The pieces that bound no face, joined through the nodes where exactly two of them meet, as
/// open chains (in file order of their first pieces).
fn chain_leftovers(
    pieces: &[Piece],
    nodes: &Nodes,
    left: &[usize],
    edges: &[usize],
    collapsed: &[usize],
    limits: &AssembleLimits,
) -> Vec<OpenChain> {
    let mut items: Vec<usize> = left
        .iter()
        .map(|&e| edges[e])
        .chain(collapsed.iter().copied())
        .collect();
    items.sort_unstable();
    let mut at: HashMap<u32, Vec<usize>> = HashMap::new();
    for &i in &items {
        at.entry(nodes.of_end[2 * i]).or_default().push(i);
        if nodes.of_end[2 * i + 1] != nodes.of_end[2 * i] {
            at.entry(nodes.of_end[2 * i + 1]).or_default().push(i);
        }
    }
    let mut done = vec![false; pieces.len()];
    let mut chains = Vec::new();
    for &first in &items {
        if std::mem::replace(&mut done[first], true) {
            continue;
        }
        let mut chain: std::collections::VecDeque<(usize, bool)> = [(first, false)].into();
        for forward in [true, false] {
            loop {
                let &(p, rev) = if forward {
                    chain.back().expect("chains are never empty")
                } else {
                    chain.front().expect("chains are never empty")
                };
                // The node the chain ends at on this side.
                let node = nodes.of_end[2 * p + usize::from(rev != forward)];
                let Some(list) = at.get(&node).filter(|l| l.len() == 2) else {
                    break;
                };
                let Some(&next) = list.iter().find(|&&q| !done[q]) else {
                    break;
                };
                done[next] = true;
                let at_start = nodes.of_end[2 * next] == node;
                if forward {
                    chain.push_back((next, !at_start));
                } else {
                    chain.push_front((next, at_start));
                }
            }
        }
        let links: Vec<(usize, bool)> = chain.into_iter().collect();
        let spans: Vec<Span> = chain_spans(&links, pieces).collect();
        chains.push(OpenChain {
            polyline: flatten_spans(&spans, limits.flatten_tolerance),
            start: spans[0].start,
            end: spans[spans.len() - 1].end,
            length: spans.iter().map(Span::length).sum(),
            entities: links
                .iter()
                .map(|&(p, _)| pieces[p].source.clone())
                .collect(),
        });
    }
    chains
}
