//! Text → [`Description`]: the TOML document is parsed with spans kept
//! ([`toml::de::DeTable`]) and walked by hand, so that every rejection names
//! the file, the full dotted key, its line/column and what was expected.
//!
//! This file holds the order of the sections; the section readers
//! (`name`, `physics`, `design`, `observer`) read like the table of
//! `shared/spec/actuator.md`, on the walker of `sect` with its typed values
//! (`number`, `choice`) and unknown-key rejection (`keys`); `checks` holds
//! the rules between sections.

mod checks;
mod choice;
mod design;
mod keys;
mod name;
mod number;
mod observer;
mod physics;
mod sect;

use std::path::Path;

use toml::de::DeTable;

use super::{Description, DescriptionError, Source};
use sect::{Ctx, Sect};

/// Reads and validates the description in `path`. An unreadable file is a
/// [`DescriptionError`] naming the file.
pub fn parse_file(path: &Path) -> Result<Description, DescriptionError> {
    let file_name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DescriptionError::io(&file_name, &e))?;
    parse_str(&text, &file_name)
}

/// Parses and validates a description; `file_name` is only used in messages
/// and in [`Description::source`].
pub fn parse_str(text: &str, file_name: &str) -> Result<Description, DescriptionError> {
    let doc = DeTable::parse(text).map_err(|e| DescriptionError::syntax(file_name, text, &e))?;
    let ctx = Ctx {
        file: file_name,
        text,
    };
    let root = Sect::root(&ctx, doc.get_ref());
    root.check_keys(None, "at the top level")?;
    let name = name::parse_name(&root)?;
    let coil = physics::parse_coil(&root.section("coil")?)?;
    let gap_sect = root.section("gap")?;
    let gap = physics::parse_gap(&gap_sect)?;
    let core_sect = root.section("core")?;
    let core = physics::parse_core(&core_sect)?;
    let mechanics = physics::parse_mechanics(&root.section("mechanics")?)?;
    let supply_sect = root.section("supply")?;
    let supply = physics::parse_supply(&supply_sect)?;
    checks::check_gap_range(&gap_sect, &gap, &mechanics)?;
    checks::check_drive(&supply_sect, &supply, &coil)?;
    let trajectory_sect = root.opt_section("trajectory")?;
    let trajectory = trajectory_sect
        .as_ref()
        .map(|s| design::parse_trajectory(s, &supply))
        .transpose()?;
    if let (Some(s), Some(t)) = (&trajectory_sect, &trajectory) {
        checks::check_trajectory_core(s, t, &core)?;
        checks::check_contact_uncertainty(s, t, &mechanics)?;
        checks::check_approach(s, t, &mechanics)?;
    }
    let controller_sect = root.opt_section("controller")?;
    let controller = controller_sect
        .as_ref()
        .map(design::parse_controller)
        .transpose()?;
    if let (Some(s), Some(c)) = (&controller_sect, &controller) {
        checks::check_controller(&root, s, c, trajectory.as_ref(), &mechanics)?;
    }
    let observer = root
        .opt_section("observer")?
        .map(|s| observer::parse_observer(&s, &supply, &core_sect, &core))
        .transpose()?;
    let mut warnings = Vec::new();
    if let (Some(s), Some(c)) = (&controller_sect, &controller) {
        checks::check_estimator(s, c, observer.as_ref())?;
        checks::check_compensation(s, c, observer.as_ref(), supply.drive)?;
        warnings.extend(checks::estimator_warning(s, c).map(|w| w.to_string()));
        let spring = checks::spring_warning(s, c, trajectory.as_ref(), &mechanics);
        warnings.extend(spring.map(|w| w.to_string()));
    }
    let source = Source {
        file_name: file_name.to_string(),
        text: text.to_string(),
    };
    Ok(Description {
        name,
        coil,
        gap,
        core,
        mechanics,
        supply,
        trajectory,
        controller,
        observer,
        source,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn help_is_attached_to_unknown_keys() {
        use miette::Diagnostic;
        let text = "name = \"v\"\nnme = 1\n";
        let err = parse_str(text, "t.toml").unwrap_err();
        assert_eq!(err.key(), "nme");
        let help = err.help().map(|h| h.to_string());
        assert_eq!(help.as_deref(), Some("did you mean `name`?"));
    }
}
