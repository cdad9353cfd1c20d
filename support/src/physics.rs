//! An actuator description's physics alone: its text without the design
//! sections, which tests extend with a design of their own (a bench record
//! needs no controller; a variant swaps the law).

/// `text` without its design sections `[trajectory]`, `[controller]` and
/// `[observer…]` (each from its header to the next header).
pub fn without_design_sections(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut skipping = false;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if trimmed.starts_with('[') {
            skipping = ["[trajectory]", "[controller]", "[observer"]
                .iter()
                .any(|section| trimmed.starts_with(section));
        }
        if !skipping {
            out.push_str(line);
        }
    }
    out
}

/// The bundled example `examples/FILE` without its design sections.
pub fn example_physics(file: &str) -> String {
    let path = crate::example_path(file);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()));
    without_design_sections(&text)
}

#[cfg(test)]
mod tests {
    use super::without_design_sections;

    #[test]
    fn design_sections_go_and_physics_stays() {
        let text = "name = \"v\"\n[coil]\nturns = 1\n[trajectory]\nx = 1\n[controller]\nlaw = \"a\"\n[observer]\ny = 2\n[observer.kalman]\nz = 3\n";
        assert_eq!(
            without_design_sections(text),
            "name = \"v\"\n[coil]\nturns = 1\n"
        );
    }
}
