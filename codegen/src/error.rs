//! Why an emission was refused.

/// Errors of the emitter: every one names the offending symbol or name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EmitError {
    #[error(
        "symbol `{0}` is reached by an output but is neither a function input nor a parameter"
    )]
    UnboundSymbol(String),
    #[error("`{0}` is not a valid name here: {1}")]
    InvalidName(String, &'static str),
    #[error("the name `{0}` is used twice")]
    DuplicateName(String),
    #[error("`{0}` is bound as an input or parameter but its expression is not a symbol")]
    NotASymbol(String),
    #[error("parameter `{name}` = {value} is not finite in {float}")]
    NonFinite {
        name: String,
        value: String,
        float: &'static str,
    },
    #[error("output `{0}` is used (through its symbol) before it is computed")]
    OutputUsedEarly(String),
    #[error("internal error: the emitted tokens do not parse as Rust: {0}")]
    Syntax(String),
}
