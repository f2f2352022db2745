//! DXF sections and entities → loose pieces (chains of spans) in world coordinates.

use cutroute_geometry::float::Libm;
use std::collections::HashMap;

use cutroute_geometry::{Point, ReadWarning, Span, Transform, WarningKind};

use super::groups::{decode_text, Codepage, Group};
use super::{DxfError, DxfOptions, DxfWarning};
use crate::assemble::{is_bounded, Piece, SourceRef};
use crate::curves::{
    approximate, approximate_elliptic, ApproxFailure, EllipticArc, Nurbs, STRAIGHT_BULGE,
};

/// Deepest chain of blocks inserting blocks; real drawings use 3–5 levels.
const MAX_BLOCK_DEPTH: usize = 16;
/// Most block instances one drawing may expand to (MINSERT arrays and nesting multiply).
const MAX_INSTANCES: usize = 1_000_000;
/// Entity types that carry no cutting geometry: skipped, with one warning per type.
const ANNOTATION: &[&str] = &[
    "TEXT",
    "MTEXT",
    "ATTRIB",
    "ATTDEF",
    "DIMENSION",
    "LEADER",
    "MULTILEADER",
    "MLEADER",
    "TOLERANCE",
    "HATCH",
    "SOLID",
    "TRACE",
    "POINT",
    "VIEWPORT",
    "IMAGE",
    "WIPEOUT",
    "OLE2FRAME",
    "ACAD_TABLE",
    "ARC_DIMENSION",
    "LARGE_RADIAL_DIMENSION",
    "XLINE",
    "RAY",
];

/// The end of a sweep from `start` that the file gives as ending at `end`: after `start`, by at
/// most a full turn (angles like 0° → 720° mean one turn, and an end before the start means the
/// sweep runs on through the next turn). Constant time for any magnitude of angle.
fn sweep_end(start: f64, end: f64) -> f64 {
    let end = if end <= start {
        let d = (end - start).rem_euclid(std::f64::consts::TAU);
        start + if d > 0.0 { d } else { std::f64::consts::TAU }
    } else {
        end
    };
    end.min(start + std::f64::consts::TAU)
}

/// One entity: its type, the line of its `0` group and its groups (without the `0` group).
#[derive(Clone, Debug)]
struct Record<'a> {
    kind: String,
    line: usize,
    body: &'a [Group<'a>],
    /// `VERTEX` records of a `POLYLINE`.
    vertices: Vec<Record<'a>>,
}

impl<'a> Record<'a> {
    fn first(&self, code: i32) -> Option<&Group<'a>> {
        self.body.iter().find(|g| g.code == code)
    }

    fn real_or(&self, code: i32, default: f64) -> Result<f64, DxfError> {
        self.first(code).map_or(Ok(default), |g| g.real())
    }

    fn real(&self, code: i32, meaning: &'static str) -> Result<f64, DxfError> {
        self.first(code)
            .ok_or_else(|| self.missing(code, meaning))?
            .real()
    }

    fn int_or(&self, code: i32, default: i64) -> Result<i64, DxfError> {
        self.first(code).map_or(Ok(default), |g| g.int())
    }

    fn point(&self, x: i32, meaning: &'static str) -> Result<Point, DxfError> {
        Ok(Point::new(
            self.real(x, meaning)?,
            self.real(x + 10, meaning)?,
        ))
    }

    fn missing(&self, code: i32, meaning: &'static str) -> DxfError {
        DxfError::MissingGroup {
            line: self.line,
            entity: self.kind.clone(),
            code,
            meaning,
        }
    }

    fn invalid(&self, reason: impl Into<String>) -> DxfError {
        DxfError::InvalidEntity {
            line: self.line,
            entity: self.kind.clone(),
            reason: reason.into(),
        }
    }

    fn in_paper_space(&self) -> Result<bool, DxfError> {
        Ok(self.int_or(67, 0)? == 1)
    }

    /// The object coordinate system of 2D entities, as a map of the plane into world
    /// coordinates seen from above (world z dropped): identity for the usual +Z extrusion, a
    /// mirror for −Z (mirrored geometry in many CAD exports), and for a tilted plane its
    /// parallel projection onto the XY plane, as the drawing shows it in plan view — an affine
    /// map, under which arcs become elliptic arcs and are approximated like any. `elevation` is
    /// the group of the plane's height along the normal. `None` when the normal is zero, or
    /// when the plane is tilted and `flat_only` (inside a block, where projecting each level
    /// on its own would not compose into the 3D placement).
    fn ocs(&self, elevation: i32, flat_only: bool) -> Result<Option<Transform>, DxfError> {
        let nx = self.real_or(210, 0.0)?;
        let ny = self.real_or(220, 0.0)?;
        let nz = self.real_or(230, 1.0)?;
        let len = (nx * nx + ny * ny + nz * nz).sqrt();
        if len == 0.0 {
            return Ok(None);
        }
        if (nx.abs() + ny.abs()) <= 1e-9 * len {
            return Ok(Some(if nz > 0.0 {
                Transform::IDENTITY
            } else {
                // The arbitrary-axis algorithm's OCS for extrusion (0, 0, −1): x ↦ −x.
                Transform::mirror_y()
            }));
        }
        if flat_only {
            return Ok(None);
        }
        let n = [nx / len, ny / len, nz / len];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let unit = |a: [f64; 3]| {
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            [a[0] / l, a[1] / l, a[2] / l]
        };
        // The DXF reference's arbitrary axis algorithm.
        let ax = if n[0].abs() < 1.0 / 64.0 && n[1].abs() < 1.0 / 64.0 {
            unit(cross([0.0, 1.0, 0.0], n))
        } else {
            unit(cross([0.0, 0.0, 1.0], n))
        };
        let ay = unit(cross(n, ax));
        let z = self.real_or(elevation, 0.0)?;
        Ok(Some(Transform {
            matrix: [[ax[0], ay[0]], [ax[1], ay[1]]],
            offset: Point::new(z * n[0], z * n[1]),
        }))
    }
}

/// The placement of a block insert: `p ↦ at + R(rotation)·(S·(p − base) + offset)`.
fn insert_placement(
    at: Point,
    scale: Point,
    rotation_deg: f64,
    base: Point,
    offset: Point,
) -> Transform {
    Transform::translation(-base.x, -base.y)
        .then(&Transform::axis_scaling(scale.x, scale.y))
        .then(&Transform::translation(offset.x, offset.y))
        .then(&Transform::rotation(rotation_deg.to_radians()))
        .then(&Transform::translation(at.x, at.y))
}

/// A block definition: base point and its entity records.
struct Block<'a> {
    base: Point,
    records: Vec<Record<'a>>,
}

/// Drawing-wide state while entities are expanded.
struct Expander<'a, 'o> {
    blocks: HashMap<Vec<u8>, Block<'a>>,
    options: &'o DxfOptions,
    codepage: Codepage,
    span_budget: usize,
    instances: usize,
    pieces: Vec<Piece>,
    warnings: Vec<DxfWarning>,
    /// Entity types skipped: the line of the first and how many.
    skipped: HashMap<String, (usize, usize)>,
}

/// Reads the sections and expands model-space entities into pieces.
pub(crate) fn collect_pieces(
    groups: &[Group<'_>],
    options: &DxfOptions,
    warnings: &mut Vec<DxfWarning>,
) -> Result<Vec<Piece>, DxfError> {
    let mut codepage = Codepage::Utf8OrAnsi1251;
    let mut unit_scale = None;
    let mut blocks = HashMap::new();
    let mut entities: Option<Vec<Record<'_>>> = None;

    let mut i = 0;
    while i < groups.len() {
        let g = &groups[i];
        if g.is(0, "EOF") {
            break;
        }
        if !g.is(0, "SECTION") {
            // Stray groups between sections are skipped.
            i += 1;
            continue;
        }
        let start_line = g.line;
        let name = groups
            .get(i + 1)
            .filter(|n| n.code == 2)
            .map(|n| n.value.to_ascii_uppercase())
            .unwrap_or_default();
        let end = groups[i + 1..]
            .iter()
            .position(|g| g.is(0, "ENDSEC"))
            .map(|p| p + i + 1)
            .ok_or_else(|| DxfError::Unterminated {
                line: start_line,
                what: format!("section {}", String::from_utf8_lossy(&name)),
            })?;
        let body = &groups[(i + 2).min(end)..end];
        match name.as_slice() {
            b"HEADER" => read_header(body, &mut codepage, &mut unit_scale, warnings)?,
            b"BLOCKS" => blocks = read_blocks(body)?,
            b"ENTITIES" => entities = Some(split_records(body)?),
            _ => {}
        }
        i = end + 1;
    }
    let entities = entities.ok_or(DxfError::NoEntities)?;
    let unit_scale = unit_scale.unwrap_or_else(|| {
        warnings.push(ReadWarning::new(
            WarningKind::Units,
            "the drawing declares no units ($INSUNITS missing); millimetres assumed",
        ));
        1.0
    });

    let mut expander = Expander {
        blocks,
        options,
        codepage,
        span_budget: options.max_spans,
        instances: 0,
        pieces: Vec::new(),
        warnings: std::mem::take(warnings),
        skipped: HashMap::new(),
    };
    let world = Transform::scaling(unit_scale);
    for record in &entities {
        if record.in_paper_space()? {
            continue;
        }
        expander.entity(record, &world, 0, "")?;
    }
    if expander.pieces.is_empty() {
        // Some drawings are drawn straight onto the layout sheet: with nothing in model space,
        // the paper-space entities are the part. Those of the active layout stand in ENTITIES
        // (group 67 = 1); the other layouts' in the `*Paper_Space…` blocks, read only when the
        // active one draws nothing either.
        let mut read = 0;
        for record in &entities {
            if record.in_paper_space()? {
                read += 1;
                expander.entity(record, &world, 0, "")?;
            }
        }
        let mut where_from = "the active layout";
        if expander.pieces.is_empty() {
            let mut layouts: Vec<Vec<u8>> = expander
                .blocks
                .keys()
                .filter(|name| name.starts_with(b"*PAPER_SPACE"))
                .cloned()
                .collect();
            layouts.sort();
            for name in layouts {
                let records = expander.blocks[&name].records.clone();
                for record in &records {
                    read += 1;
                    expander.entity(record, &world, 0, "")?;
                }
            }
            where_from = "the layouts";
        }
        if read > 0 && !expander.pieces.is_empty() {
            expander.warnings.push(ReadWarning::new(
                WarningKind::PaperSpace,
                format!(
                    "model space draws nothing; the {read} paper-space entities of {where_from} \
                     were read instead"
                ),
            ));
        }
    }
    let mut skipped: Vec<(String, (usize, usize))> = expander.skipped.drain().collect();
    skipped.sort_by_key(|(_, (line, _))| *line);
    for (kind, (line, count)) in skipped {
        let what = if ANNOTATION.contains(&kind.as_str()) {
            "not cutting geometry"
        } else {
            "not read by cutroute"
        };
        let message = if count == 1 {
            format!("1 {kind} entity skipped ({what})")
        } else {
            format!("{count} {kind} entities skipped ({what}); the first is here")
        };
        expander
            .warnings
            .push(ReadWarning::new(WarningKind::Skipped, message).at_line(line, None));
    }
    *warnings = expander.warnings;
    Ok(expander.pieces)
}

/// Millimetres per drawing unit of an `$INSUNITS` code, for the codes a cutting drawing can
/// mean (lengths from microinches to metres); `None` for unitless (0), for the astronomic and
/// geographic ones and for codes the DXF reference does not define.
fn insunits_scale(units: i64) -> Option<f64> {
    Some(match units {
        1 => 25.4,
        2 => 304.8,
        4 => 1.0,
        5 => 10.0,
        6 => 1000.0,
        8 => 25.4e-6,
        9 => 25.4e-3,
        10 => 914.4,
        13 => 1e-3,
        14 => 100.0,
        21 => 1200.0 / 3937.0 * 1000.0,
        22 => 1000.0 / 39.37,
        23 => 3600.0 / 3937.0 * 1000.0,
        _ => return None,
    })
}

fn read_header(
    body: &[Group<'_>],
    codepage: &mut Codepage,
    unit_scale: &mut Option<f64>,
    warnings: &mut Vec<DxfWarning>,
) -> Result<(), DxfError> {
    let mut variable: &[u8] = b"";
    for g in body {
        if g.code == 9 {
            variable = g.value;
            continue;
        }
        match variable {
            b"$ACADVER" if g.code == 1 => {
                // AC1021 (AutoCAD 2007) and later store strings as UTF-8.
                let version = std::str::from_utf8(g.value).unwrap_or("");
                let number: u32 = version.get(2..).and_then(|v| v.parse().ok()).unwrap_or(0);
                if number >= 1021 {
                    *codepage = Codepage::Utf8;
                }
            }
            b"$DWGCODEPAGE"
                if g.code == 3
                    && *codepage != Codepage::Utf8
                    && g.value.eq_ignore_ascii_case(b"ANSI_1251") =>
            {
                *codepage = Codepage::Ansi1251;
            }
            b"$INSUNITS" if g.code == 70 => {
                let units = g.int()?;
                let (scale, message) = match (units, insunits_scale(units)) {
                    (4, _) => (1.0, None),
                    (_, Some(s)) => (
                        s,
                        Some(format!(
                            "drawing units $INSUNITS = {units}; scaled by {s} to mm"
                        )),
                    ),
                    (0, None) => (
                        1.0,
                        Some(
                            "the drawing has no units ($INSUNITS = 0); millimetres assumed".into(),
                        ),
                    ),
                    (_, None) => (
                        1.0,
                        Some(format!(
                            "drawing units $INSUNITS = {units} are not lengths cutroute reads; \
                             millimetres assumed"
                        )),
                    ),
                };
                *unit_scale = Some(scale);
                if let Some(message) = message {
                    warnings.push(
                        ReadWarning::new(WarningKind::Units, message).at_line(g.value_at, None),
                    );
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Splits a section body into entity records, attaching `VERTEX` records to their `POLYLINE`.
fn split_records<'a>(body: &'a [Group<'a>]) -> Result<Vec<Record<'a>>, DxfError> {
    let mut flat: Vec<Record<'a>> = Vec::new();
    let mut i = 0;
    while i < body.len() {
        let g = &body[i];
        if g.code != 0 {
            // Groups before the first entity: not an entity, skip.
            i += 1;
            continue;
        }
        let end = body[i + 1..]
            .iter()
            .position(|g| g.code == 0)
            .map_or(body.len(), |p| p + i + 1);
        flat.push(Record {
            kind: String::from_utf8_lossy(g.value).to_ascii_uppercase(),
            line: g.line,
            body: &body[i + 1..end],
            vertices: Vec::new(),
        });
        i = end;
    }
    let mut out: Vec<Record<'a>> = Vec::with_capacity(flat.len());
    let mut iter = flat.into_iter().peekable();
    while let Some(mut record) = iter.next() {
        if record.kind == "POLYLINE" {
            while let Some(next) = iter.peek() {
                match next.kind.as_str() {
                    "VERTEX" => record.vertices.push(iter.next().expect("peeked")),
                    "SEQEND" => {
                        iter.next();
                        break;
                    }
                    // A missing SEQEND: the polyline ends where another entity starts.
                    _ => break,
                }
            }
        }
        out.push(record);
    }
    Ok(out)
}

fn read_blocks<'a>(body: &'a [Group<'a>]) -> Result<HashMap<Vec<u8>, Block<'a>>, DxfError> {
    let records = split_records(body)?;
    let mut blocks = HashMap::new();
    let mut iter = records.into_iter();
    while let Some(record) = iter.next() {
        if record.kind != "BLOCK" {
            continue;
        }
        let name = record
            .first(2)
            .map(|g| g.value.to_ascii_uppercase())
            .ok_or_else(|| record.missing(2, "block name"))?;
        let base = Point::new(record.real_or(10, 0.0)?, record.real_or(20, 0.0)?);
        let mut content = Vec::new();
        let mut terminated = false;
        for inner in iter.by_ref() {
            if inner.kind == "ENDBLK" {
                terminated = true;
                break;
            }
            content.push(inner);
        }
        if !terminated {
            return Err(DxfError::Unterminated {
                line: record.line,
                what: format!("block {:?}", String::from_utf8_lossy(&name)),
            });
        }
        blocks.insert(
            name,
            Block {
                base,
                records: content,
            },
        );
    }
    Ok(blocks)
}

impl Expander<'_, '_> {
    fn layer(&self, record: &Record<'_>, inherited: &str) -> String {
        match record.first(8) {
            // Entities on layer 0 inside a block take the insert's layer.
            Some(g) if g.value != b"0" || inherited.is_empty() => {
                decode_text(g.value, self.codepage)
            }
            _ if !inherited.is_empty() => inherited.to_owned(),
            _ => "0".to_owned(),
        }
    }

    fn skip(&mut self, record: &Record<'_>) {
        let entry = self
            .skipped
            .entry(record.kind.clone())
            .or_insert((record.line, 0));
        entry.0 = entry.0.min(record.line);
        entry.1 += 1;
    }

    fn warn(&mut self, kind: WarningKind, line: usize, message: impl Into<String>) {
        // Keep the report readable on hostile files with millions of bad entities.
        if self.warnings.len() < 1000 {
            self.warnings
                .push(ReadWarning::new(kind, message).at_line(line, None));
        }
    }

    fn entity(
        &mut self,
        record: &Record<'_>,
        to_world: &Transform,
        depth: usize,
        inherited_layer: &str,
    ) -> Result<(), DxfError> {
        let kind = record.kind.as_str();
        if ANNOTATION.contains(&kind) {
            self.skip(record);
            return Ok(());
        }
        let layer = self.layer(record, inherited_layer);
        let source = SourceRef {
            entity: kind.to_owned(),
            line: record.line,
            layer: layer.clone(),
        };
        match kind {
            "LINE" => {
                let a = record.point(10, "start point")?;
                let b = record.point(11, "end point")?;
                if a == b {
                    self.warn(
                        WarningKind::ZeroArea,
                        record.line,
                        "zero-length LINE skipped",
                    );
                    return Ok(());
                }
                self.path(vec![Span::line(a, b)], false, to_world, source)
            }
            "ARC" | "CIRCLE" => {
                let Some(ocs) = record.ocs(30, depth > 0)? else {
                    self.warn(
                        WarningKind::Skipped,
                        record.line,
                        format!("{kind} in a tilted plane skipped"),
                    );
                    return Ok(());
                };
                let center = record.point(10, "centre")?;
                let radius = record.real(40, "radius")?;
                if radius <= 0.0 {
                    self.warn(
                        WarningKind::ZeroArea,
                        record.line,
                        format!("{kind} with radius {radius} skipped"),
                    );
                    return Ok(());
                }
                let (t0, t1, closed) = if kind == "CIRCLE" {
                    (0.0, std::f64::consts::TAU, true)
                } else {
                    let start = record.real(50, "start angle")?.to_radians();
                    let end = sweep_end(start, record.real(51, "end angle")?.to_radians());
                    (start, end, false)
                };
                let arc = EllipticArc {
                    center,
                    u: Point::new(radius, 0.0),
                    v: Point::new(0.0, radius),
                    t0,
                    t1,
                };
                self.elliptic(arc, closed, &ocs.then(to_world), source)
            }
            "ELLIPSE" => {
                let center = record.point(10, "centre")?;
                let major = record.point(11, "major axis end")?;
                let ratio = record.real(40, "axis ratio")?;
                let nz = record.real_or(230, 1.0)?;
                if ratio <= 0.0 || (major.x == 0.0 && major.y == 0.0) {
                    self.warn(
                        WarningKind::ZeroArea,
                        record.line,
                        "degenerate ELLIPSE skipped",
                    );
                    return Ok(());
                }
                let t0 = record.real_or(41, 0.0)?;
                let t1 = sweep_end(t0, record.real_or(42, std::f64::consts::TAU)?);
                let closed = (t1 - t0 - std::f64::consts::TAU).abs() < 1e-9;
                // The minor axis is N × major scaled by the ratio (N = ±Z turns it ±90°); both
                // are world vectors, seen from above like the rest of the drawing.
                let nx = record.real_or(210, 0.0)?;
                let ny = record.real_or(220, 0.0)?;
                let mz = record.real_or(31, 0.0)?;
                let n_len = (nx * nx + ny * ny + nz * nz).sqrt();
                if n_len == 0.0 {
                    self.warn(
                        WarningKind::Skipped,
                        record.line,
                        "ELLIPSE with a zero normal skipped",
                    );
                    return Ok(());
                }
                let (nx, ny, nz) = (nx / n_len, ny / n_len, nz / n_len);
                let v = Point::new(
                    (ny * mz - nz * major.y) * ratio,
                    (nz * major.x - nx * mz) * ratio,
                );
                let arc = EllipticArc {
                    center,
                    u: major,
                    v,
                    t0,
                    t1,
                };
                self.elliptic(arc, closed, to_world, source)
            }
            "LWPOLYLINE" => {
                let Some(ocs) = record.ocs(38, depth > 0)? else {
                    self.warn(
                        WarningKind::Skipped,
                        record.line,
                        "LWPOLYLINE in a tilted plane skipped",
                    );
                    return Ok(());
                };
                let closed = record.int_or(70, 0)? & 1 == 1;
                let mut vertices: Vec<(Point, f64)> = Vec::new();
                for g in record.body {
                    match g.code {
                        10 => vertices.push((Point::new(g.real()?, 0.0), 0.0)),
                        20 => {
                            let v = vertices.last_mut().ok_or_else(|| {
                                record.invalid(format!("line {}: y before any x", g.line))
                            })?;
                            v.0.y = g.real()?;
                        }
                        42 => {
                            if let Some(v) = vertices.last_mut() {
                                v.1 = g.real()?;
                            }
                        }
                        _ => {}
                    }
                }
                self.polyline(record, &vertices, closed, &ocs.then(to_world), source)
            }
            "POLYLINE" => {
                let flags = record.int_or(70, 0)?;
                if flags & (16 | 64) != 0 {
                    self.warn(
                        WarningKind::Skipped,
                        record.line,
                        "polygon mesh / polyface POLYLINE skipped",
                    );
                    return Ok(());
                }
                let is_3d = flags & 8 != 0;
                let ocs = if is_3d {
                    Some(Transform::IDENTITY)
                } else {
                    record.ocs(30, depth > 0)?
                };
                let Some(ocs) = ocs else {
                    self.warn(
                        WarningKind::Skipped,
                        record.line,
                        "POLYLINE in a tilted plane skipped",
                    );
                    return Ok(());
                };
                let mut vertices = Vec::with_capacity(record.vertices.len());
                for v in &record.vertices {
                    // Spline frame control points are not on the curve.
                    if v.int_or(70, 0)? & 16 != 0 {
                        continue;
                    }
                    let p = v.point(10, "vertex location")?;
                    let bulge = if is_3d { 0.0 } else { v.real_or(42, 0.0)? };
                    vertices.push((p, bulge));
                }
                self.polyline(
                    record,
                    &vertices,
                    flags & 1 == 1,
                    &ocs.then(to_world),
                    source,
                )
            }
            "SPLINE" => self.spline(record, to_world, source),
            "INSERT" | "MINSERT" => self.insert(record, to_world, depth, &layer),
            // The end of a heavy polyline's vertices carries nothing.
            "SEQEND" => Ok(()),
            _ => {
                self.skip(record);
                Ok(())
            }
        }
    }

    fn polyline(
        &mut self,
        record: &Record<'_>,
        vertices: &[(Point, f64)],
        closed: bool,
        to_world: &Transform,
        source: SourceRef,
    ) -> Result<(), DxfError> {
        let mut spans = Vec::with_capacity(vertices.len());
        let n = vertices.len();
        let count = if closed { n } else { n.saturating_sub(1) };
        for i in 0..count {
            let (a, bulge) = vertices[i];
            let (b, _) = vertices[(i + 1) % n];
            if a != b {
                spans.push(Span::new(a, b, bulge));
            }
        }
        if spans.is_empty() {
            self.warn(
                WarningKind::ZeroArea,
                record.line,
                format!("{} without extent skipped", record.kind),
            );
            return Ok(());
        }
        self.path(spans, closed, to_world, source)
    }

    /// Emits a chain of spans given in local coordinates.
    fn path(
        &mut self,
        spans: Vec<Span>,
        closed: bool,
        to_world: &Transform,
        source: SourceRef,
    ) -> Result<(), DxfError> {
        let mut out = Vec::with_capacity(spans.len());
        let similar = to_world.is_similarity();
        let flip = to_world.is_reflection();
        for s in spans {
            let start = to_world.apply(s.start);
            let end = to_world.apply(s.end);
            if s.bulge == 0.0 || similar {
                out.push(Span::new(start, end, if flip { -s.bulge } else { s.bulge }));
            } else if let Some(center) = s
                .centre()
                .filter(|_| s.bulge.abs() >= STRAIGHT_BULGE && s.chord_length() >= 1e-15)
            {
                // An unevenly scaled arc is an elliptic arc: approximate it. A nearly straight
                // or vanishing one stays a line: its centre would be meaningless.
                let radius = s.radius();
                let t0 = (s.start.y - center.y).atan2_libm(s.start.x - center.x);
                let arc = EllipticArc {
                    center,
                    u: Point::new(radius, 0.0),
                    v: Point::new(0.0, radius),
                    t0,
                    t1: t0 + s.sweep(),
                };
                out.extend(self.approximate_elliptic(&arc, to_world)?);
            } else {
                out.push(Span::line(start, end));
            }
        }
        self.push(out, closed, source)
    }

    fn elliptic(
        &mut self,
        arc: EllipticArc,
        closed: bool,
        to_world: &Transform,
        source: SourceRef,
    ) -> Result<(), DxfError> {
        let world = EllipticArc {
            center: to_world.apply(arc.center),
            u: to_world.apply_vector(arc.u),
            v: to_world.apply_vector(arc.v),
            t0: arc.t0,
            t1: arc.t1,
        };
        let spans = match world.as_circular_spans() {
            Some(spans) => spans,
            None => self.approximate_elliptic(&arc, to_world)?,
        };
        self.push(spans, closed, source)
    }

    fn approximate_elliptic(
        &mut self,
        arc: &EllipticArc,
        to_world: &Transform,
    ) -> Result<Vec<Span>, DxfError> {
        let world = EllipticArc {
            center: to_world.apply(arc.center),
            u: to_world.apply_vector(arc.u),
            v: to_world.apply_vector(arc.v),
            t0: arc.t0,
            t1: arc.t1,
        };
        approximate_elliptic(
            &world,
            self.options.approximation_tolerance,
            &mut self.span_budget,
        )
        .map_err(|ApproxFailure::BudgetExceeded| DxfError::TooComplex {
            limit: self.options.max_spans,
        })
    }

    fn spline(
        &mut self,
        record: &Record<'_>,
        to_world: &Transform,
        source: SourceRef,
    ) -> Result<(), DxfError> {
        let flags = record.int_or(70, 0)?;
        let degree = record.int_or(71, 3)?;
        let mut knots = Vec::new();
        let mut weights = Vec::new();
        let mut control: Vec<Point> = Vec::new();
        let mut fit: Vec<Point> = Vec::new();
        for g in record.body {
            match g.code {
                40 => knots.push(g.real()?),
                41 => weights.push(g.real()?),
                10 => control.push(Point::new(g.real()?, 0.0)),
                20 => set_y(&mut control, g, record)?,
                11 => fit.push(Point::new(g.real()?, 0.0)),
                21 => set_y(&mut fit, g, record)?,
                _ => {}
            }
        }
        let invalid = |reason: String| DxfError::InvalidSpline {
            line: record.line,
            reason,
        };
        // Declared counts must agree with the data: a mismatch means a damaged file.
        for (code, what, actual) in [
            (72, "knots", knots.len()),
            (73, "control points", control.len()),
            (74, "fit points", fit.len()),
        ] {
            if let Some(g) = record.first(code) {
                let declared = g.int()?;
                if declared != actual as i64 {
                    return Err(invalid(format!(
                        "declares {declared} {what} but lists {actual}"
                    )));
                }
            }
        }
        if control.is_empty() {
            if fit.len() < 2 {
                return Err(invalid("neither control points nor fit points".into()));
            }
            // Fit-point-only splines need AutoCAD's interpolation rules; the fit polyline is a
            // usable stand-in but not within the stated tolerance, so say so.
            self.warn(
                WarningKind::Approximated,
                record.line,
                "SPLINE has only fit points: replaced by the polyline through them",
            );
            let spans: Vec<Span> = fit
                .windows(2)
                .filter(|w| w[0] != w[1])
                .map(|w| Span::line(w[0], w[1]))
                .collect();
            return self.path(spans, flags & 1 == 1, to_world, source);
        }
        let degree = usize::try_from(degree).map_err(|_| invalid(format!("degree {degree}")))?;
        let world_control: Vec<Point> = control.iter().map(|p| to_world.apply(*p)).collect();
        let nurbs = Nurbs::new(degree, knots, &world_control, &weights).map_err(invalid)?;
        let (t0, t1) = nurbs.domain();
        let spans = approximate(
            &|t| nurbs.point_at(t),
            t0,
            t1,
            &nurbs.breaks(),
            self.options.approximation_tolerance,
            &mut self.span_budget,
        )
        .map_err(|ApproxFailure::BudgetExceeded| DxfError::TooComplex {
            limit: self.options.max_spans,
        })?;
        let spans: Vec<Span> = spans.into_iter().filter(|s| s.start != s.end).collect();
        if spans.is_empty() {
            self.warn(
                WarningKind::ZeroArea,
                record.line,
                "SPLINE without extent skipped",
            );
            return Ok(());
        }
        // Closed splines come back to their start; the joiner closes them like any chain.
        self.push(spans, false, source)
    }

    fn insert(
        &mut self,
        record: &Record<'_>,
        to_world: &Transform,
        depth: usize,
        layer: &str,
    ) -> Result<(), DxfError> {
        let raw_name = record
            .first(2)
            .ok_or_else(|| record.missing(2, "block name"))?
            .value;
        let display = decode_text(raw_name, self.codepage);
        let key = raw_name.to_ascii_uppercase();
        if depth >= MAX_BLOCK_DEPTH {
            return Err(DxfError::BlockNestingTooDeep {
                line: record.line,
                name: display,
                limit: MAX_BLOCK_DEPTH,
            });
        }
        let Some(ocs) = record.ocs(30, depth > 0)? else {
            self.warn(
                WarningKind::Skipped,
                record.line,
                "INSERT in a tilted plane skipped",
            );
            return Ok(());
        };
        let at = Point::new(record.real_or(10, 0.0)?, record.real_or(20, 0.0)?);
        let scale = Point::new(record.real_or(41, 1.0)?, record.real_or(42, 1.0)?);
        let rotation = record.real_or(50, 0.0)?;
        let columns = record.int_or(70, 1)?.max(1);
        let rows = record.int_or(71, 1)?.max(1);
        let column_spacing = record.real_or(44, 0.0)?;
        let row_spacing = record.real_or(45, 0.0)?;
        if scale.x == 0.0 || scale.y == 0.0 {
            self.warn(
                WarningKind::ZeroArea,
                record.line,
                format!("INSERT of {display:?} with zero scale skipped"),
            );
            return Ok(());
        }
        let copies = columns.saturating_mul(rows);
        if copies > MAX_INSTANCES as i64 {
            return Err(record.invalid(format!("{columns} × {rows} array is too large")));
        }
        let Some(block) = self.blocks.get(&key) else {
            return Err(DxfError::UnknownBlock {
                line: record.line,
                name: display,
            });
        };
        let base = block.base;
        // Clone the records' cheap handles so `self` can be borrowed mutably while expanding.
        let records: Vec<Record<'_>> = block.records.clone();
        for row in 0..rows {
            for column in 0..columns {
                self.instances += 1;
                if self.instances > MAX_INSTANCES {
                    return Err(DxfError::TooComplex {
                        limit: self.options.max_spans,
                    });
                }
                let offset = Point::new(column as f64 * column_spacing, row as f64 * row_spacing);
                let local = insert_placement(at, scale, rotation, base, offset);
                let inner = local.then(&ocs).then(to_world);
                if !is_bounded(&inner) {
                    return Err(record
                        .invalid("nested insert scales and offsets grow beyond 1e6× / 1e12 mm"));
                }
                for r in &records {
                    if r.in_paper_space()? {
                        continue;
                    }
                    self.entity(r, &inner, depth + 1, layer)?;
                }
            }
        }
        Ok(())
    }

    fn push(&mut self, spans: Vec<Span>, closed: bool, source: SourceRef) -> Result<(), DxfError> {
        if spans.len() > self.span_budget {
            return Err(DxfError::TooComplex {
                limit: self.options.max_spans,
            });
        }
        self.span_budget -= spans.len();
        self.pieces.push(Piece {
            spans,
            closed,
            source,
        });
        Ok(())
    }
}

fn set_y(points: &mut [Point], g: &Group<'_>, record: &Record<'_>) -> Result<(), DxfError> {
    let last = points
        .last_mut()
        .ok_or_else(|| record.invalid(format!("line {}: y before any x", g.line)))?;
    last.y = g.real()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placement_rotates_scales_and_moves() {
        let m = insert_placement(
            Point::new(10.0, 0.0),
            Point::new(2.0, 2.0),
            90.0,
            Point::new(1.0, 0.0),
            Point::new(0.0, 0.0),
        );
        let p = m.apply(Point::new(2.0, 0.0));
        assert!((p.x - 10.0).abs() < 1e-12 && (p.y - 2.0).abs() < 1e-12);
        assert!(m.is_similarity());
        let uneven = insert_placement(
            Point::new(0.0, 0.0),
            Point::new(1.0, 3.0),
            0.0,
            Point::new(0.0, 0.0),
            Point::new(0.0, 0.0),
        );
        assert!(!uneven.is_similarity());
        assert!(Transform::mirror_y().determinant() < 0.0);
    }
}
