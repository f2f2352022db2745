//! T-FLEX nesting projects (`.tfnesting`, XML) → one [`Nest`] per sheet layout.
//!
//! A project defines parts (`Parts/PartDefinition`: an `ID`, a `Name` and a `PartProfile` of
//! contours made of `ContourLine`/`ContourArc` objects, or `CircleContour`/`RectangularContour`
//! shapes), sheets (`Sheets/SheetDefinition`: a `RectangularSheet` of `Width` × `Length` or a
//! `ContourSheet` with a `SheetProfile`), and the nesting result
//! (`Results/NestingResult/Layouts/SheetLayout`), whose `PartPosition`s place parts on a sheet.
//!
//! # Placement semantics
//!
//! A placed part's points are `position + R(AngleDeg) · M · p`, where `p` is a point of the part
//! definition in its own coordinates, `M` mirrors `x ↦ −x` when `Inverted` is true (identity
//! otherwise), `R` turns counter-clockwise by `AngleDeg` **degrees**, and `position` is where the
//! part's **own origin** lands (not its bounding box corner). This was established on the
//! reference projects: with these semantics the 406 parts of `Nest02` (angles 0, 90, 116, 135,
//! 180, 270, 296, 315°) and `Nest03` (125 mirrored parts) lie on their 6000 × 2000 sheet without
//! overlapping (see `tests/tflex_files.rs`), whereas clockwise angles, bounding-box anchoring or
//! an `y ↦ −y` mirror produce dozens of overlaps or parts off the sheet. In the reference data
//! only unrotated parts are mirrored, so the order of mirror and rotation is not pinned down by
//! data; mirror-then-rotate is the natural reading of a flipped part turned on the sheet.
//! `ContourArc/Angle` is the signed sweep in radians (negative = clockwise, agreeing with
//! `Ccw`); `Rotated` merely says whether `AngleDeg` is non-zero. `RectangularContour` and
//! `RectangularSheet` span `(0, 0)`–`(Width, Length)`: `Width` runs along x.
//!
//! Contours are re-oriented after placement (a mirror reverses them): the outer contour (the
//! largest) clockwise, the holes counter-clockwise.

use cutroute_geometry::float::Libm;
use std::collections::HashMap;

use cutroute_geometry::{Contour, Nest, Part, Point, Transform, Vertex};
use roxmltree::{Document, Node};

const XSI: &str = "http://www.w3.org/2001/XMLSchema-instance";
/// Largest accepted coordinate magnitude (mm): far beyond any sheet, far below overflow.
const MAX_MAGNITUDE: f64 = cutroute_geometry::MAX_COORDINATE;
/// Most vertices all placed parts together may have: placements multiply part definitions, so
/// a small hostile file could otherwise ask for billions.
const MAX_PLACED_VERTICES: usize = 5_000_000;
/// Largest gap (mm) between one contour object's end and the next one's beginning.
const CONTINUITY_TOLERANCE: f64 = 0.01;

/// Why a T-FLEX project could not be read: the CAD readers' shared [`CadError`](crate::CadError),
/// whose shared and `T-FLEX:` variants this reader returns. `path` is the element path, e.g.
/// `/Project/Parts/PartDefinition[2]/PartProfile/Contours/Contour[1]`, and `line`/`column`
/// locate it in the file (1-based).
pub type TflexError = crate::CadError;

/// One part placement of a sheet layout, as stored in the project.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// `PartID` of the placed part definition.
    pub part_id: i64,
    /// Counter-clockwise turn, degrees.
    pub angle_deg: f64,
    /// Whether the part is mirrored (`x ↦ −x` before turning).
    pub mirrored: bool,
    /// Where the part's own origin lands on the sheet.
    pub position: Point,
}

/// One sheet layout: the sheet, the placements and the resulting nest.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetLayout {
    /// `SheetID` of the sheet definition.
    pub sheet_id: i64,
    /// `SheetIndex`: which copy of that sheet.
    pub sheet_index: i64,
    /// The sheet's name.
    pub sheet_name: String,
    /// The placements in file order.
    pub placements: Vec<Placement>,
    /// Sheet contour and placed parts (named after their definitions), in placement order.
    pub nest: Nest,
}

/// A whole project: every sheet layout of its nesting result.
#[derive(Clone, Debug, PartialEq)]
pub struct TflexProject {
    /// The project's name.
    pub name: String,
    /// One entry per `SheetLayout`.
    pub layouts: Vec<SheetLayout>,
}

/// Reads a T-FLEX nesting project: one nest per sheet layout (sheet contour included).
pub fn read_tfnesting(bytes: &[u8]) -> Result<Vec<Nest>, TflexError> {
    Ok(read_tfnesting_project(bytes)?
        .layouts
        .into_iter()
        .map(|l| l.nest)
        .collect())
}

/// Reads a T-FLEX nesting project with its sheet and placement details.
pub fn read_tfnesting_project(bytes: &[u8]) -> Result<TflexProject, TflexError> {
    let text = crate::error::xml_text(bytes)?;
    let doc = crate::error::xml_document(text, roxmltree::ParsingOptions::default())?;
    let root = doc.root_element();
    if root.tag_name().name() != "Project" {
        return Err(TflexError::NotAProject {
            found: root.tag_name().name().to_owned(),
        });
    }
    let r = Reader { doc: &doc };

    let mut parts: HashMap<i64, (String, Vec<Contour>)> = HashMap::new();
    let parts_node = r.child(root, "Parts")?;
    for def in children(parts_node, "PartDefinition") {
        let id = r.int(r.child(def, "ID")?)?;
        let name = r.child(def, "Name").map(text_of).unwrap_or_default();
        let profile = r.child(def, "PartProfile")?;
        let contours = r.profile(profile)?;
        parts.insert(id, (name.to_owned(), contours));
    }

    let mut sheets: HashMap<i64, (String, Vec<Contour>)> = HashMap::new();
    if let Some(sheets_node) = child(root, "Sheets") {
        for def in children(sheets_node, "SheetDefinition") {
            let id = r.int(r.child(def, "ID")?)?;
            let name = child(def, "Name").map(text_of).unwrap_or_default();
            let contours = match def.attribute((XSI, "type")) {
                Some("ContourSheet") => r.profile(r.child(def, "SheetProfile")?)?,
                Some("RectangularSheet") | None => vec![r.rectangle(def)?],
                Some(other) => return Err(r.unknown_type(def, other)),
            };
            sheets.insert(id, (name.to_owned(), contours));
        }
    }

    let name = child(root, "Name")
        .map(text_of)
        .unwrap_or_default()
        .to_owned();
    let mut layouts = Vec::new();
    let mut vertex_total = 0usize;
    let results = child(root, "Results");
    let results_iter = results
        .into_iter()
        .flat_map(|n| children(n, "NestingResult"));
    for result in results_iter {
        let Some(layouts_node) = child(result, "Layouts") else {
            continue;
        };
        for layout in children(layouts_node, "SheetLayout") {
            let sheet_id = r.int(r.child(layout, "SheetID")?)?;
            let sheet_index = child(layout, "SheetIndex")
                .map(|n| r.int(n))
                .transpose()?
                .unwrap_or(0);
            let (sheet_name, sheet_contours) = sheets
                .get(&sheet_id)
                .ok_or_else(|| r.unknown_reference(layout, "sheet", sheet_id))?;
            let mut placements = Vec::new();
            let mut placed = Vec::new();
            if let Some(positions) = child(layout, "PartPositions") {
                for pos in children(positions, "PartPosition") {
                    let part_id = r.int(r.child(pos, "PartID")?)?;
                    let angle_deg = child(pos, "AngleDeg")
                        .map(|n| r.real(n))
                        .transpose()?
                        .unwrap_or(0.0);
                    let mirrored = child(pos, "Inverted")
                        .map(|n| r.boolean(n))
                        .transpose()?
                        .unwrap_or(false);
                    let position = r.point(r.child(pos, "Position")?)?;
                    let (part_name, contours) = parts
                        .get(&part_id)
                        .ok_or_else(|| r.unknown_reference(pos, "part", part_id))?;
                    vertex_total = vertex_total
                        .saturating_add(contours.iter().map(|c| c.vertices.len()).sum::<usize>());
                    if vertex_total > MAX_PLACED_VERTICES {
                        return Err(TflexError::TooLarge {
                            limit: MAX_PLACED_VERTICES,
                        });
                    }
                    let placement = Placement {
                        part_id,
                        angle_deg,
                        mirrored,
                        position,
                    };
                    placed.push(Part {
                        name: part_name.clone(),
                        contours: place(contours, &placement),
                    });
                    placements.push(placement);
                }
            }
            let sheet = Part {
                name: sheet_name.clone(),
                contours: orient(sheet_contours.clone()),
            };
            layouts.push(SheetLayout {
                sheet_id,
                sheet_index,
                sheet_name: sheet_name.clone(),
                placements,
                nest: Nest {
                    sheet: Some(sheet),
                    parts: placed,
                },
            });
        }
    }
    Ok(TflexProject { name, layouts })
}

/// Applies a placement to a part definition's contours and re-orients them: mirrored in the
/// y axis if asked, turned by the angle, moved to the position.
fn place(contours: &[Contour], placement: &Placement) -> Vec<Contour> {
    let mirror = if placement.mirrored {
        Transform::mirror_y()
    } else {
        Transform::IDENTITY
    };
    let map = mirror
        .then(&Transform::rotation(placement.angle_deg.to_radians()))
        .then(&Transform::translation(
            placement.position.x,
            placement.position.y,
        ));
    orient(contours.iter().map(|c| c.transformed(&map)).collect())
}

/// Largest contour first and clockwise, the others counter-clockwise.
fn orient(contours: Vec<Contour>) -> Vec<Contour> {
    let mut with_area: Vec<(f64, Contour)> =
        contours.into_iter().map(|c| (c.signed_area(), c)).collect();
    let outer = with_area
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .0.abs().total_cmp(&b.1 .0.abs()))
        .map(|(i, _)| i);
    if let Some(i) = outer {
        let first = with_area.remove(i);
        with_area.insert(0, first);
    }
    with_area
        .into_iter()
        .enumerate()
        .map(|(k, (area, c))| {
            let want_ccw = k > 0;
            if (area > 0.0) != want_ccw {
                c.reversed()
            } else {
                c
            }
        })
        .collect()
}

fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    node.children()
        .find(|n| n.is_element() && n.tag_name().name() == name)
}

fn children<'a, 'i: 'a>(
    node: Node<'a, 'i>,
    name: &'a str,
) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
    node.children()
        .filter(move |n| n.is_element() && n.tag_name().name() == name)
}

fn text_of<'a>(node: Node<'a, '_>) -> &'a str {
    node.text().unwrap_or("").trim()
}

/// Element lookups that turn absence and bad text into located errors.
struct Reader<'d, 'i> {
    doc: &'d Document<'i>,
}

impl<'d, 'i> Reader<'d, 'i> {
    fn position(&self, node: Node<'_, '_>) -> (u32, u32) {
        let p = self.doc.text_pos_at(node.range().start);
        (p.row, p.col)
    }

    /// `/Project/Parts/PartDefinition[2]/…` with 1-based indices among same-named siblings.
    fn path(&self, node: Node<'_, '_>) -> String {
        let mut segments = Vec::new();
        let mut current = Some(node);
        while let Some(n) = current {
            if n.is_element() {
                let name = n.tag_name().name();
                let same: Vec<_> = n
                    .parent()
                    .map(|p| children(p, name).collect())
                    .unwrap_or_default();
                if same.len() > 1 {
                    let index = same.iter().position(|s| *s == n).unwrap_or(0) + 1;
                    segments.push(format!("{name}[{index}]"));
                } else {
                    segments.push(name.to_owned());
                }
            }
            current = n.parent();
        }
        segments.reverse();
        format!("/{}", segments.join("/"))
    }

    fn child<'a>(
        &self,
        node: Node<'a, 'i>,
        element: &'static str,
    ) -> Result<Node<'a, 'i>, TflexError> {
        child(node, element).ok_or_else(|| {
            let (line, column) = self.position(node);
            TflexError::MissingElement {
                path: self.path(node),
                element,
                line,
                column,
            }
        })
    }

    fn bad_value(&self, node: Node<'_, '_>, expected: &'static str) -> TflexError {
        let (line, column) = self.position(node);
        TflexError::BadValue {
            path: self.path(node),
            expected,
            text: text_of(node).chars().take(60).collect(),
            line,
            column,
        }
    }

    fn unknown_type(&self, node: Node<'_, '_>, found: &str) -> TflexError {
        let (line, column) = self.position(node);
        TflexError::UnknownType {
            path: self.path(node),
            found: found.to_owned(),
            line,
            column,
        }
    }

    fn unknown_reference(&self, node: Node<'_, '_>, what: &'static str, id: i64) -> TflexError {
        let (line, column) = self.position(node);
        TflexError::UnknownReference {
            path: self.path(node),
            what,
            id,
            line,
            column,
        }
    }

    fn invalid(&self, node: Node<'_, '_>, reason: impl Into<String>) -> TflexError {
        let (line, column) = self.position(node);
        TflexError::InvalidGeometry {
            path: self.path(node),
            reason: reason.into(),
            line,
            column,
        }
    }

    fn real(&self, node: Node<'_, '_>) -> Result<f64, TflexError> {
        match text_of(node).parse::<f64>() {
            Ok(v) if v.is_finite() && v.abs() <= MAX_MAGNITUDE => Ok(v),
            _ => Err(self.bad_value(node, "a finite number within ±1e9")),
        }
    }

    fn int(&self, node: Node<'_, '_>) -> Result<i64, TflexError> {
        text_of(node)
            .parse::<i64>()
            .map_err(|_| self.bad_value(node, "an integer"))
    }

    fn boolean(&self, node: Node<'_, '_>) -> Result<bool, TflexError> {
        match text_of(node) {
            "true" | "True" | "1" => Ok(true),
            "false" | "False" | "0" => Ok(false),
            _ => Err(self.bad_value(node, "true or false")),
        }
    }

    fn point(&self, node: Node<'_, '_>) -> Result<Point, TflexError> {
        Ok(Point::new(
            self.real(self.child(node, "X")?)?,
            self.real(self.child(node, "Y")?)?,
        ))
    }

    fn positive(&self, node: Node<'_, '_>, what: &str) -> Result<f64, TflexError> {
        let v = self.real(node)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(node, format!("{what} {v} must be positive")))
        }
    }

    /// `(0, 0)`–`(Width, Length)`, clockwise.
    fn rectangle(&self, node: Node<'_, '_>) -> Result<Contour, TflexError> {
        let w = self.positive(self.child(node, "Width")?, "width")?;
        let l = self.positive(self.child(node, "Length")?, "length")?;
        Ok(Contour::new(vec![
            Vertex::line(0.0, 0.0),
            Vertex::line(0.0, l),
            Vertex::line(w, l),
            Vertex::line(w, 0.0),
        ]))
    }

    fn profile(&self, profile: Node<'_, '_>) -> Result<Vec<Contour>, TflexError> {
        let contours_node = self.child(profile, "Contours")?;
        let mut contours = Vec::new();
        for contour in children(contours_node, "Contour") {
            contours.push(self.contour(contour)?);
        }
        if contours.is_empty() {
            return Err(self.invalid(contours_node, "the profile has no contour"));
        }
        Ok(contours)
    }

    fn contour(&self, node: Node<'_, '_>) -> Result<Contour, TflexError> {
        match node.attribute((XSI, "type")) {
            Some("FigureContour") => self.figure(node),
            Some("CircleContour") => {
                let c = self.point(self.child(node, "Center")?)?;
                let r = self.positive(self.child(node, "Radius")?, "radius")?;
                Ok(Contour::new(vec![
                    Vertex::arc(c.x + r, c.y, 1.0),
                    Vertex::arc(c.x - r, c.y, 1.0),
                ]))
            }
            Some("RectangularContour") => self.rectangle(node),
            other => Err(self.unknown_type(node, other.unwrap_or("(none)"))),
        }
    }

    fn figure(&self, node: Node<'_, '_>) -> Result<Contour, TflexError> {
        let objects = self.child(node, "Objects")?;
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut previous_end: Option<(Point, Node<'_, '_>)> = None;
        for object in children(objects, "ContourObject") {
            let begin = self.point(self.child(object, "Begin")?)?;
            let end = self.point(self.child(object, "End")?)?;
            if let Some((prev, prev_node)) = previous_end {
                if prev.distance(begin) > CONTINUITY_TOLERANCE {
                    return Err(self.invalid(
                        object,
                        format!(
                            "begins {:.4} mm away from where {} ends",
                            prev.distance(begin),
                            self.path(prev_node)
                        ),
                    ));
                }
            }
            match object.attribute((XSI, "type")) {
                Some("ContourLine") => vertices.push(Vertex {
                    point: begin,
                    bulge: 0.0,
                }),
                Some("ContourArc") => {
                    let center = self.point(self.child(object, "Center")?)?;
                    let angle_node = self.child(object, "Angle")?;
                    let sweep = self.real(angle_node)?;
                    if sweep == 0.0 || sweep.abs() > std::f64::consts::TAU + 1e-9 {
                        return Err(self.invalid(
                            angle_node,
                            format!("arc angle {sweep} rad is not in (0, 2π]"),
                        ));
                    }
                    if center == begin {
                        return Err(self.invalid(object, "arc of zero radius"));
                    }
                    if sweep.abs() > std::f64::consts::PI {
                        // Split large arcs: a single span's bulge tends to infinity at 2π.
                        let (s, c) = (sweep / 2.0).sin_cos_libm();
                        let (dx, dy) = (begin.x - center.x, begin.y - center.y);
                        let middle =
                            Point::new(center.x + c * dx - s * dy, center.y + s * dx + c * dy);
                        let bulge = (sweep / 8.0).tan_libm();
                        vertices.push(Vertex {
                            point: begin,
                            bulge,
                        });
                        vertices.push(Vertex {
                            point: middle,
                            bulge,
                        });
                    } else {
                        vertices.push(Vertex {
                            point: begin,
                            bulge: (sweep / 4.0).tan_libm(),
                        });
                    }
                }
                other => return Err(self.unknown_type(object, other.unwrap_or("(none)"))),
            }
            previous_end = Some((end, object));
        }
        let Some(first) = vertices.first() else {
            return Err(self.invalid(objects, "the contour has no objects"));
        };
        if let Some((last, last_node)) = previous_end {
            if last.distance(first.point) > CONTINUITY_TOLERANCE {
                return Err(self.invalid(last_node, "the contour does not close"));
            }
        }
        let contour = Contour::new(vertices);
        // A nesting program's output: a contour that is not cuttable is refused, located, as
        // the other nest formats refuse it.
        if let Err(fault) = contour.check_cuttable(CONTINUITY_TOLERANCE) {
            return Err(self.invalid(node, fault.to_string()));
        }
        Ok(contour)
    }
}
