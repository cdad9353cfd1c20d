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

#[cfg(test)]
mod tests {
    use super::changed_lines;

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
