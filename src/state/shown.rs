//! What the drawing, the stats and the exports show: the job's best result, else the result
//! the file holds, and the head's moves along it.

use cutroute_geometry::{Nest, PathRoute, Route, Toolpath};
use leptos::prelude::*;

use crate::drawing::path_route_toolpath;
use crate::state::{DocumentState, JobState};

/// The nest and route shown.
#[derive(Clone, Copy)]
pub struct Shown {
    pub nest: Signal<Option<Nest>>,
    /// A route of whole contours; none while tool-on paths are shown.
    pub route: Signal<Option<Route>>,
    /// A route of tool-on paths (segment cutting, AOE, or a G-code file's open paths).
    pub paths: Signal<Option<PathRoute>>,
    /// The head's moves: drawn, animated and exported.
    pub toolpath: Signal<Option<Toolpath>>,
    /// CCP's certificate of each contour of the route, in its order.
    pub certified: Memo<Vec<bool>>,
}

impl Shown {
    /// Follows the document and the job.
    pub fn new(document: DocumentState, job: JobState) -> Self {
        let nest = Signal::from(Memo::new(move |_| document.nest()));
        // Once the job has reported, its result is shown (routes of whole contours or tool-on
        // paths); before, the tool-on paths of a G-code file that cuts open paths.
        let paths = Signal::from(Memo::new(move |_| {
            if job.progress.with(Option::is_some) {
                job.best_paths.get()
            } else {
                document.file_paths.get()
            }
        }));
        // The solver's best route, or else the route the file holds (result files); none
        // while tool-on paths are shown.
        let route = Signal::from(Memo::new(move |_| {
            if paths.with(Option::is_some) {
                return None;
            }
            job.best_route.get().or_else(|| {
                document
                    .document
                    .with(|d| d.as_ref().and_then(|d| d.route.clone()))
            })
        }));
        let toolpath = Signal::from(Memo::new(move |_| {
            nest.with(|nest: &Option<Nest>| {
                let nest = nest.as_ref()?;
                match route.get() {
                    Some(route) => Toolpath::new(&route, nest).ok(),
                    None => paths.with(|p| p.as_ref().map(|p| path_route_toolpath(p, nest))),
                }
            })
        }));
        let certified = Memo::new(move |_| {
            job.progress
                .with(|p| p.as_ref().map(|p| p.certified.clone()).unwrap_or_default())
        });
        Self {
            nest,
            route,
            paths,
            toolpath,
            certified,
        }
    }

    /// Whether a route (of contours or of tool-on paths) is shown.
    pub fn has_route(&self) -> bool {
        self.route.with(Option::is_some) || self.paths.with(Option::is_some)
    }

    /// What one pierce starts, for the animation: a tool-on path or a whole contour.
    pub fn piece(&self) -> &'static str {
        if self.paths.with(Option::is_some) {
            "path"
        } else {
            "contour"
        }
    }
}
