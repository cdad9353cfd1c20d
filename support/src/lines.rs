//! Line-by-line comparison of two texts of the same shape: what "one changed
//! parameter is one changed line" tests look at in emitted code.

/// The pairs of lines that differ between `a` and `b`, in order. Panics when
/// the two texts do not have the same number of lines (then a line-by-line
/// comparison says nothing).
pub fn changed_lines<'a>(a: &'a str, b: &'a str) -> Vec<(&'a str, &'a str)> {
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    assert_eq!(
        la.len(),
        lb.len(),
        "the texts differ in their number of lines"
    );
    la.into_iter().zip(lb).filter(|(x, y)| x != y).collect()
}

/// `text` with `from` replaced once; panics when `from` is not there (a
/// test that changes an example must change something).
pub fn replaced_once(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` is not in the text");
    text.replacen(from, to, 1)
}

/// The lines of emitted code without its comments (`//` lines, `/* … */`
/// blocks: prettyplease writes a multi-line doc attribute as one), for tests
/// that look for words the code must not contain.
pub fn code_only(text: &str) -> Vec<&str> {
    let mut in_block = false;
    let mut code = Vec::new();
    for line in text.lines() {
        let t = line.trim_start();
        if in_block || t.starts_with("/*") {
            in_block = !line.contains("*/");
        } else if !t.starts_with("//") {
            code.push(line);
        }
    }
    code
}

#[cfg(test)]
mod tests {
    use super::{changed_lines, code_only};

    #[test]
    fn comments_are_not_code() {
        let text = "// a\nlet x = 1;\n/** doc\n  more */\nfn f() {}\n    /// d\n";
        assert_eq!(code_only(text), ["let x = 1;", "fn f() {}"]);
    }

    #[test]
    fn only_the_differing_lines_in_order() {
        assert_eq!(
            changed_lines("a\nb\nc\nd", "a\nB\nc\nD"),
            [("b", "B"), ("d", "D")]
        );
        assert!(changed_lines("x\ny", "x\ny").is_empty());
    }

    #[test]
    #[should_panic(expected = "number of lines")]
    fn texts_of_different_length_are_refused() {
        changed_lines("a\nb", "a");
    }
}
