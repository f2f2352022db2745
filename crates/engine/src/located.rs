//! Where a reader's typed error points in its file, for the page's located error messages
//! ([`cutroute_protocol::OpenError`]).

use cutroute_cad::CadError;
use cutroute_formats::{DbsError, JsonError, ReadError};
use cutroute_gcode::GcodeReadError;
use cutroute_pcgtsp::ParseError;
use cutroute_protocol::SourceLocation;

/// A reader's error that may name a place in its file.
pub(crate) trait Located {
    /// The place, if the error names one.
    fn location(&self) -> Option<SourceLocation>;
}

fn at_line(line: usize) -> Option<SourceLocation> {
    Some(SourceLocation::Line { line, column: None })
}

fn line_column(line: usize, column: usize) -> Option<SourceLocation> {
    Some(SourceLocation::Line {
        line,
        column: Some(column),
    })
}

impl Located for ReadError {
    fn location(&self) -> Option<SourceLocation> {
        match self {
            ReadError::Dbs(e) => e.location(),
            ReadError::Json(e) => e.location(),
            _ => None,
        }
    }
}

impl Located for JsonError {
    fn location(&self) -> Option<SourceLocation> {
        match self {
            JsonError::Syntax { line, column, .. } | JsonError::Schema { line, column, .. } => {
                line_column(*line, *column)
            }
            JsonError::BadPoint { path, .. }
            | JsonError::TooShort { path, .. }
            | JsonError::BadContour { path, .. }
            | JsonError::Inconsistent { path, .. } => {
                Some(SourceLocation::JsonPath { path: path.clone() })
            }
        }
    }
}

impl Located for DbsError {
    fn location(&self) -> Option<SourceLocation> {
        match self {
            DbsError::Truncated { offset, .. }
            | DbsError::SizeMismatch { offset, .. }
            | DbsError::RecordOverrun { offset, .. }
            | DbsError::RecordTooShort { offset, .. }
            | DbsError::CopyMatrixSize { offset, .. }
            | DbsError::NegativeId { offset, .. }
            | DbsError::DuplicateId { offset, .. }
            | DbsError::NonFinite { offset, .. }
            | DbsError::SingularMatrix { offset, .. }
            | DbsError::MissingContour { offset, .. }
            | DbsError::CyclicReference { offset, .. }
            | DbsError::EmptyPart { offset, .. }
            | DbsError::BadContour { offset, .. }
            | DbsError::TooManyVertices { offset, .. } => {
                Some(SourceLocation::Byte { offset: *offset })
            }
        }
    }
}

impl Located for CadError {
    fn location(&self) -> Option<SourceLocation> {
        match self {
            CadError::NotUtf8 { byte } => Some(SourceLocation::Byte { offset: *byte }),
            CadError::BadGroupCode { line, .. }
            | CadError::MissingValue { line, .. }
            | CadError::BadNumber { line, .. }
            | CadError::OutOfRange { line, .. }
            | CadError::Unterminated { line, .. }
            | CadError::MissingGroup { line, .. }
            | CadError::InvalidSpline { line, .. }
            | CadError::InvalidEntity { line, .. }
            | CadError::UnknownBlock { line, .. }
            | CadError::BlockNestingTooDeep { line, .. } => at_line(*line),
            CadError::BinaryDxf { offset, .. } => Some(SourceLocation::Byte { offset: *offset }),
            CadError::Xml { line, column, .. }
            | CadError::BadAttribute { line, column, .. }
            | CadError::BadPathData { line, column, .. }
            | CadError::TooDeep { line, column, .. }
            | CadError::MissingElement { line, column, .. }
            | CadError::BadValue { line, column, .. }
            | CadError::UnknownType { line, column, .. }
            | CadError::InvalidGeometry { line, column, .. }
            | CadError::UnknownReference { line, column, .. } => {
                line_column(*line as usize, *column as usize)
            }
            CadError::TooComplex { .. }
            | CadError::InvalidOptions(_)
            | CadError::NothingClosed { .. }
            | CadError::NoEntities
            | CadError::NotSvg { .. }
            | CadError::NotAProject { .. }
            | CadError::TooLarge { .. } => None,
        }
    }
}

impl Located for ParseError {
    fn location(&self) -> Option<SourceLocation> {
        match self {
            ParseError::Empty => None,
            ParseError::UnknownKeyword { line, .. }
            | ParseError::Unsupported { line, .. }
            | ParseError::Missing { line, .. }
            | ParseError::Duplicate { line, .. }
            | ParseError::InvalidNumber { line, .. }
            | ParseError::DimensionOutOfRange { line, .. }
            | ParseError::ClusterCountOutOfRange { line, .. }
            | ParseError::NegativeWeight { line, .. }
            | ParseError::Truncated { line, .. }
            | ParseError::TooManyValues { line, .. }
            | ParseError::Unterminated { line, .. }
            | ParseError::NodeOutOfRange { line, .. }
            | ParseError::ClusterOutOfRange { line, .. }
            | ParseError::ClusterDefinedTwice { line, .. }
            | ParseError::EmptyCluster { line, .. }
            | ParseError::NodeInTwoClusters { line, .. }
            | ParseError::NodeInNoCluster { line, .. }
            | ParseError::SelfPrecedence { line, .. }
            | ParseError::PrecedenceBeforeDepot { line, .. }
            | ParseError::CyclicPrecedence { line, .. }
            | ParseError::BadStartGroup { line, .. } => at_line(*line),
        }
    }
}

impl Located for GcodeReadError {
    fn location(&self) -> Option<SourceLocation> {
        let (l, c) = GcodeReadError::location(self);
        line_column(l, c)
    }
}

impl Located for std::str::Utf8Error {
    fn location(&self) -> Option<SourceLocation> {
        Some(SourceLocation::Byte {
            offset: self.valid_up_to(),
        })
    }
}
