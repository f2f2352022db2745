//! LinuxCNC's parameters and expressions: the values a word may have besides a plain number.
//!
//! - `#n` numbered parameters (1–5602, 0 until set, as rs274 starts with an empty parameter
//!   file); `#1`–`#30` are a subroutine's arguments.
//! - `#<name>` named parameters: local to the subroutine level that set them; `#<_name>`
//!   global. Reading one never set is an error, as in LinuxCNC.
//! - `[expr]` expressions with LinuxCNC's binary operators, in its precedence from high to low:
//!   `**`; `*` `/` `MOD`; `+` `-`; `EQ NE GT GE LT LE`; `AND OR XOR`, each level left to right.
//!   A leading `-` or `+` belongs to the operand (`[-2**2]` is 4).
//! - Functions `ABS ACOS ASIN COS EXP FIX FUP ROUND LN SIN SQRT TAN`, `ATAN[y]/[x]` and
//!   `EXISTS[#<name>]`; angles in degrees.
//! - Machine state the reader follows is readable (`#<_x>`, `#<_y>`, `#5420`, `#5421`,
//!   `#<_metric>`, `#<_imperial>`, `#<_absolute>`, `#<_incremental>`, `#5211`/`#5212` the G92
//!   offset, `#5220` the work offset's number as rs274 starts, `#<_value>`); what only a running
//!   machine knows (`#<_hal[…]>`, `#<_ini[…]>`, tool data `#5400`–`#5413`, Z and rotary axes)
//!   is refused with what it would need.

use std::collections::HashMap;

use cutroute_geometry::float::Libm;

use super::GcodeReadError;

/// Deepest nesting of brackets and parameter references in one value.
const MAX_DEPTH: usize = 64;
/// Two values closer than this are equal for `EQ` and `NE` (LinuxCNC's tolerance).
const EQUAL: f64 = 1e-4;
/// Highest parameter number LinuxCNC has.
const MAX_NUMBERED: i64 = 5602;

/// A character of a line after comments and spaces are removed, lower case, with its column.
pub(super) type Char = (char, usize);

/// The machine state a program may read back through parameters.
#[derive(Clone, Copy, Default)]
pub(super) struct Machine {
    /// Where the head stands, in the program's units and frame.
    pub x: f64,
    pub y: f64,
    /// The G92 offset, in the program's units.
    pub g92_x: f64,
    pub g92_y: f64,
    pub metric: bool,
    pub absolute: bool,
}

/// Every parameter of a program: the numbered ones, the globals, and the locals of each
/// subroutine level (the last is the current one).
pub(super) struct Parameters {
    numbered: HashMap<i64, f64>,
    globals: HashMap<String, f64>,
    locals: Vec<HashMap<String, f64>>,
    /// `#1`–`#30` of each calling level, restored when its subroutine returns.
    saved: Vec<[f64; 30]>,
}

/// Where an assignment goes.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Target {
    Numbered(i64),
    Named(String),
}

impl Parameters {
    pub(super) fn new() -> Self {
        Parameters {
            numbered: HashMap::new(),
            globals: HashMap::new(),
            locals: vec![HashMap::new()],
            saved: Vec::new(),
        }
    }

    /// How many subroutine calls deep the program is.
    pub(super) fn call_level(&self) -> usize {
        self.saved.len()
    }

    /// A subroutine is called with `args` as `#1`, `#2`, …; the others of `#1`–`#30` are 0.
    pub(super) fn enter(&mut self, args: &[f64]) {
        let mut saved = [0.0; 30];
        for (n, slot) in saved.iter_mut().enumerate() {
            *slot = self.number(n as i64 + 1);
            let value = args.get(n).copied().unwrap_or(0.0);
            self.numbered.insert(n as i64 + 1, value);
        }
        self.saved.push(saved);
        self.locals.push(HashMap::new());
    }

    /// The subroutine returns (with `value`, for `#<_value>`): the caller's `#1`–`#30` and
    /// locals come back.
    pub(super) fn leave(&mut self, value: Option<f64>) {
        if let Some(saved) = self.saved.pop() {
            for (n, v) in saved.iter().enumerate() {
                self.numbered.insert(n as i64 + 1, *v);
            }
            self.locals.pop();
        }
        self.globals
            .insert("_value".into(), value.unwrap_or(self.global("_value")));
        self.globals.insert(
            "_value_returned".into(),
            f64::from(u8::from(value.is_some())),
        );
    }

    fn number(&self, n: i64) -> f64 {
        self.numbered.get(&n).copied().unwrap_or(0.0)
    }

    fn global(&self, name: &str) -> f64 {
        self.globals.get(name).copied().unwrap_or(0.0)
    }

    /// Sets the parameters a line assigned (after the whole line was read).
    pub(super) fn assign(
        &mut self,
        target: Target,
        value: f64,
        line: usize,
        column: usize,
    ) -> Result<(), GcodeReadError> {
        match target {
            Target::Numbered(n) => {
                self.numbered.insert(n, value);
            }
            Target::Named(name) if predefined(&name) => {
                return Err(expression(
                    line,
                    column,
                    format!("cannot assign to read-only parameter #<{name}>"),
                ))
            }
            Target::Named(name) if name.starts_with('_') => {
                self.globals.insert(name, value);
            }
            Target::Named(name) => {
                if let Some(locals) = self.locals.last_mut() {
                    locals.insert(name, value);
                }
            }
        }
        Ok(())
    }

    fn named(&self, name: &str, machine: &Machine) -> Option<f64> {
        let flag = |b: bool| Some(f64::from(u8::from(b)));
        match name {
            "_x" => Some(machine.x),
            "_y" => Some(machine.y),
            "_metric" => flag(machine.metric),
            "_imperial" => flag(!machine.metric),
            "_absolute" => flag(machine.absolute),
            "_incremental" => flag(!machine.absolute),
            "_call_level" => Some(self.call_level() as f64),
            "_value" | "_value_returned" => Some(self.global(name)),
            _ if name.starts_with('_') => self.globals.get(name).copied(),
            _ => self.locals.last().and_then(|l| l.get(name).copied()),
        }
    }
}

/// LinuxCNC's read-only named parameters (the ones the reader models and the others).
fn predefined(name: &str) -> bool {
    const NAMES: [&str; 12] = [
        "_x",
        "_y",
        "_z",
        "_metric",
        "_imperial",
        "_absolute",
        "_incremental",
        "_call_level",
        "_line",
        "_current_tool",
        "_feed",
        "_rpm",
    ];
    NAMES.contains(&name) || name.starts_with("_hal[") || name.starts_with("_ini[")
}

fn expression(line: usize, column: usize, problem: String) -> GcodeReadError {
    GcodeReadError::Expression {
        line,
        column,
        problem,
    }
}

fn unknown(line: usize, column: usize, item: String, needs: &'static str) -> GcodeReadError {
    GcodeReadError::UnknownValue {
        line,
        column,
        item,
        needs,
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Operator {
    Power,
    Times,
    Divide,
    Modulo,
    Plus,
    Minus,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
}

impl Operator {
    fn precedence(self) -> u8 {
        use Operator::*;
        match self {
            Power => 5,
            Times | Divide | Modulo => 4,
            Plus | Minus => 3,
            Eq | Ne | Gt | Ge | Lt | Le => 2,
            And | Or | Xor => 1,
        }
    }
}

/// Reads values from one line's characters, at `i`, with the parameters as they stood when
/// the line began.
pub(super) struct Reader<'a> {
    pub chars: &'a [Char],
    pub i: usize,
    pub line: usize,
    pub parameters: &'a Parameters,
    pub machine: Machine,
}

impl Reader<'_> {
    pub(super) fn peek(&self) -> Option<char> {
        self.chars.get(self.i).map(|c| c.0)
    }

    /// Column of the character at `i` (or just past the line's end).
    pub(super) fn column(&self) -> usize {
        self.chars
            .get(self.i)
            .or(self.chars.last())
            .map_or(1, |c| c.1 + usize::from(self.i >= self.chars.len()))
    }

    fn error(&self, problem: impl Into<String>) -> GcodeReadError {
        expression(self.line, self.column(), problem.into())
    }

    fn eat(&mut self, word: &str) -> bool {
        let n = word.chars().count();
        let matches = self.chars.len() >= self.i + n
            && self.chars[self.i..self.i + n]
                .iter()
                .map(|c| c.0)
                .eq(word.chars());
        if matches {
            self.i += n;
        }
        matches
    }

    fn expect(&mut self, c: char) -> Result<(), GcodeReadError> {
        if self.eat(&c.to_string()) {
            Ok(())
        } else {
            Err(self.error(format!("expected '{c}'")))
        }
    }

    /// A word's value: a number, a parameter, a bracketed expression or a function, with an
    /// optional sign.
    pub(super) fn value(&mut self) -> Result<f64, GcodeReadError> {
        self.operand(0)
    }

    fn operand(&mut self, depth: usize) -> Result<f64, GcodeReadError> {
        if depth > MAX_DEPTH {
            return Err(self.error(format!("nested deeper than {MAX_DEPTH} levels")));
        }
        let value = match self.peek() {
            Some('-') => {
                self.i += 1;
                -self.operand(depth + 1)?
            }
            Some('+') => {
                self.i += 1;
                self.operand(depth + 1)?
            }
            Some('[') => self.bracket(depth + 1)?,
            Some('#') => {
                let column = self.column();
                self.i += 1;
                self.parameter(depth + 1, column)?
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number()?,
            Some(c) if c.is_ascii_alphabetic() => self.function(depth + 1)?,
            _ => return Err(self.error("expected a number, a parameter or an expression")),
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(self.error("the value is not a finite number"))
        }
    }

    fn number(&mut self) -> Result<f64, GcodeReadError> {
        let begin = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_digit() || c == '.') {
            self.i += 1;
        }
        let text: String = self.chars[begin..self.i].iter().map(|c| c.0).collect();
        if !text.contains(|c: char| c.is_ascii_digit()) || text.matches('.').count() > 1 {
            self.i = begin;
            return Err(self.error(format!("{text} is not a number")));
        }
        text.parse()
            .map_err(|_| self.error(format!("{text} is not a number")))
    }

    fn bracket(&mut self, depth: usize) -> Result<f64, GcodeReadError> {
        self.expect('[')?;
        let value = self.binary(depth)?;
        self.expect(']')?;
        Ok(value)
    }

    /// Operands joined by binary operators, inside brackets.
    fn binary(&mut self, depth: usize) -> Result<f64, GcodeReadError> {
        let mut values = vec![self.operand(depth)?];
        let mut operators: Vec<(Operator, usize)> = Vec::new();
        loop {
            let column = self.column();
            let Some(op) = self.operator() else { break };
            while let Some(&(top, _)) = operators.last() {
                if top.precedence() < op.precedence() {
                    break;
                }
                operators.pop();
                let right = values.pop().unwrap_or(0.0);
                let left = values.pop().unwrap_or(0.0);
                values.push(self.apply(top, left, right, column)?);
            }
            operators.push((op, column));
            values.push(self.operand(depth)?);
        }
        while let Some((op, column)) = operators.pop() {
            let right = values.pop().unwrap_or(0.0);
            let left = values.pop().unwrap_or(0.0);
            values.push(self.apply(op, left, right, column)?);
        }
        Ok(values.pop().unwrap_or(0.0))
    }

    fn operator(&mut self) -> Option<Operator> {
        use Operator::*;
        // `**` before `*`.
        let table = [
            ("**", Power),
            ("*", Times),
            ("/", Divide),
            ("mod", Modulo),
            ("+", Plus),
            ("-", Minus),
            ("eq", Eq),
            ("ne", Ne),
            ("gt", Gt),
            ("ge", Ge),
            ("lt", Lt),
            ("le", Le),
            ("and", And),
            ("or", Or),
            ("xor", Xor),
        ];
        table
            .into_iter()
            .find(|(text, _)| self.eat(text))
            .map(|(_, op)| op)
    }

    fn apply(
        &self,
        op: Operator,
        left: f64,
        right: f64,
        column: usize,
    ) -> Result<f64, GcodeReadError> {
        use Operator::*;
        let fail = |problem: &str| expression(self.line, column, problem.into());
        let truth = |b: bool| f64::from(u8::from(b));
        let value = match op {
            Power => {
                if left < 0.0 && right.fract() != 0.0 {
                    return Err(fail("a negative number raised to a non-integer power"));
                }
                left.powf_libm(right)
            }
            Times => left * right,
            Divide if right == 0.0 => return Err(fail("division by zero")),
            Divide => left / right,
            Modulo if right == 0.0 => return Err(fail("MOD by zero")),
            Modulo => {
                let m = left % right;
                if m < 0.0 {
                    m + right.abs()
                } else {
                    m
                }
            }
            Plus => left + right,
            Minus => left - right,
            Eq => truth((left - right).abs() < EQUAL),
            Ne => truth((left - right).abs() >= EQUAL),
            Gt => truth(left > right),
            Ge => truth(left >= right),
            Lt => truth(left < right),
            Le => truth(left <= right),
            And => truth(left != 0.0 && right != 0.0),
            Or => truth(left != 0.0 || right != 0.0),
            Xor => truth((left != 0.0) != (right != 0.0)),
        };
        if value.is_finite() {
            Ok(value)
        } else {
            Err(fail("the result is not a finite number"))
        }
    }

    fn function(&mut self, depth: usize) -> Result<f64, GcodeReadError> {
        let column = self.column();
        let line = self.line;
        let fail = move |problem: &str| expression(line, column, problem.into());
        if self.eat("exists") {
            self.expect('[')?;
            self.expect('#')?;
            let name = self.name()?;
            self.expect(']')?;
            return Ok(f64::from(u8::from(
                self.parameters.named(&name, &self.machine).is_some(),
            )));
        }
        if self.eat("atan") {
            let y = self.bracket(depth)?;
            self.expect('/')?;
            let x = self.bracket(depth)?;
            return Ok(y.atan2_libm(x).to_degrees());
        }
        // Longer names first where one begins another (`acos` before `cos`? they differ at
        // the first letter; `fix`/`fup` too): the table is tried in order.
        type Function = fn(f64) -> Option<f64>;
        let table: [(&str, Function); 12] = [
            ("abs", |x| Some(x.abs())),
            ("acos", |x| {
                (-1.0..=1.0)
                    .contains(&x)
                    .then(|| x.acos_libm().to_degrees())
            }),
            ("asin", |x| {
                (-1.0..=1.0)
                    .contains(&x)
                    .then(|| x.asin_libm().to_degrees())
            }),
            ("cos", |x| Some(x.to_radians().cos_libm())),
            ("exp", |x| Some(x.exp_libm())),
            ("fix", |x| Some(x.floor())),
            ("fup", |x| Some(x.ceil())),
            ("round", |x| Some(x.round())),
            // The shared maths has no logarithm yet: the platform's, which may differ in the last bit.
            ("ln", |x| (x > 0.0).then(|| x.ln())),
            ("sin", |x| Some(x.to_radians().sin_libm())),
            ("sqrt", |x| (x >= 0.0).then(|| x.sqrt())),
            ("tan", |x| Some(x.to_radians().tan_libm())),
        ];
        let Some((name, f)) = table.into_iter().find(|(name, _)| self.eat(name)) else {
            return Err(fail("unknown function or operator"));
        };
        let x = self.bracket(depth)?;
        f(x).ok_or_else(|| fail(&format!("{} is undefined for {x}", name.to_uppercase())))
    }

    /// A parameter's name after `#`: `<name>` (spaces are already gone).
    fn name(&mut self) -> Result<String, GcodeReadError> {
        self.expect('<')?;
        let begin = self.i;
        while self.peek().is_some_and(|c| c != '>') {
            self.i += 1;
        }
        let name: String = self.chars[begin..self.i].iter().map(|c| c.0).collect();
        self.expect('>')?;
        if name.is_empty() {
            return Err(self.error("a parameter without a name"));
        }
        Ok(name)
    }

    /// What `#` refers to: `#<name>`, or `#` and a number, parameter or expression.
    pub(super) fn target(&mut self, depth: usize) -> Result<Target, GcodeReadError> {
        if self.peek().is_none() {
            // Located at the `#` itself.
            let column = self.chars.get(self.i.wrapping_sub(1)).map_or(1, |c| c.1);
            return Err(expression(
                self.line,
                column,
                "# without a parameter".into(),
            ));
        }
        if self.peek() == Some('<') {
            return Ok(Target::Named(self.name()?));
        }
        let column = self.column();
        let n = self.operand(depth)?;
        if (n - n.round()).abs() > EQUAL || n.round() < 1.0 || n.round() > MAX_NUMBERED as f64 {
            return Err(expression(
                self.line,
                column,
                format!("#{n} is not a parameter number (1–{MAX_NUMBERED})"),
            ));
        }
        Ok(Target::Numbered(n.round() as i64))
    }

    /// The value of the parameter after the `#` at `column`.
    fn parameter(&mut self, depth: usize, column: usize) -> Result<f64, GcodeReadError> {
        match self.target(depth)? {
            Target::Named(name) => self.read_named(name, column),
            Target::Numbered(n) => self.read_numbered(n, column),
        }
    }

    fn read_named(&self, name: String, column: usize) -> Result<f64, GcodeReadError> {
        let line = self.line;
        if name.starts_with("_hal[") {
            return Err(unknown(
                line,
                column,
                format!("#<{name}>"),
                "the HAL pin's value from a running LinuxCNC (rs274 refuses it too)",
            ));
        }
        if name.starts_with("_ini[") {
            return Err(unknown(
                line,
                column,
                format!("#<{name}>"),
                "the machine's INI file",
            ));
        }
        if let Some(v) = self.parameters.named(&name, &self.machine) {
            return Ok(v);
        }
        if predefined(&name) {
            return Err(unknown(
                line,
                column,
                format!("#<{name}>"),
                "machine state the reader does not follow (Z, tools, feed, spindle)",
            ));
        }
        Err(expression(
            line,
            column,
            format!("named parameter #<{name}> is not defined"),
        ))
    }

    fn read_numbered(&self, n: i64, column: usize) -> Result<f64, GcodeReadError> {
        let m = &self.machine;
        match n {
            5211 => Ok(m.g92_x),
            5212 => Ok(m.g92_y),
            5220 => Ok(1.0),
            5420 => Ok(m.x),
            5421 => Ok(m.y),
            5210 | 5213..=5219 => Err(unknown(
                self.line,
                column,
                format!("#{n}"),
                "G92 state the reader does not follow (Z and rotary axes)",
            )),
            5400..=5413 => Err(unknown(
                self.line,
                column,
                format!("#{n}"),
                "the machine's tool table and the tool in the spindle",
            )),
            5422..=MAX_NUMBERED => Err(unknown(
                self.line,
                column,
                format!("#{n}"),
                "the position of Z and the rotary axes, which the reader ignores",
            )),
            _ => Ok(self.parameters.number(n)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chars(text: &str) -> Vec<Char> {
        text.chars()
            .zip(1..)
            .filter(|c| !c.0.is_whitespace())
            .map(|(c, column)| (c.to_ascii_lowercase(), column))
            .collect()
    }

    fn eval_with(text: &str, parameters: &Parameters) -> Result<f64, GcodeReadError> {
        let chars = chars(text);
        let mut reader = Reader {
            chars: &chars,
            i: 0,
            line: 1,
            parameters,
            machine: Machine {
                x: 3.0,
                metric: true,
                absolute: true,
                ..Machine::default()
            },
        };
        let v = reader.value()?;
        assert_eq!(reader.i, chars.len(), "{text}: not all read");
        Ok(v)
    }

    fn eval(text: &str) -> f64 {
        eval_with(text, &Parameters::new()).unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    #[test]
    fn precedence_is_linuxcncs() {
        assert_eq!(eval("[1 + 2 * 3]"), 7.0);
        assert_eq!(eval("[2 ** 3 ** 2]"), 64.0, "left to right");
        assert_eq!(eval("[-2 ** 2]"), 4.0, "the sign belongs to the operand");
        assert_eq!(eval("[1 + 2 EQ 3]"), 1.0);
        assert_eq!(eval("[1 EQ 1 AND 2 GT 1]"), 1.0);
        assert_eq!(eval("[8 / 2 / 2]"), 2.0);
        assert_eq!(eval("[10 - 2 - 3]"), 5.0);
        assert_eq!(eval("[-7 MOD 3]"), 2.0);
        assert_eq!(eval("[1 EQ 1.00001]"), 1.0, "EQ has a tolerance");
        assert_eq!(eval("[2 * [1 + 2]]"), 6.0);
        assert_eq!(eval("[1 XOR 1]"), 0.0);
        assert_eq!(eval("[0 OR 3]"), 1.0);
    }

    #[test]
    fn functions_take_and_give_degrees() {
        assert!((eval("SIN[30]") - 0.5).abs() < 1e-12);
        assert!((eval("[COS[60]]") - 0.5).abs() < 1e-12);
        assert!((eval("ATAN[1]/[1]") - 45.0).abs() < 1e-12);
        assert!((eval("ACOS[0]") - 90.0).abs() < 1e-12);
        assert_eq!(eval("ROUND[-2.5]"), -3.0);
        assert_eq!(eval("FIX[-2.5]"), -3.0);
        assert_eq!(eval("FUP[2.1]"), 3.0);
        assert_eq!(eval("SQRT[16]"), 4.0);
        assert_eq!(eval("ABS[-4]"), 4.0);
        assert_eq!(eval("EXISTS[#<_x>]"), 1.0);
        assert_eq!(eval("EXISTS[#<nothing>]"), 0.0);
        assert_eq!(eval("#<_x>"), 3.0);
    }

    #[test]
    fn parameters_are_read_by_number_name_and_indirection() {
        let mut p = Parameters::new();
        p.assign(Target::Numbered(1), 2.0, 1, 1).unwrap();
        p.assign(Target::Numbered(2), 7.0, 1, 1).unwrap();
        p.assign(Target::Named("w".into()), 5.0, 1, 1).unwrap();
        assert_eq!(eval_with("##1", &p).unwrap(), 7.0);
        assert_eq!(eval_with("#[#1 - 1]", &p).unwrap(), 2.0);
        assert_eq!(eval_with("-#<w>", &p).unwrap(), -5.0);
        assert_eq!(eval_with("#99", &p).unwrap(), 0.0, "0 until set");
        // Locals belong to their subroutine level; globals to all.
        p.assign(Target::Named("_g".into()), 1.0, 1, 1).unwrap();
        p.enter(&[9.0]);
        assert_eq!(eval_with("#1", &p).unwrap(), 9.0);
        assert_eq!(eval_with("#2", &p).unwrap(), 0.0);
        assert!(eval_with("#<w>", &p).is_err());
        assert_eq!(eval_with("#<_g>", &p).unwrap(), 1.0);
        p.leave(Some(4.0));
        assert_eq!(eval_with("#<w>", &p).unwrap(), 5.0);
        assert_eq!(eval_with("#2", &p).unwrap(), 7.0);
        assert_eq!(eval_with("#<_value>", &p).unwrap(), 4.0);
        assert!(p.assign(Target::Named("_x".into()), 1.0, 1, 1).is_err());
    }

    #[test]
    fn what_has_no_value_is_a_located_error() {
        let p = Parameters::new();
        for (text, column, says) in [
            ("[1 / 0]", 4, "division by zero"),
            ("[1 + ]", 6, "expected"),
            ("[1 + 2", 7, "expected ']'"),
            ("SQRT[-1]", 1, "SQRT"),
            ("#<nothing>", 1, "not defined"),
            ("#<_hal[plasmac.cut-feed-rate]>", 1, "HAL"),
            ("#<_ini[traj]units>", 1, "INI"),
            ("#5400", 1, "tool table"),
            ("#0", 2, "parameter number"),
            ("FOO[1]", 1, "unknown function"),
        ] {
            let error = eval_with(text, &p).unwrap_err();
            assert_eq!(error.location(), (1, column), "{text}: {error}");
            assert!(error.to_string().contains(says), "{text}: {error}");
        }
        let deep = format!("{}1{}", "[".repeat(200), "]".repeat(200));
        let error = eval_with(&deep, &p).unwrap_err();
        assert!(error.to_string().contains("nested deeper"), "{error}");
    }
}
