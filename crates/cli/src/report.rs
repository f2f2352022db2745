//! A `solve` report as it is written: its fields as a JSON value, and what there can be
//! hundreds of thousands of — a path route's spans, a contour route's steps — as JSON text of
//! their own.
//!
//! The fields are edited after they are made (warnings, heat, leads per path), so they are a
//! [`Value`]. As values (a map or three each) the spans of a 200,000-span route, or the steps
//! of a 160,000-contour route, took seconds to make, write and free; as text, milliseconds.
//! The steps are made as [`StepReport`]s, which the thermal and kerf reports fill in, and
//! written once. Both are put back in their place (each path's `spans`, the `route`) when
//! the report is written; the output is the same JSON (inside a span, the keys come in the
//! span's field order, not sorted).

use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};
use serde_json::value::RawValue;
use serde_json::Value;

use cutroute_geometry::PathRoute;

/// A report ready to write.
pub struct Report {
    /// Every field; a path route's `route.paths[i]` without its `spans`, a contour route's
    /// `route` a placeholder for its steps.
    pub fields: Value,
    /// Path `i`'s spans (empty: no path route, or its paths are in the fields).
    spans: Vec<Box<RawValue>>,
    /// A contour route's steps, written as `route`.
    steps: Option<Box<RawValue>>,
}

/// One step of a contour route's report: the contour cut, where it is pierced, the link into
/// it (chains); with the thermal report its pierce time `t`, with kerf its leads. The fields
/// are in the JSON's key order (sorted, as a value's map writes them); an absent one is not
/// written.
#[derive(serde::Serialize, Debug, Default)]
pub struct StepReport {
    /// [part, contour].
    pub contour: [usize; 2],
    /// Kerf: where the lead-in meets the contour.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contour_point: Option<[f64; 2]>,
    /// Kerf: pierced at the sheet's border.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub edge_pierce: bool,
    /// Kerf: where the lead-in starts the cut.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub entry: Option<[f64; 2]>,
    /// Kerf: pierced in the open kerf of this [part, contour], cut before.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kerf_pierce: Option<[usize; 2]>,
    /// Kerf: the leads as [x, y, bulge] vertices.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lead_in: Option<Vec<[f64; 3]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lead_out: Option<Vec<[f64; 3]>>,
    /// A chain's link into the contour: its corners.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<Vec<[f64; 2]>>,
    /// The pierce point (absent for a step a chain's link enters).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pierce: Option<[f64; 2]>,
    /// Kerf: where the torch is switched off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub switch_off: Option<[f64; 2]>,
    /// The pierce's time on the machine's clock (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
    /// Kerf: each tab's gap, where the torch stops and where it pierces again.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tabs: Option<Vec<TabGap>>,
}

/// A tab's gap in a step's report.
#[derive(serde::Serialize, Debug)]
pub struct TabGap {
    pub from: [f64; 2],
    pub to: [f64; 2],
}

impl Report {
    /// A report whose fields are all of it.
    pub fn new(fields: Value) -> Report {
        Report {
            fields,
            spans: Vec::new(),
            steps: None,
        }
    }

    /// A report of `fields` whose `route` is `steps`.
    pub fn with_steps(mut fields: Value, steps: &[StepReport]) -> Result<Report, String> {
        fields["route"] = Value::Null;
        let steps = serde_json::value::to_raw_value(steps).map_err(|e| e.to_string())?;
        Ok(Report {
            fields,
            spans: Vec::new(),
            steps: Some(steps),
        })
    }

    /// The JSON value of `route` without its paths' spans, and each path's spans as text: the
    /// parts of [`Report::with_spans`].
    pub fn path_route(route: &PathRoute) -> Result<(Value, Vec<Box<RawValue>>), String> {
        let spans = route
            .paths
            .iter()
            .map(|p| serde_json::value::to_raw_value(&p.spans).map_err(|e| e.to_string()))
            .collect::<Result<Vec<_>, String>>()?;
        let paths: Vec<Value> = route
            .paths
            .iter()
            .map(|p| serde_json::json!({ "pierce": p.pierce, "leads": p.leads }))
            .collect();
        let value = serde_json::json!({
            "start": route.start,
            "paths": paths,
            "finish": route.finish,
        });
        Ok((value, spans))
    }

    /// A report of `fields` whose `route.paths` lack the `spans` given here.
    pub fn with_spans(fields: Value, spans: Vec<Box<RawValue>>) -> Report {
        Report {
            fields,
            spans,
            steps: None,
        }
    }

    /// The report as one line of JSON.
    pub fn to_json(&self) -> Result<String, String> {
        serde_json::to_string(self).map_err(|e| e.to_string())
    }
}

impl Serialize for Report {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let Value::Object(fields) = &self.fields else {
            return self.fields.serialize(serializer);
        };
        if self.spans.is_empty() && self.steps.is_none() {
            return self.fields.serialize(serializer);
        }
        let mut map = serializer.serialize_map(Some(fields.len()))?;
        for (key, value) in fields {
            match &self.steps {
                Some(steps) if key == "route" => map.serialize_entry(key, steps)?,
                _ if key == "route" => {
                    map.serialize_entry(key, &RouteWithSpans(value, &self.spans))?
                }
                _ => map.serialize_entry(key, value)?,
            }
        }
        map.end()
    }
}

/// A route's value with its paths' spans put back.
struct RouteWithSpans<'a>(&'a Value, &'a [Box<RawValue>]);

impl Serialize for RouteWithSpans<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let Value::Object(fields) = self.0 else {
            return self.0.serialize(serializer);
        };
        let mut map = serializer.serialize_map(Some(fields.len()))?;
        for (key, value) in fields {
            match value {
                Value::Array(paths) if key == "paths" => {
                    map.serialize_entry(key, &PathsWithSpans(paths, self.1))?
                }
                _ => map.serialize_entry(key, value)?,
            }
        }
        map.end()
    }
}

/// A route's paths, path `i` with `spans[i]`.
struct PathsWithSpans<'a>(&'a [Value], &'a [Box<RawValue>]);

impl Serialize for PathsWithSpans<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut seq = serializer.serialize_seq(Some(self.0.len()))?;
        for (i, path) in self.0.iter().enumerate() {
            match (path, self.1.get(i)) {
                (Value::Object(fields), Some(spans)) => {
                    seq.serialize_element(&PathWithSpans(fields, spans))?
                }
                _ => seq.serialize_element(path)?,
            }
        }
        seq.end()
    }
}

/// One path's fields with `spans` among them, in the fields' order (sorted keys, as a value's
/// own map writes them).
struct PathWithSpans<'a>(&'a serde_json::Map<String, Value>, &'a RawValue);

impl Serialize for PathWithSpans<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len() + 1))?;
        let mut written = false;
        for (key, value) in self.0 {
            if !written && key.as_str() > "spans" {
                map.serialize_entry("spans", self.1)?;
                written = true;
            }
            map.serialize_entry(key, value)?;
        }
        if !written {
            map.serialize_entry("spans", self.1)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cutroute_geometry::{Point, Span, ToolOnPath};

    /// The report written with its spans apart is the JSON of the whole route, annotations of
    /// its paths included.
    #[test]
    fn the_spans_written_apart_are_the_routes_own_json() {
        let square = |x: f64| {
            let corners = [(x, 0.0), (x + 10.0, 0.0), (x + 10.0, 10.0), (x, 10.0)];
            let spans = (0..4)
                .map(|k| {
                    let (a, b) = (corners[k], corners[(k + 1) % 4]);
                    Span {
                        start: Point::new(a.0, a.1),
                        end: Point::new(b.0, b.1),
                        bulge: 0.25 * k as f64,
                    }
                })
                .collect();
            ToolOnPath::new(Point::new(x, 0.0), spans)
        };
        let route = PathRoute {
            start: Point::new(-1.0, -2.0),
            paths: vec![square(0.0), square(20.0)],
            finish: Some(Point::new(5.0, 5.0)),
        };
        let mut whole = serde_json::json!({ "solver": "sccp", "route": route, "ub": 3.5 });
        let (value, spans) = Report::path_route(&route).unwrap();
        let mut apart = Report::with_spans(
            serde_json::json!({ "solver": "sccp", "route": value, "ub": 3.5 }),
            spans,
        );
        // What the reports add to each path after it is made.
        for fields in [&mut whole, &mut apart.fields] {
            for (i, path) in fields["route"]["paths"]
                .as_array_mut()
                .unwrap()
                .iter_mut()
                .enumerate()
            {
                path["t"] = serde_json::json!(i as f64 * 2.0);
            }
        }
        // The same JSON; inside a span the keys come in the span's field order.
        let read: Value = serde_json::from_str(&apart.to_json().unwrap()).unwrap();
        assert_eq!(read, whole);
        assert_eq!(apart.to_json().unwrap().len(), whole.to_string().len());
    }
}
