//! Identification from measured data (`reldesign fit`): parameters of a
//! description fitted to a bench recording (jiles-atherton-actuator-model §4–5).
