//! Numbers and arrays of numbers, each checked against its key's schema
//! [`Domain`] and printed with its unit: the domain logic (what is admitted,
//! the "expected …" text) is the schema's, the parser only adds the value an
//! `Above` domain compares with and the unit that follows `supply.drive`.

use std::ops::Range;

use toml::de::DeValue;
use toml::Spanned;

use super::sect::{Ctx, Res, Sect};
use crate::description::schema::{Domain, Presence};

/// What a number must be: its domain, the value of the key an `Above`
/// domain names, and its unit.
#[derive(Clone, Copy)]
struct Expect<'u> {
    domain: Domain,
    lower: Option<f64>,
    unit: &'u str,
}

impl Expect<'_> {
    /// "a number > 0", "a number > z_min (= 0.001)".
    fn text(self) -> String {
        self.domain.expected(self.lower)
    }
}

impl Ctx<'_> {
    /// A finite number within `expect` (integers accepted), or an error
    /// about `key` at `span`.
    fn number(
        &self,
        key: String,
        span: Range<usize>,
        value: &Spanned<DeValue>,
        expect: Expect,
    ) -> Res<f64> {
        let found = self.found(value);
        let wanted = format!("expected {} [{}]", expect.text(), expect.unit);
        let label = format!("expected {}", expect.text());
        match as_number(value.get_ref()) {
            None => Err(self.err(key, span, format!("{wanted}, found {found}"), &label)),
            Some(x) if !x.is_finite() => {
                let msg = format!("{wanted}, found {found} (NaN and infinities are not allowed)");
                Err(self.err(key, span, msg, "not a finite number"))
            }
            Some(x) if !expect.domain.admits(x, expect.lower) => {
                Err(self.err(key, span, format!("{wanted}, found {found}"), &label))
            }
            Some(x) => Ok(x),
        }
    }
}

/// An integer or float as f64 (integers of any radix).
fn as_number(value: &DeValue) -> Option<f64> {
    match value {
        DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
            Ok(n) => Some(n as f64),
            Err(_) if i.radix() == 10 => i.as_str().parse().ok(),
            Err(_) => u64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|n| n as f64),
        },
        DeValue::Float(f) => f.as_str().parse().ok(),
        _ => None,
    }
}

impl Sect<'_> {
    /// The schema's domain and unit of `key` (an `Above` domain needs its
    /// value: see [`Sect::req_above`]).
    fn expect(&self, key: &str) -> Expect<'static> {
        let spec = self.spec(key);
        Expect {
            domain: spec.domain,
            lower: None,
            unit: spec.unit,
        }
    }

    /// An optional number, with the schema's domain and unit.
    pub(super) fn opt(&self, key: &str) -> Res<Option<f64>> {
        self.opt_num(key, self.expect(key))
    }

    /// A required number, with the schema's domain and unit.
    pub(super) fn req(&self, key: &str) -> Res<f64> {
        self.num(key, self.expect(key))
    }

    /// A required number in `unit` (where the unit follows `supply.drive`).
    pub(super) fn req_in(&self, key: &str, unit: &str) -> Res<f64> {
        self.num(
            key,
            Expect {
                unit,
                ..self.expect(key)
            },
        )
    }

    /// A required number above `lower`, the value of the key the schema's
    /// `Above` domain names.
    pub(super) fn req_above(&self, key: &str, lower: f64) -> Res<f64> {
        self.req_above_in(key, lower, self.spec(key).unit)
    }

    pub(super) fn req_above_in(&self, key: &str, lower: f64, unit: &str) -> Res<f64> {
        let lower = Some(lower);
        self.num(
            key,
            Expect {
                lower,
                unit,
                ..self.expect(key)
            },
        )
    }

    /// An optional number with the schema's default.
    pub(super) fn or_default(&self, key: &str) -> Res<f64> {
        let spec = self.spec(key);
        let Presence::Default(default) = spec.presence else {
            unreachable!("`{}` has no default in the schema", spec.path);
        };
        Ok(self.opt(key)?.unwrap_or(default))
    }

    fn opt_num(&self, key: &str, expect: Expect) -> Res<Option<f64>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let (full, span) = (self.full_key(key), self.key_span(key));
        self.ctx.number(full, span, value, expect).map(Some)
    }

    fn num(&self, key: &str, expect: Expect) -> Res<f64> {
        let x = self.opt_num(key, expect)?;
        x.ok_or_else(|| self.missing(key, &format!("{} [{}]", expect.text(), expect.unit)))
    }

    /// A required array of numbers, with the schema's domain and unit.
    pub(super) fn req_array(&self, key: &str) -> Res<Vec<f64>> {
        let expect = self.expect(key);
        let what = format!("an array of numbers [{}]", expect.unit);
        self.opt_array(key, expect)?
            .ok_or_else(|| self.missing(key, &what))
    }

    /// An optional array of numbers, with the schema's domain and unit.
    pub(super) fn opt_numbers(&self, key: &str) -> Res<Option<Vec<f64>>> {
        self.opt_array(key, self.expect(key))
    }

    fn opt_array(&self, key: &str, expect: Expect) -> Res<Option<Vec<f64>>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let Some(items) = value.get_ref().as_array() else {
            let msg = format!(
                "expected an array of numbers [{}], found {}",
                expect.unit,
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected an array"));
        };
        let full = self.full_key(key);
        let numbers = items
            .iter()
            .enumerate()
            .map(|(i, item)| {
                self.ctx
                    .number(format!("{full}[{i}]"), item.span(), item, expect)
            })
            .collect::<Res<Vec<f64>>>()?;
        Ok(Some(numbers))
    }

    /// `values` (of `key`) has as many entries as this section's `z`.
    pub(super) fn same_length(&self, key: &str, values: &[f64], n: usize) -> Res<()> {
        if values.len() == n {
            return Ok(());
        }
        let msg = format!(
            "expected {n} values (as many as {}), found {}",
            self.full_key("z"),
            values.len()
        );
        Err(self.err(key, msg, "length differs from `z`"))
    }

    /// `values` (of `key`) increase strictly; `why` follows "values" in the
    /// message.
    pub(super) fn strictly_increasing(&self, key: &str, values: &[f64], why: &str) -> Res<()> {
        let full = self.full_key(key);
        for i in 1..values.len() {
            if values[i] <= values[i - 1] {
                let msg = format!(
                    "expected strictly increasing values{why}: {full}[{i}] = {} is not > \
                     {full}[{}] = {}",
                    values[i],
                    i - 1,
                    values[i - 1]
                );
                return Err(self.elem_err(key, i, msg, "not increasing"));
            }
        }
        Ok(())
    }
}
