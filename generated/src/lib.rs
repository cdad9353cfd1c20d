//! Checked-in generated code for the bundled examples, rewritten by
//! `UPDATE_GENERATED=1 cargo test` and checked for staleness by a test.
//! Filled by the soft-landing pipeline (issue 3).
#![no_std]
