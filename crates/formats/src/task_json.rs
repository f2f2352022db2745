//! The RouteManager cutting task (`rm-task.json`, thesis Listing Г.2): the contour tree
//! (`NestedContours`: inner contours must be cut before the contour containing them), the
//! candidate pierce points of every contour, and the process parameters (`TaskData`).
//!
//! The schema forbids extra properties; real files add `CircuitPointX/Y` and `FinishCutX/Y` to
//! pierce points, which are accepted here. Anything else unknown is rejected with its path.

use cutroute_geometry::{domain, Point};
use serde::{Deserialize, Serialize};

use crate::json::{self, JsonError, JsonWriteError};

/// A cutting task for RouteManager.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "PascalCase", deny_unknown_fields)]
pub struct RmTask {
    /// Process parameters.
    pub task_data: TaskData,
    /// The top-level contours of the tree.
    pub contours: Vec<TaskContour>,
}

/// Process parameters (`TaskData`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "PascalCase", deny_unknown_fields)]
pub struct TaskData {
    /// Start point x (the machine's home, M₀).
    pub start_x: f64,
    /// Start point y.
    pub start_y: f64,
    /// Whether the route must return to the finish point.
    pub terminal_motion: bool,
    /// Finish point x.
    pub finish_x: f64,
    /// Finish point y.
    pub finish_y: f64,
    /// Sheet bounding box: minimum x.
    pub sheet_min_x: f64,
    /// Sheet bounding box: maximum x.
    pub sheet_max_x: f64,
    /// Sheet bounding box: minimum y.
    pub sheet_min_y: f64,
    /// Sheet bounding box: maximum y.
    pub sheet_max_y: f64,
    /// Idle speed V_off, mm/s.
    pub tool_idling_speed: f64,
    /// Cutting speed V_on, mm/s.
    pub tool_cut_speed: f64,
    /// Time per pierce, s.
    pub piercing_duration: f64,
}

impl TaskData {
    /// The start point.
    pub fn start(&self) -> Point {
        Point::new(self.start_x, self.start_y)
    }

    /// The finish point when the route must return (`TerminalMotion`), else `None`.
    pub fn finish(&self) -> Option<Point> {
        self.terminal_motion
            .then(|| Point::new(self.finish_x, self.finish_y))
    }
}

/// A contour of the tree with its candidate pierce points (not its geometry).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "PascalCase", deny_unknown_fields)]
pub struct TaskContour {
    /// 1-based contour index.
    pub index: i64,
    /// 0-based contour index.
    pub zero_based_index: i64,
    /// Candidate pierce points.
    pub points: Vec<PiercePoint>,
    /// Contours directly inside this one; they are cut first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nested_contours: Option<Vec<TaskContour>>,
}

/// A candidate pierce point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "PascalCase", deny_unknown_fields)]
pub struct PiercePoint {
    /// 1-based index within the contour.
    pub index: i64,
    /// 0-based index within the contour.
    pub zero_based_index: i64,
    /// 1-based index among all points of the task.
    pub global_index: i64,
    /// 0-based index among all points of the task.
    pub zero_based_global_index: i64,
    /// Pierce point x.
    #[serde(rename = "X")]
    pub x: f64,
    /// Pierce point y.
    #[serde(rename = "Y")]
    pub y: f64,
    /// The pierce point, the contour's cut-start point and the switch-off point differ.
    pub use_circuit_and_finish_cut_point: bool,
    /// Extension: where cutting of the contour itself starts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circuit_point_x: Option<f64>,
    /// Extension: where cutting of the contour itself starts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circuit_point_y: Option<f64>,
    /// Extension: where the tool is switched off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finish_cut_x: Option<f64>,
    /// Extension: where the tool is switched off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finish_cut_y: Option<f64>,
}

impl PiercePoint {
    /// The pierce point.
    pub fn point(&self) -> Point {
        Point::new(self.x, self.y)
    }
}

/// A contour of the tree visited depth-first, with its place in the tree.
#[derive(Clone, Copy, Debug)]
pub struct FlatTaskContour<'a> {
    /// The contour.
    pub contour: &'a TaskContour,
    /// Depth in the tree (0 = top level).
    pub depth: usize,
    /// Index (in the returned list) of the contour directly containing it.
    pub parent: Option<usize>,
}

impl RmTask {
    /// Every contour of the tree, parents before children (pre-order).
    pub fn flat_contours(&self) -> Vec<FlatTaskContour<'_>> {
        let mut out = Vec::new();
        // An explicit stack: the tree depth is bounded by the JSON parser, but keep it cheap.
        let mut stack: Vec<(&TaskContour, usize, Option<usize>)> =
            self.contours.iter().rev().map(|c| (c, 0, None)).collect();
        while let Some((contour, depth, parent)) = stack.pop() {
            let me = out.len();
            out.push(FlatTaskContour {
                contour,
                depth,
                parent,
            });
            for child in contour.nested_contours.iter().flatten().rev() {
                stack.push((child, depth + 1, Some(me)));
            }
        }
        out
    }

    /// Number of candidate pierce points in the whole task.
    pub fn pierce_point_count(&self) -> usize {
        self.flat_contours()
            .iter()
            .map(|c| c.contour.points.len())
            .sum()
    }
}

/// Reads a task file and checks the schema and the index bookkeeping.
pub fn read_task_json(bytes: &[u8]) -> Result<RmTask, JsonError> {
    let task: RmTask = json::parse(bytes)?;
    validate(&task)?;
    Ok(task)
}

fn validate(task: &RmTask) -> Result<(), JsonError> {
    let d = &task.task_data;
    if d.sheet_min_x > d.sheet_max_x || d.sheet_min_y > d.sheet_max_y {
        return Err(JsonError::Inconsistent {
            path: "TaskData".into(),
            message: "the sheet box has minimum above maximum".into(),
        });
    }
    for (name, v) in [
        ("ToolIdlingSpeed", d.tool_idling_speed),
        ("ToolCutSpeed", d.tool_cut_speed),
    ] {
        // `!(v > 0)` also refuses NaN.
        if !(v > 0.0 && v <= MAX_SPEED) {
            return Err(JsonError::Inconsistent {
                path: format!("TaskData.{name}"),
                message: format!("speed {v} is not within (0, {MAX_SPEED:e}] mm/s"),
            });
        }
    }
    if !(d.piercing_duration >= 0.0 && d.piercing_duration <= MAX_PIERCE_DURATION_S) {
        return Err(JsonError::Inconsistent {
            path: "TaskData.PiercingDuration".into(),
            message: format!(
                "duration {} is not within [0, {MAX_PIERCE_DURATION_S:e}] s",
                d.piercing_duration
            ),
        });
    }
    for (name, v) in [
        ("StartX", d.start_x),
        ("StartY", d.start_y),
        ("FinishX", d.finish_x),
        ("FinishY", d.finish_y),
        ("SheetMinX", d.sheet_min_x),
        ("SheetMaxX", d.sheet_max_x),
        ("SheetMinY", d.sheet_min_y),
        ("SheetMaxY", d.sheet_max_y),
    ] {
        domain::check_coordinate(0, v).map_err(|_| JsonError::Inconsistent {
            path: format!("TaskData.{name}"),
            message: format!("{v} is not a finite coordinate within ±1e9 mm"),
        })?;
    }
    check_contours(&task.contours, "Contours")
}

/// Largest idle or cutting speed a task may give, mm/s (1,000 km/s: no machine comes near).
pub const MAX_SPEED: f64 = 1e9;
/// Longest pierce a task may give, s (about 11.6 days).
pub const MAX_PIERCE_DURATION_S: f64 = 1e6;

fn check_contours(contours: &[TaskContour], path: &str) -> Result<(), JsonError> {
    if contours.is_empty() {
        return Err(JsonError::TooShort {
            path: path.into(),
            len: 0,
            min: 1,
        });
    }
    for (i, c) in contours.iter().enumerate() {
        let here = format!("{path}[{i}]");
        if c.index != c.zero_based_index + 1 {
            return Err(JsonError::Inconsistent {
                path: format!("{here}.Index"),
                message: format!(
                    "Index {} is not ZeroBasedIndex {} + 1",
                    c.index, c.zero_based_index
                ),
            });
        }
        for (j, p) in c.points.iter().enumerate() {
            let at = format!("{here}.Points[{j}]");
            for (name, v) in [("X", p.x), ("Y", p.y)] {
                domain::check_coordinate(j, v).map_err(|_| JsonError::Inconsistent {
                    path: format!("{at}.{name}"),
                    message: format!("{v} is not a finite coordinate within ±1e9 mm"),
                })?;
            }
            if p.index != p.zero_based_index + 1 || p.global_index != p.zero_based_global_index + 1
            {
                return Err(JsonError::Inconsistent {
                    path: at,
                    message: "1-based and 0-based indices differ by other than 1".into(),
                });
            }
        }
        if let Some(nested) = &c.nested_contours {
            // The recursion depth is bounded by serde_json's nesting limit (128).
            check_contours(nested, &format!("{here}.NestedContours"))?;
        }
    }
    Ok(())
}

/// Writes a task file (pretty-printed).
pub fn write_task_json(task: &RmTask) -> Result<String, JsonWriteError> {
    json::to_pretty(task)
}
