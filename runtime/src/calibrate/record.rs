//! What an operation leaves for the calibration: the measured voltage and
//! current in a fixed buffer of S stored samples, decimated by the design,
//! and the flags the checks read (non-finite, saturated, supply dips).

use crate::linalg::Scalar;
use crate::math::Real;

use super::{small, Refusal, Settings};

/// The measured voltage and current of one operation.
///
/// Stored sample 0 is the current at the operation's start (and the voltage
/// held before it); stored sample k ≥ 1 the mean measured voltage over its
/// block of `decimation` samples and the current at the block's end (the
/// ADC samples i before the next voltage is applied). RAM: 2·S floats and a
/// few words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record<T, const S: usize> {
    u: [T; S],
    i: [T; S],
    len: usize,
    /// The stop the armature rests on at the start [m].
    z0: T,
    /// Samples in the current block and their voltages' sum.
    block: u32,
    sum: T,
    samples: u32,
    dips: u32,
    not_finite: bool,
    saturated: bool,
}

impl<T: Scalar, const S: usize> Default for Record<T, S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Scalar, const S: usize> Record<T, S> {
    /// An empty record.
    #[must_use]
    pub const fn new() -> Self {
        Record {
            u: [T::ZERO; S],
            i: [T::ZERO; S],
            len: 0,
            z0: T::ZERO,
            block: 0,
            sum: T::ZERO,
            samples: 0,
            dips: 0,
            not_finite: false,
            saturated: false,
        }
    }

    /// Starts recording an operation whose armature rests at `z0` [m].
    pub fn start(&mut self, z0: T) {
        *self = Self::new();
        self.z0 = z0;
    }

    /// One sample: the voltage `commanded` and `measured` over the last
    /// sample period and the current `current` measured now. The first
    /// sample after [`Record::start`] is the starting current. Samples past
    /// the buffer are counted for the checks, not stored.
    pub fn push<const P: usize>(
        &mut self,
        settings: &Settings<T, P>,
        commanded: T,
        measured: T,
        current: T,
    ) {
        if !(measured.finite() && current.finite()) {
            self.not_finite = true;
            return;
        }
        if Real::abs(current) >= settings.current_limit {
            self.saturated = true;
        }
        if self.len == 0 {
            self.store(measured, current);
            return;
        }
        self.samples = self.samples.saturating_add(1);
        if Real::abs(commanded - measured) > settings.dip_tolerance {
            self.dips = self.dips.saturating_add(1);
        }
        self.sum = self.sum + measured;
        self.block = self.block.saturating_add(1);
        if self.block >= settings.decimation {
            let mean = self.sum / small::<T>(self.block);
            self.store(mean, current);
            self.block = 0;
            self.sum = T::ZERO;
        }
    }

    /// Stores (u, i) where the buffer has room.
    fn store(&mut self, u: T, i: T) {
        if let (Some(su), Some(si)) = (self.u.get_mut(self.len), self.i.get_mut(self.len)) {
            *su = u;
            *si = i;
            self.len = self.len.saturating_add(1);
        }
    }

    /// The stop the armature rested on at the start [m].
    #[must_use]
    pub fn start_position(&self) -> T {
        self.z0
    }

    /// The stored samples: (mean voltage over the block, current at its end).
    pub fn samples(&self) -> impl Iterator<Item = (T, T)> + '_ {
        self.u
            .iter()
            .copied()
            .zip(self.i.iter().copied())
            .take(self.len)
    }

    /// Stored samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// No sample stored.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Why the record is not an operation to learn from, if it is not.
    #[must_use]
    pub fn refusal<const P: usize>(&self, settings: &Settings<T, P>) -> Option<Refusal> {
        if self.not_finite {
            Some(Refusal::NotFinite)
        } else if self.saturated {
            Some(Refusal::Saturated)
        } else if self.len < settings.min_samples {
            Some(Refusal::TooShort)
        } else if small::<T>(self.dips) > settings.dip_share * small::<T>(self.samples) {
            Some(Refusal::SupplyDip)
        } else {
            None
        }
    }
}
