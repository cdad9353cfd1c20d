//! Where the current residual of a replay concentrates.
