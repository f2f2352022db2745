//! Base segments and the ensembles of them that one nest gives.

use std::collections::HashMap;

use cutroute_aoe::{PlanGraph, PlanOptions};
use cutroute_geometry::{ContainmentForest, ContourRef, Nest, Point, Span};
use serde::{Deserialize, Serialize};

use crate::SegmentError;

/// A base segment: a chain of spans end to end that a route cuts whole from one pierce. It has
/// no cutting direction of its own: an open segment is cut from either end, a closed one from
/// any point of it round in the direction of its spans (the CCP rule).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// The spans, each starting where the previous one ends.
    pub spans: Vec<Span>,
    /// Whether the last span ends where the first starts.
    pub closed: bool,
    /// The contours the spans lie on (two or more along common edges), sorted.
    pub contours: Vec<ContourRef>,
}

impl Segment {
    /// A segment from spans; closed when the chain ends within `tolerance` of its start.
    pub fn new(spans: Vec<Span>, mut contours: Vec<ContourRef>, tolerance: f64) -> Segment {
        contours.sort();
        contours.dedup();
        let closed = match (spans.first(), spans.last()) {
            (Some(a), Some(b)) => a.start.distance(b.end) <= tolerance,
            _ => false,
        };
        Segment {
            spans,
            closed,
            contours,
        }
    }

    /// Tool-on length, mm.
    pub fn length(&self) -> f64 {
        self.spans.iter().map(|s| s.length()).sum()
    }

    /// Where the spans start.
    pub fn first_point(&self) -> Point {
        self.spans.first().map_or_else(Point::default, |s| s.start)
    }

    /// Where the spans end.
    pub fn last_point(&self) -> Point {
        self.spans.last().map_or_else(Point::default, |s| s.end)
    }
}

/// How an ensemble's base segments are made from the nest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum EnsembleKind {
    /// Standard cutting: every contour one closed segment (the CCP).
    Standard,
    /// Multi-contour cutting: the chains of an OE-route of the plan graph
    /// ([`PlanGraph::route`]): neighbouring parts cut along their common edges once, few
    /// pierces; chains of one connected piece keep their order.
    Chains,
    /// Contours split at junctions: every edge of the plan graph (a common edge once, the
    /// rest of each contour between the points where neighbours touch it) one segment.
    Junctions,
}

impl EnsembleKind {
    /// Every kind, in the order GSCCP tries them.
    pub const ALL: [EnsembleKind; 3] = [
        EnsembleKind::Standard,
        EnsembleKind::Chains,
        EnsembleKind::Junctions,
    ];

    /// A short lower-case name (`standard`, `chains`, `junctions`).
    pub fn name(self) -> &'static str {
        match self {
            EnsembleKind::Standard => "standard",
            EnsembleKind::Chains => "chains",
            EnsembleKind::Junctions => "junctions",
        }
    }
}

/// One SCCP: a fixed set of base segments plus the order they must keep.
#[derive(Clone, Debug, PartialEq)]
pub struct Ensemble {
    /// How the segments were made.
    pub kind: EnsembleKind,
    /// The base segments.
    pub segments: Vec<Segment>,
    /// Pairs `(a, b)`: segment `a` must be cut before segment `b`. Holds the containment rule
    /// (every segment touching a contour inside contour C before every segment touching C)
    /// and the ensemble's own rules (the order of chains in one piece of the plan graph).
    pub precedence: Vec<(usize, usize)>,
}

impl Ensemble {
    /// Builds the ensemble of `kind` for `nest`; `tolerance` (mm) is the plan graph's
    /// (points closer than it are one vertex).
    ///
    /// When the ensemble's own order rules contradict the containment rule (a piece of the
    /// plan holding both a hole and a part in it), they are dropped and only the containment
    /// rule is kept; the route's check then decides.
    pub fn build(nest: &Nest, kind: EnsembleKind, tolerance: f64) -> Result<Self, SegmentError> {
        let ensemble = match kind {
            EnsembleKind::Standard => standard(nest),
            EnsembleKind::Chains => chains(nest, tolerance)?,
            EnsembleKind::Junctions => junctions(nest, tolerance)?,
        };
        let forest = ContainmentForest::new(nest);
        let containment = containment_precedence(&ensemble.segments, &forest);
        let mut full = ensemble.clone();
        full.precedence.extend(containment.iter().copied());
        full.precedence.sort_unstable();
        full.precedence.dedup();
        if full.check_acyclic().is_ok() || ensemble.precedence.is_empty() {
            full.check_acyclic()?;
            return Ok(full);
        }
        let mut relaxed = ensemble.clone();
        relaxed.precedence = containment;
        relaxed.precedence.sort_unstable();
        relaxed.precedence.dedup();
        if relaxed.check_acyclic().is_ok() || kind != EnsembleKind::Chains {
            relaxed.check_acyclic()?;
            return Ok(relaxed);
        }
        // Chains that run across nesting levels (parts touching the hole they sit in) can
        // make containment cyclic. Split every chain where the depths of the contours under
        // its edges change: segments whose contours all share one depth only ever precede
        // shallower ones, so the rule becomes acyclic but for pieces where levels touch.
        let mut split = split_by_depth(ensemble, nest, &forest, tolerance);
        split.precedence = containment_precedence(&split.segments, &forest);
        split.precedence.sort_unstable();
        split.precedence.dedup();
        split.check_acyclic()?;
        Ok(split)
    }

    /// Number of pierces any route of this ensemble makes (one per segment).
    pub fn pierces(&self) -> usize {
        self.segments.len()
    }

    /// Tool-on length of any route of this ensemble, mm.
    pub fn cut_length(&self) -> f64 {
        self.segments.iter().map(Segment::length).sum()
    }

    fn check_acyclic(&self) -> Result<(), SegmentError> {
        let n = self.segments.len();
        let mut indegree = vec![0usize; n];
        let mut next = vec![Vec::new(); n];
        for &(a, b) in &self.precedence {
            indegree[b] += 1;
            next[a].push(b);
        }
        let mut ready: Vec<usize> = (0..n).filter(|&i| indegree[i] == 0).collect();
        let mut seen = 0;
        while let Some(i) = ready.pop() {
            seen += 1;
            for &j in &next[i] {
                indegree[j] -= 1;
                if indegree[j] == 0 {
                    ready.push(j);
                }
            }
        }
        if seen == n {
            Ok(())
        } else {
            let stuck = (0..n).find(|&i| indegree[i] > 0).unwrap_or(0);
            Err(SegmentError::CyclicPrecedence {
                kind: self.kind,
                segment: stuck,
            })
        }
    }
}

/// Splits every segment into maximal runs of spans lying on contours of the same depths.
fn split_by_depth(
    ensemble: Ensemble,
    nest: &Nest,
    forest: &ContainmentForest,
    tolerance: f64,
) -> Ensemble {
    let mut segments = Vec::new();
    for segment in ensemble.segments {
        // The contours each span lies on: those of the segment within tolerance of its
        // middle.
        let depth_of = |c: &ContourRef| forest.depth(*c).unwrap_or(0);
        let mut runs: Vec<(Vec<usize>, Vec<Span>, Vec<ContourRef>)> = Vec::new();
        for span in &segment.spans {
            let mid = span.point_at(0.5);
            let under: Vec<ContourRef> = segment
                .contours
                .iter()
                .copied()
                .filter(|c| {
                    nest.contour(*c)
                        .is_some_and(|k| k.distance_to(mid) <= tolerance)
                })
                .collect();
            let mut depths: Vec<usize> = under.iter().map(depth_of).collect();
            depths.sort_unstable();
            depths.dedup();
            match runs.last_mut() {
                Some((d, spans, contours)) if *d == depths => {
                    spans.push(*span);
                    contours.extend(under);
                }
                _ => runs.push((depths, vec![*span], under)),
            }
        }
        // A closed chain whose last run continues its first: join them.
        if segment.closed && runs.len() > 1 && runs[0].0 == runs[runs.len() - 1].0 {
            let (_, mut spans, mut contours) = runs.pop().expect("more than one run");
            spans.append(&mut runs[0].1);
            contours.append(&mut runs[0].2);
            runs[0].1 = spans;
            runs[0].2 = contours;
        }
        if runs.len() <= 1 {
            segments.push(segment);
            continue;
        }
        for (_, spans, contours) in runs {
            segments.push(Segment::new(spans, contours, tolerance));
        }
    }
    Ensemble {
        kind: ensemble.kind,
        segments,
        precedence: Vec::new(),
    }
}

fn standard(nest: &Nest) -> Ensemble {
    let segments = nest
        .contour_refs()
        .filter_map(|r| {
            let c = nest.contour(r)?;
            (c.span_count() > 0).then(|| Segment {
                spans: c.spans().collect(),
                closed: true,
                contours: vec![r],
            })
        })
        .collect();
    Ensemble {
        kind: EnsembleKind::Standard,
        segments,
        precedence: Vec::new(),
    }
}

fn plan(nest: &Nest, tolerance: f64) -> Result<PlanGraph, SegmentError> {
    let options = PlanOptions {
        tolerance,
        ..PlanOptions::default()
    };
    Ok(PlanGraph::from_nest(nest, &options)?)
}

/// Connected piece of the plan graph each edge belongs to.
fn edge_components(plan: &PlanGraph) -> Vec<usize> {
    let g = plan.graph();
    let mut parent: Vec<usize> = (0..g.vertex_count()).collect();
    fn find(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for e in 0..g.edge_count() {
        let (a, b) = g.ends(e);
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        parent[ra] = rb;
    }
    (0..g.edge_count())
        .map(|e| find(&mut parent, g.ends(e).0))
        .collect()
}

fn chains(nest: &Nest, tolerance: f64) -> Result<Ensemble, SegmentError> {
    let plan = plan(nest, tolerance)?;
    let route = plan.route()?;
    let component = edge_components(&plan);
    let mut segments = Vec::with_capacity(route.len());
    let mut precedence = Vec::new();
    let mut last_of_component: HashMap<usize, usize> = HashMap::new();
    for chain in route {
        let Some(first) = chain.edges.first() else {
            continue;
        };
        let contours = chain
            .edges
            .iter()
            .flat_map(|d| plan.edge_contours(d.edge).iter().copied())
            .collect();
        let index = segments.len();
        // The OE-route's order within one piece of the plan: a chain never encloses edges
        // that later chains cut.
        if let Some(previous) = last_of_component.insert(component[first.edge], index) {
            precedence.push((previous, index));
        }
        segments.push(Segment::new(chain.spans, contours, tolerance));
    }
    Ok(Ensemble {
        kind: EnsembleKind::Chains,
        segments,
        precedence,
    })
}

fn junctions(nest: &Nest, tolerance: f64) -> Result<Ensemble, SegmentError> {
    let plan = plan(nest, tolerance)?;
    let components = plan.components()?;
    let edge_count = plan.graph().edge_count();
    let segments: Vec<Segment> = (0..edge_count)
        .map(|e| {
            Segment::new(
                plan.edge_spans(e).to_vec(),
                plan.edge_contours(e).to_vec(),
                tolerance,
            )
        })
        .collect();
    // Within a piece of the plan, edges farther from its outer face first: a closed set of
    // cut edges whose last edge has rank r encloses only edges of rank > r, cut before it.
    let mut precedence = Vec::new();
    for component in &components {
        let mut by_rank: HashMap<u32, Vec<usize>> = HashMap::new();
        for (local, &e) in component.edges.iter().enumerate() {
            by_rank
                .entry(component.embedding.edge_rank(local))
                .or_default()
                .push(e);
        }
        let mut ranks: Vec<u32> = by_rank.keys().copied().collect();
        ranks.sort_unstable();
        for w in ranks.windows(2) {
            for &outer in &by_rank[&w[0]] {
                for &inner in &by_rank[&w[1]] {
                    precedence.push((inner, outer));
                }
            }
        }
    }
    Ok(Ensemble {
        kind: EnsembleKind::Junctions,
        segments,
        precedence,
    })
}

/// Every segment touching a contour inside contour C before every segment touching C
/// (pairs within one segment are that segment's own business, checked on the route).
fn containment_precedence(segments: &[Segment], forest: &ContainmentForest) -> Vec<(usize, usize)> {
    let mut touching: HashMap<ContourRef, Vec<usize>> = HashMap::new();
    for (i, s) in segments.iter().enumerate() {
        for &c in &s.contours {
            touching.entry(c).or_default().push(i);
        }
    }
    let mut pairs = Vec::new();
    for (i, s) in segments.iter().enumerate() {
        for &c in &s.contours {
            for outer in forest.ancestors(c) {
                for &j in touching.get(&outer).into_iter().flatten() {
                    if j != i {
                        pairs.push((i, j));
                    }
                }
            }
        }
    }
    pairs
}
