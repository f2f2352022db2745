//! The one error type of the CAD readers: the failures DXF, SVG and T-FLEX share (text that is
//! not UTF-8, malformed XML, unusable options, a drawing too complex or with nothing closed) are
//! one variant each, and each format has its own variants where its failures differ. Every
//! variant that concerns a place in the file says where in its message: a DXF line, an XML line
//! and column (with the element path for T-FLEX), or a byte offset.

use roxmltree::Document;

/// Why a CAD file could not be read. The DXF reader returns the shared variants and the
/// `DXF:` ones, the SVG reader the shared and `SVG:` ones, the T-FLEX reader the shared and
/// `T-FLEX:` ones. DXF lines are 1-based lines of the file; XML `line`/`column` are 1-based
/// positions; T-FLEX `path`s are element paths such as
/// `/Project/Parts/PartDefinition[2]/PartProfile/Contours/Contour[1]`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CadError {
    /// The file is not UTF-8 (SVG, T-FLEX).
    #[error("byte {byte}: the file is not valid UTF-8")]
    NotUtf8 {
        /// Offset of the first invalid byte.
        byte: usize,
    },
    /// The file is not well-formed XML (SVG, T-FLEX).
    #[error("{line}:{column}: malformed XML: {source}")]
    Xml {
        /// What the XML parser says.
        #[source]
        source: roxmltree::Error,
        /// Line of the error.
        line: u32,
        /// Column of the error.
        column: u32,
    },
    /// The drawing would produce more spans than the options' `max_spans` (DXF, SVG).
    #[error(
        "the drawing needs more than {limit} spans (a block explosion or too fine a tolerance)"
    )]
    TooComplex {
        /// The limit that was hit.
        limit: usize,
    },
    /// The options are unusable: tolerances (and SVG's scales) must be finite and positive
    /// (DXF, SVG).
    #[error("invalid options: {0}")]
    InvalidOptions(String),
    /// The drawing yields no closed contour at all (DXF, SVG).
    #[error("no closed contour in the drawing ({open} open chains, first: {first})")]
    NothingClosed {
        /// How many open chains there are.
        open: usize,
        /// The first open chain, described (with its line or element).
        first: String,
    },

    /// DXF: a binary DXF file that does not read, at a byte offset (binary files have no
    /// lines).
    #[error("byte {offset}: binary DXF: {reason}")]
    BinaryDxf {
        /// Offset of the group concerned.
        offset: usize,
        /// What is wrong.
        reason: String,
    },
    /// DXF: a group code line does not hold an integer.
    #[error("line {line}: group code expected, found {text:?}")]
    BadGroupCode {
        /// Line of the would-be group code.
        line: usize,
        /// What stands there.
        text: String,
    },
    /// DXF: the file ends after a group code, before its value (truncated file).
    #[error("line {line}: group code {code} has no value line (file truncated?)")]
    MissingValue {
        /// Line of the group code.
        line: usize,
        /// The group code.
        code: i32,
    },
    /// DXF: a value that must be a number is not one (or is NaN or infinite).
    #[error("line {line}: group {code} must be a finite number, found {text:?}")]
    BadNumber {
        /// Line of the value.
        line: usize,
        /// Its group code.
        code: i32,
        /// What stands there.
        text: String,
    },
    /// DXF: a number is beyond ±1e9, larger than any drawing in millimetres.
    #[error("line {line}: group {code} value {value} is out of range (|value| > 1e9)")]
    OutOfRange {
        /// Line of the value.
        line: usize,
        /// Its group code.
        code: i32,
        /// The value.
        value: f64,
    },
    /// DXF: a section, block or polyline is not closed before the file ends (truncated file).
    #[error("line {line}: {what} is not terminated before the end of the file (truncated?)")]
    Unterminated {
        /// Line where the unterminated item starts.
        line: usize,
        /// What it is (`section ENTITIES`, `block X`, …).
        what: String,
    },
    /// DXF: the file has no `ENTITIES` section.
    #[error("the file has no ENTITIES section")]
    NoEntities,
    /// DXF: an entity lacks a group it cannot do without.
    #[error("line {line}: {entity} has no group {code} ({meaning})")]
    MissingGroup {
        /// Line of the entity.
        line: usize,
        /// Entity type.
        entity: String,
        /// The missing group code.
        code: i32,
        /// What the group means.
        meaning: &'static str,
    },
    /// DXF: a spline whose data are inconsistent (degree, counts, knots, weights).
    #[error("line {line}: invalid SPLINE: {reason}")]
    InvalidSpline {
        /// Line of the spline.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// DXF: another inconsistent entity (negative counts, absurd array sizes, …).
    #[error("line {line}: invalid {entity}: {reason}")]
    InvalidEntity {
        /// Line of the entity.
        line: usize,
        /// Entity type.
        entity: String,
        /// What is wrong.
        reason: String,
    },
    /// DXF: an `INSERT` names a block the file does not define.
    #[error("line {line}: INSERT of undefined block {name:?}")]
    UnknownBlock {
        /// Line of the INSERT.
        line: usize,
        /// The block name.
        name: String,
    },
    /// DXF: blocks insert each other deeper than the limit (or in a cycle).
    #[error("line {line}: blocks nest deeper than {limit} levels at block {name:?} (cycle?)")]
    BlockNestingTooDeep {
        /// Line of the innermost INSERT.
        line: usize,
        /// The block being inserted.
        name: String,
        /// The depth limit.
        limit: usize,
    },

    /// SVG: the root element is not `<svg>`.
    #[error("the root element is <{found}>, expected <svg>")]
    NotSvg {
        /// The root element found.
        found: String,
    },
    /// SVG: an attribute's value is not what it must be.
    #[error("{line}:{column}: <{element}> attribute {attribute}={value:?}: {reason}")]
    BadAttribute {
        /// The element's tag name.
        element: String,
        /// The attribute.
        attribute: String,
        /// Its value (shortened to 80 characters).
        value: String,
        /// What is wrong.
        reason: String,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// SVG: path data that does not parse.
    #[error("{line}:{column}: <path> d, character {offset}: {reason}")]
    BadPathData {
        /// 0-based character offset in the `d` attribute.
        offset: usize,
        /// What is wrong.
        reason: String,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// SVG: elements nest deeper than the limit.
    #[error("{line}:{column}: elements nest deeper than {limit} levels")]
    TooDeep {
        /// The limit.
        limit: usize,
        /// Line of the innermost element.
        line: u32,
        /// Column of the innermost element.
        column: u32,
    },

    /// T-FLEX: the root element is not `Project`.
    #[error("the root element is <{found}>, expected <Project>")]
    NotAProject {
        /// The root element found.
        found: String,
    },
    /// T-FLEX: a required child element is missing.
    #[error("{line}:{column}: {path} has no <{element}>")]
    MissingElement {
        /// Path of the parent element.
        path: String,
        /// The missing child.
        element: &'static str,
        /// Line of the parent.
        line: u32,
        /// Column of the parent.
        column: u32,
    },
    /// T-FLEX: an element's text is not what it must be (a finite number, a boolean, an integer).
    #[error("{line}:{column}: {path} must be {expected}, found {text:?}")]
    BadValue {
        /// Path of the element.
        path: String,
        /// What was expected.
        expected: &'static str,
        /// The text found.
        text: String,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// T-FLEX: a contour or contour object of a type this reader does not know.
    #[error("{line}:{column}: {path} has unknown type {found:?}")]
    UnknownType {
        /// Path of the element.
        path: String,
        /// The `xsi:type` found.
        found: String,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// T-FLEX: geometry that cannot be cut: zero radius, a broken contour, an empty profile, …
    #[error("{line}:{column}: {path}: {reason}")]
    InvalidGeometry {
        /// Path of the element.
        path: String,
        /// What is wrong.
        reason: String,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// T-FLEX: a placement names a part or sheet the project does not define.
    #[error("{line}:{column}: {path} refers to undefined {what} {id}")]
    UnknownReference {
        /// Path of the referring element.
        path: String,
        /// `part` or `sheet`.
        what: &'static str,
        /// The missing ID.
        id: i64,
        /// Line of the element.
        line: u32,
        /// Column of the element.
        column: u32,
    },
    /// T-FLEX: the placed geometry would exceed the size limit.
    #[error("the placed parts would have more than {limit} vertices")]
    TooLarge {
        /// The vertex limit.
        limit: usize,
    },
}

/// The text of an XML file: UTF-8 (else [`CadError::NotUtf8`] at the first bad byte), without
/// a byte-order mark.
pub(crate) fn xml_text(bytes: &[u8]) -> Result<&str, CadError> {
    let text = std::str::from_utf8(bytes).map_err(|e| CadError::NotUtf8 {
        byte: e.valid_up_to(),
    })?;
    Ok(text.strip_prefix('\u{FEFF}').unwrap_or(text))
}

/// The parsed XML document, or [`CadError::Xml`] with the parser's error as its source. A
/// truncated file is located at its end, where the text stops (the parser places that error
/// at the start).
pub(crate) fn xml_document<'t>(
    text: &'t str,
    parsing: roxmltree::ParsingOptions<'t>,
) -> Result<Document<'t>, CadError> {
    Document::parse_with_options(text, parsing).map_err(|source| {
        let (line, column) = match source {
            roxmltree::Error::UnclosedRootNode | roxmltree::Error::UnexpectedEndOfStream => {
                end_position(text)
            }
            _ => (source.pos().row, source.pos().col),
        };
        CadError::Xml {
            source,
            line,
            column,
        }
    })
}

/// The 1-based line and column just past the last character of `text`.
fn end_position(text: &str) -> (u32, u32) {
    let line = text.bytes().filter(|&b| b == b'\n').count() + 1;
    let column = text.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (
        u32::try_from(line).unwrap_or(u32::MAX),
        u32::try_from(column).unwrap_or(u32::MAX),
    )
}
