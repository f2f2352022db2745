//! Opening files: bytes in, a solvable [`Document`] out.

use cutroute_geometry::{Contour, Nest, Part, Point, Vertex};
use cutroute_protocol::{Document, Problem};

/// Read a file whose format is recognised from its content.
pub fn open_document(file_name: &str, bytes: &[u8]) -> Result<Document, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| format!("{file_name}: not a text file ({e})"))?;
    let parts: Vec<GeometryPart> =
        serde_json::from_str(text).map_err(|e| format!("{file_name}: {e}"))?;
    let mut parts: Vec<Part> = parts.into_iter().map(GeometryPart::into_part).collect();
    let sheet = if parts.is_empty() { None } else { Some(parts.remove(0)) };
    let nest = Nest { sheet, parts };
    Ok(Document {
        file_name: file_name.to_string(),
        format: "geometry JSON".into(),
        problem: Problem::Nest { nest, start: Point::new(0.0, 0.0), finish: None },
    })
}

#[derive(serde::Deserialize)]
struct GeometryPart {
    partid: String,
    paths: Vec<Vec<Vec<f64>>>,
}

impl GeometryPart {
    fn into_part(self) -> Part {
        let contours = self
            .paths
            .into_iter()
            .map(|path| {
                let mut vertices: Vec<Vertex> = path
                    .iter()
                    .map(|p| Vertex::arc(p[0], p[1], p.get(2).copied().unwrap_or(0.0)))
                    .collect();
                if vertices.len() > 1 && vertices.first().map(|v| v.point) == vertices.last().map(|v| v.point) {
                    vertices.pop();
                }
                Contour::new(vertices)
            })
            .collect();
        Part { name: self.partid, contours }
    }
}
