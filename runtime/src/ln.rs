//! Natural logarithm for f64 (being written).
