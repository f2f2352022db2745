//! A `solve` report as it is written: its fields as a JSON value, and a path route's spans as
//! JSON text of their own.
//!
//! The fields are edited after they are made (warnings, heat, leads per path), so they are a
//! [`Value`]. The spans are not edited, and there can be hundreds of thousands of them: as
//! values (three maps a span) the report of a 200,000-span route took seconds to make, write
//! and free, as text it takes milliseconds. They are put back in their place, each path's
//! `spans`, when the report is written; the output is the same JSON (inside a span, the keys
//! come in the span's field order, not sorted).

use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};
use serde_json::value::RawValue;
use serde_json::Value;

use cutroute_geometry::PathRoute;

/// A report ready to write.
pub struct Report {
    /// Every field; a path route's `route.paths[i]` without its `spans`.
    pub fields: Value,
    /// Path `i`'s spans (empty: the fields are the whole report).
    spans: Vec<Box<RawValue>>,
}

impl Report {
    /// A report whose fields are all of it.
    pub fn new(fields: Value) -> Report {
        Report {
            fields,
            spans: Vec::new(),
        }
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
        Report { fields, spans }
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
        if self.spans.is_empty() {
            return self.fields.serialize(serializer);
        }
        let mut map = serializer.serialize_map(Some(fields.len()))?;
        for (key, value) in fields {
            if key == "route" {
                map.serialize_entry(key, &RouteWithSpans(value, &self.spans))?;
            } else {
                map.serialize_entry(key, value)?;
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
