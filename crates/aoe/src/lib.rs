//! Common-edge cutting routes: AOE-chains in plane graphs of cutting plans.
//!
//! When parts of a nest share edges, the cutting plan is a plane graph: curves are edges,
//! touching and crossing points are vertices, and the cyclic order of curves around each point
//! is the embedding. One pierce can then cut a whole cluster of parts along an *AOE-chain*
//! (Makarovskikh 2019, seed 001; digest `docs/science/aoe-chains.md`): an Euler trail that never
//! crosses itself (consecutive edges are neighbours around their vertex, the A-condition) and
//! whose every prefix encloses no uncut edge (ordered enclosing, OE).
//!
//! This crate holds
//! - [`PlaneGraph`]: a rotation system on half-edges (darts), so loops and multiple edges work;
//!   faces, the dual graph; [`Embedding`]: the outer face, face and edge ranks, rank-k cut points;
//! - [`edge_list`]: the paper's edge-list text format (reader with located errors, writer);
//! - [`aoe_chain`]: cut-point splitting and the greedy construction, linear time, with the
//!   digest's corrections (split rule, per-edge orientation, half-edges, stop at |E|, failure
//!   reported as an error);
//! - [`check_chain`], [`check_route`], [`PlanGraph::check_route`]: independent checkers of the
//!   Euler, A / non-crossing and OE properties (for a whole plan, across components too);
//! - [`PlanGraph`]: the plane graph of a nest's contours (common edges merged, curves split at
//!   touching and crossing points, rotation by tangent angle and curvature);
//! - [`oe_route`]: beyond 4-regular graphs (T-junctions, any degree): non-crossing chains
//!   joined by idle moves, ordered so the whole route is OE, with few pierces;
//!   [`PlanGraph::route`] runs it on every component of a nest, inner components first;
//! - [`solve_nest`]: the solver behind `--solver aoe`: a nest in, a [`cutroute_geometry::PathRoute`]
//!   out (components ordered inner-first with short idle moves), checked by both checkers;
//! - [`random`]: seeded random plane 4-regular graphs (medial graphs of random plane multigraphs).
//!
//! [`pierce_lower_bound`] (and the job's `lb` built on it) bounds the routes of the plan model
//! that cut every plan edge once as trails: tool-on only along the plan's edges, the torch off
//! between paths. Routes that cut a common edge twice, and chain routes whose tool-on links
//! run through the scrap, are outside it (the README's solver table says which routes every
//! solver's `lb` bounds).
//!
//! ```
//! use cutroute_aoe::{aoe_chain, check_chain, AoeOptions, Embedding, PlaneGraph};
//!
//! // Two loops at one vertex side by side (a figure-eight): darts 0,1 of loop 0, then 2,3.
//! let graph = PlaneGraph::from_rotations(1, &[(0, 0), (0, 0)], &[vec![0, 1, 2, 3]])?;
//! // The outer face is the one left of dart 1 (outside both loops).
//! let embedding = Embedding::with_outer_dart(graph, 1)?;
//! assert_eq!(embedding.cut_points().len(), 1); // the vertex is a rank-1 cut point
//! let chain = aoe_chain(&embedding, 0, &AoeOptions::default())?;
//! assert_eq!(chain.darts.len(), 2);
//! check_chain(&embedding, &chain.darts)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod chain;
mod check;
pub mod edge_list;
mod embedding;
mod graph;
mod plan;
pub mod random;
mod route;
mod solve;

pub use chain::{
    aoe_chain, split_cut_points, AoeChain, AoeError, AoeOptions, SplitRule, Transitions,
};
pub use check::{check_chain, check_route, CheckError};
pub use cutroute_anytime::{run_to_end, AnytimeSolver, Bounds, Status};
pub use embedding::{CutPoint, Embedding, EmbeddingError};
pub use graph::{Dart, DualGraph, Faces, GraphError, PlaneGraph};
pub use plan::{CutChain, DirectedEdge, PlanComponent, PlanError, PlanGraph, PlanOptions};
pub use route::{oe_route, pierce_lower_bound, OeRoute};
pub use solve::{
    solve_nest, AoeHeat, AoeSolution, AoeSolveError, AoeSolveOptions, AoeSolving, AoeStage,
};
