//! The CSS that decides what an SVG draws: `style="…"` declarations, `<style>` sheets with
//! simple selectors (type, `*`, `.class`, `#id` and their compounds), and presentation
//! attributes, with CSS precedence (`!important` sheet and style, then the `style`
//! attribute, then the sheet by specificity and order, then the attribute).
//!
//! Only the properties that change geometry are kept (`display`, `visibility`, `font-size`
//! for `em` lengths, and `transform`, which is reported, not applied); a rule that sets one of
//! them with a selector this reader does not understand is reported by the caller, never
//! applied or dropped in silence.

use roxmltree::Node;

/// Properties that change what is cut; all others (fill, stroke, …) are of no concern.
const RELEVANT: [&str; 5] = [
    "display",
    "visibility",
    "font-size",
    "transform",
    "clip-path",
];
/// Most relevant rules kept from the sheets: bounds the matching work per element.
pub(super) const MAX_RULES: usize = 256;

/// One `name: value` of a declaration block, `name` in lower case.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Declaration {
    pub name: String,
    pub value: String,
    pub important: bool,
}

/// The declarations of a block (`a: b; c: d !important`), relevant ones only.
pub(super) fn declarations(block: &str) -> Vec<Declaration> {
    block
        .split(';')
        .filter_map(|item| {
            let (name, value) = item.split_once(':')?;
            let name = name.trim().to_ascii_lowercase();
            if !RELEVANT.contains(&name.as_str()) {
                return None;
            }
            let mut value = value.trim();
            let mut important = false;
            if let Some(at) = value.to_ascii_lowercase().rfind("!important") {
                value = value[..at].trim();
                important = true;
            }
            Some(Declaration {
                name,
                value: value.to_owned(),
                important,
            })
        })
        .collect()
}

/// A compound selector: an optional element name and any ids and classes.
#[derive(Clone, Debug, PartialEq)]
struct Compound {
    element: Option<String>,
    ids: Vec<String>,
    classes: Vec<String>,
}

impl Compound {
    fn parse(text: &str) -> Option<Self> {
        let text = text.trim();
        let name_char = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
        let mut rest = text;
        let head: String = rest
            .chars()
            .take_while(|&c| name_char(c) || c == '*')
            .collect();
        rest = &rest[head.len()..];
        let element = match head.as_str() {
            "" | "*" => None,
            name if name.chars().all(name_char) => Some(name.to_owned()),
            _ => return None,
        };
        let mut ids = Vec::new();
        let mut classes = Vec::new();
        while let Some(marker) = rest.chars().next() {
            let name: String = rest[1..].chars().take_while(|&c| name_char(c)).collect();
            if name.is_empty() {
                return None;
            }
            match marker {
                '#' => ids.push(name.clone()),
                '.' => classes.push(name.clone()),
                _ => return None,
            }
            rest = &rest[1 + name.len()..];
        }
        if text.is_empty() {
            return None;
        }
        Some(Self {
            element,
            ids,
            classes,
        })
    }

    fn specificity(&self) -> (usize, usize, usize) {
        (
            self.ids.len(),
            self.classes.len(),
            usize::from(self.element.is_some()),
        )
    }

    fn matches(&self, node: Node<'_, '_>) -> bool {
        if let Some(element) = &self.element {
            if node.tag_name().name() != element {
                return false;
            }
        }
        let id = node.attribute("id");
        if self.ids.iter().any(|i| Some(i.as_str()) != id) {
            return false;
        }
        let classes = node.attribute("class").unwrap_or("");
        self.classes
            .iter()
            .all(|c| classes.split_ascii_whitespace().any(|k| k == c))
    }
}

#[derive(Clone, Debug)]
struct Rule {
    selector: Compound,
    order: usize,
    declarations: Vec<Declaration>,
}

/// The rules of every `<style>` sheet of a drawing that set a relevant property.
#[derive(Clone, Debug, Default)]
pub(super) struct StyleSheet {
    rules: Vec<Rule>,
}

/// Something in a sheet that sets a relevant property and is not applied.
pub(super) struct NotUnderstood {
    /// The selector or at-rule, shortened.
    pub what: String,
}

impl StyleSheet {
    /// Adds the rules of one sheet's text; returns what it could not apply.
    pub fn add(&mut self, css: &str) -> Vec<NotUnderstood> {
        let css = strip_comments(css);
        let mut problems = Vec::new();
        let mut rest = css.as_str();
        while let Some(open) = rest.find('{') {
            let prelude = rest[..open].trim();
            let (block, after) = block_at(&rest[open + 1..]);
            rest = after;
            // At-rules without a block (`@import …;`) sit in front of the next prelude.
            let (at_rules, prelude) = match prelude.rfind(';') {
                Some(k) => (&prelude[..k], prelude[k + 1..].trim()),
                None => ("", prelude),
            };
            if at_rules.contains("@import") {
                problems.push(NotUnderstood {
                    what: shorten(at_rules.trim()),
                });
            }
            if prelude.starts_with('@') {
                // @media, @supports, @font-face…: not followed; told when it sets what we read.
                if !declarations(&block.replace(['{', '}'], ";")).is_empty() {
                    problems.push(NotUnderstood {
                        what: shorten(prelude),
                    });
                }
                continue;
            }
            let declarations = declarations(block);
            if declarations.is_empty() {
                continue;
            }
            for selector in prelude.split(',') {
                match Compound::parse(selector) {
                    Some(selector) if self.rules.len() < MAX_RULES => self.rules.push(Rule {
                        selector,
                        order: self.rules.len(),
                        declarations: declarations.clone(),
                    }),
                    _ => problems.push(NotUnderstood {
                        what: shorten(selector.trim()),
                    }),
                }
            }
        }
        if rest.contains("@import") {
            problems.push(NotUnderstood {
                what: shorten(rest.trim()),
            });
        }
        problems
    }

    /// The value of `property` for `node`: its `style` attribute, the sheet, then the
    /// presentation attribute, by CSS precedence.
    pub fn value(&self, node: Node<'_, '_>, property: &str) -> Option<String> {
        self.css_value(node, property)
            .or_else(|| node.attribute(property).map(|v| v.trim().to_owned()))
    }

    /// Whether CSS (the `style` attribute or a sheet) sets `property` for `node`.
    pub fn declared(&self, node: Node<'_, '_>, property: &str) -> bool {
        self.css_value(node, property).is_some()
    }

    /// The value CSS gives `property` for `node`, without presentation attributes.
    fn css_value(&self, node: Node<'_, '_>, property: &str) -> Option<String> {
        let inline = node
            .attribute("style")
            .map(declarations)
            .unwrap_or_default()
            .into_iter()
            .filter(|d| d.name == property)
            .max_by_key(|d| d.important);
        // (important, specificity, order): the largest wins.
        let sheet = self
            .rules
            .iter()
            .filter(|r| r.selector.matches(node))
            .flat_map(|r| {
                r.declarations
                    .iter()
                    .filter(|d| d.name == property)
                    .map(move |d| ((d.important, r.selector.specificity(), r.order), d))
            })
            .max_by_key(|(key, _)| *key);
        match (inline, sheet) {
            (Some(i), Some((key, s))) if key.0 && !i.important => Some(s.value.clone()),
            (Some(i), _) => Some(i.value),
            (None, Some((_, s))) => Some(s.value.clone()),
            (None, None) => None,
        }
    }
}

fn strip_comments(css: &str) -> String {
    let mut out = String::with_capacity(css.len());
    let mut rest = css;
    while let Some(start) = rest.find("/*") {
        out.push_str(&rest[..start]);
        rest = match rest[start + 2..].find("*/") {
            Some(end) => &rest[start + 2 + end + 2..],
            None => "",
        };
    }
    out.push_str(rest);
    out
}

/// The text of a block up to its matching `}` (nested blocks included), and what follows.
fn block_at(text: &str) -> (&str, &str) {
    let mut depth = 0usize;
    for (k, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => return (&text[..k], &text[k + 1..]),
            '}' => depth -= 1,
            _ => {}
        }
    }
    (text, "")
}

fn shorten(text: &str) -> String {
    let short: String = text.chars().take(60).collect();
    if short.len() < text.len() {
        format!("{short}…")
    } else {
        short
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn style_beats_sheet_beats_attribute_and_important_beats_style() {
        let doc = roxmltree::Document::parse(
            r#"<svg><rect id="a" class="x y" display="none" style="display: inline"/>
               <rect id="b" class="x" display="inline"/><rect id="c" class="x" style="display:inline"/>
               <circle class="y"/></svg>"#,
        )
        .unwrap();
        let mut sheet = StyleSheet::default();
        let problems = sheet.add(
            "/* c */ .x { fill: red; display: none } rect#c.x { display: none !important }
             svg > rect { display: none } circle { stroke: red }",
        );
        assert_eq!(problems.len(), 1, "the child combinator is not understood");
        assert_eq!(problems[0].what, "svg > rect");
        let nodes: Vec<_> = doc.descendants().filter(|n| n.is_element()).collect();
        let display = |k: usize| sheet.value(nodes[k], "display");
        assert_eq!(display(1).as_deref(), Some("inline")); // style over sheet
        assert_eq!(display(2).as_deref(), Some("none")); // sheet over attribute
        assert_eq!(display(3).as_deref(), Some("none")); // important sheet over style
        assert_eq!(display(4), None);
    }

    #[test]
    fn at_rules_that_set_display_are_reported() {
        let mut sheet = StyleSheet::default();
        let problems = sheet.add("@media print { .a { display: none } } @font-face { src: x }");
        assert_eq!(problems.len(), 1);
        assert!(problems[0].what.starts_with("@media"));
        assert!(sheet.rules.is_empty());
    }
}
