//! Where a field is written in a model's text: the line and column of the value at a field
//! path (`bodies.crank.mass`, `pairs[2].at`), for the errors of the checks that read the
//! parsed model (the parsers locate their own errors). The text has parsed, so this reads
//! its structure leniently, as much as a path needs: YAML block style by indentation, flow
//! style (`{...}`, `[...]`) and JSON; scalars are skipped, not read.
//!
//! Written here because no parser at hand keeps positions for a field path: serde_yaml drops
//! them after deserialisation, serde_path_to_error gives them for parse errors only, and a
//! YAML parser with markers (yaml-rust2, saphyr) would be a second YAML parser that does not
//! read JSON.

use super::Format;
use crate::model::spec::FIELD_ALIASES;

/// A 1-based line and column.
pub(super) type At = (usize, usize);

/// Nesting beyond which the text is not read (a parsed model's is below 10; the parsers
/// refuse beyond 128 in JSON, `nesting::MAX_NESTING` in YAML): a bound on the recursion.
const MAX_DEPTH: usize = 200;

/// The line and column of the field at `path` in `text`: of its value where the value starts
/// on its key's line (or its list dash's), of the key otherwise; that of the deepest
/// component of the path found where the rest is not written (a field left to its default,
/// `bodies.crank` for `bodies.crank.inertia`); `None` where not even the first is, and in
/// data (`Format::Data`: no text its user wrote).
pub(super) fn field_line(text: &str, format: Format, path: &str) -> Option<At> {
    if format == Format::Data {
        return None;
    }
    let root = Reader::new(text, format).document()?;
    let (mut node, mut rest, mut found) = (&root, path, None);
    while let Some((entry, after)) = node.child(rest) {
        found = Some(entry.at());
        node = &entry.node;
        rest = after.strip_prefix('.').unwrap_or(after);
    }
    found
}

/// A node of the text: where it starts, and its children.
struct Node {
    at: At,
    kind: Kind,
}

enum Kind {
    Map(Vec<(String, Entry)>),
    Seq(Vec<Entry>),
    Scalar,
}

/// A child with where it is written: its key or its list dash, and its value.
struct Entry {
    at: At,
    node: Node,
}

impl Entry {
    /// The value's start where it is on the line of its key or dash; the key or dash otherwise
    /// (a block below it).
    fn at(&self) -> At {
        if self.node.at.0 == self.at.0 {
            self.node.at
        } else {
            self.at
        }
    }
}

impl Node {
    fn scalar(at: At) -> Node {
        Node { at, kind: Kind::Scalar }
    }

    /// The child that the path `rest` starts with (`[2]` in a list; in a mapping the longest
    /// key, or key read by its field's name, followed by `.`, `[` or the end, for names that
    /// hold a dot), and the path after it.
    fn child<'p>(&self, rest: &'p str) -> Option<(&Entry, &'p str)> {
        match &self.kind {
            Kind::Seq(items) => {
                let (index, after) = rest.strip_prefix('[')?.split_once(']')?;
                Some((items.get(index.parse::<usize>().ok()?)?, after))
            }
            Kind::Map(entries) => {
                let field = |key: &str| FIELD_ALIASES.iter().find(|(_, alias)| *alias == key).map(|(f, _)| *f);
                let matches = entries.iter().filter_map(|(key, entry)| {
                    let after = after_name(rest, key).or_else(|| after_name(rest, field(key)?))?;
                    Some((entry, after))
                });
                matches.min_by_key(|(_, after)| after.len())
            }
            Kind::Scalar => None,
        }
    }
}

/// The path after its first component `name`, if it is.
fn after_name<'p>(path: &'p str, name: &str) -> Option<&'p str> {
    path.strip_prefix(name).filter(|after| after.is_empty() || after.starts_with(['.', '[']))
}

/// A cursor in the text, by line and character (0-based).
struct Reader {
    lines: Vec<Vec<char>>,
    line: usize,
    col: usize,
    yaml: bool,
    depth: usize,
}

impl Reader {
    fn new(text: &str, format: Format) -> Reader {
        let lines = text.lines().map(|l| l.chars().collect()).collect();
        Reader { lines, line: 0, col: 0, yaml: format == Format::Yaml, depth: 0 }
    }

    fn document(mut self) -> Option<Node> {
        if !self.yaml {
            return self.flow();
        }
        self.next_content_line();
        if self.eof() {
            return None;
        }
        self.block()
    }

    fn eof(&self) -> bool {
        self.line >= self.lines.len()
    }
    fn peek(&self) -> Option<char> {
        self.lines.get(self.line)?.get(self.col).copied()
    }
    fn peek_next(&self) -> Option<char> {
        self.lines.get(self.line)?.get(self.col + 1).copied()
    }
    fn at(&self) -> At {
        (self.line + 1, self.col + 1)
    }
    fn bump(&mut self) {
        self.col += 1;
    }
    fn next_line(&mut self) {
        self.line += 1;
        self.col = 0;
    }
    fn skip_spaces(&mut self) {
        while matches!(self.peek(), Some(' ' | '\t' | '\u{feff}')) {
            self.bump();
        }
    }
    /// Nothing more on the line but a comment.
    fn rest_blank(&self) -> bool {
        self.peek().is_none_or(|c| self.yaml && c == '#')
    }
    /// A block list's dash: `-` then a space or the end of the line.
    fn dash(&self) -> bool {
        self.peek() == Some('-') && matches!(self.peek_next(), None | Some(' ' | '\t'))
    }

    /// From the start of the current line to the first with content (not blank, a comment,
    /// a directive or a document marker), at its indentation; the end of the text if none.
    fn next_content_line(&mut self) {
        while let Some(line) = self.lines.get(self.line) {
            let indent = line.iter().take_while(|&&c| c == ' ').count();
            let rest = &line[indent..];
            let marker = indent == 0
                && (rest.first() == Some(&'%')
                    || ([['-'; 3], ['.'; 3]].iter().any(|m| rest.starts_with(m))
                        && rest.get(3).is_none_or(|&c| c == ' ')));
            let blank = rest.iter().all(|c| c.is_whitespace()) || rest.first() == Some(&'#');
            if !(blank || marker) {
                self.col = indent;
                return;
            }
            self.next_line();
        }
    }

    /// Past the lines indented deeper than `indent` (the continuation of a scalar); at the next
    /// content line.
    fn skip_deeper(&mut self, indent: usize) {
        while !self.eof() && self.col > indent {
            self.next_line();
            self.next_content_line();
        }
    }

    /// Anchors `&name` and tags `!tag` before a value.
    fn skip_properties(&mut self) {
        while matches!(self.peek(), Some('&' | '!')) {
            while self.peek().is_some_and(|c| !c.is_whitespace()) {
                self.bump();
            }
            self.skip_spaces();
        }
    }

    /// Spaces, line ends and comments between the tokens of a flow node.
    fn skip_flow_space(&mut self) {
        loop {
            match self.peek() {
                Some(' ' | '\t' | '\r' | '\u{feff}') => self.bump(),
                Some('#') if self.yaml => self.next_line(),
                None if !self.eof() => self.next_line(),
                _ => return,
            }
        }
    }

    /// A quoted scalar at the cursor (`"..."` with backslash escapes, `'...'` with `''`), its
    /// text; the cursor after it, on a later line if it spans lines.
    fn quoted(&mut self) -> String {
        let quote = self.peek();
        self.bump();
        let mut text = String::new();
        while !self.eof() {
            match self.peek() {
                None => {
                    self.next_line();
                    text.push(' ');
                }
                Some(c) if Some(c) == quote => {
                    self.bump();
                    if c == '"' || self.peek() != Some('\'') {
                        break;
                    }
                    text.push('\'');
                    self.bump();
                }
                Some(c) => {
                    self.bump();
                    match (c, self.peek()) {
                        ('\\', Some(escaped)) if quote == Some('"') => {
                            text.push(escaped);
                            self.bump();
                        }
                        _ => text.push(c),
                    }
                }
            }
        }
        text
    }

    /// A plain scalar at the cursor, to the end of its part of the line: before `: ` (or `:`
    /// at the end) and ` #`, in a flow node also before `,[]{}` and a `:` before them.
    fn plain(&mut self, flow: bool) -> String {
        let mut text = String::new();
        while let Some(c) = self.peek() {
            let ends = match c {
                ':' => self.peek_next().is_none_or(|n| n == ' ' || n == '\t' || (flow && ",[]{}".contains(n))),
                '#' => text.ends_with([' ', '\t']),
                ',' | '[' | ']' | '{' | '}' => flow,
                _ => false,
            };
            if ends {
                break;
            }
            text.push(c);
            self.bump();
        }
        text.trim_end().to_string()
    }

    /// A mapping key at the cursor and the cursor after its `:`, if a `:` follows it.
    fn key(&mut self, flow: bool) -> Option<String> {
        let key = match self.peek()? {
            '"' | '\'' => {
                let key = self.quoted();
                self.skip_spaces();
                key
            }
            _ => self.plain(flow),
        };
        (self.peek() == Some(':')).then(|| {
            self.bump();
            key
        })
    }

    /// A block mapping's key, on one line, at the cursor (the cursor kept).
    fn at_key(&mut self) -> bool {
        let (line, col) = (self.line, self.col);
        let key = self.key(false).is_some() && self.line == line;
        (self.line, self.col) = (line, col);
        key
    }

    /// The node at the cursor in block context; the cursor then at the next content line
    /// (at its indentation) after it.
    fn block(&mut self) -> Option<Node> {
        if self.depth >= MAX_DEPTH {
            return None;
        }
        self.depth += 1;
        self.skip_properties();
        let col = self.col;
        let node = if self.dash() {
            self.seq(col)
        } else if matches!(self.peek(), Some('{' | '[')) || !self.at_key() {
            let node = if matches!(self.peek(), Some('{' | '[')) { self.flow() } else { Some(Node::scalar(self.at())) };
            self.next_line();
            self.next_content_line();
            node
        } else {
            self.map(col)
        };
        self.depth -= 1;
        node
    }

    /// The value below a key or dash at column `indent`, deeper, or a list at the key's
    /// indentation (`pairs:\n- ...`) where `list_level`; a null at `at` (the key or dash) if none.
    fn value_below(&mut self, indent: usize, list_level: bool, at: At) -> Option<Node> {
        self.next_line();
        self.next_content_line();
        if !self.eof() && (self.col > indent || (list_level && self.col == indent && self.dash())) {
            return self.block();
        }
        Some(Node::scalar(at))
    }

    /// A block mapping whose first key is at the cursor, its keys at column `indent`.
    fn map(&mut self, indent: usize) -> Option<Node> {
        let (start, mut entries) = (self.at(), Vec::new());
        loop {
            let (at, line) = (self.at(), self.line);
            match self.key(false) {
                Some(key) if self.line == line => {
                    self.skip_spaces();
                    self.skip_properties();
                    let node = if self.rest_blank() { self.value_below(indent, true, at)? } else { self.block()? };
                    entries.push((key, Entry { at, node }));
                }
                _ => {
                    self.next_line();
                    self.next_content_line();
                }
            }
            self.skip_deeper(indent);
            if self.eof() || self.col != indent || self.dash() {
                break;
            }
        }
        Some(Node { at: start, kind: Kind::Map(entries) })
    }

    /// A block list whose first dash is at the cursor, its dashes at column `indent`.
    fn seq(&mut self, indent: usize) -> Option<Node> {
        let (start, mut items) = (self.at(), Vec::new());
        while self.dash() {
            let at = self.at();
            self.bump();
            self.skip_spaces();
            self.skip_properties();
            let node = if self.rest_blank() { self.value_below(indent, false, at)? } else { self.block()? };
            items.push(Entry { at, node });
            self.skip_deeper(indent);
            if self.eof() || self.col != indent {
                break;
            }
        }
        Some(Node { at: start, kind: Kind::Seq(items) })
    }

    /// A flow node at the cursor (JSON, or YAML's `{...}`, `[...]` and the scalars in them);
    /// the cursor after it.
    fn flow(&mut self) -> Option<Node> {
        if self.depth >= MAX_DEPTH {
            return None;
        }
        self.depth += 1;
        self.skip_flow_space();
        self.skip_properties();
        let at = self.at();
        let node = match self.peek() {
            Some(open @ ('{' | '[')) => {
                self.bump();
                let mut kind = if open == '{' { Kind::Map(Vec::new()) } else { Kind::Seq(Vec::new()) };
                loop {
                    self.skip_flow_space();
                    let here = (self.line, self.col);
                    match self.peek() {
                        None => break,
                        Some('}' | ']') => {
                            self.bump();
                            break;
                        }
                        Some(',') => self.bump(),
                        Some(_) => match &mut kind {
                            Kind::Map(entries) => {
                                let key_at = self.at();
                                if let Some(key) = self.key(true) {
                                    let node = self.flow()?;
                                    entries.push((key, Entry { at: key_at, node }));
                                }
                            }
                            Kind::Seq(items) => {
                                let node = self.flow()?;
                                items.push(Entry { at: node.at, node });
                            }
                            Kind::Scalar => {}
                        },
                    }
                    // A token neither part read (a `:` alone): past it.
                    if (self.line, self.col) == here {
                        self.bump();
                    }
                }
                Node { at, kind }
            }
            Some('"' | '\'') => {
                self.quoted();
                Node::scalar(at)
            }
            _ => {
                self.plain(true);
                Node::scalar(at)
            }
        };
        self.depth -= 1;
        Some(node)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Line `line` (1-based) of `text` and the column where `written` starts on it.
    fn at(text: &str, line: usize, written: &str) -> Option<At> {
        let row = text.lines().nth(line - 1).unwrap();
        Some((line, row[..row.find(written).unwrap()].chars().count() + 1))
    }

    // One model's fields in each style, the refused values the loader's checks name: a body's
    // mass, a pair in a list, a point, a drive's table entry.
    const BLOCK: &str = r#"# a comment: bodies: not a key
name: "x: y"
about: >-
  bodies: a folded scalar's line, not a key

  more
points:
  O: [0, 0]
  B.1: {by: circles, about: [A, D], radii: [0.5, 0.3]}
bodies:
  crank:
    points: [O, A]
    mass: -1.0   # refused
  rocker: &r
    points: [D, B.1]
pairs:
- {type: revolute, at: O, bodies: [ground, crank]}
- type: revolute
  at: Q
  bodies:
    - coupler
    -   rocker
drives:
  - coordinate: theta1
    table:
      t: [0, 2, 1]
      effort: [1, 2, 3]
"#;

    #[test]
    fn yaml_block_fields_are_found_by_their_path() {
        let line = |path| field_line(BLOCK, Format::Yaml, path);
        assert_eq!(line("name"), at(BLOCK, 2, "\"x: y\""));
        assert_eq!(line("bodies.crank.mass"), at(BLOCK, 13, "-1.0"));
        // A value below its key: the key.
        assert_eq!(line("bodies.crank"), at(BLOCK, 11, "crank"));
        assert_eq!(line("pairs[0].at"), at(BLOCK, 17, "O,"));
        assert_eq!(line("pairs[1]"), at(BLOCK, 18, "type"));
        assert_eq!(line("pairs[1].at"), at(BLOCK, 19, "Q"));
        assert_eq!(line("pairs[1].bodies[1]"), at(BLOCK, 22, "rocker"));
        // A name holding a dot is one component.
        assert_eq!(line("points.B.1"), at(BLOCK, 9, "{by"));
        assert_eq!(line("drives[0].table.t[2]"), at(BLOCK, 26, "1]"));
        assert_eq!(line("pairs"), at(BLOCK, 16, "pairs"));
    }

    #[test]
    fn a_field_not_written_is_located_at_its_deepest_written_parent() {
        let line = |path| field_line(BLOCK, Format::Yaml, path);
        // `rocker: &r` then its fields below: the key (the anchor is no value).
        assert_eq!(line("bodies.rocker.mass"), at(BLOCK, 14, "rocker"));
        assert_eq!(line("pairs[1].name"), at(BLOCK, 18, "type"));
        assert_eq!(line("pairs[5].at"), at(BLOCK, 16, "pairs"));
        assert_eq!(line("drives[0].table.t[7]"), at(BLOCK, 26, "["));
        // Nothing of the path in the text (a folded scalar's text is no key), or no text.
        assert_eq!(line("units"), None);
        assert_eq!(line("bodies"), at(BLOCK, 10, "bodies"));
        assert_eq!(field_line(BLOCK, Format::Yaml, "coordinates[0]"), None);
        assert_eq!(field_line("", Format::Yaml, "name"), None);
        assert_eq!(field_line("", Format::Json, "name"), None);
    }

    const FLOW: &str = r#"--- # the same in flow style, over lines
{name: 'x: y', points: {O: [0, 0],
  "B.1": {by: circles, about: [A, D]}},
 bodies: {crank: {points: [O, A],
   mass: -1.0}, rocker: {points: [D, B]}},
 pairs: [{type: revolute, at: O}, {type: revolute,
   at: Q, bodies: [coupler, rocker]}],
 drives: [{coordinate: theta1, table: {t: [0, 2, 1]}}]}
"#;

    #[test]
    fn yaml_flow_fields_are_found_by_their_path() {
        let line = |path| field_line(FLOW, Format::Yaml, path);
        assert_eq!(line("bodies.crank.mass"), at(FLOW, 5, "-1.0"));
        assert_eq!(line("pairs[1].at"), at(FLOW, 7, "Q"));
        // The second `{type: revolute,` of the line.
        assert_eq!(line("pairs[1]"), Some((6, 35)));
        assert_eq!(line("pairs[1].bodies[1]"), at(FLOW, 7, "rocker"));
        assert_eq!(line("points.B.1"), at(FLOW, 3, "{by"));
        assert_eq!(line("drives[0].table.t[2]"), at(FLOW, 8, "1]"));
        assert_eq!(line("bodies.rocker.mass"), at(FLOW, 5, "{points: [D"));
    }

    const JSON: &str = r#"{
  "name": "x: y, # not a comment",
  "points_at_t0": {"O": [0, 0], "B.1": {"by": "circles", "about": ["A", "D"]}},
  "bodies": {
    "crank": {
      "points": ["O", "A"],
      "inertia_about_com": 1e-3,
      "mass": -1.0
    },
    "rocker": {"points": ["D", "B"]}
  },
  "pairs": [
    {"type": "revolute", "at": "O"},
    {
      "type": "revolute",
      "at": "Q", "bodies": ["coupler", "rocker"]
    }
  ],
  "drives": [{"coordinate": "theta1", "table": {"t": [0, 2, 1]}}]
}"#;

    #[test]
    fn json_fields_are_found_by_their_path_and_aliases_by_their_field() {
        let line = |path| field_line(JSON, Format::Json, path);
        assert_eq!(line("bodies.crank.mass"), at(JSON, 8, "-1.0"));
        assert_eq!(line("bodies.crank.inertia"), at(JSON, 7, "1e-3"));
        assert_eq!(line("pairs[1].at"), at(JSON, 16, "\"Q\""));
        assert_eq!(line("pairs[1].bodies[1]"), at(JSON, 16, "\"rocker\""));
        assert_eq!(line("pairs[1]"), at(JSON, 14, "{"));
        assert_eq!(line("points.B.1"), at(JSON, 3, "{\"by\""));
        assert_eq!(line("drives[0].table.t[2]"), at(JSON, 19, "1]"));
        assert_eq!(line("bodies.rocker.mass"), at(JSON, 10, "{\"points\": [\"D\""));
        assert_eq!(line("units"), None);
        // Every alias is read by its field's name (the loader accepts them: spec.rs).
        for (field, alias) in FIELD_ALIASES {
            let text = format!("{{\"x\": 0,\n \"{alias}\": 1}}");
            assert_eq!(field_line(&text, Format::Json, field), Some((2, 4 + alias.len() + 2)), "{alias}");
        }
    }
}
