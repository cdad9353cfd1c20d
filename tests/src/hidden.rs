//! Data with a hidden effect: a bundled example, one extension of the
//! measured-data vocabulary added in secret, a simulated noisy experiment.
