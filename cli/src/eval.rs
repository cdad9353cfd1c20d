//! `reldesign eval MODEL.toml STATES.json`: model quantities at given states,
//! printed as one JSON object of arrays (shortest round-trip numbers).

use std::path::Path;

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

fn evaluate(model: &mut Model, p: &Points) -> Value {
    let n = model.dim();
    let jacobian = model.jacobian();
    let r_gap_dz2 = model.graph.diff(model.r_gap_dz, model.states[0]);
    let mut exprs = model.f.clone();
    exprs.extend([
        model.current,
        model.voltage,
        model.f_mag,
        model.r_gap,
        model.r_gap_dz,
        r_gap_dz2,
    ]);
    exprs.extend(jacobian.iter().flatten());
    let tape = model.compile(&exprs);
    let mut scratch = tape.scratch();
    let mut values = vec![0.0; exprs.len()];
    let mut columns: [Vec<Value>; 8] = Default::default();
    for k in 0..p.x.len() {
        let mut inputs = p.x[k].clone();
        inputs.extend([p.u[k], p.t[k]]);
        tape.eval(&inputs, &mut scratch, &mut values);
        columns[0].push(json!(values[..n]));
        for (j, column) in columns[1..7].iter_mut().enumerate() {
            column.push(json!(values[n + j]));
        }
        let jac: Vec<&[f64]> = values[n + 6..].chunks(n).collect();
        columns[7].push(json!(jac));
    }
    let names = [
        "f",
        "i",
        "v_coil",
        "f_mag",
        "r_gap",
        "r_gap_dz",
        "r_gap_dz2",
        "df_dx",
    ];
    let map: Map<String, Value> = names
        .iter()
        .zip(columns)
        .map(|(k, v)| (k.to_string(), Value::Array(v.to_vec())))
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
