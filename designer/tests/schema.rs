//! The description schema is the parser's: every number the bundled examples
//! give is refused outside the schema's domain with the schema's unit, the
//! model's parameters are the schema's symbols, and the generated reference
//! page is fresh.

use designer::description::schema::{self, Domain, Kind, Presence};
use designer::description::{parse_file, parse_str};
use designer::model::Model;
use support::{example_path, example_paths, root};

/// A value outside `domain`, if the domain excludes any.
fn outside(domain: Domain) -> Option<f64> {
    match domain {
        Domain::Any | Domain::Above(_) => None,
        Domain::Positive | Domain::NonNegative | Domain::Unit | Domain::UnitOpen => Some(-1.0),
        Domain::UnitLeftOpen => Some(0.0),
        Domain::Negative => Some(1.0),
    }
}

#[test]
fn every_number_outside_its_schema_domain_is_refused_with_its_unit() {
    let mut checked = 0;
    for file in example_paths() {
        let text = std::fs::read_to_string(&file).expect("readable example");
        let doc: toml_edit::DocumentMut = text.parse().expect("example is TOML");
        for key in schema::KEYS.iter().filter(|k| k.kind == Kind::Number) {
            let Some(bad) = outside(key.domain) else {
                continue;
            };
            let mut doc = doc.clone();
            let Some(item) = key
                .path
                .split('.')
                .try_fold(doc.as_item_mut(), |item, part| item.get_mut(part))
            else {
                continue;
            };
            if !item.is_value() {
                continue;
            }
            *item = toml_edit::value(bad);
            let err = parse_str(&doc.to_string(), "t.toml").expect_err(key.path);
            let msg = err.to_string();
            let expected = format!("{}: expected {} [", key.path, key.domain.text());
            assert!(
                msg.contains(&expected),
                "{}: {msg}\nwanted: {expected}",
                file.display()
            );
            if key.path.starts_with("supply.") || key.path.ends_with("u_bound") {
                continue; // the unit follows supply.drive
            }
            assert!(msg.contains(&format!("[{}]", key.unit)), "{msg}");
            checked += 1;
        }
    }
    assert!(checked > 60, "only {checked} keys were checked");
}

#[test]
fn defaults_are_the_schemas() {
    let text =
        std::fs::read_to_string(example_path("perfect-tracking-valve.toml")).expect("example");
    let d = parse_str(&text, "p.toml").expect("valid");
    let default = |path: &str| match schema::key(path).presence {
        Presence::Default(x) => x,
        other => panic!("{path}: {other:?}"),
    };
    assert!(!text.contains("resistance_drift"));
    assert_eq!(d.coil.resistance_drift, default("coil.resistance_drift"));
}

#[test]
fn model_parameters_are_schema_symbols_with_the_description_values() {
    for file in example_paths() {
        let d = parse_file(&file).expect("valid example");
        let model = Model::build(&d);
        for (symbol, _, value) in model.params.iter() {
            let key = schema::by_symbol(symbol)
                .unwrap_or_else(|| panic!("{}: `{symbol}` is in no schema key", file.display()));
            assert!(
                key.domain.contains(value),
                "{}: {symbol} = {value}",
                key.path
            );
        }
    }
}

#[test]
fn symbols_are_unique_and_every_fittable_key_has_one() {
    let mut seen = std::collections::BTreeSet::new();
    for key in schema::KEYS {
        if let Some(s) = key.symbol {
            assert!(seen.insert(s), "symbol `{s}` twice");
        }
        assert!(!key.fittable || key.symbol.is_some(), "{}", key.path);
        assert!(
            schema::lookup(key.path).is_some_and(|k| k == key),
            "{} twice",
            key.path
        );
    }
}

#[test]
fn reference_page_is_fresh() {
    let path = root().join("docs/reference/description.md");
    let want = schema::reference_markdown();
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have.replace("\r\n", "\n") == want {
        return;
    }
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&path, &want).expect("write the reference");
        panic!(
            "{} was stale and has been rewritten: commit it",
            path.display()
        );
    }
    panic!(
        "{} is stale: run `UPDATE_DOCS=1 cargo test -p reldesign-designer --test schema` and commit it",
        path.display()
    );
}
