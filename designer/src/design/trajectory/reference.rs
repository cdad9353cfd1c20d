//! Position references for soft landing (perfect-tracking-soft-landing [PT §4]).
//!
//! [PT 51]: z_r = z₀ before t₀, z_m(t) on [t₀, t_f], z_f after t_f, where z_m meets
//! the soft-landing conditions [PT 52–53]: zero velocity and acceleration at
//! both ends. The simplest such z_m is the 5th-degree polynomial
//! z₀ + (z_f − z₀)·(10τ³ − 15τ⁴ + 6τ⁵), τ = (t − t₀)/(t_f − t₀).

/// Position and its derivatives up to the jerk at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flat {
    pub z: f64,
    pub v: f64,
    pub a: f64,
    pub jerk: f64,
}

/// A reference z_r(t) with derivatives up to the jerk.
pub trait Reference {
    fn at(&self, t: f64) -> Flat;
    /// The motion interval [t₀, t_f].
    fn motion(&self) -> (f64, f64);
}

impl<R: Reference + ?Sized> Reference for Box<R> {
    fn at(&self, t: f64) -> Flat {
        (**self).at(t)
    }

    fn motion(&self) -> (f64, f64) {
        (**self).motion()
    }
}

/// [PT 51–53] with the 5th-degree polynomial motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polynomial {
    pub z0: f64,
    pub zf: f64,
    pub t0: f64,
    pub tf: f64,
}

impl Reference for Polynomial {
    fn at(&self, t: f64) -> Flat {
        let duration = self.tf - self.t0;
        let tau = ((t - self.t0) / duration).clamp(0.0, 1.0);
        let inside = t > self.t0 && t < self.tf;
        let dz = self.zf - self.z0;
        // s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ and its derivatives in τ
        let s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
        let s1 = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau);
        let s2 = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau);
        let s3 = 60.0 * (1.0 - 6.0 * tau + 6.0 * tau * tau);
        let moving = if inside { 1.0 } else { 0.0 };
        Flat {
            z: self.z0 + dz * s,
            v: moving * dz * s1 / duration,
            a: moving * dz * s2 / (duration * duration),
            jerk: moving * dz * s3 / (duration * duration * duration),
        }
    }

    fn motion(&self) -> (f64, f64) {
        (self.t0, self.tf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomial_meets_soft_landing_conditions_and_differentiates_consistently() {
        let p = Polynomial {
            z0: 1e-3,
            zf: 0.0,
            t0: 1e-3,
            tf: 6e-3,
        };
        for t in [p.t0, p.tf] {
            let f = p.at(t);
            assert_eq!((f.v, f.a), (0.0, 0.0));
        }
        assert_eq!(p.at(0.0).z, 1e-3);
        assert_eq!(p.at(7e-3).z, 0.0);
        let h = 1e-9;
        for k in 1..20 {
            let t = p.t0 + (p.tf - p.t0) * k as f64 / 20.0;
            let (fm, f0, fp) = (p.at(t - h), p.at(t), p.at(t + h));
            assert!(((fp.z - fm.z) / (2.0 * h) - f0.v).abs() < 1e-6 * f0.v.abs().max(1e-3));
            assert!(((fp.v - fm.v) / (2.0 * h) - f0.a).abs() < 1e-6 * f0.a.abs().max(1.0));
            assert!(((fp.a - fm.a) / (2.0 * h) - f0.jerk).abs() < 1e-6 * f0.jerk.abs().max(1e3));
        }
    }
}
