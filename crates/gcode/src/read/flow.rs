//! LinuxCNC's O-word control flow over a whole program: subroutines defined in the file
//! (`sub`/`endsub`, `call` with arguments `#1`…, `return`), `if`/`elseif`/`else`/`endif`,
//! `while`/`endwhile`, `do`/`while`, `repeat`/`endrepeat`, `break` and `continue`. Each line
//! is read (its values evaluated, its assignments made) when it runs; `M2`/`M30` end the
//! program. A program that runs more than [`MAX_BLOCKS`] lines, or calls deeper than
//! [`MAX_CALLS`], is refused where it stands.

use std::collections::HashMap;

use super::expr::{Char, Parameters, Reader, Target};
use super::{GcodeReadError, State, Word, MAX_VALUE};

/// Most lines a program may run (loops included) before it is taken for one that never ends.
pub(super) const MAX_BLOCKS: usize = 1_000_000;
/// Deepest subroutine nesting.
pub(super) const MAX_CALLS: usize = 100;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Keyword {
    Sub,
    Endsub,
    Call,
    Return,
    If,
    Elseif,
    Else,
    Endif,
    While,
    Endwhile,
    Do,
    /// The `while` that closes a `do`.
    DoWhile,
    Repeat,
    Endrepeat,
    Break,
    Continue,
}

impl Keyword {
    fn parse(word: &str) -> Option<Keyword> {
        use Keyword::*;
        Some(match word {
            "sub" => Sub,
            "endsub" => Endsub,
            "call" => Call,
            "return" => Return,
            "if" => If,
            "elseif" => Elseif,
            "else" => Else,
            "endif" => Endif,
            "while" => While,
            "endwhile" => Endwhile,
            "do" => Do,
            "repeat" => Repeat,
            "endrepeat" => Endrepeat,
            "break" => Break,
            "continue" => Continue,
            _ => return None,
        })
    }

    /// The keyword as a program writes it.
    fn name(self) -> &'static str {
        use Keyword::*;
        match self {
            Sub => "sub",
            Endsub => "endsub",
            Call => "call",
            Return => "return",
            If => "if",
            Elseif => "elseif",
            Else => "else",
            Endif => "endif",
            While | DoWhile => "while",
            Endwhile => "endwhile",
            Do => "do",
            Repeat => "repeat",
            Endrepeat => "endrepeat",
            Break => "break",
            Continue => "continue",
        }
    }

    fn is_loop(self) -> bool {
        matches!(self, Keyword::While | Keyword::Do | Keyword::Repeat)
    }
}

/// An O-word line: its label (`100` or `<name>`), keyword and what follows it.
struct OLine {
    label: String,
    keyword: Keyword,
    column: usize,
    rest: Vec<Char>,
    /// The line that opens this one's construct (for closers, `break` and `continue`).
    open: usize,
    /// The line that closes this one's construct.
    close: usize,
    /// The next `elseif`/`else`/`endif` of an `if` chain.
    next: usize,
    /// The `if`/`elseif` this `elseif`/`else`/`endif` follows.
    previous: usize,
}

/// A line of the program: a block (stripped again each time it runs, so a long program is not
/// held twice), or an O-word line.
enum Source {
    Block,
    Flow(Box<OLine>),
}

/// A line without its comments and spaces, in lower case, each character with its column.
fn strip(raw: &str, line: usize) -> Result<Vec<Char>, GcodeReadError> {
    let chars: Vec<char> = raw.chars().collect();
    let mut out = Vec::with_capacity(chars.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        match c {
            '(' => match chars[i..].iter().position(|&d| d == ')') {
                Some(close) => i += close,
                None => {
                    return Err(GcodeReadError::UnclosedComment {
                        line,
                        column: i + 1,
                    })
                }
            },
            ';' => break,
            c if c.is_whitespace() => {}
            // Tape marks and block delete (the block is executed).
            '%' | '/' if out.is_empty() => {}
            c => out.push((c.to_ascii_lowercase(), i + 1)),
        }
        i += 1;
    }
    Ok(out)
}

fn flow_error(line: usize, column: usize, problem: String) -> GcodeReadError {
    GcodeReadError::ControlFlow {
        line,
        column,
        problem,
    }
}

/// Reads an O-word line, or `None` for a plain block (an `O1234` program number is one).
fn o_line(chars: &[Char], line: usize) -> Result<Option<OLine>, GcodeReadError> {
    if chars.first().map(|c| c.0) != Some('o') {
        return Ok(None);
    }
    let column = chars[0].1;
    let mut i = 1;
    let label: String = if chars.get(1).map(|c| c.0) == Some('<') {
        let end = chars[1..]
            .iter()
            .position(|c| c.0 == '>')
            .ok_or_else(|| flow_error(line, column, "O-word name without '>'".into()))?;
        i = end + 2;
        chars[1..=end + 1].iter().map(|c| c.0).collect()
    } else {
        while chars.get(i).is_some_and(|c| c.0.is_ascii_digit()) {
            i += 1;
        }
        let digits: String = chars[1..i].iter().map(|c| c.0).collect();
        if digits.is_empty() {
            return Err(GcodeReadError::MissingNumber {
                line,
                column,
                letter: 'O',
            });
        }
        digits.trim_start_matches('0').to_string()
    };
    let begin = i;
    while chars.get(i).is_some_and(|c| c.0.is_ascii_alphabetic()) {
        i += 1;
    }
    let word: String = chars[begin..i].iter().map(|c| c.0).collect();
    if word.is_empty() {
        if label.starts_with('<') {
            return Err(flow_error(
                line,
                column,
                format!("o{label} without sub, call, if, while, do or repeat"),
            ));
        }
        // A program number: the rest of the line is a block.
        return Ok(None);
    }
    let keyword = Keyword::parse(&word).ok_or_else(|| {
        flow_error(
            line,
            chars[begin].1,
            format!("o{label} {word}: not an O-word keyword"),
        )
    })?;
    Ok(Some(OLine {
        label,
        keyword,
        column,
        rest: chars[i..].to_vec(),
        open: usize::MAX,
        close: usize::MAX,
        next: usize::MAX,
        previous: usize::MAX,
    }))
}

/// The program's lines, with every construct's opening and closing lines linked.
struct Structure<'a> {
    lines: Vec<&'a str>,
    sources: Vec<Source>,
    subs: HashMap<String, usize>,
}

/// The characters of a block line, without an `O1234` program number.
fn block_chars(raw: &str, line: usize) -> Result<Vec<Char>, GcodeReadError> {
    let chars = strip(raw, line)?;
    if chars.first().map(|c| c.0) != Some('o') {
        return Ok(chars);
    }
    Ok(chars
        .iter()
        .skip(1)
        .skip_while(|c| c.0.is_ascii_digit())
        .copied()
        .collect())
}

fn structure(text: &str) -> Result<Structure<'_>, GcodeReadError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut sources = Vec::with_capacity(lines.len());
    for (index, raw) in lines.iter().enumerate() {
        let chars = strip(raw, index + 1)?;
        sources.push(match o_line(&chars, index + 1)? {
            Some(o) => Source::Flow(Box::new(o)),
            None => Source::Block,
        });
    }
    let mut subs = HashMap::new();
    let mut open: Vec<usize> = Vec::new();
    for i in 0..sources.len() {
        let Source::Flow(o) = &sources[i] else {
            continue;
        };
        let (keyword, label, column) = (o.keyword, o.label.clone(), o.column);
        let line = i + 1;
        let top = open.last().copied();
        let top_is = |k: &[Keyword], sources: &[Source]| match top.map(|t| &sources[t]) {
            Some(Source::Flow(t)) => k.contains(&t.keyword) && t.label == label,
            _ => false,
        };
        let mismatch = |what: &str| {
            flow_error(
                line,
                column,
                format!("o{label} {what} does not close an open o{label} block"),
            )
        };
        use Keyword::*;
        match keyword {
            Sub => {
                if !open.is_empty() {
                    return Err(flow_error(
                        line,
                        column,
                        format!("o{label} sub inside another block"),
                    ));
                }
                subs.insert(label, i);
                open.push(i);
            }
            If | Do | Repeat => open.push(i),
            While if top_is(&[Do], &sources) => {
                let t = open.pop().unwrap_or(i);
                link(&mut sources, t, i, DoWhile);
            }
            While => open.push(i),
            Elseif | Else => {
                if !top_is(&[If, Elseif], &sources) {
                    return Err(mismatch(if keyword == Else { "else" } else { "elseif" }));
                }
                let t = open.pop().unwrap_or(i);
                chain(&mut sources, t, i);
                open.push(i);
            }
            Endsub | Endif | Endwhile | Endrepeat => {
                let opener = match keyword {
                    Endsub => vec![Sub],
                    Endif => vec![If, Elseif, Else],
                    Endwhile => vec![While],
                    _ => vec![Repeat],
                };
                if !top_is(&opener, &sources) {
                    return Err(mismatch(keyword.name()));
                }
                let t = open.pop().unwrap_or(i);
                if keyword == Endif {
                    chain(&mut sources, t, i);
                    close_chain(&mut sources, t, i);
                } else {
                    link(&mut sources, t, i, keyword);
                }
            }
            Break | Continue | Return => {
                let wanted = |k: Keyword| {
                    if keyword == Return {
                        k == Sub
                    } else {
                        k.is_loop()
                    }
                };
                let found = open.iter().rev().copied().find(|&t| match &sources[t] {
                    Source::Flow(f) => wanted(f.keyword) && (keyword == Return || f.label == label),
                    _ => false,
                });
                match (found, &mut sources[i]) {
                    (Some(t), Source::Flow(f)) => f.open = t,
                    _ if keyword == Return => {
                        return Err(flow_error(
                            line,
                            column,
                            format!("o{label} return outside a subroutine"),
                        ))
                    }
                    _ => {
                        return Err(flow_error(
                            line,
                            column,
                            format!("o{label} {} outside an o{label} loop", keyword.name()),
                        ))
                    }
                }
            }
            Call | DoWhile => {}
        }
    }
    // A construct left open is an error only where the program must jump past its end (as
    // in rs274, which runs an unclosed loop's body to the program's end).
    // Break and continue jump to their loop's closing line, known only now.
    for i in 0..sources.len() {
        let Source::Flow(f) = &sources[i] else {
            continue;
        };
        if matches!(f.keyword, Keyword::Break | Keyword::Continue) {
            let t = f.open;
            let close = match &sources[t] {
                Source::Flow(l) => l.close,
                Source::Block => usize::MAX,
            };
            if let Source::Flow(f) = &mut sources[i] {
                f.close = close;
            }
        }
    }
    Ok(Structure {
        lines,
        sources,
        subs,
    })
}

/// Links an opening line and its closing line; the closer becomes `keyword`.
fn link(sources: &mut [Source], open: usize, close: usize, keyword: Keyword) {
    if let Source::Flow(o) = &mut sources[open] {
        o.close = close;
    }
    if let Source::Flow(c) = &mut sources[close] {
        c.open = open;
        c.keyword = keyword;
    }
}

/// `next` follows `from` in an `if` chain.
fn chain(sources: &mut [Source], from: usize, next: usize) {
    if let Source::Flow(o) = &mut sources[from] {
        o.next = next;
    }
    if let Source::Flow(o) = &mut sources[next] {
        o.previous = from;
    }
}

/// Every line of the `if` chain ending at `last` (`endif`) closes there.
fn close_chain(sources: &mut [Source], last_branch: usize, endif: usize) {
    // Walk back from the last branch to the `if`.
    let mut branch = last_branch;
    while let Some(Source::Flow(o)) = sources.get_mut(branch) {
        o.close = endif;
        if o.keyword == Keyword::If {
            break;
        }
        branch = o.previous;
    }
}

/// The line after `target`, the closing line of `o`'s construct, if there is one.
fn past(o: &OLine, target: usize, line: usize) -> Result<usize, GcodeReadError> {
    if target == usize::MAX {
        return Err(flow_error(
            line,
            o.column,
            format!(
                "o{} {}: its block is never closed before the program ends",
                o.label,
                o.keyword.name()
            ),
        ));
    }
    Ok(target + 1)
}

/// A subroutine call under way.
struct Frame {
    return_to: usize,
    /// `repeat` counters of this level, by the `repeat` line.
    repeats: HashMap<usize, i64>,
}

/// Runs the program through `state`, line by line as the control flow goes.
pub(super) fn run(text: &str, state: &mut State) -> Result<usize, GcodeReadError> {
    let Structure {
        lines,
        sources,
        subs,
    } = structure(text)?;
    let mut parameters = Parameters::new();
    let mut frames: Vec<Frame> = Vec::new();
    let mut repeats: HashMap<usize, i64> = HashMap::new();
    let mut pc = 0;
    // LinuxCNC's interpreter remembers that a `break` ran until the end of a `do` loop: that
    // loop then does not repeat, whatever its condition (rs274 behaves so; so does the reader).
    let mut break_pending = false;
    let mut ran = 0usize;
    let mut last_line = 0;
    while pc < sources.len() {
        ran += 1;
        let line = pc + 1;
        last_line = line;
        if ran > MAX_BLOCKS {
            return Err(GcodeReadError::RunsTooLong {
                line,
                column: 1,
                limit: MAX_BLOCKS,
            });
        }
        let o = match &sources[pc] {
            Source::Block => {
                let chars = block_chars(lines[pc], line)?;
                if chars.is_empty() {
                    pc += 1;
                    continue;
                }
                let (words, assignments) = read_block(&chars, line, &parameters, state)?;
                for (target, value, column) in assignments {
                    parameters.assign(target, value, line, column)?;
                }
                state.block(&words, line)?;
                let ends = words
                    .iter()
                    .any(|w| w.letter == 'M' && (w.value == 2.0 || w.value == 30.0));
                if ends {
                    break;
                }
                pc += 1;
                continue;
            }
            Source::Flow(o) => o,
        };
        let machine = state.machine();
        let values = |parameters: &Parameters, o: &OLine, line: usize| {
            let mut reader = Reader {
                chars: &o.rest,
                i: 0,
                line,
                parameters,
                machine,
            };
            let mut values = Vec::new();
            while reader.peek().is_some() {
                if reader.peek() != Some('[') {
                    return Err(GcodeReadError::Expression {
                        line,
                        column: reader.column(),
                        problem: format!("o{} expects [expressions] here", o.label),
                    });
                }
                values.push(reader.value()?);
            }
            Ok(values)
        };
        let condition = |parameters: &Parameters, o: &OLine, line: usize| {
            let v = values(parameters, o, line)?;
            match v.as_slice() {
                [c] => Ok(*c != 0.0),
                _ => Err(GcodeReadError::Expression {
                    line,
                    column: o.column,
                    problem: format!("o{} {} needs one [condition]", o.label, o.keyword.name()),
                }),
            }
        };
        use Keyword::*;
        pc = match o.keyword {
            Sub => past(o, o.close, line)?,
            Endsub | Return => {
                let value = values(&parameters, o, line)?.first().copied();
                let Some(frame) = frames.pop() else {
                    // The main program ran into a subroutine's end: LinuxCNC ends there.
                    break;
                };
                parameters.leave(value);
                repeats = frame.repeats;
                frame.return_to
            }
            Call => {
                let args = values(&parameters, o, line)?;
                let Some(&start) = subs.get(&o.label) else {
                    return Err(flow_error(
                        line,
                        o.column,
                        format!(
                            "o{} call: the subroutine is not in this program (a controller would look for it in its SUBROUTINE_PATH)",
                            o.label
                        ),
                    ));
                };
                if frames.len() >= MAX_CALLS {
                    return Err(flow_error(
                        line,
                        o.column,
                        format!(
                            "o{} call: subroutines nest deeper than {MAX_CALLS}",
                            o.label
                        ),
                    ));
                }
                parameters.enter(&args);
                frames.push(Frame {
                    return_to: pc + 1,
                    repeats: std::mem::take(&mut repeats),
                });
                start + 1
            }
            If => {
                if condition(&parameters, o, line)? {
                    pc + 1
                } else {
                    let mut branch = past(o, o.next, line)? - 1;
                    loop {
                        let Source::Flow(b) = &sources[branch] else {
                            break branch + 1;
                        };
                        match b.keyword {
                            Elseif if condition(&parameters, b, branch + 1)? => break branch + 1,
                            Elseif => branch = past(b, b.next, branch + 1)? - 1,
                            _ => break branch + 1,
                        }
                    }
                }
            }
            Elseif | Else => past(o, o.close, line)?,
            Endif | Do => pc + 1,
            While => {
                if condition(&parameters, o, line)? {
                    pc + 1
                } else {
                    past(o, o.close, line)?
                }
            }
            Endwhile => o.open,
            DoWhile => {
                if condition(&parameters, o, line)? && !break_pending {
                    o.open + 1
                } else {
                    break_pending = false;
                    pc + 1
                }
            }
            Repeat => {
                let count = values(&parameters, o, line)?
                    .first()
                    .copied()
                    .unwrap_or(0.0);
                let count = count.round().clamp(0.0, MAX_BLOCKS as f64) as i64;
                if count < 1 {
                    past(o, o.close, line)?
                } else {
                    repeats.insert(pc, count);
                    pc + 1
                }
            }
            Endrepeat => {
                let left = repeats.get(&o.open).copied().unwrap_or(1) - 1;
                if left >= 1 {
                    repeats.insert(o.open, left);
                    o.open + 1
                } else {
                    repeats.remove(&o.open);
                    pc + 1
                }
            }
            Break => {
                break_pending = true;
                repeats.remove(&o.open);
                past(o, o.close, line)?
            }
            Continue => match &sources[o.open] {
                Source::Flow(l) if l.keyword == While => o.open,
                _ => past(o, o.close, line)? - 1,
            },
        };
    }
    Ok(last_line)
}

/// A block's words, with their values as the parameters stood when the line began, and its
/// assignments (made after the whole line is read).
#[allow(clippy::type_complexity)]
fn read_block(
    chars: &[Char],
    line: usize,
    parameters: &Parameters,
    state: &State,
) -> Result<(Vec<Word>, Vec<(Target, f64, usize)>), GcodeReadError> {
    let mut reader = Reader {
        chars,
        i: 0,
        line,
        parameters,
        machine: state.machine(),
    };
    let mut words = Vec::new();
    let mut assignments = Vec::new();
    while let Some(c) = reader.peek() {
        let column = reader.column();
        if c == '#' {
            reader.i += 1;
            let target = reader.target(1)?;
            if reader.peek() != Some('=') {
                return Err(GcodeReadError::Expression {
                    line,
                    column: reader.column(),
                    problem: "expected '=' after the parameter".into(),
                });
            }
            reader.i += 1;
            let value = reader.value()?;
            assignments.push((target, value, column));
            continue;
        }
        if !(c.is_ascii_alphabetic() || "$@^".contains(c)) {
            return Err(GcodeReadError::UnexpectedCharacter {
                line,
                column,
                found: c,
            });
        }
        let letter = c.to_ascii_uppercase();
        reader.i += 1;
        let starts_value = reader
            .peek()
            .is_some_and(|d| d.is_ascii_alphanumeric() || "+-.[#".contains(d));
        if !starts_value {
            return Err(GcodeReadError::MissingNumber {
                line,
                column,
                letter,
            });
        }
        let value = reader.value()?;
        if value.abs() > MAX_VALUE {
            return Err(GcodeReadError::NumberOutOfRange {
                line,
                column,
                letter,
            });
        }
        words.push(Word {
            letter,
            value,
            column,
        });
    }
    Ok((words, assignments))
}
