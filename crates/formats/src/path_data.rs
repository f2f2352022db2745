//! SVG path data with every digit of the coordinates: the `svg` crate's own builder keeps its
//! numbers as `f32`, which moves a point 74 m from the origin by up to 4 µm and makes a
//! converted drawing read back with another perimeter. Commands are written as that builder
//! writes them (`M0,0 V500 H700 z`, arcs `A r,r,0,0,sweep,x,y`), each number in the shortest
//! form that reads back as the same `f64`.

use std::fmt::Write;

/// The `d` attribute of one `<path>`, built command by command.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PathData(String);

impl PathData {
    pub(crate) fn new() -> PathData {
        PathData::default()
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// One command and its numbers, comma-separated.
    fn command(mut self, letter: char, numbers: &[f64]) -> PathData {
        if !self.0.is_empty() {
            self.0.push(' ');
        }
        self.0.push(letter);
        for (i, n) in numbers.iter().enumerate() {
            if i > 0 {
                self.0.push(',');
            }
            // `-0` is written as `0`: the same point, and no reader trips on it.
            let n = if *n == 0.0 { 0.0 } else { *n };
            let _ = write!(self.0, "{n}");
        }
        self
    }

    pub(crate) fn move_to(self, (x, y): (f64, f64)) -> PathData {
        self.command('M', &[x, y])
    }

    pub(crate) fn line_to(self, (x, y): (f64, f64)) -> PathData {
        self.command('L', &[x, y])
    }

    pub(crate) fn horizontal_line_to(self, x: f64) -> PathData {
        self.command('H', &[x])
    }

    pub(crate) fn vertical_line_to(self, y: f64) -> PathData {
        self.command('V', &[y])
    }

    /// A circular arc of radius `r` to (x, y), never the large one; `sweep` 1 is the positive
    /// angle direction of SVG's (y-down) frame.
    pub(crate) fn arc_to(self, r: f64, sweep: bool, (x, y): (f64, f64)) -> PathData {
        self.command('A', &[r, r, 0.0, 0.0, f64::from(u8::from(sweep)), x, y])
    }

    pub(crate) fn close(self) -> PathData {
        self.command('z', &[])
    }
}

impl From<PathData> for svg::node::Value {
    fn from(data: PathData) -> svg::node::Value {
        data.0.into()
    }
}

#[cfg(test)]
mod tests {
    use super::PathData;

    #[test]
    fn numbers_keep_every_digit_of_an_f64() {
        let d = PathData::new()
            .move_to((73952.431949, -0.0))
            .horizontal_line_to(74435.544947123)
            .arc_to(2.5, true, (0.1, 0.2))
            .close();
        let text = String::from(svg::node::Value::from(d));
        assert_eq!(
            text,
            "M73952.431949,0 H74435.544947123 A2.5,2.5,0,0,1,0.1,0.2 z"
        );
    }
}
