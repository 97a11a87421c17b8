//! A linear scan that refuses YAML nested deeper than any model needs, before the parser
//! sees it: the YAML parser's time grows with the square of the nesting depth (100,000
//! levels of `[` took over a minute before its error). JSON needs no scan: serde_json stops
//! at 128 levels by itself.

/// Nesting levels allowed: a model file needs about 6 (`bodies.crank.parts[0].com[0]`), so
/// 64 leaves room for any hand-written layout while keeping the parser's work negligible.
pub const MAX_NESTING: usize = 64;

/// The 1-based line and column where the YAML `text` first nests deeper than [`MAX_NESTING`]
/// levels, counting block indentation levels, compact `- ` entries and flow brackets. Quoted
/// strings and comments are skipped; brackets inside unquoted text can only make the count
/// err upwards by their imbalance, far below the limit for any real file.
pub fn too_deep(text: &str) -> Option<(usize, usize)> {
    let mut indents: Vec<usize> = Vec::new();
    let mut flow: usize = 0;
    for (line_no, line) in text.lines().enumerate() {
        let body = line.trim_start_matches(' ');
        if body.is_empty() || body.starts_with('#') {
            continue;
        }
        let indent = line.len() - body.len();
        if flow == 0 {
            while indents.last().is_some_and(|&i| i >= indent) {
                indents.pop();
            }
            indents.push(indent);
        }
        let bytes = body.as_bytes();
        let (mut k, mut compact, mut quote) = (0, 0, None::<u8>);
        // Compact nested sequence entries `- - - x` each open a level.
        while k + 1 < bytes.len() && bytes[k] == b'-' && bytes[k + 1] == b' ' {
            compact += 1;
            k += 2;
            while k < bytes.len() && bytes[k] == b' ' {
                k += 1;
            }
        }
        while k < bytes.len() {
            let c = bytes[k];
            match quote {
                Some(b'"') if c == b'\\' => k += 1,
                Some(q) if c == q => quote = None,
                Some(_) => {}
                None => match c {
                    b'"' | b'\'' => quote = Some(c),
                    b'#' if k == 0 || bytes[k - 1] == b' ' => break,
                    b'[' | b'{' => flow += 1,
                    b']' | b'}' => flow = flow.saturating_sub(1),
                    _ => {}
                },
            }
            if indents.len() + compact + flow > MAX_NESTING {
                return Some((line_no + 1, indent + k + 1));
            }
            k += 1;
        }
        if indents.len() + compact + flow > MAX_NESTING {
            return Some((line_no + 1, indent + k));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_layouts_pass_and_deep_ones_are_located() {
        let ok = "name: x\nbodies:\n  crank:\n    parts:\n      - {mass: 1, com: [0, 0]}  # [ not counted\n";
        assert_eq!(too_deep(ok), None);
        // Flow brackets: the 65th `[` (line 2, column 9 + 64) is the first level too many.
        let flow = format!("name: x\npoints: {}{}", "[".repeat(100), "]".repeat(100));
        assert_eq!(too_deep(&flow), Some((2, 9 + MAX_NESTING - 1)));
        // Compact sequences `- - - ...` on one line.
        let dashes = format!("a:\n{}x\n", "- ".repeat(100));
        assert!(too_deep(&dashes).is_some_and(|(line, _)| line == 2));
        // Block indentation, one level a line.
        let block: String = (0..100).map(|i| format!("{}a{i}:\n", " ".repeat(i))).collect();
        assert_eq!(too_deep(&block).map(|(line, _)| line), Some(MAX_NESTING + 1));
        // Brackets in quoted text do not count.
        let quoted = format!("about: \"{}\"\nname: '{}'", "[".repeat(100), "{".repeat(100));
        assert_eq!(too_deep(&quoted), None);
    }
}
