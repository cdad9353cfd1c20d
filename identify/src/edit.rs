//! Edits of a description's TOML text that keep its comments and layout.
//!
//! `reldesign diagnose` extends a user's model (eddy currents, a saturating or
//! Jiles–Atherton core, a McLyman gap, …) and writes it back next to the data.
//! [`write_physics`] rewrites only the physics sections (`[coil]`, `[gap]`,
//! `[core]`, `[mechanics]`) of the original text with `toml_edit`, so the
//! user's comments, key order and the design sections survive. A value that
//! did not change keeps its exact spelling; a changed value keeps its
//! comments; keys a new model variant does not have are dropped (with their
//! comments) and its new keys are appended with a comment naming the unit.
//! The result is re-parsed and compared with the requested physics: nothing
//! invalid or different is ever returned.

use toml_edit::{DocumentMut, Item, TableLike, Value};

use crate::description::{
    parse_str, schema, Coil, Core, Description, DescriptionError, Gap, Mechanics, Reversal,
};

/// Why the physics could not be written into a description's text.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    #[error("{file}: not a valid TOML document: {message}")]
    Syntax { file: String, message: String },
    #[error("{file}: expected a table [{section}] to rewrite, found {found}")]
    Section {
        file: String,
        section: &'static str,
        found: &'static str,
    },
    #[error("{file}: the rewritten description is rejected: {source}")]
    Invalid {
        file: String,
        source: DescriptionError,
    },
    #[error(
        "{file}: the rewritten description parses to another [{section}] than requested \
         (wrote {written}, requested {requested})"
    )]
    Mismatch {
        file: String,
        section: &'static str,
        written: String,
        requested: String,
    },
}

/// Rewrites the `[coil]`, `[gap]`, `[core]` and `[mechanics]` sections of the
/// description `text` so that it parses to the physics of `desc` (bit-exact);
/// everything else (`name`, `[supply]`, design sections, comments) is kept.
/// A file that gives `mechanics.rest_position` keeps it when an exact
/// rest position exists for `desc`'s preload, else it gets `preload`.
pub fn write_physics(text: &str, file_name: &str, desc: &Description) -> Result<String, EditError> {
    let mut doc: DocumentMut =
        text.parse()
            .map_err(|e: toml_edit::TomlError| EditError::Syntax {
                file: file_name.to_string(),
                message: e.to_string(),
            })?;
    write_coil(section(&mut doc, "coil", file_name)?, &desc.coil);
    write_gap(section(&mut doc, "gap", file_name)?, &desc.gap);
    write_core(section(&mut doc, "core", file_name)?, &desc.core);
    write_mechanics(section(&mut doc, "mechanics", file_name)?, &desc.mechanics);
    let out = doc.to_string();
    verify(&out, file_name, desc)?;
    Ok(out)
}

/// Prepends `header_comment` to `text` as `#` comment lines (one per line of
/// the header; lines already starting with `#` are kept as they are).
pub fn annotate(text: &str, header_comment: &str) -> String {
    let mut out = String::with_capacity(text.len() + header_comment.len() + 8);
    for line in header_comment.lines() {
        if line.trim_start().starts_with('#') {
            out.push_str(line);
        } else if line.is_empty() {
            out.push('#');
        } else {
            out.push_str("# ");
            out.push_str(line);
        }
        out.push('\n');
    }
    out.push_str(text);
    out
}

// ------------------------------------------------------------------ sections

/// A physics section of the document as a table, however it was written.
fn section<'a>(
    doc: &'a mut DocumentMut,
    name: &'static str,
    file: &str,
) -> Result<Sect<'a>, EditError> {
    let err = |found| EditError::Section {
        file: file.to_string(),
        section: name,
        found,
    };
    let item = doc.get_mut(name).ok_or_else(|| err("nothing"))?;
    let commented = item.is_table();
    let table = item
        .as_table_like_mut()
        .ok_or_else(|| err("a value that is not a table"))?;
    Ok(Sect {
        name,
        table,
        commented,
    })
}

/// One table being rewritten; `commented` is false for inline tables, where
/// no comment can follow a value.
struct Sect<'a> {
    /// The section's name (`coil`, …): with a key, its schema path.
    name: &'static str,
    table: &'a mut dyn TableLike,
    commented: bool,
}

fn write_coil(mut s: Sect, coil: &Coil) {
    s.num("turns", coil.turns);
    s.num("resistance", coil.resistance);
    s.num("eddy", coil.eddy);
    s.opt_num("resistance_drift", coil.resistance_drift, 0.0);
}

fn write_gap(mut s: Sect, gap: &Gap) {
    match gap {
        Gap::Linear { slope, offset } => {
            s.model("linear", &["slope", "offset"]);
            s.num("slope", *slope);
            s.opt_num("offset", *offset, 0.0);
        }
        Gap::McLyman {
            area,
            winding_length,
        } => {
            s.model("mclyman", &["area", "winding_length"]);
            s.num("area", *area);
            s.num("winding_length", *winding_length);
        }
        Gap::McLymanFit {
            r0,
            r0_prime,
            k1,
            k2,
        } => {
            s.model("mclyman-fit", &["r0", "r0_prime", "k1", "k2"]);
            s.num("r0", *r0);
            s.num("r0_prime", *r0_prime);
            s.num("k1", *k1);
            s.num("k2", *k2);
        }
        Gap::Table { z, r, r_prime } => {
            s.model("table", &["z", "r", "r_prime"]);
            s.array("z", z);
            s.array("r", r);
            match r_prime {
                Some(rp) => s.array("r_prime", rp),
                None => {
                    s.table.remove("r_prime");
                }
            }
        }
    }
}

fn write_core(mut s: Sect, core: &Core) {
    match core {
        Core::Linear { r0 } => {
            s.model("linear", &["r0"]);
            s.num("r0", *r0);
        }
        Core::Saturating { r0, phi_sat } => {
            s.model("saturating", &["r0", "phi_sat"]);
            s.num("r0", *r0);
            s.num("phi_sat", *phi_sat);
        }
        Core::JilesAtherton(ja) => {
            let keys = [
                "length", "area", "m_sat", "b", "c", "kappa", "alpha", "epsilon", "reversal",
            ];
            s.model("jiles-atherton", &keys);
            s.num("length", ja.length);
            s.num("area", ja.area);
            s.num("m_sat", ja.m_sat);
            s.num("b", ja.b);
            s.num("c", ja.c);
            s.num("kappa", ja.kappa);
            s.num("alpha", ja.alpha);
            s.opt_num("epsilon", ja.epsilon, 1e-3);
            let reversal = match ja.reversal {
                Reversal::Clamp => "clamp",
                Reversal::Reversible => "reversible",
            };
            s.opt_str("reversal", reversal, "clamp");
        }
    }
}

fn write_mechanics(mut s: Sect, m: &Mechanics) {
    s.num("mass", m.mass);
    s.num("stiffness", m.stiffness);
    s.num("damping", m.damping);
    write_preload(&mut s, m);
    s.num("z_min", m.z_min);
    s.num("z_max", m.z_max);
    s.num("restitution", m.restitution);
    s.num("bounce_threshold", m.bounce_threshold);
}

/// F0 as the file gives it: `rest_position` z_s with F0 = −k_s·z_s when the
/// file uses it and such a z_s exists in f64, else `preload`.
fn write_preload(s: &mut Sect, m: &Mechanics) {
    if s.table.contains_key("rest_position") {
        let exact = |z_s: f64| -m.stiffness * z_s == m.preload;
        if s.current("rest_position").is_some_and(exact) {
            return;
        }
        if let Some(z_s) = rest_position_for(m.preload, m.stiffness) {
            s.num("rest_position", z_s);
            return;
        }
        s.table.remove("rest_position");
    }
    s.num("preload", m.preload);
}

/// z_s with −k_s·z_s == F0 exactly: −F0/k_s or one of its f64 neighbours.
fn rest_position_for(preload: f64, stiffness: f64) -> Option<f64> {
    if stiffness == 0.0 || !stiffness.is_finite() {
        return None;
    }
    let guess = -preload / stiffness;
    if guess == 0.0 {
        return (-stiffness * 0.0 == preload).then_some(0.0);
    }
    (0..=8)
        .flat_map(|k: i64| [k, -k])
        .map(|d| f64::from_bits((guess.to_bits() as i64 + d) as u64))
        .find(|&z_s| -stiffness * z_s == preload)
}

// ---------------------------------------------------------------- key edits

impl Sect<'_> {
    /// The numeric value of `key` (integer or float), if it has one.
    fn current(&self, key: &str) -> Option<f64> {
        let item = self.table.get(key)?;
        item.as_float()
            .or_else(|| item.as_integer().map(|n| n as f64))
    }

    /// Sets `key = x`: untouched when it already parses to x, rewritten in
    /// place (comments kept) when it differs, appended with a unit comment
    /// when absent.
    fn num(&mut self, key: &str, x: f64) {
        if self.current(key) == Some(x) && same_sign(self.current(key), x) {
            return;
        }
        self.put(key, number(x));
    }

    /// Like [`num`](Self::num) for an optional key: an absent key whose value
    /// would be the default stays absent.
    fn opt_num(&mut self, key: &str, x: f64, default: f64) {
        if self.table.contains_key(key) || x != default {
            self.num(key, x);
        }
    }

    /// Sets `key = "value"` for an optional string key: an absent key whose
    /// value would be the default stays absent.
    fn opt_str(&mut self, key: &str, value: &str, default: &str) {
        let now = self.table.get(key).and_then(|i| i.as_str());
        if now == Some(value) || (now.is_none() && value == default) {
            return;
        }
        self.put(key, Value::from(value));
    }

    /// Sets an array of numbers (untouched when equal element by element).
    fn array(&mut self, key: &str, xs: &[f64]) {
        let now: Option<Vec<f64>> = self.table.get(key).and_then(|i| i.as_array()).map(|a| {
            a.iter()
                .map(|v| v.as_float().or_else(|| v.as_integer().map(|n| n as f64)))
                .collect::<Option<Vec<f64>>>()
                .unwrap_or_default()
        });
        if now.as_deref() == Some(xs) {
            return;
        }
        let text: Vec<String> = xs.iter().map(|x| format!("{x:?}")).collect();
        self.put(key, parse_value(&format!("[{}]", text.join(", "))));
    }

    /// Sets `model = name`; when the variant changes, drops every key but
    /// `model` and the new variant's `keys`.
    fn model(&mut self, name: &str, keys: &[&str]) {
        let now = self.table.get("model").and_then(|i| i.as_str());
        if now == Some(name) {
            return;
        }
        let stale: Vec<String> = self
            .table
            .iter()
            .map(|(k, _)| k.to_string())
            .filter(|k| k != "model" && !keys.contains(&k.as_str()))
            .collect();
        for k in stale {
            self.table.remove(&k);
        }
        self.put("model", Value::from(name));
    }

    /// Replaces the value of `key`, keeping its decoration (comments) and
    /// the column of a trailing comment; or appends it with a unit comment.
    fn put(&mut self, key: &str, mut value: Value) {
        if let Some(old) = self.table.get_mut(key).and_then(Item::as_value_mut) {
            let prefix = old
                .decor()
                .prefix()
                .and_then(|p| p.as_str())
                .map(str::to_owned);
            let suffix = old
                .decor()
                .suffix()
                .and_then(|p| p.as_str())
                .map(str::to_owned);
            let (old_len, new_len) = (bare_len(old), bare_len(&value));
            let suffix = suffix.map(|s| realign(&s, old_len, new_len));
            value
                .decor_mut()
                .set_prefix(prefix.unwrap_or_else(|| " ".into()));
            value.decor_mut().set_suffix(suffix.unwrap_or_default());
            *old = value;
            return;
        }
        if self.commented {
            value.decor_mut().set_prefix(" ");
            value
                .decor_mut()
                .set_suffix(format!("  # {}", unit(self.name, key)));
        }
        self.table.insert(key, Item::Value(value));
    }
}

/// Shifts a trailing comment so that it stays in its column when a value
/// grows or shrinks (at least one space is kept before `#`).
fn realign(suffix: &str, old_len: usize, new_len: usize) -> String {
    let pad = suffix.len() - suffix.trim_start_matches(' ').len();
    let rest = &suffix[pad..];
    if !rest.starts_with('#') {
        return suffix.to_string();
    }
    let pad = (pad + old_len).saturating_sub(new_len).max(1);
    format!("{}{rest}", " ".repeat(pad))
}

/// Characters of a value's own text, without its decoration.
fn bare_len(value: &Value) -> usize {
    let mut bare = value.clone();
    bare.decor_mut().clear();
    bare.to_string().trim().chars().count()
}

/// −0.0 and 0.0 compare equal; keep a rewrite when only the sign differs.
fn same_sign(now: Option<f64>, x: f64) -> bool {
    now.is_some_and(|n| n.is_sign_negative() == x.is_sign_negative())
}

/// A TOML float in the shortest form that reads back to the same f64
/// (Rust's `{:?}` of f64 always has a `.` or an exponent: `1200.0`, `1e-10`).
fn number(x: f64) -> Value {
    parse_value(&format!("{x:?}"))
}

fn parse_value(text: &str) -> Value {
    // Built from `{:?}` of finite f64s, which are valid TOML floats.
    text.parse::<Value>()
        .unwrap_or_else(|e| unreachable!("`{text}` is not a TOML value: {e}"))
}

/// The unit comment of a key appended to a physics section: the schema's
/// unit (`[-]` for dimensionless values and for `model`).
fn unit(section: &str, key: &str) -> String {
    let unit = schema::lookup(&format!("{section}.{key}")).map_or("", |k| k.unit);
    match unit {
        "" => "[-]".to_string(),
        u => format!("[{u}]"),
    }
}

// -------------------------------------------------------------- verification

/// Parses `out` and checks that its physics is exactly `desc`'s.
fn verify(out: &str, file: &str, desc: &Description) -> Result<(), EditError> {
    let got = parse_str(out, file).map_err(|source| EditError::Invalid {
        file: file.to_string(),
        source,
    })?;
    let mismatch = |section, written: String, requested: String| EditError::Mismatch {
        file: file.to_string(),
        section,
        written,
        requested,
    };
    if got.coil != desc.coil {
        return Err(mismatch(
            "coil",
            format!("{:?}", got.coil),
            format!("{:?}", desc.coil),
        ));
    }
    if got.gap != desc.gap {
        return Err(mismatch(
            "gap",
            format!("{:?}", got.gap),
            format!("{:?}", desc.gap),
        ));
    }
    if got.core != desc.core {
        return Err(mismatch(
            "core",
            format!("{:?}", got.core),
            format!("{:?}", desc.core),
        ));
    }
    if got.mechanics != desc.mechanics {
        let (w, r) = (&got.mechanics, &desc.mechanics);
        return Err(mismatch("mechanics", format!("{w:?}"), format!("{r:?}")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::JilesAtherton;
    use std::path::PathBuf;

    fn examples() -> Vec<(String, String)> {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        files.sort();
        assert!(files.len() >= 5, "bundled examples not found in {dir:?}");
        files
            .into_iter()
            .map(|p| {
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                (name, std::fs::read_to_string(&p).unwrap())
            })
            .collect()
    }

    fn example(name: &str) -> (String, Description) {
        let (_, text) = examples().into_iter().find(|(n, _)| n == name).unwrap();
        let d = parse_str(&text, name).unwrap();
        (text, d)
    }

    /// Writes `target`'s physics into `name`'s text, re-parses, and checks
    /// that the physics matches and the other sections are untouched.
    fn rewrite(name: &str, edit: impl FnOnce(&mut Description)) -> (String, String) {
        let (text, mut d) = example(name);
        edit(&mut d);
        let out = write_physics(&text, name, &d).unwrap_or_else(|e| panic!("{e}"));
        let back = parse_str(&out, name).unwrap();
        assert_eq!(
            (&back.coil, &back.gap, &back.core, &back.mechanics),
            (&d.coil, &d.gap, &d.core, &d.mechanics)
        );
        assert_eq!(back.name, d.name);
        assert_eq!(back.supply, d.supply);
        assert_eq!(
            (&back.trajectory, &back.controller, &back.observer),
            (&d.trajectory, &d.controller, &d.observer)
        );
        (text, out)
    }

    /// Lines of `out` that mention `needle`.
    fn line_with<'a>(out: &'a str, needle: &str) -> &'a str {
        out.lines()
            .find(|l| l.contains(needle))
            .unwrap_or_else(|| panic!("no line with `{needle}` in\n{out}"))
    }

    #[test]
    fn every_example_round_trips_byte_identical() {
        for (name, text) in examples() {
            let d = parse_str(&text, &name).unwrap();
            assert_eq!(write_physics(&text, &name, &d).unwrap(), text, "{name}");
        }
    }

    #[test]
    fn eddy_value_changes_in_place_and_keeps_its_comment() {
        let (_, out) = rewrite("semera-valve.toml", |d| d.coil.eddy = 1234.5);
        let line = line_with(&out, "eddy =");
        assert!(
            line.starts_with("eddy = 1234.5") && line.contains("# the paper's flux model (51)"),
            "{line}"
        );
        // The comment stays in its column.
        let before = line_with(&example("semera-valve.toml").0, "eddy =").find('#');
        assert_eq!(line.find('#'), before);
    }

    #[test]
    fn linear_to_saturating_core_appends_phi_sat() {
        let (text, _) = example("semera-valve.toml");
        let lin = text.replace(
            "model = \"saturating\"\nr0 = 3.25e6                 # R_iron0 [H⁻¹], Table I\nphi_sat = 2e-5              # φ_sat = λ_sat/N = 0.024 Wb / 1200, Table I\n",
            "model = \"linear\"            # was saturating\nr0 = 3.25e6                 # R_iron0 [H⁻¹], Table I\n",
        );
        assert_ne!(lin, text);
        let d0 = parse_str(&lin, "lin.toml").unwrap();
        let mut d = d0.clone();
        d.core = Core::Saturating {
            r0: 3.25e6,
            phi_sat: 1.7e-5,
        };
        let out = write_physics(&lin, "lin.toml", &d).unwrap();
        assert_eq!(parse_str(&out, "lin.toml").unwrap().core, d.core);
        assert!(line_with(&out, "model = \"saturating\"").contains("# was saturating"));
        assert!(out.contains("r0 = 3.25e6                 # R_iron0 [H⁻¹], Table I"));
        assert!(out.contains("phi_sat = 1.7e-5  # [Wb]"), "{out}");
        assert!(out.contains("# eq. (50): R_air = k_air·h, fringing neglected"));
    }

    #[test]
    fn saturating_to_jiles_atherton_drops_phi_sat_and_r0() {
        let ja = JilesAtherton {
            length: 0.055,
            area: 1.26e-5,
            m_sat: 1.45e6,
            b: 2.45e-3,
            c: 0.736,
            kappa: 943.0,
            alpha: 3.66e-3,
            epsilon: 1e-3,
            reversal: Reversal::Clamp,
        };
        let (text, out) = rewrite("semera-valve.toml", |d| d.core = Core::JilesAtherton(ja));
        assert!(
            !out.contains("phi_sat") && !out.contains("R_iron0"),
            "{out}"
        );
        assert!(out.contains("m_sat = 1450000.0  # [A/m]"), "{out}");
        assert!(out.contains("kappa = 943.0  # [A/m]"));
        assert!(!out.contains("epsilon"), "the default ε stays implicit");
        // Comments of the core's header and of every other section survive.
        assert!(out.contains("[core]                      # eq. (50): Fröhlich–Kennelly"));
        for comment in text.lines().filter(|l| l.starts_with('#')) {
            assert!(out.contains(comment), "lost `{comment}`");
        }
    }

    #[test]
    fn linear_to_jiles_atherton_core() {
        let (text, d) = example("semera-valve.toml");
        let lin = text
            .replace("phi_sat = 2e-5", "")
            .replace("\"saturating\"", "\"linear\"");
        let mut target = parse_str(&lin, "lin.toml").unwrap();
        assert_eq!(target.core, Core::Linear { r0: 3.25e6 });
        target.core = Core::JilesAtherton(JilesAtherton {
            length: 0.04,
            area: 2e-5,
            m_sat: 1.2e6,
            b: 2e-3,
            c: 0.5,
            kappa: 800.0,
            alpha: 1e-3,
            epsilon: 2e-3,
            reversal: Reversal::Reversible,
        });
        let out = write_physics(&lin, "lin.toml", &target).unwrap();
        let back = parse_str(&out, "lin.toml").unwrap();
        assert_eq!(back.core, target.core);
        assert!(out.contains("epsilon = 0.002  # [-]"), "{out}");
        assert!(out.contains("reversal = \"reversible\""), "{out}");
        assert_eq!(back.observer, d.observer);
    }

    #[test]
    fn linear_gap_to_mclyman_and_table_to_linear() {
        let (text, out) = rewrite("semera-valve.toml", |d| {
            d.gap = Gap::McLyman {
                area: 20e-6,
                winding_length: 15e-3,
            }
        });
        assert!(!out.contains("slope") && !out.contains("offset"));
        assert!(
            out.contains("area = 2e-5  # [m²]") && out.contains("winding_length = 0.015  # [m]")
        );
        assert!(out.contains("[gap]                       # eq. (50): R_air = k_air·h"));
        assert!(text.contains("slope = 2.7e10"));
        let (_, out) = rewrite("table-gap-valve.toml", |d| {
            d.gap = Gap::Linear {
                slope: 2.1e10,
                offset: 1.5e5,
            }
        });
        assert!(!out.contains("r_prime") && !out.contains("z = ["), "{out}");
        assert!(out.contains("slope = 21000000000.0  # [H⁻¹/m]"), "{out}");
        assert!(out.contains("offset = 150000.0  # [H⁻¹]"));
        assert!(out.contains("# How the table was generated"));
    }

    #[test]
    fn resistance_drift_and_restitution() {
        let (_, out) = rewrite("perfect-tracking-valve.toml", |d| {
            d.coil.resistance_drift = 0.75;
            d.mechanics.restitution = 0.45;
            d.mechanics.bounce_threshold = 2.5e-3;
        });
        assert!(out.contains("resistance_drift = 0.75  # [Ω/s]"));
        let line = line_with(&out, "restitution =");
        assert!(line.starts_with("restitution = 0.45 ") && line.contains("# γ = 0.5, Table 1"));
        assert!(line_with(&out, "bounce_threshold").contains("0.0025"));
        // Removing the effects again: an explicit drift is kept, set to 0.
        let mut back = parse_str(&out, "x.toml").unwrap();
        back.coil.resistance_drift = 0.0;
        back.mechanics.restitution = 0.0;
        let out = write_physics(&out, "x.toml", &back).unwrap();
        let line = line_with(&out, "resistance_drift");
        assert!(line.starts_with("resistance_drift = 0.0 ") && line.ends_with("# [Ω/s]"));
        assert_eq!(line.find('#'), Some("resistance_drift = 0.75  ".len()));
        assert_eq!(
            parse_str(&out, "x.toml").unwrap().mechanics.restitution,
            0.0
        );
    }

    #[test]
    fn rest_position_is_kept_and_converted_exactly() {
        for f0 in [-0.8, -0.7514, -1.23456789, 0.0] {
            let (_, out) = rewrite("semera-valve.toml", |d| d.mechanics.preload = f0);
            assert!(!out.contains("preload"), "{out}");
            assert!(line_with(&out, "rest_position").contains("# h_s = 22.5 mm, Table I"));
        }
        // A stiffness change keeps F0 and moves the rest position.
        let (_, out) = rewrite("jiles-atherton-valve.toml", |d| {
            d.mechanics.stiffness = 60.0
        });
        assert!(out.contains("rest_position = 0.01375"), "{out}");
        // Without a stiffness no rest position gives F0 ≠ 0: `preload` is written.
        let (_, out) = rewrite("semera-valve.toml", |d| d.mechanics.stiffness = 0.0);
        assert!(!out.contains("rest_position") && out.contains("preload = -0.8325  # [N]"));
        // A file with `preload` keeps it.
        let (_, out) = rewrite("perfect-tracking-valve.toml", |d| {
            d.mechanics.preload = -0.6
        });
        assert!(line_with(&out, "preload = -0.6 ").contains("# F0 = −0.75 N, Table 1"));
    }

    #[test]
    fn bit_exact_numbers_round_trip() {
        for x in [0.1 + 0.2, 1e-10, 1.0 / 3.0, 6.02214076e23, 5e-324, 1200.0] {
            let (_, out) = rewrite("sliding-mode-valve.toml", |d| d.coil.eddy = x);
            assert_eq!(
                parse_str(&out, "x").unwrap().coil.eddy.to_bits(),
                x.to_bits()
            );
        }
    }

    #[test]
    fn invalid_targets_are_refused() {
        let (text, mut d) = example("semera-valve.toml");
        d.mechanics.mass = -1.0;
        let e = write_physics(&text, "v.toml", &d).unwrap_err().to_string();
        assert!(e.contains("v.toml") && e.contains("mechanics.mass"), "{e}");
        let e = write_physics("name = \"x\"\n[coil", "bad.toml", &d).unwrap_err();
        assert!(
            e.to_string().starts_with("bad.toml: not a valid TOML"),
            "{e}"
        );
        let e = write_physics("name = \"x\"\ncoil = 3\n", "c.toml", &d).unwrap_err();
        assert!(e.to_string().contains("[coil]"), "{e}");
    }

    #[test]
    fn annotate_prepends_comment_lines() {
        let out = annotate(
            "name = \"v\"\n",
            "extended by reldesign diagnose: cause = hysteresis\n# kept",
        );
        assert_eq!(
            out,
            "# extended by reldesign diagnose: cause = hysteresis\n# kept\nname = \"v\"\n"
        );
    }
}
