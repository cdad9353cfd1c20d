//! The backstepping law [SFB 19] and its region [SFB Theorem 3] on the
//! bundled valves.

use designer::description::parse_file;
use designer::design::Design;
use support::example_path;

#[test]
fn probe() {
    let d = parse_file(&example_path("backstepping-valve.toml")).unwrap();
    let design = Design::new(&d).unwrap();
    let b = design.backstepping.unwrap();
    println!("{:#?}", b.region);
    println!("rest {} guard {} holding {:?}", b.rest, b.phi_guard, b.holding);
}
