//! The fit with the voltage edges' instants among its parameters
//! (`edge_fit`): on a record whose supply steps fall 0.37 of a sample after
//! a sample instant, with the edges started at their midpoints, it must
//! find the instants and the values together; the fit on the midpoints
//! alone must not (else the test would show nothing).

use designer::description::{parse_file, Description};
use reldesign_identify::edge_fit::fit_with_edges;
use reldesign_identify::edges::Edge;
use reldesign_identify::{fit, params, simulate_outputs, FitOptions, FitParam, Measured};
use support::example_path;

const DT: f64 = 40e-6;
/// Where in its interval each of the supply's steps falls.
const TRUE_PLACE: f64 = 0.37;

/// The SEMERA valve with eddy currents (its current jumps at a step, so
/// the instants matter at once).
fn truth() -> Description {
    let mut d = parse_file(&example_path("semera-valve.toml")).unwrap();
    params::set(&mut d, "coil.eddy", 1500.0).unwrap();
    d
}

/// 24 V / 0 V, 300 samples each, over 3000 samples: 9 steps, each between
/// samples k and k + 1 at `place` of the interval.
fn record(place: f64) -> Measured {
    let n = 3000;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let v: Vec<f64> = (0..n)
        .map(|k| if (k / 300) % 2 == 0 { 24.0 } else { 0.0 })
        .collect();
    let edges = (1..10)
        .map(|m| Edge {
            k: 300 * m - 1,
            tau: t[300 * m - 1] + place * DT,
            located: true,
        })
        .collect();
    Measured {
        i: vec![0.0; n],
        z: None,
        phi: None,
        lambda: None,
        dt: DT,
        file_name: "synthetic.csv".into(),
        edges: Some(edges),
        t,
        v,
    }
}

/// The truth's current on the record stepping at [`TRUE_PLACE`], the edges
/// then put at the midpoints (as a placement that knew nothing would).
fn measured() -> Measured {
    let mut data = record(TRUE_PLACE);
    data.i = simulate_outputs(&truth(), &data).unwrap().current;
    data.edges = record(0.5).edges;
    data
}

/// R and k_e, started 3 % off (from 10 % the fit on the true edges too
/// ends on the bound of k_e).
fn params() -> (Description, Vec<FitParam>) {
    let mut start = truth();
    let r = start.coil.resistance;
    params::set(&mut start, "coil.resistance", 1.03 * r).unwrap();
    params::set(&mut start, "coil.eddy", 0.97 * 1500.0).unwrap();
    let bounds = |path: &str, x: f64| FitParam {
        path: path.into(),
        lower: 0.5 * x,
        upper: 2.0 * x,
    };
    (
        start,
        vec![bounds("coil.resistance", r), bounds("coil.eddy", 1500.0)],
    )
}

/// The fit as the diagnosis runs it: the current alone. (The flux term's
/// reference is integrated from the samples, which know nothing of the
/// edges: it would pull the instants towards the midpoints.)
fn no_flux() -> FitOptions {
    FitOptions {
        use_flux: false,
        ..FitOptions::default()
    }
}

fn relative_errors(values: &[(String, f64)]) -> Vec<f64> {
    let truth = truth();
    values
        .iter()
        .map(|(path, x)| (x / params::get(&truth, path).unwrap() - 1.0).abs())
        .collect()
}

#[test]
fn the_edges_instants_are_fitted_with_the_values() {
    let data = measured();
    let (start, fitted) = params();
    let options = no_flux();
    let joint = fit_with_edges(&start, &data, &fitted, &options).unwrap();
    for err in relative_errors(&joint.report.values) {
        assert!(err < 1e-8, "{:?}", joint.report.values);
    }
    for e in &joint.edges {
        let place = (e.tau - data.t[e.k]) / DT;
        assert!(
            (place - TRUE_PLACE).abs() < 1e-7,
            "edge at {}: {place}",
            e.k
        );
    }
    // one column per value, then one per edge
    assert_eq!(joint.jacobian.ncols(), 2 + 9);
    assert!(
        joint.report.wnrmse_current < 1e-9,
        "{}",
        joint.report.wnrmse_current
    );
    // On the midpoints the values cannot come that near (k_e 8.5 % off).
    let plain = fit(&start, &data, &fitted, &options, &|_| {}).unwrap();
    let worst = relative_errors(&plain.values)
        .into_iter()
        .fold(0.0, f64::max);
    assert!(worst > 1e-2, "{:?}", plain.values);
}

#[test]
fn edges_the_current_could_not_place_stay_where_they_are() {
    let mut data = measured();
    let edges = data.edges.as_mut().unwrap();
    edges[3].located = false;
    let (start, fitted) = params();
    let joint = fit_with_edges(&start, &data, &fitted, &no_flux()).unwrap();
    assert_eq!(joint.jacobian.ncols(), 2 + 8);
    assert_eq!(joint.edges[3], data.edges.as_ref().unwrap()[3]);
    let moved = joint
        .edges
        .iter()
        .filter(|e| (e.tau - data.t[e.k] - 0.5 * DT).abs() > 1e-3 * DT);
    assert_eq!(moved.count(), 8);
}

/// Beyond `MAX_FITTED_EDGES` (a slow PWM) the instants stay where they were
/// placed and only the values are fitted: the Jacobian keeps its size.
#[test]
fn many_edges_are_held_where_they_were_placed() {
    use reldesign_identify::edge_fit::MAX_FITTED_EDGES;
    let mut data = measured();
    let n = data.len();
    data.v = (0..n)
        .map(|k| if (k / 20) % 2 == 0 { 24.0 } else { 0.0 })
        .collect();
    data.edges = Some(
        (1..n / 20)
            .map(|m| Edge {
                k: 20 * m - 1,
                tau: data.t[20 * m - 1] + 0.5 * DT,
                located: true,
            })
            .collect(),
    );
    assert!(data.edges.as_ref().unwrap().len() > MAX_FITTED_EDGES);
    let (start, fitted) = params();
    let joint = fit_with_edges(&start, &data, &fitted, &no_flux()).unwrap();
    assert_eq!(joint.jacobian.ncols(), 2);
    assert_eq!(Some(&joint.edges), data.edges.as_ref());
}
