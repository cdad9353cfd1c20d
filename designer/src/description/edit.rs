//! Edits of a description's TOML text that keep its comments and layout.
