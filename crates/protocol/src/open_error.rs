//! Why a file could not be opened, as data: a kind with its parameters and the place in the
//! file, so the page words it in its own language; `message` is the English text the CLI prints.

use serde::{Deserialize, Serialize};

/// Where in a file a reader stopped.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SourceLocation {
    /// A line (from 1), and a column (from 1) when the reader knows it.
    Line {
        /// The line.
        line: usize,
        /// The column.
        column: Option<usize>,
    },
    /// A byte offset (from 0) of a binary file.
    Byte {
        /// The offset.
        offset: usize,
    },
    /// A place in a JSON document (`[1].paths[0]`).
    JsonPath {
        /// The path.
        path: String,
    },
}

/// What kind of failure, with the numbers and names it is about.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum OpenErrorKind {
    /// The reader of the detected format refused the file.
    Unreadable {
        /// The format's name (`DBS binary`, `DXF`, …).
        format: String,
    },
    /// A task file alone: it holds no geometry.
    TaskWithoutGeometry,
    /// No known format.
    UnknownFormat,
    /// A JSON object that does not parse, or is none of the JSON formats.
    MalformedJson,
    /// No closed contour to cut.
    NothingToCut,
    /// A G-code program that does not read.
    Gcode,
    /// A G-code program that cuts no closed contour.
    GcodeCutsNothing,
    /// A PCGLNS result alone.
    TourAlone,
    /// Two files of one kind in a batch.
    TwoOfAKind {
        /// The kind, in English words.
        kind: String,
        /// The second file.
        second: String,
    },
    /// A file that combines with none of the others.
    NotCombinable,
    /// A tour that fails the independent checker.
    InfeasibleTour {
        /// What it was checked against.
        against: String,
    },
    /// The tour's checked cost differs from the file's.
    CostMismatch {
        /// What it was checked against.
        against: String,
        /// The cost in the file.
        reported: f64,
        /// The recomputed cost.
        checked: f64,
    },
    /// An instance that does not belong to the task.
    InstanceNotOfTask {
        /// Its nodes.
        nodes: usize,
        /// The task file.
        task: String,
        /// The task's pierce points.
        points: usize,
    },
    /// A task contour on no contour of the nest.
    TaskNotOnNest {
        /// The task contour's 1-based index.
        index: i64,
        /// Its pierce point.
        x: f64,
        /// Its pierce point.
        y: f64,
        /// The nest file.
        nest: String,
    },
    /// The tour is no valid cutting route of the nest.
    InvalidRoute {
        /// The nest file.
        nest: String,
    },
    /// A sheet the file does not have.
    NoSuchSheet {
        /// Asked for, from 1.
        sheet: usize,
        /// Sheets in the file.
        count: usize,
    },
    /// A task with no nest.
    TaskWithoutNest,
}

/// Why a file could not be opened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OpenError {
    /// The file (for two files, the first).
    pub file_name: String,
    /// What kind of failure.
    pub kind: OpenErrorKind,
    /// Where in the file, when the reader says.
    pub location: Option<SourceLocation>,
    /// The reader's or checker's own finding, in English (empty when the kind says it all).
    pub detail: String,
    /// The whole English text, as the CLI prints it.
    pub message: String,
}
