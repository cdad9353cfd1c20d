//! A bench recording as the fit sees it: uniformly sampled time, coil
//! voltage and current, and the optional position, flux and flux-linkage
//! columns of `shared/spec/measured-data.md`.
//!
//! Everything is checked through the [`Record`] helpers, so errors name the
//! file, the line and the column.

use std::path::Path;

use crate::record::{Record, RecordError};

/// Measured signals, one value per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Time [s], strictly increasing, uniform within 1 %.
    pub t: Vec<f64>,
    /// Coil voltage [V].
    pub v: Vec<f64>,
    /// Coil current [A].
    pub i: Vec<f64>,
    /// Armature position (gap length) [m], if measured.
    pub z: Option<Vec<f64>>,
    /// Magnetic flux [Wb], if measured.
    pub phi: Option<Vec<f64>>,
    /// Flux linkage [Wb], if measured.
    pub lambda: Option<Vec<f64>>,
    /// The (median) sampling period [s].
    pub dt: f64,
    pub file_name: String,
    /// The voltage edges' instants when placed for the record
    /// ([`super::edges::located`]): every replay steps there; `None`: the
    /// replays join the samples linearly.
    pub edges: Option<Vec<super::edges::Edge>>,
}

/// Fewest samples a recording must have to be fitted.
pub const MIN_SAMPLES: usize = 4;

impl Measured {
    /// Required `t`, `v`, `i`; optional `z`, `phi`, `lambda`.
    pub fn from_record(record: &Record) -> Result<Measured, RecordError> {
        let t = record.time(MIN_SAMPLES)?;
        let dt = record.check_uniform(&t)?;
        let optional = |name: &str| {
            record
                .column_index(name)
                .ok()
                .map(|j| record.rows.iter().map(|r| r[j]).collect::<Vec<f64>>())
        };
        Ok(Measured {
            v: record.column("v")?,
            i: record.column("i")?,
            z: optional("z"),
            phi: optional("phi"),
            lambda: optional("lambda"),
            t,
            dt,
            file_name: record.file_name.clone(),
            edges: None,
        })
    }

    /// Reads and checks a CSV recording.
    pub fn read(path: &Path) -> Result<Measured, RecordError> {
        Measured::from_record(&Record::read(path)?)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The first `n` samples (all of them when `n` ≥ the length).
    pub fn head(&self, n: usize) -> Measured {
        let n = n.min(self.len());
        let cut = |x: &Vec<f64>| x[..n].to_vec();
        Measured {
            t: cut(&self.t),
            v: cut(&self.v),
            i: cut(&self.i),
            z: self.z.as_ref().map(cut),
            phi: self.phi.as_ref().map(cut),
            lambda: self.lambda.as_ref().map(cut),
            dt: self.dt,
            file_name: self.file_name.clone(),
            edges: self
                .edges
                .as_ref()
                .map(|e| e.iter().filter(|e| e.k + 1 < n).copied().collect()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_required_and_optional_columns() {
        let text = "t,i,v,phi\n0,0,1,0\n1e-3,0.1,1,1e-6\n2e-3,0.2,1,2e-6\n3e-3,0.3,1,3e-6\n";
        let m = Measured::from_record(&Record::parse(text, "m.csv").unwrap()).unwrap();
        assert_eq!(m.i, vec![0.0, 0.1, 0.2, 0.3]);
        assert_eq!(m.phi.as_ref().map(Vec::len), Some(4));
        assert!(m.z.is_none() && m.lambda.is_none());
        assert!((m.dt - 1e-3).abs() < 1e-15);
    }

    #[test]
    fn missing_current_and_non_uniform_time_are_named() {
        let e =
            Measured::from_record(&Record::parse("t,v\n0,1\n1,1\n2,1\n3,1\n", "a.csv").unwrap())
                .unwrap_err()
                .to_string();
        assert!(e.contains("a.csv") && e.contains("`i`"), "{e}");
        let text = "t,v,i\n0,1,0\n1,1,0\n2,1,0\n3.5,1,0\n";
        let e = Measured::from_record(&Record::parse(text, "b.csv").unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("b.csv:5") && e.contains("uniform"), "{e}");
    }
}
