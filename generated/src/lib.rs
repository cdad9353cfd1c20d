//! Checked-in controller and observer code for the bundled examples that
//! carry `[trajectory]` + `[controller]` or `[observer]` sections, exactly as `reldesign build`
//! emits it. `tests/fresh.rs` regenerates every module and fails when one is
//! stale; `UPDATE_GENERATED=1 cargo test -p reldesign-generated` rewrites them.
//!
//! This crate is `no_std` and depends only on the runtime, like a firmware
//! crate using the generated code would.
#![no_std]
#![forbid(unsafe_code)]

/// `examples/perfect-tracking-valve.toml`: the valve of
/// perfect-tracking-soft-landing Table 1 with the paper's design.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod perfect_tracking_valve;

/// `examples/sliding-mode-valve.toml`: the valve of
/// model-free-sliding-mode-soft-landing Table 1 with the paper's §4.2 design.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod sliding_mode_valve;

/// `examples/semera-valve.toml`: the valve of semera-electromagnetic-estimation
/// Table I with the SEMERA and integral estimators of its Table II.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod semera_valve;

/// `examples/jiles-atherton-valve.toml`: the valve of jiles-atherton-actuator-model
/// Tables 1–2 with the position hold of its §6.3.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod jiles_atherton_valve;

/// `examples/backstepping-valve.toml`: backstepping position control
/// (switched-force-backstepping) on the perfect-tracking valve, with its
/// certified region and the hybrid switching strategy.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod backstepping_valve;

/// `examples/self-calibrating-valve.toml`: the perfect-tracking valve,
/// sensorless at 50 µs (the UKF from the coil voltage and current), with its
/// run-to-run self-calibration: θ read at run time by the law and the filter,
/// and the update between runs (`docs/guide/self-calibration.md`).
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod self_calibrating_valve;

/// `examples/uncertain-stop-valve.toml`: the perfect-tracking valve and its
/// design on sensors, with the probability-based energy-optimal references
/// for stops spread σ = 10 µm (1 % of the stroke) into the stroke.
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod uncertain_stop_valve;

/// `examples/self-calibrating-sensor-valve.toml`: the perfect-tracking valve
/// and its design on sensors, with the replay self-calibration: the
/// parameters each operation's current identifies, read at run time by the
/// law and updated between operations (`docs/guide/self-calibration.md`).
#[rustfmt::skip] // formatted by the generator (prettyplease); the freshness test keeps it exact
pub mod self_calibrating_sensor_valve;
