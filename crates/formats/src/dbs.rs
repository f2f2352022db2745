//! The legacy binary DBS format of САПР «Сириус» (thesis Appendix В).
//!
//! A file is a chain of records, each a 16-byte header (`size`, `size'`, `type`, `id`, every
//! int16 in a 4-byte little-endian slot) followed by a payload of `4·(size+1) − 16` bytes, and
//! ends with the marker `FF FF FF FF`. This module reads records 1 (contour geometry), 2 (contour
//! copy), 8 (contours of a part), 26 (part name) and 27 (area and perimeter), skips every other
//! type by its size, and writes files the way the reference writer does (contours, 8, 26, 27 per
//! part; no copies; identity matrices).
//!
//! **Record 27.** The reader keeps it as stored ([`DbsPartRecord::area_dm2`],
//! [`DbsPartRecord::perimeter_dm`]). The writer stores the material area (outer contour minus
//! holes) and the total perimeter, computed from the float32 coordinates it writes. The
//! reference writer sums signed contour areas instead, which differs when a file stores holes
//! clockwise (some parts of `test0.json.dbs` do).
//!
//! **The sheet.** DBS has no sheet marker; files written from nests store the sheet as their
//! first part (named e.g. `LIST` or after its area). [`SheetDetection::Auto`] takes the first part
//! as the sheet when the file has more than one part and the first part's outer contour encloses
//! the bounding box of every other part. The writer stores `Nest::sheet` as the first part, so a
//! nest survives the round trip.

use std::collections::{HashMap, HashSet};

use cutroute_geometry::{Contour, Nest, Part, Transform, Vertex};

use crate::contour_check::{self, ContourProblem, DEFAULT_CLOSURE_TOLERANCE};

/// Record type: contour geometry.
const TYPE_GEOMETRY: i16 = 1;
/// Record type: copy of a contour with a transformation.
const TYPE_COPY: i16 = 2;
/// Record type: the contours making up a part.
const TYPE_PART: i16 = 8;
/// Record type: part designation.
const TYPE_NAME: i16 = 26;
/// Record type: part area and perimeter.
const TYPE_DIMENSIONS: i16 = 27;

/// Bytes of a header.
const HEADER_LEN: usize = 16;
/// Bytes of a type-2 record; a type-1 record starts with the same 64 bytes.
const COPY_LEN: usize = 64;
/// Bytes of a stored point (x, y, bulge as float32).
const POINT_LEN: usize = 12;
/// The end-of-file marker the writer appends.
const END_MARKER: [u8; 4] = [0xFF; 4];

/// How the reader decides whether the file's first part is the sheet.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SheetDetection {
    /// The first part is the sheet when there are at least two parts and its outer contour's
    /// bounding box encloses every other part.
    #[default]
    Auto,
    /// The first part is always the sheet (when the file has any part).
    FirstPart,
    /// The file has no sheet: every part goes to `Nest::parts`.
    None,
}

/// The contour with every arc of more than a semicircle (|bulge| > 1) halved at its middle:
/// the same curve, stored well. DBS keeps coordinates and bulges as 32-bit floats, and the
/// chord of a nearly full circle is short next to its radius, so its rounding grows into the
/// radius (a bulge of 9999 moved a perimeter by 0.1 %); each half is at most a semicircle, whose
/// radius follows its chord.
fn with_short_arcs(contour: &Contour) -> std::borrow::Cow<'_, Contour> {
    if contour.vertices.iter().all(|v| v.bulge.abs() <= 1.0) {
        return std::borrow::Cow::Borrowed(contour);
    }
    let mut vertices = Vec::with_capacity(contour.vertices.len() + 1);
    for (v, span) in contour.vertices.iter().zip(contour.spans()) {
        if v.bulge.abs() > 1.0 {
            let (first, second) = span.halved();
            vertices.push(Vertex::arc(first.start.x, first.start.y, first.bulge));
            vertices.push(Vertex::arc(second.start.x, second.start.y, second.bulge));
        } else {
            vertices.push(*v);
        }
    }
    std::borrow::Cow::Owned(Contour::new(vertices))
}

/// Options of [`read_dbs_with`].
#[derive(Clone, Debug, PartialEq)]
pub struct DbsReadOptions {
    /// Where the sheet comes from.
    pub sheet: SheetDetection,
    /// Maximum distance (mm) between a contour's first and last stored point.
    pub closure_tolerance: f64,
    /// Reject contours that cross or touch themselves.
    pub check_self_intersection: bool,
    /// Upper bound on the vertices of the resolved nest: contour copies can multiply a small
    /// file into a huge nest, so hostile input is cut off here.
    pub max_vertices: usize,
}

impl Default for DbsReadOptions {
    fn default() -> Self {
        Self {
            sheet: SheetDetection::Auto,
            closure_tolerance: DEFAULT_CLOSURE_TOLERANCE,
            check_self_intersection: true,
            max_vertices: 10_000_000,
        }
    }
}

/// One part as the file stores it (records 8, 26 and 27 with the same id), the sheet included.
#[derive(Clone, Debug, PartialEq)]
pub struct DbsPartRecord {
    /// The part's record id.
    pub id: i16,
    /// Byte offset of its type-8 record.
    pub offset: usize,
    /// Designation from record 26, unswapped and trimmed (empty when there is none).
    pub name: String,
    /// Ids of its contour records (type 1 or 2), outer first.
    pub contour_ids: Vec<i16>,
    /// Area from record 27, dm² (outer contour minus holes), if the file has that record.
    pub area_dm2: Option<f32>,
    /// Perimeter from record 27, dm (all contours), if the file has that record.
    pub perimeter_dm: Option<f32>,
}

/// What [`read_dbs`] returns: the nest plus the file's own facts about its parts.
#[derive(Clone, Debug, PartialEq)]
pub struct DbsFile {
    /// The resolved nest (copies expanded, closing points dropped).
    pub nest: Nest,
    /// Every part record in file order, the sheet (if any) first.
    pub part_records: Vec<DbsPartRecord>,
    /// How many records of types this reader does not interpret were skipped.
    pub skipped_records: usize,
}

/// Everything that can be wrong with a DBS file; offsets are byte offsets into the file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DbsError {
    /// The file ends inside a record header, or before the end record.
    #[error("DBS truncated at byte {offset}: expected {expected}")]
    Truncated {
        /// Where the missing data should start.
        offset: usize,
        /// What was expected there.
        expected: &'static str,
    },
    /// The header's `size` and `size'` disagree.
    #[error("DBS record at byte {offset}: size {size} differs from its copy size' {size_copy}")]
    SizeMismatch {
        /// Record start.
        offset: usize,
        /// The `size` field.
        size: i16,
        /// The `size'` field.
        size_copy: i16,
    },
    /// The record claims more bytes than the file has left.
    #[error("DBS record at byte {offset} claims {claimed} bytes but only {available} remain")]
    RecordOverrun {
        /// Record start.
        offset: usize,
        /// `4·(size+1)`.
        claimed: usize,
        /// Bytes from the record start to the end of the file.
        available: usize,
    },
    /// The record is too short for its header or for the fields of its type.
    #[error(
        "DBS record at byte {offset} (type {record_type}) is {len} bytes, needs at least {needed}"
    )]
    RecordTooShort {
        /// Record start.
        offset: usize,
        /// Record type.
        record_type: i16,
        /// Its length in bytes.
        len: usize,
        /// The minimum for its type.
        needed: usize,
    },
    /// A type-2 record whose size is not 15: its matrix does not have exactly six numbers.
    #[error("DBS contour copy at byte {offset} has size {size}; its 2×2 matrix and offset need exactly size 15")]
    CopyMatrixSize {
        /// Record start.
        offset: usize,
        /// The record's size field.
        size: i16,
    },
    /// A record id (or a referenced id) is negative.
    #[error("DBS record at byte {offset} uses negative id {id}")]
    NegativeId {
        /// Offset of the field.
        offset: usize,
        /// The id.
        id: i16,
    },
    /// Two records of one kind share an id, or a contour and a part share one.
    #[error("DBS record at byte {offset}: id {id} is already used by {other}")]
    DuplicateId {
        /// Record start.
        offset: usize,
        /// The id.
        id: i16,
        /// What already has it.
        other: &'static str,
    },
    /// A float field is NaN or infinite.
    #[error("DBS value at byte {offset} ({what}) is not a finite number")]
    NonFinite {
        /// Offset of the float.
        offset: usize,
        /// Which field.
        what: &'static str,
    },
    /// The transformation matrix of a contour record has determinant 0.
    #[error("DBS contour record at byte {offset}: its matrix is singular (determinant 0)")]
    SingularMatrix {
        /// Record start.
        offset: usize,
    },
    /// A part or a copy refers to a contour id no type-1/2 record has.
    #[error("DBS record at byte {offset} refers to contour {id}, which the file does not contain")]
    MissingContour {
        /// Start of the referring record.
        offset: usize,
        /// The missing id.
        id: i16,
    },
    /// Following `original` links from a copy comes back to a record already visited.
    #[error("DBS contour copy at byte {offset} (id {id}) is part of a cyclic chain of copies")]
    CyclicReference {
        /// Start of the copy record.
        offset: usize,
        /// Its id.
        id: i16,
    },
    /// A type-8 record lists no contours.
    #[error("DBS part record at byte {offset} (id {id}) lists no contours")]
    EmptyPart {
        /// Record start.
        offset: usize,
        /// Part id.
        id: i16,
    },
    /// A stored contour is unusable (unclosed, degenerate, self-intersecting, …).
    #[error("DBS contour record at byte {offset} (id {id}): {problem}")]
    BadContour {
        /// Record start.
        offset: usize,
        /// Contour id.
        id: i16,
        /// What is wrong.
        problem: ContourProblem,
    },
    /// Resolving the copies would exceed [`DbsReadOptions::max_vertices`].
    #[error("DBS part record at byte {offset} expands the nest beyond {limit} vertices")]
    TooManyVertices {
        /// Start of the part record being resolved.
        offset: usize,
        /// The configured limit.
        limit: usize,
    },
}

/// Everything that can stop [`write_dbs`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DbsWriteError {
    /// More records than 16-bit ids can number.
    #[error("nest needs record id {needed}, beyond the DBS limit 32767")]
    TooManyRecords {
        /// The id that would be needed.
        needed: usize,
    },
    /// A contour has more points than one record can hold.
    #[error("part {part} contour {contour} has {points} points; a DBS record holds at most 10917")]
    ContourTooLong {
        /// Part index (the sheet is 0 when present).
        part: usize,
        /// Contour index.
        contour: usize,
        /// Stored points (closing point included).
        points: usize,
    },
    /// A part without contours cannot be stored.
    #[error("part {part} has no contours")]
    EmptyPart {
        /// Part index (the sheet is 0 when present).
        part: usize,
    },
    /// A contour without vertices cannot be stored.
    #[error("part {part} contour {contour} has no vertices")]
    EmptyContour {
        /// Part index (the sheet is 0 when present).
        part: usize,
        /// Contour index.
        contour: usize,
    },
    /// A coordinate or bulge is NaN, infinite or beyond float32 range.
    #[error("part {part} contour {contour} vertex {vertex} is not representable as float32")]
    NotRepresentable {
        /// Part index (the sheet is 0 when present).
        part: usize,
        /// Contour index.
        contour: usize,
        /// Vertex index.
        vertex: usize,
    },
    /// The part's area or perimeter (record 27, dm², dm) overflows float32.
    #[error("part {part} area or perimeter is beyond float32 range")]
    DimensionsNotRepresentable {
        /// Part index (the sheet is 0 when present).
        part: usize,
    },
    /// The name does not fit 8 CP866 characters (ASCII and Russian letters).
    #[error(
        "part {part} name {name:?} does not fit 8 CP866 characters (ASCII and Russian letters)"
    )]
    NameNotRepresentable {
        /// Part index (the sheet is 0 when present).
        part: usize,
        /// The name.
        name: String,
    },
}

/// Options of [`write_dbs_with`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DbsWriteOptions {
    /// Cut names longer than 8 characters, and write characters CP866 lacks as `?`, instead
    /// of failing.
    pub truncate_long_names: bool,
}

/// Reads a DBS file with [`DbsReadOptions::default`].
pub fn read_dbs(bytes: &[u8]) -> Result<DbsFile, DbsError> {
    read_dbs_with(bytes, &DbsReadOptions::default())
}

/// A type-1 or type-2 record as read.
struct ContourRecord {
    offset: usize,
    original: i16,
    reversed: bool,
    /// The record's map, formula В.1 (`Transform::from_dbs`).
    matrix: Transform,
    /// Type 1 only: the stored contour (closing point dropped, untransformed).
    geometry: Option<Contour>,
}

/// A contour expressed as a transformation of a type-1 record's stored geometry.
#[derive(Clone, Copy)]
struct Resolved {
    base: i16,
    matrix: Transform,
    reversed: bool,
}

#[derive(Default)]
struct PartAcc {
    offset: usize,
    contour_ids: Vec<i16>,
    seen: bool,
    name: Option<String>,
    dimensions: Option<(f32, f32)>,
}

struct Cursor<'a> {
    bytes: &'a [u8],
}

impl Cursor<'_> {
    /// Caller guarantees `at + 2 <= len`.
    fn i16(&self, at: usize) -> i16 {
        i16::from_le_bytes([self.bytes[at], self.bytes[at + 1]])
    }
    /// Caller guarantees `at + 4 <= len`.
    fn f32(&self, at: usize) -> f32 {
        f32::from_le_bytes([
            self.bytes[at],
            self.bytes[at + 1],
            self.bytes[at + 2],
            self.bytes[at + 3],
        ])
    }
    fn finite(&self, at: usize, what: &'static str) -> Result<f64, DbsError> {
        let v = self.f32(at);
        if v.is_finite() {
            Ok(f64::from(v))
        } else {
            Err(DbsError::NonFinite { offset: at, what })
        }
    }
}

/// Reads a DBS file: parses every record, then resolves parts, copies and forward references.
pub fn read_dbs_with(bytes: &[u8], options: &DbsReadOptions) -> Result<DbsFile, DbsError> {
    let cur = Cursor { bytes };
    let mut contours: HashMap<i16, ContourRecord> = HashMap::new();
    let mut parts: HashMap<i16, PartAcc> = HashMap::new();
    let mut part_order: Vec<i16> = Vec::new();
    let mut skipped_records = 0;
    let mut pos = 0usize;
    loop {
        if bytes.len() < pos + 2 {
            return Err(DbsError::Truncated {
                offset: pos,
                expected: "a record header or the end record",
            });
        }
        let size = cur.i16(pos);
        if size < 0 {
            break; // the end record: its first int16 has bit 0x8000 set
        }
        if bytes.len() < pos + HEADER_LEN {
            return Err(DbsError::Truncated {
                offset: pos,
                expected: "a 16-byte record header",
            });
        }
        let size_copy = cur.i16(pos + 4);
        if size_copy != size {
            return Err(DbsError::SizeMismatch {
                offset: pos,
                size,
                size_copy,
            });
        }
        let record_type = cur.i16(pos + 8);
        let len = 4 * (size as usize + 1);
        if len < HEADER_LEN {
            return Err(DbsError::RecordTooShort {
                offset: pos,
                record_type,
                len,
                needed: HEADER_LEN,
            });
        }
        if bytes.len() - pos < len {
            return Err(DbsError::RecordOverrun {
                offset: pos,
                claimed: len,
                available: bytes.len() - pos,
            });
        }
        let id = cur.i16(pos + 12);
        if id < 0 {
            return Err(DbsError::NegativeId {
                offset: pos + 12,
                id,
            });
        }
        let end = pos + len;
        let too_short = |needed: usize| DbsError::RecordTooShort {
            offset: pos,
            record_type,
            len,
            needed,
        };
        match record_type {
            TYPE_GEOMETRY | TYPE_COPY => {
                if len < COPY_LEN {
                    return Err(too_short(COPY_LEN));
                }
                if record_type == TYPE_COPY && len != COPY_LEN {
                    return Err(DbsError::CopyMatrixSize { offset: pos, size });
                }
                if contours.contains_key(&id) {
                    return Err(DbsError::DuplicateId {
                        offset: pos,
                        id,
                        other: "another contour record",
                    });
                }
                let original = cur.i16(pos + 32);
                let reversed = cur.i16(pos + 36) != 0;
                let mut m = [0.0; 6];
                for (k, m) in m.iter_mut().enumerate() {
                    *m = cur.finite(pos + 40 + 4 * k, "transformation matrix")?;
                }
                let matrix = Transform::from_dbs(m[0], m[1], m[2], m[3], m[4], m[5]);
                if matrix.determinant() == 0.0 {
                    return Err(DbsError::SingularMatrix { offset: pos });
                }
                let geometry = if record_type == TYPE_GEOMETRY {
                    let n = (len - COPY_LEN) / POINT_LEN;
                    let mut points = Vec::with_capacity(n);
                    for k in 0..n {
                        let at = pos + COPY_LEN + k * POINT_LEN;
                        // Non-finite values are reported with their exact offset here.
                        points.push([
                            cur.finite(at, "point x")?,
                            cur.finite(at + 4, "point y")?,
                            cur.finite(at + 8, "point bulge")?,
                        ]);
                    }
                    let contour = contour_check::closed_contour(
                        &points,
                        options.closure_tolerance,
                        options.check_self_intersection,
                    )
                    .map_err(|problem| DbsError::BadContour {
                        offset: pos,
                        id,
                        problem,
                    })?;
                    Some(contour)
                } else {
                    if original < 0 {
                        return Err(DbsError::NegativeId {
                            offset: pos + 32,
                            id: original,
                        });
                    }
                    None
                };
                contours.insert(
                    id,
                    ContourRecord {
                        offset: pos,
                        original,
                        reversed,
                        matrix,
                        geometry,
                    },
                );
            }
            TYPE_PART => {
                let acc = parts.entry(id).or_default();
                if acc.seen {
                    return Err(DbsError::DuplicateId {
                        offset: pos,
                        id,
                        other: "another part record",
                    });
                }
                acc.seen = true;
                acc.offset = pos;
                for at in (pos + HEADER_LEN..end).step_by(4) {
                    let cid = cur.i16(at);
                    if cid < 0 {
                        return Err(DbsError::NegativeId {
                            offset: at,
                            id: cid,
                        });
                    }
                    acc.contour_ids.push(cid);
                }
                if acc.contour_ids.is_empty() {
                    return Err(DbsError::EmptyPart { offset: pos, id });
                }
                part_order.push(id);
            }
            TYPE_NAME => {
                if len < HEADER_LEN + 8 {
                    return Err(too_short(HEADER_LEN + 8));
                }
                let raw = &bytes[pos + HEADER_LEN..pos + HEADER_LEN + 8];
                // Characters are stored pair-swapped: «CIRCLE1» is «ICCREL 1».
                let name: String = (0..8).map(|i| cp866_char(raw[i ^ 1])).collect();
                let name = name
                    .trim_matches(|c: char| c == ' ' || c == '\0')
                    .to_string();
                let acc = parts.entry(id).or_default();
                if acc.name.is_some() {
                    return Err(DbsError::DuplicateId {
                        offset: pos,
                        id,
                        other: "another name record",
                    });
                }
                acc.name = Some(name);
            }
            TYPE_DIMENSIONS => {
                if len < HEADER_LEN + 8 {
                    return Err(too_short(HEADER_LEN + 8));
                }
                let area = cur.finite(pos + 16, "part area")? as f32;
                let perimeter = cur.finite(pos + 20, "part perimeter")? as f32;
                let acc = parts.entry(id).or_default();
                if acc.dimensions.is_some() {
                    return Err(DbsError::DuplicateId {
                        offset: pos,
                        id,
                        other: "another dimensions record",
                    });
                }
                acc.dimensions = Some((area, perimeter));
            }
            _ => skipped_records += 1,
        }
        pos = end;
    }

    // Resolve every part in file order; copies may refer forwards.
    let mut memo: HashMap<i16, Resolved> = HashMap::new();
    let mut records = Vec::with_capacity(part_order.len());
    let mut all_parts = Vec::with_capacity(part_order.len());
    let mut vertex_budget = options.max_vertices;
    for id in part_order {
        let acc = parts.remove(&id).unwrap_or_default();
        if contours.contains_key(&id) {
            return Err(DbsError::DuplicateId {
                offset: acc.offset,
                id,
                other: "a contour record",
            });
        }
        let mut part = Part {
            name: acc.name.clone().unwrap_or_default(),
            contours: Vec::new(),
        };
        for &cid in &acc.contour_ids {
            let resolved = resolve(cid, acc.offset, &contours, &mut memo)?;
            let base = contours[&resolved.base]
                .geometry
                .as_ref()
                .expect("resolve ends at a type-1 record");
            if base.vertices.len() > vertex_budget {
                return Err(DbsError::TooManyVertices {
                    offset: acc.offset,
                    limit: options.max_vertices,
                });
            }
            vertex_budget -= base.vertices.len();
            let contour = transform(base, &resolved);
            // Chained copies can scale coordinates past f64 range; refuse rather than return ∞.
            if contour
                .vertices
                .iter()
                .any(|v| !v.point.x.is_finite() || !v.point.y.is_finite())
            {
                return Err(DbsError::NonFinite {
                    offset: contours[&cid].offset,
                    what: "contour point after the copy transformation",
                });
            }
            part.contours.push(contour);
        }
        records.push(DbsPartRecord {
            id,
            offset: acc.offset,
            name: part.name.clone(),
            contour_ids: acc.contour_ids,
            area_dm2: acc.dimensions.map(|d| d.0),
            perimeter_dm: acc.dimensions.map(|d| d.1),
        });
        all_parts.push(part);
    }
    let has_sheet = match options.sheet {
        SheetDetection::None => false,
        SheetDetection::FirstPart => !all_parts.is_empty(),
        SheetDetection::Auto => all_parts.len() >= 2 && encloses_others(&all_parts),
    };
    let mut all_parts = all_parts.into_iter();
    let sheet = if has_sheet { all_parts.next() } else { None };
    Ok(DbsFile {
        nest: Nest {
            sheet,
            parts: all_parts.collect(),
        },
        part_records: records,
        skipped_records,
    })
}

/// The map that turns a type-1 record's stored geometry into contour `id` as a part uses it.
fn resolve(
    id: i16,
    part_offset: usize,
    contours: &HashMap<i16, ContourRecord>,
    memo: &mut HashMap<i16, Resolved>,
) -> Result<Resolved, DbsError> {
    let record = contours.get(&id).ok_or(DbsError::MissingContour {
        offset: part_offset,
        id,
    })?;
    if record.geometry.is_some() {
        // A part using a type-1 record directly gets that record's own (normally identity) map.
        return Ok(Resolved {
            base: id,
            matrix: record.matrix,
            reversed: record.reversed,
        });
    }
    copy_map(id, contours, memo)
}

/// The map of copy `id`: its own matrix applied to the geometry of its original, which is the
/// raw stored points of a type-1 record or, recursively, another copy.
fn copy_map(
    id: i16,
    contours: &HashMap<i16, ContourRecord>,
    memo: &mut HashMap<i16, Resolved>,
) -> Result<Resolved, DbsError> {
    // Walk the chain iteratively (hostile chains cannot exhaust the stack) until a type-1
    // record or an already resolved copy; `on_chain` catches cycles.
    let mut chain: Vec<i16> = Vec::new();
    let mut on_chain: HashSet<i16> = HashSet::new();
    let mut current = id;
    let tail = loop {
        if let Some(r) = memo.get(&current) {
            break *r;
        }
        let record = &contours[&current];
        if record.geometry.is_some() {
            break Resolved {
                base: current,
                matrix: Transform::IDENTITY,
                reversed: false,
            };
        }
        if !on_chain.insert(current) {
            return Err(DbsError::CyclicReference {
                offset: record.offset,
                id: current,
            });
        }
        chain.push(current);
        let next = record.original;
        if !contours.contains_key(&next) {
            return Err(DbsError::MissingContour {
                offset: record.offset,
                id: next,
            });
        }
        current = next;
    };
    let mut acc = tail;
    for &cid in chain.iter().rev() {
        let rec = &contours[&cid];
        acc = Resolved {
            base: acc.base,
            // The original's map first, then the copy's own.
            matrix: acc.matrix.then(&rec.matrix),
            reversed: acc.reversed ^ rec.reversed,
        };
        memo.insert(cid, acc);
    }
    Ok(acc)
}

/// Applies a resolved map to stored geometry: transform points, flip bulges under a mirror,
/// then reverse the direction if asked (the reference reader's order).
fn transform(base: &Contour, r: &Resolved) -> Contour {
    let mapped = base.transformed(&r.matrix);
    if r.reversed {
        Contour::new(reversed(&mapped.vertices))
    } else {
        mapped
    }
}

/// The same closed contour traversed backwards: the span that entered a vertex now leaves it,
/// with its bulge negated.
fn reversed(v: &[Vertex]) -> Vec<Vertex> {
    let n = v.len();
    (0..n)
        .map(|k| {
            let i = (n - k) % n; // vertex order v0, v(n-1), …, v1
            let entering = (i + n - 1) % n;
            Vertex {
                point: v[i].point,
                bulge: -v[entering].bulge,
            }
        })
        .collect()
}

/// Does the first part's outer contour enclose the bounding box of every other part?
fn encloses_others(parts: &[Part]) -> bool {
    let Some(sheet) = parts[0].contours.first().map(Contour::bounding_box) else {
        return false;
    };
    let sheet = sheet.expanded(1e-3);
    parts[1..]
        .iter()
        .flat_map(|p| p.contours.first())
        .all(|c| sheet.contains_box(&c.bounding_box()))
}

/// Writes a nest as DBS with [`DbsWriteOptions::default`].
pub fn write_dbs(nest: &Nest) -> Result<Vec<u8>, DbsWriteError> {
    write_dbs_with(nest, &DbsWriteOptions::default())
}

fn put_i16(out: &mut Vec<u8>, v: i16) {
    // Every int16 sits in a 4-byte slot whose upper half is zero.
    out.extend_from_slice(&v.to_le_bytes());
    out.extend_from_slice(&[0, 0]);
}

fn put_header(out: &mut Vec<u8>, payload_len: usize, record_type: i16, id: i16) {
    let size = ((HEADER_LEN + payload_len - 4) / 4) as i16;
    out.extend_from_slice(&size.to_le_bytes());
    out.extend_from_slice(&id.to_le_bytes());
    put_i16(out, size);
    put_i16(out, record_type);
    put_i16(out, id);
}

/// Writes a nest as DBS: the sheet first (when present), then the parts; per part its contours
/// as type-1 records, then records 8, 26 and 27, all numbered like the reference writer.
pub fn write_dbs_with(nest: &Nest, options: &DbsWriteOptions) -> Result<Vec<u8>, DbsWriteError> {
    let mut out = Vec::new();
    let mut seq = 0usize;
    for (index, part) in nest.sheet.iter().chain(&nest.parts).enumerate() {
        if part.contours.is_empty() {
            return Err(DbsWriteError::EmptyPart { part: index });
        }
        let name = encode_name(&part.name, options.truncate_long_names).ok_or_else(|| {
            DbsWriteError::NameNotRepresentable {
                part: index,
                name: part.name.clone(),
            }
        })?;
        let part_id = seq + part.contours.len() + 1;
        if part_id > i16::MAX as usize {
            return Err(DbsWriteError::TooManyRecords { needed: part_id });
        }
        let part_id = part_id as i16;
        // Record 27 is computed from the coordinates as stored (float32), not from the f64
        // input: otherwise a second rewrite could round the dimensions differently.
        let mut as_stored = Part {
            name: String::new(),
            contours: Vec::with_capacity(part.contours.len()),
        };
        for (k, contour) in part.contours.iter().enumerate() {
            let id = (seq + k + 1) as i16;
            let points = contour_check::stored_points(&with_short_arcs(contour));
            if contour.vertices.is_empty() {
                return Err(DbsWriteError::EmptyContour {
                    part: index,
                    contour: k,
                });
            }
            // size = 15 + 3n must fit an int16.
            if 15 + 3 * points.len() > i16::MAX as usize {
                return Err(DbsWriteError::ContourTooLong {
                    part: index,
                    contour: k,
                    points: points.len(),
                });
            }
            put_header(
                &mut out,
                COPY_LEN - HEADER_LEN + POINT_LEN * points.len(),
                TYPE_GEOMETRY,
                id,
            );
            put_i16(&mut out, 1); // subtype
            put_i16(&mut out, 0); // text
            put_i16(&mut out, 0); // autoseq
            put_i16(&mut out, if k == 0 { -part_id } else { part_id });
            put_i16(&mut out, id); // original = itself
            put_i16(&mut out, 0); // rev
            for m in [1.0f32, 0.0, 0.0, 1.0, 0.0, 0.0] {
                out.extend_from_slice(&m.to_le_bytes());
            }
            for (vertex, p) in points.iter().enumerate() {
                for v in p {
                    // `+ 0.0` turns −0.0 into +0.0: the reader's identity transform does the
                    // same, so a rewrite would otherwise flip sign bits.
                    let f = *v as f32 + 0.0;
                    if !f.is_finite() {
                        return Err(DbsWriteError::NotRepresentable {
                            part: index,
                            contour: k,
                            vertex,
                        });
                    }
                    out.extend_from_slice(&f.to_le_bytes());
                }
            }
            as_stored.contours.push(Contour::new(
                points[..points.len() - 1]
                    .iter()
                    .map(|p| {
                        Vertex::arc(
                            f64::from(p[0] as f32),
                            f64::from(p[1] as f32),
                            f64::from(p[2] as f32),
                        )
                    })
                    .collect(),
            ));
        }
        put_header(&mut out, 4 * part.contours.len(), TYPE_PART, part_id);
        for k in 0..part.contours.len() {
            put_i16(&mut out, (seq + k + 1) as i16);
        }
        put_header(&mut out, 8, TYPE_NAME, part_id);
        out.extend_from_slice(&name);
        put_header(&mut out, 8, TYPE_DIMENSIONS, part_id);
        let area = (as_stored.area() * 1e-4) as f32 + 0.0;
        let perimeter = (as_stored.perimeter() * 1e-2) as f32 + 0.0;
        if !area.is_finite() || !perimeter.is_finite() {
            return Err(DbsWriteError::DimensionsNotRepresentable { part: index });
        }
        out.extend_from_slice(&area.to_le_bytes());
        out.extend_from_slice(&perimeter.to_le_bytes());
        seq = part_id as usize;
    }
    out.extend_from_slice(&END_MARKER);
    Ok(out)
}

/// The 8 stored bytes of a name: CP866 (the DOS code page of the «Сириус» CAD that made the
/// format, so Cyrillic names fit one byte per letter), space-padded, characters swapped within
/// each pair. Fails on names over 8 characters or with characters CP866 lacks, unless
/// `truncate`: then the name is cut to its first 8 characters and such characters become `?`.
fn encode_name(name: &str, truncate: bool) -> Option<[u8; 8]> {
    let chars: Vec<u8> = name
        .chars()
        .map(|c| cp866_byte(c).or(truncate.then_some(b'?')))
        .collect::<Option<_>>()?;
    if chars.len() > 8 && !truncate {
        return None;
    }
    let mut plain = [b' '; 8];
    for (slot, c) in plain.iter_mut().zip(chars) {
        *slot = c;
    }
    let mut stored = [0u8; 8];
    for i in 0..8 {
        stored[i] = plain[i ^ 1];
    }
    Some(stored)
}

/// The CP866 byte of an ASCII character or a Russian letter.
fn cp866_byte(c: char) -> Option<u8> {
    let code = u32::from(c);
    let byte = match code {
        0x00..=0x7F => code,
        0x0410..=0x043F => code - 0x0410 + 0x80, // А–Я, а–п
        0x0440..=0x044F => code - 0x0440 + 0xE0, // р–я
        0x0401 => 0xF0,                          // Ё
        0x0451 => 0xF1,                          // ё
        _ => return None,
    };
    u8::try_from(byte).ok()
}

/// The character of a stored name byte: CP866 letters are Russian letters, other bytes above
/// 0x7F (CP866 box drawing, never in names) read as Latin-1, as before CP866 was known.
fn cp866_char(byte: u8) -> char {
    let code = match byte {
        0x80..=0xAF => u32::from(byte) - 0x80 + 0x0410,
        0xE0..=0xEF => u32::from(byte) - 0xE0 + 0x0440,
        0xF0 => 0x0401,
        0xF1 => 0x0451,
        _ => return char::from(byte),
    };
    char::from_u32(code).unwrap_or(char::REPLACEMENT_CHARACTER)
}
