//! The YAML that robot tools write for one pose, read into a small tree:
//! block mappings by indentation (`position:` then `  x: 0.1`), flow
//! mappings and lists (`{x: 0.1, y: 0.2}`, `[1, 0, 0, 0.1]`, spanning lines
//! as OpenCV's `data: [ ... ]` does), lists of `- item` lines, `#`
//! comments, document markers (`---`, `...`, `%YAML`) and tags
//! (`!!opencv-matrix`, ignored). Anchors, aliases, multi-line strings and
//! lists of mappings are not pose data and are refused with their line.
//!
//! This is deliberately not a YAML library: a pose file is a handful of
//! numbers under a few keys, and a subset that refuses what it does not
//! read, naming the line, keeps every rule here in sight. JSON pose files go
//! through serde_json into the same tree ([`Node::from_json`]).

use crate::error::{Error, Result};

/// A parsed document: mappings keep their key order; scalars keep their text
/// and line (0 when unknown, as for JSON).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Node {
    /// Keys in file order with their values.
    Map(Vec<(String, Node)>),
    /// Items in order.
    List(Vec<Node>),
    /// A scalar's text (quotes removed) and its 1-based line.
    Scalar(String, usize),
}

impl Node {
    /// A JSON value as a tree (numbers printed back exactly, lines 0).
    pub fn from_json(value: &serde_json::Value) -> Node {
        use serde_json::Value;
        match value {
            Value::Object(o) => Node::Map(
                o.iter()
                    .map(|(k, v)| (k.clone(), Node::from_json(v)))
                    .collect(),
            ),
            Value::Array(a) => Node::List(a.iter().map(Node::from_json).collect()),
            Value::String(s) => Node::Scalar(s.clone(), 0),
            Value::Number(n) => Node::Scalar(n.to_string(), 0),
            Value::Null => Node::Scalar(String::new(), 0),
            Value::Bool(b) => Node::Scalar(b.to_string(), 0),
        }
    }
}

/// One content line: its number, indentation and text without comment.
struct Line {
    number: usize,
    indent: usize,
    text: String,
}

/// The text before a ` #` comment (a `#` inside quotes is kept).
fn strip_comment(line: &str) -> &str {
    let mut quote = None;
    let mut prev = ' ';
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '#') if prev.is_whitespace() => return &line[..i],
            _ => {}
        }
        prev = c;
    }
    line
}

fn content_lines(text: &str) -> Vec<Line> {
    text.lines()
        .enumerate()
        .filter_map(|(i, raw)| {
            let raw = raw.trim_start_matches('\u{feff}');
            let body = strip_comment(raw).trim_end();
            let t = body.trim_start();
            let marker =
                t == "---" || t == "..." || t.starts_with("%YAML") || t.starts_with("%TAG");
            (!t.is_empty() && !marker).then(|| Line {
                number: i + 1,
                indent: body.len() - t.len(),
                text: t.to_string(),
            })
        })
        .collect()
}

/// `key: rest` (rest may be empty), or None when the line is not a mapping
/// entry. Quoted keys are unquoted.
pub(crate) fn split_key(text: &str) -> Option<(String, &str)> {
    if let Some(q) = text.chars().next().filter(|c| *c == '"' || *c == '\'') {
        let end = text[1..].find(q)? + 1;
        let rest = text[end + 1..].strip_prefix(':')?;
        if !(rest.is_empty() || rest.starts_with([' ', '\t'])) {
            return None;
        }
        return Some((text[1..end].to_string(), rest.trim()));
    }
    if text.starts_with(['{', '[', '-']) {
        return None;
    }
    let colon = text
        .match_indices(':')
        .map(|(i, _)| i)
        .find(|&i| text[i + 1..].is_empty() || text[i + 1..].starts_with([' ', '\t']))?;
    let key = text[..colon].trim();
    (!key.is_empty() && !key.contains(',')).then(|| (key.to_string(), text[colon + 1..].trim()))
}

/// Whether the text reads as YAML mappings rather than a table of numbers:
/// some content line is `key: ...` or starts a flow mapping.
pub(crate) fn looks_like_yaml(text: &str) -> bool {
    content_lines(text)
        .iter()
        .any(|l| split_key(&l.text).is_some() || l.text.starts_with('{'))
}

/// A value with a tag (`!!opencv-matrix`, `!custom`) dropped.
fn untagged(rest: &str) -> &str {
    if rest.starts_with('!') {
        rest.split_once([' ', '\t'])
            .map_or("", |(_, r)| r.trim_start())
    } else {
        rest
    }
}

fn unsupported(line: usize, what: &str) -> Error {
    Error::parse(
        line,
        0,
        format!("{what}: a pose file holds numbers under keys, e.g. 'position: {{x: 0.1, y: 0.2, z: 0.3}}'"),
    )
}

/// Parses the YAML subset of the module docs.
pub(crate) fn parse_yaml(text: &str) -> Result<Node> {
    let lines = content_lines(text);
    let Some(first) = lines.first() else {
        return Ok(Node::Map(Vec::new()));
    };
    let mut pos = 0;
    let node = block(&lines, &mut pos, first.indent)?;
    match lines.get(pos) {
        None => Ok(node),
        Some(l) => Err(Error::parse(
            l.number,
            0,
            "indented less than the first line, or a second document: one pose per file",
        )),
    }
}

fn block(lines: &[Line], pos: &mut usize, indent: usize) -> Result<Node> {
    let is_item = |t: &str| t == "-" || t.starts_with("- ");
    if is_item(&lines[*pos].text) {
        let mut items = Vec::new();
        while let Some(l) = lines
            .get(*pos)
            .filter(|l| l.indent == indent && is_item(&l.text))
        {
            *pos += 1;
            let rest = untagged(l.text[1..].trim());
            if split_key(rest).is_some() {
                return Err(unsupported(l.number, "a list of mappings is not read"));
            }
            items.push(value(lines, pos, l, rest, indent)?);
        }
        return after_block(lines, *pos, indent, Node::List(items));
    }
    let mut entries: Vec<(String, Node)> = Vec::new();
    while let Some(l) = lines.get(*pos).filter(|l| l.indent == indent) {
        if is_item(&l.text) {
            return Err(Error::parse(
                l.number,
                0,
                "a list item where a 'key: value' was expected",
            ));
        }
        let Some((key, rest)) = split_key(&l.text) else {
            if l.text.starts_with('{') && entries.is_empty() {
                *pos += 1;
                let node = value(lines, pos, l, &l.text, indent)?;
                return after_block(lines, *pos, indent, node);
            }
            let shown: String = l.text.chars().take(40).collect();
            return Err(Error::parse(
                l.number,
                0,
                format!("expected 'key: value', found '{shown}'"),
            ));
        };
        if entries.iter().any(|(k, _)| *k == key) {
            return Err(Error::parse(
                l.number,
                0,
                format!("the key '{key}' appears twice"),
            ));
        }
        *pos += 1;
        let child = value(lines, pos, l, untagged(rest), indent)?;
        entries.push((key, child));
    }
    after_block(lines, *pos, indent, Node::Map(entries))
}

fn after_block(lines: &[Line], pos: usize, indent: usize, node: Node) -> Result<Node> {
    match lines.get(pos) {
        Some(l) if l.indent > indent => Err(Error::parse(l.number, 0, "unexpected indentation")),
        _ => Ok(node),
    }
}

/// The value after `key:` or `-` on line `l`: nested block, flow, or scalar.
fn value(lines: &[Line], pos: &mut usize, l: &Line, rest: &str, indent: usize) -> Result<Node> {
    if rest.is_empty() {
        return match lines.get(*pos) {
            Some(next) if next.indent > indent => block(lines, pos, next.indent),
            // `key:` followed by `- item` at the key's own indentation.
            Some(next)
                if next.indent == indent
                    && next.text.starts_with('-')
                    && split_key(&l.text).is_some() =>
            {
                block(lines, pos, indent)
            }
            _ => Ok(Node::Scalar(String::new(), l.number)),
        };
    }
    if rest.starts_with(['&', '*']) {
        return Err(unsupported(l.number, "anchors and aliases are not read"));
    }
    if rest.starts_with(['|', '>']) {
        return Err(unsupported(l.number, "multi-line strings are not read"));
    }
    if rest.starts_with(['{', '[']) {
        let mut text = rest.to_string();
        while !balanced(&text) {
            let Some(next) = lines.get(*pos) else {
                return Err(Error::parse(
                    l.number,
                    0,
                    format!("'{}' is not closed", &rest[..1]),
                ));
            };
            text.push('\n');
            text.push_str(&next.text);
            *pos += 1;
        }
        let mut flow = Flow {
            chars: text.chars().collect(),
            at: 0,
            line: l.number,
        };
        let node = flow.value()?;
        flow.skip_space();
        if flow.at < flow.chars.len() {
            return Err(Error::parse(flow.line, 0, "text after the closing bracket"));
        }
        return Ok(node);
    }
    Ok(Node::Scalar(unquote(rest), l.number))
}

/// Whether every `{`/`[` outside quotes is closed.
fn balanced(text: &str) -> bool {
    let mut depth = 0i32;
    let mut quote = None;
    for c in text.chars() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '{' | '[') => depth += 1,
            (None, '}' | ']') => depth -= 1,
            _ => {}
        }
    }
    depth <= 0
}

fn unquote(s: &str) -> String {
    let s = s.trim();
    let quoted = s.len() >= 2
        && ((s.starts_with('"') && s.ends_with('"')) || (s.starts_with('\'') && s.ends_with('\'')));
    if quoted {
        s[1..s.len() - 1].to_string()
    } else {
        s.to_string()
    }
}

/// A flow collection (`{..}`, `[..]`) over characters, counting lines.
struct Flow {
    chars: Vec<char>,
    at: usize,
    line: usize,
}

impl Flow {
    fn skip_space(&mut self) {
        while let Some(&c) = self.chars.get(self.at) {
            if c == '\n' {
                self.line += 1;
            } else if !c.is_whitespace() {
                break;
            }
            self.at += 1;
        }
    }

    fn error(&self, message: String) -> Error {
        Error::parse(self.line, 0, message)
    }

    fn value(&mut self) -> Result<Node> {
        self.skip_space();
        match self.chars.get(self.at) {
            Some('{') => self.collection('}'),
            Some('[') => self.collection(']'),
            _ => {
                let line = self.line;
                Ok(Node::Scalar(unquote(&self.scalar(&[',', ']', '}'])), line))
            }
        }
    }

    /// Text up to one of `stops` outside quotes.
    fn scalar(&mut self, stops: &[char]) -> String {
        let mut out = String::new();
        let mut quote = None;
        while let Some(&c) = self.chars.get(self.at) {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, c) if stops.contains(&c) => break,
                _ => {}
            }
            if c == '\n' {
                self.line += 1;
            }
            out.push(c);
            self.at += 1;
        }
        out.trim().to_string()
    }

    fn collection(&mut self, close: char) -> Result<Node> {
        self.at += 1;
        let mut items = Vec::new();
        let mut entries: Vec<(String, Node)> = Vec::new();
        loop {
            self.skip_space();
            match self.chars.get(self.at) {
                None => return Err(self.error(format!("'{close}' is missing"))),
                Some(&c) if c == close => {
                    self.at += 1;
                    break;
                }
                _ => {}
            }
            if close == '}' {
                let key = unquote(&self.scalar(&[':', ',', '}']));
                if self.chars.get(self.at) != Some(&':') {
                    return Err(
                        self.error(format!("expected 'key: value' in '{{...}}', found '{key}'"))
                    );
                }
                self.at += 1;
                if entries.iter().any(|(k, _)| *k == key) {
                    return Err(self.error(format!("the key '{key}' appears twice")));
                }
                let v = self.value()?;
                entries.push((key, v));
            } else {
                items.push(self.value()?);
            }
            self.skip_space();
            match self.chars.get(self.at) {
                Some(',') => self.at += 1,
                Some(&c) if c == close => {}
                Some(&c) => {
                    return Err(self.error(format!("expected ',' or '{close}', found '{c}'")))
                }
                None => return Err(self.error(format!("'{close}' is missing"))),
            }
        }
        Ok(if close == '}' {
            Node::Map(entries)
        } else {
            Node::List(items)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(text: &str, line: usize) -> Node {
        Node::Scalar(text.into(), line)
    }

    #[test]
    fn block_and_flow_mappings_lists_and_comments() {
        let text = "# a pose\n---\nheader:\n  frame_id: \"base\"  # the frame\npose:\n  position: {x: 0.1, y: -2e-3, z: 0.3}\n  orientation:\n    x: 0\n    w: 1\ndata: [ 1., 2.,\n   3. ]\nrows:\n- 4\n- 5\n";
        let node = parse_yaml(text).unwrap();
        let Node::Map(top) = node else { panic!() };
        assert_eq!(
            top[0],
            (
                "header".into(),
                Node::Map(vec![("frame_id".into(), s("base", 4))])
            )
        );
        assert_eq!(
            top[1].1,
            Node::Map(vec![
                (
                    "position".into(),
                    Node::Map(vec![
                        ("x".into(), s("0.1", 6)),
                        ("y".into(), s("-2e-3", 6)),
                        ("z".into(), s("0.3", 6))
                    ])
                ),
                (
                    "orientation".into(),
                    Node::Map(vec![("x".into(), s("0", 8)), ("w".into(), s("1", 9))])
                ),
            ])
        );
        assert_eq!(
            top[2].1,
            Node::List(vec![s("1.", 10), s("2.", 10), s("3.", 11)])
        );
        assert_eq!(top[3].1, Node::List(vec![s("4", 13), s("5", 14)]));
    }

    #[test]
    fn what_is_not_read_is_refused_with_its_line() {
        let err = |t: &str| parse_yaml(t).unwrap_err().to_string();
        assert_eq!(
            err("a:\n  x: 1\n    y: 2\n"),
            "line 3: unexpected indentation"
        );
        assert_eq!(err("a: 1\na: 2\n"), "line 2: the key 'a' appears twice");
        assert_eq!(err("a: [1, 2\n"), "line 1: '[' is not closed");
        assert_eq!(
            err("a: {x 1}\n"),
            "line 1: expected 'key: value' in '{...}', found 'x 1'"
        );
        assert_eq!(
            err("a: &anchor 1\n"),
            "line 1: anchors and aliases are not read: a pose file holds numbers under keys, e.g. 'position: {x: 0.1, y: 0.2, z: 0.3}'"
        );
        assert_eq!(
            err("a: 1\nnot a key\n"),
            "line 2: expected 'key: value', found 'not a key'"
        );
    }
}
