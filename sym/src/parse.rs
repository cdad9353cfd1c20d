//! Infix text to nodes, mainly for tests: `g.parse("x^3 + 2*x", &[])`.
//!
//! ```text
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = "-" unary | power            (-x^2 is -(x^2))
//! power   = atom ("^" unary)?            (right-associative: 2^3^2 = 2^9)
//! atom    = number | name | name "(" sum ("," sum)* ")" | "(" sum ")"
//! ```
//!
//! Numbers are decimal (`2`, `0.5`, `1e-3`); `−` and `·` read as `-` and `*`.
//! Functions are the graph's: `sqrt exp ln abs sign tanh coth`, `min(a, b)`,
//! `max(a, b)` and `select(c, a, b)` (a where c ≥ 0, else b). A name bound in
//! `symbols` stands for that node; any other name is the graph's symbol of
//! that name, created on first use, so tests need no bindings.
//!
//! Every step calls the smart constructor of `build.rs` it names (`a - b` is
//! [`Graph::sub`], `x^3` is [`Graph::pow`]), in reading order. Text is
//! tokenised before any node is built, but a syntax error after that may
//! leave unused nodes in the graph.

use super::graph::{Func, Graph, Id};

/// Where parsing stopped, and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("column {column}: expected {expected}, found {found}")]
pub struct ParseError {
    /// 1-based, in characters.
    pub column: usize,
    pub expected: String,
    pub found: String,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    /// One of `+ - * / ^ ( ) ,`.
    Punct(char),
    End,
}

const OPERAND: &str = "a number, a name, `(` or `-`";

impl Graph {
    /// The node of an infix expression (see the module docs for the syntax);
    /// `symbols` binds names to existing nodes.
    pub fn parse(&mut self, text: &str, symbols: &[(&str, Id)]) -> Result<Id, ParseError> {
        let mut p = Parser {
            g: self,
            symbols,
            tokens: lex(text)?,
            next: 0,
        };
        let e = p.sum()?;
        match p.peek() {
            Token::End => Ok(e),
            _ => Err(p.error("an operator or the end")),
        }
    }
}

/// Tokens with their 1-based columns, ending with [`Token::End`].
fn lex(text: &str) -> Result<Vec<(usize, Token)>, ParseError> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let start = i;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let token = if c.is_ascii_digit() || c == '.' {
            i = number_end(&chars, i);
            let literal: String = chars[start..i].iter().collect();
            match literal.parse::<f64>() {
                Ok(v) if v.is_finite() => Token::Number(v),
                _ => return Err(lex_error(start, "a finite number", &literal)),
            }
        } else if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            Token::Name(chars[start..i].iter().collect())
        } else {
            i += 1;
            match c {
                '+' | '-' | '*' | '/' | '^' | '(' | ')' | ',' => Token::Punct(c),
                '−' => Token::Punct('-'),
                '·' => Token::Punct('*'),
                _ => {
                    return Err(lex_error(
                        start,
                        "an operand or an operator",
                        &c.to_string(),
                    ))
                }
            }
        };
        tokens.push((start + 1, token));
    }
    tokens.push((chars.len() + 1, Token::End));
    Ok(tokens)
}

/// End of the number starting at `i`: digits, `.` digits, then `e±digits`.
fn number_end(chars: &[char], mut i: usize) -> usize {
    let digits = |mut i: usize| {
        while chars.get(i).is_some_and(char::is_ascii_digit) {
            i += 1;
        }
        i
    };
    i = digits(i);
    if chars.get(i) == Some(&'.') {
        i = digits(i + 1);
    }
    if matches!(chars.get(i), Some('e' | 'E')) {
        let sign = usize::from(matches!(chars.get(i + 1), Some('+' | '-')));
        if chars.get(i + 1 + sign).is_some_and(char::is_ascii_digit) {
            i = digits(i + 1 + sign);
        }
    }
    i
}

fn lex_error(start: usize, expected: &str, found: &str) -> ParseError {
    ParseError {
        column: start + 1,
        expected: expected.to_owned(),
        found: format!("`{found}`"),
    }
}

struct Parser<'a> {
    g: &'a mut Graph,
    symbols: &'a [(&'a str, Id)],
    tokens: Vec<(usize, Token)>,
    next: usize,
}

impl Parser<'_> {
    fn peek(&self) -> &Token {
        &self.tokens[self.next].1
    }

    fn bump(&mut self) -> Token {
        let t = self.tokens[self.next].1.clone();
        if t != Token::End {
            self.next += 1;
        }
        t
    }

    /// Consumes `c` if it comes next.
    fn eat(&mut self, c: char) -> bool {
        let found = *self.peek() == Token::Punct(c);
        if found {
            self.next += 1;
        }
        found
    }

    fn error(&self, expected: &str) -> ParseError {
        let (column, token) = &self.tokens[self.next];
        let found = match token {
            Token::Number(v) => format!("`{v}`"),
            Token::Name(n) => format!("`{n}`"),
            Token::Punct(c) => format!("`{c}`"),
            Token::End => "the end".to_owned(),
        };
        ParseError {
            column: *column,
            expected: expected.to_owned(),
            found,
        }
    }

    fn sum(&mut self) -> Result<Id, ParseError> {
        let mut acc = self.product()?;
        loop {
            if self.eat('+') {
                let b = self.product()?;
                acc = self.g.add(acc, b);
            } else if self.eat('-') {
                let b = self.product()?;
                acc = self.g.sub(acc, b);
            } else {
                return Ok(acc);
            }
        }
    }

    fn product(&mut self) -> Result<Id, ParseError> {
        let mut acc = self.unary()?;
        loop {
            if self.eat('*') {
                let b = self.unary()?;
                acc = self.g.mul(acc, b);
            } else if self.eat('/') {
                let b = self.unary()?;
                acc = self.g.div(acc, b);
            } else {
                return Ok(acc);
            }
        }
    }

    fn unary(&mut self) -> Result<Id, ParseError> {
        if self.eat('-') {
            let a = self.unary()?;
            return Ok(self.g.neg(a));
        }
        let base = self.atom()?;
        if self.eat('^') {
            let exponent = self.unary()?;
            return Ok(self.g.pow(base, exponent));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Id, ParseError> {
        match self.peek().clone() {
            Token::Number(v) => {
                self.bump();
                Ok(self.g.constant(v))
            }
            Token::Name(name) => {
                let column = self.tokens[self.next].0;
                self.bump();
                if self.eat('(') {
                    self.call(&name, column)
                } else {
                    Ok(self.name(&name))
                }
            }
            Token::Punct('(') => {
                self.bump();
                let e = self.sum()?;
                if self.eat(')') {
                    Ok(e)
                } else {
                    Err(self.error("`)`"))
                }
            }
            _ => Err(self.error(OPERAND)),
        }
    }

    fn name(&mut self, name: &str) -> Id {
        match self.symbols.iter().find(|(n, _)| *n == name) {
            Some(&(_, id)) => id,
            None => self.g.symbol(name),
        }
    }

    /// `name(args)`, after the `(`.
    fn call(&mut self, name: &str, column: usize) -> Result<Id, ParseError> {
        let Some(call) = Call::named(name) else {
            return Err(ParseError {
                column,
                expected: format!("a function ({})", function_names()),
                found: format!("`{name}`"),
            });
        };
        let mut args = vec![self.sum()?];
        while self.eat(',') {
            args.push(self.sum()?);
        }
        if !self.eat(')') {
            return Err(self.error("`,` or `)`"));
        }
        match (call, args.as_slice()) {
            (Call::Func(f), &[a]) => Ok(self.g.func(f, a)),
            (Call::Min, &[a, b]) => Ok(self.g.min(a, b)),
            (Call::Max, &[a, b]) => Ok(self.g.max(a, b)),
            (Call::Select, &[c, a, b]) => Ok(self.g.select(c, a, b)),
            _ => Err(ParseError {
                column,
                expected: format!("{} argument(s) to `{name}`", call.arity()),
                found: args.len().to_string(),
            }),
        }
    }
}

#[derive(Clone, Copy)]
enum Call {
    Func(Func),
    Min,
    Max,
    Select,
}

impl Call {
    fn named(name: &str) -> Option<Call> {
        match name {
            "min" => Some(Call::Min),
            "max" => Some(Call::Max),
            "select" => Some(Call::Select),
            _ => Func::ALL
                .into_iter()
                .find(|f| f.name() == name)
                .map(Call::Func),
        }
    }

    fn arity(self) -> usize {
        match self {
            Call::Func(_) => 1,
            Call::Min | Call::Max => 2,
            Call::Select => 3,
        }
    }
}

fn function_names() -> String {
    let mut names: Vec<&str> = Func::ALL.iter().map(|f| f.name()).collect();
    names.extend(["min", "max", "select"]);
    names.join(", ")
}
