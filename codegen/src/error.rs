//! Why an emission was refused: by the expression emitter ([`EmitError`]) or
//! by a controller module ([`ControllerError`], every law's).

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
    #[error("not emitted: {0}")]
    Unsupported(String),
}

/// Why a controller could not be emitted (every law's module returns it).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControllerError {
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no float type to emit")]
    NoFloat,
    #[error("the {0} law has no gains K [PT 48]: it is emitted by its own module")]
    NotFeedbackLinearization(&'static str),
    #[error("internal error: the sliding-mode module was asked to emit another law")]
    NotSlidingMode,
    #[error("the design value `{name}` = {value} is not finite in the float type")]
    BadValue { name: String, value: f64 },
    #[error(
        "the name `{0}` of a design constant or reference symbol is already taken by the model"
    )]
    NameTaken(String),
}
