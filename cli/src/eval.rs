//! `reldesign eval MODEL.toml STATES.json`: model quantities at given states,
//! printed as one JSON object of arrays (shortest round-trip numbers).

use std::path::Path;

use designer::design::Linearization;
use designer::model::Model;
use miette::Report;
use serde_json::{json, Map, Value};

use crate::fail;

/// States, inputs and times read from STATES.json.
struct Points {
    x: Vec<Vec<f64>>,
    u: Vec<f64>,
    t: Vec<f64>,
}

pub fn run(model_path: &Path, states_path: &Path) -> Result<(), Report> {
    let description = crate::load(model_path)?;
    let mut model = Model::build(&description);
    let points = read_points(states_path, &model.state_names())?;
    let out = evaluate(&mut model, &points);
    println!("{}", serde_json::to_string(&out).map_err(fail)?);
    Ok(())
}

/// Named quantities: (name, number of values per state, expressions).
type Quantity = (&'static str, usize, Vec<designer::sym::Id>);

fn quantities(model: &mut Model) -> Vec<Quantity> {
    let n = model.dim();
    let jacobian: Vec<_> = model.jacobian().into_iter().flatten().collect();
    let r_gap_dz2 = model.graph.diff(model.r_gap_dz, model.states[0]);
    let mut q: Vec<Quantity> = vec![
        ("f", n, model.f.clone()),
        ("i", 1, vec![model.current]),
        ("v_coil", 1, vec![model.voltage]),
        ("f_mag", 1, vec![model.f_mag]),
        ("r_gap", 1, vec![model.r_gap]),
        ("r_gap_dz", 1, vec![model.r_gap_dz]),
        ("r_gap_dz2", 1, vec![r_gap_dz2]),
        ("df_dx", n * n, jacobian),
    ];
    // The chain z, v, a (H_c exogenous on the Jiles–Atherton core).
    if let Ok(lin) = Linearization::derive(model) {
        q.extend([
            ("alpha", 1, vec![lin.alpha]),
            ("beta", 1, vec![lin.beta]),
            ("lf3h", 1, vec![lin.lf3h]),
            ("lglf2h", 1, vec![lin.lglf2h]),
            ("t", 3, lin.transform.to_vec()),
            ("f_j", 1, vec![lin.jerk_drift]),
            ("b_j", 1, vec![lin.jerk_gain]),
        ]);
    }
    q
}

fn evaluate(model: &mut Model, p: &Points) -> Value {
    let n = model.dim();
    let quantities = quantities(model);
    let exprs: Vec<_> = quantities
        .iter()
        .flat_map(|q| q.2.iter().copied())
        .collect();
    let tape = model.compile(&exprs);
    let mut scratch = tape.scratch();
    let mut values = vec![0.0; exprs.len()];
    let mut columns: Vec<Vec<Value>> = vec![Vec::new(); quantities.len()];
    for k in 0..p.x.len() {
        let mut inputs = p.x[k].clone();
        inputs.extend([p.u[k], p.t[k]]);
        tape.eval(&inputs, &mut scratch, &mut values);
        let mut offset = 0;
        for (column, (name, len, _)) in columns.iter_mut().zip(&quantities) {
            let v = &values[offset..offset + len];
            column.push(match (*name, len) {
                ("df_dx", _) => json!(v.chunks(n).collect::<Vec<_>>()),
                (_, 1) => json!(v[0]),
                _ => json!(v),
            });
            offset += len;
        }
    }
    let map: Map<String, Value> = quantities
        .iter()
        .zip(columns)
        .map(|((k, _, _), v)| (k.to_string(), Value::Array(v)))
        .collect();
    Value::Object(map)
}

fn read_points(path: &Path, state_names: &[&str]) -> Result<Points, Report> {
    let file = path.display();
    let text =
        std::fs::read_to_string(path).map_err(|e| fail(format!("{file}: cannot read: {e}")))?;
    let root: Value = serde_json::from_str(&text).map_err(|e| {
        fail(format!(
            "{file}:{}:{}: invalid JSON: {e}",
            e.line(),
            e.column()
        ))
    })?;
    let obj = root.as_object().ok_or_else(|| {
        fail(format!(
            "{file}: expected a JSON object {{\"x\": [...], \"u\": [...]}}"
        ))
    })?;
    for key in obj.keys() {
        if !["x", "u", "t"].contains(&key.as_str()) {
            return Err(fail(format!(
                "{file}: unknown key `{key}` (expected `x`, `u` and optionally `t`)"
            )));
        }
    }
    let n = state_names.len();
    let expected_state = format!("an array of {n} numbers [{}]", state_names.join(", "));
    let x = array(obj, "x", &file)?
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let row = row
                .as_array()
                .filter(|r| r.len() == n)
                .ok_or_else(|| fail(format!("{file}: x[{k}]: expected {expected_state}")))?;
            row.iter()
                .enumerate()
                .map(|(j, v)| number(v, &format!("x[{k}][{j}]"), &file))
                .collect()
        })
        .collect::<Result<Vec<Vec<f64>>, Report>>()?;
    let numbers = |key: &str| -> Result<Vec<f64>, Report> {
        array(obj, key, &file)?
            .iter()
            .enumerate()
            .map(|(k, v)| number(v, &format!("{key}[{k}]"), &file))
            .collect()
    };
    let u = numbers("u")?;
    let t = if obj.contains_key("t") {
        numbers("t")?
    } else {
        vec![0.0; x.len()]
    };
    for (key, len) in [("u", u.len()), ("t", t.len())] {
        if len != x.len() {
            return Err(fail(format!(
                "{file}: `{key}` has {len} entries but `x` has {} (one per state)",
                x.len()
            )));
        }
    }
    Ok(Points { x, u, t })
}

fn array<'a>(
    obj: &'a Map<String, Value>,
    key: &str,
    file: &impl std::fmt::Display,
) -> Result<&'a Vec<Value>, Report> {
    obj.get(key)
        .and_then(Value::as_array)
        .ok_or_else(|| fail(format!("{file}: missing or non-array key `{key}`")))
}

fn number(v: &Value, at: &str, file: &impl std::fmt::Display) -> Result<f64, Report> {
    v.as_f64()
        .filter(|x| x.is_finite())
        .ok_or_else(|| fail(format!("{file}: {at}: expected a finite number, found {v}")))
}
