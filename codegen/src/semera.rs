//! SEMERA and integral estimator emission (being written).
