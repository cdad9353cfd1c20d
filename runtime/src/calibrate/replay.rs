//! The record's voltage replayed through the model from its starting rest:
//! the predicted current, and with it the forward sensitivities S = ∂x/∂θ
//! (Ṡ = f_x·S + f_θ, classical RK4 on x and S together over each stored
//! sample's d·T_s), accumulated as JᵀJ and Jᵀe of the current's error in
//! relative coordinates (column j scaled by θ_d,j).
//!
//! The stops are inelastic in the replay: an armature that reaches one stays
//! (z at the stop, v = 0, their sensitivities 0) while its free acceleration
//! points into it; it leaves when that acceleration points away. A soft
//! landing has no bounce to model, and a slam is what the update removes.
//! The starting flux is the one whose current is the record's first
//! (Newton on i(z₀, φ) = i₀, bracketed), with ∂φ₀/∂θ = −i_θ / i_φ.

use crate::control::saturate_to;
use crate::linalg::Scalar;
use crate::math::Real;

use super::{small, Predictor, Record, Settings};

/// A replay's error and, where asked, its Gauss–Newton normal equations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Replay<T, const P: usize> {
    /// Mean squared current error [A²] over the stored samples after the first.
    pub cost: T,
    /// JᵀJ, J the current's relative sensitivities (zero without sensitivities).
    pub jtj: [[T; P]; P],
    /// Jᵀe, e = i_measured − i_predicted.
    pub jte: [T; P],
    /// 10⁻³ of JᵀJ's largest diagonal: the damping's floor.
    pub jtj_floor: T,
}

/// x = [z, v, φ] and S = ∂x/∂θ, integrated together.
#[derive(Clone, Copy)]
struct Flow<T, const P: usize> {
    x: [T; 3],
    s: [[T; P]; 3],
}

/// Replays `record` with `theta`: with `sensitivities`, the normal
/// equations too; with `held`, the armature held at its start stop.
pub fn replay<T: Scalar, M: Predictor<T, P>, const P: usize, const S: usize>(
    model: &M,
    settings: &Settings<T, P>,
    record: &Record<T, S>,
    theta: &[T; P],
    sensitivities: bool,
    held: bool,
) -> Replay<T, P> {
    let mut out = Replay {
        cost: T::ZERO,
        jtj: [[T::ZERO; P]; P],
        jte: [T::ZERO; P],
        jtj_floor: T::ZERO,
    };
    let mut samples = record.samples();
    let Some((u0, i0)) = samples.next() else {
        // no replay: an infinite error, which every caller refuses
        out.cost = T::ONE / T::ZERO;
        return out;
    };
    let mut flow = start(model, theta, record.start_position(), u0, i0);
    let h = settings.sample_period * small::<T>(settings.decimation);
    let mut n = 0u32;
    for (u, i_measured) in samples {
        flow = step(model, settings, theta, &flow, u, h, held);
        let c = model.current(theta, &flow.x, u);
        let e = i_measured - c.i;
        out.cost = out.cost + e * e;
        n = n.saturating_add(1);
        if sensitivities {
            let row = relative_row(&c.i_x, &c.i_theta, &flow.s, &settings.nominal);
            accumulate(&mut out, &row, e);
        }
    }
    out.cost = out.cost / small::<T>(n);
    out.jtj_floor = out
        .jtj
        .iter()
        .enumerate()
        .filter_map(|(k, row)| row.get(k).copied())
        .fold(T::ZERO, Real::max)
        / small::<T>(1000);
    out
}

/// (i_x·S + i_θ)_j·θ_d,j: the current's sensitivity to a relative change.
fn relative_row<T: Scalar, const P: usize>(
    i_x: &[T; 3],
    i_theta: &[T; P],
    s: &[[T; P]; 3],
    nominal: &[T; P],
) -> [T; P] {
    let mut row = *i_theta;
    for (k, out) in row.iter_mut().enumerate() {
        let mut sum = *out;
        for (gx, s_row) in i_x.iter().zip(s) {
            sum = sum + *gx * s_row.get(k).copied().unwrap_or(T::ZERO);
        }
        *out = sum * nominal.get(k).copied().unwrap_or(T::ZERO);
    }
    row
}

/// JᵀJ += rowᵀ·row, Jᵀe += rowᵀ·e.
fn accumulate<T: Scalar, const P: usize>(out: &mut Replay<T, P>, row: &[T; P], e: T) {
    for ((a_row, b), r) in out.jtj.iter_mut().zip(out.jte.iter_mut()).zip(row) {
        for (a, c) in a_row.iter_mut().zip(row) {
            *a = *a + *r * *c;
        }
        *b = *b + *r * e;
    }
}

/// At rest at `z0` with the flux whose current is `i0` under `u0`, and its
/// sensitivity −i_θ / i_φ (z and v are known: their rows are 0).
fn start<T: Scalar, M: Predictor<T, P>, const P: usize>(
    model: &M,
    theta: &[T; P],
    z0: T,
    u0: T,
    i0: T,
) -> Flow<T, P> {
    let phi = starting_flux(model, theta, z0, u0, i0);
    let x = [z0, T::ZERO, phi];
    let c = model.current(theta, &x, u0);
    let [_, _, i_phi] = c.i_x;
    let mut s = [[T::ZERO; P]; 3];
    if let Some(row) = s.get_mut(2) {
        for (out, gi) in row.iter_mut().zip(&c.i_theta) {
            *out = -*gi / i_phi;
        }
    }
    Flow { x, s }
}

/// φ with i(z0, φ, u0) = i0: Newton steps kept inside a bracket that every
/// evaluation narrows (bisection where a step leaves it or is not finite).
/// The current rises with φ.
fn starting_flux<T: Scalar, M: Predictor<T, P>, const P: usize>(
    model: &M,
    theta: &[T; P],
    z0: T,
    u0: T,
    i0: T,
) -> T {
    let mut phi = T::ZERO;
    let mut lo: Option<T> = None;
    let mut hi: Option<T> = None;
    for _ in 0..60 {
        let c = model.current(theta, &[z0, T::ZERO, phi], u0);
        let [_, _, slope] = c.i_x;
        let error = c.i - i0;
        // past a saturating core's pole the current turns against the flux:
        // a flux too large in magnitude, whatever the error says
        let beyond = c.i * phi < T::ZERO;
        let above = if beyond {
            phi > T::ZERO
        } else {
            !error.finite() || error > T::ZERO
        };
        if above {
            hi = Some(phi);
        } else {
            lo = Some(phi);
        }
        if !beyond
            && error.finite()
            && Real::abs(error) <= Real::abs(i0) * small::<T>(1) / small::<T>(1 << 30)
        {
            break;
        }
        let newton = phi - error / slope;
        let inside = match (lo, hi) {
            (Some(a), Some(b)) => newton > a && newton < b,
            (Some(a), None) => newton > a,
            (None, Some(b)) => newton < b,
            (None, None) => true,
        };
        phi = match (lo, hi) {
            _ if inside && newton.finite() => newton,
            (Some(a), Some(b)) => (a + b) / small::<T>(2),
            (Some(a), None) => a + Real::abs(a) + Real::abs(i0 / slope),
            (None, Some(b)) => b - Real::abs(b) - Real::abs(i0 / slope),
            (None, None) => phi,
        };
    }
    phi
}

/// One RK4 step of x and S over `h` under `u`: stuck at a stop (or `held`)
/// only φ moves; an armature that passes a stop stays there.
fn step<T: Scalar, M: Predictor<T, P>, const P: usize>(
    model: &M,
    settings: &Settings<T, P>,
    theta: &[T; P],
    flow: &Flow<T, P>,
    u: T,
    h: T,
    held: bool,
) -> Flow<T, P> {
    let stuck = held || resting(model, settings, theta, flow, u);
    let rate = |f: &Flow<T, P>| rates(model, settings, theta, f, u, stuck);
    let two = small::<T>(2);
    let k1 = rate(flow);
    let k2 = rate(&advance(flow, &k1, h / two));
    let k3 = rate(&advance(flow, &k2, h / two));
    let k4 = rate(&advance(flow, &k3, h));
    let sixth = h / small::<T>(6);
    let mut next = *flow;
    combine(&mut next, [&k1, &k2, &k3, &k4], sixth);
    contact(&mut next, settings);
    next
}

/// At a stop with the free acceleration pointing into it.
fn resting<T: Scalar, M: Predictor<T, P>, const P: usize>(
    model: &M,
    settings: &Settings<T, P>,
    theta: &[T; P],
    flow: &Flow<T, P>,
    u: T,
) -> bool {
    let [z, v, _] = flow.x;
    if v != T::ZERO {
        return false;
    }
    let [_, a, _] = model.derivative(theta, &flow.x, u).dx;
    (z <= settings.z_min && a <= T::ZERO) || (z >= settings.z_max && a >= T::ZERO)
}

/// (ẋ, Ṡ) at `f`; stuck: ż = v̇ = 0 and their rows of Ṡ 0. A stage past
/// a stop sees the field at the stop (the model is defined on [z_min, z_max]).
fn rates<T: Scalar, M: Predictor<T, P>, const P: usize>(
    model: &M,
    settings: &Settings<T, P>,
    theta: &[T; P],
    f: &Flow<T, P>,
    u: T,
    stuck: bool,
) -> Flow<T, P> {
    let [z, v, phi] = f.x;
    let z = saturate_to(z, settings.z_min, settings.z_max);
    let d = model.derivative(theta, &[z, v, phi], u);
    let mut out = Flow {
        x: d.dx,
        s: [[T::ZERO; P]; 3],
    };
    for ((s_dot, fx_row), ft_row) in out.s.iter_mut().zip(&d.f_x).zip(&d.f_theta) {
        for (k, value) in s_dot.iter_mut().enumerate() {
            let mut sum = ft_row.get(k).copied().unwrap_or(T::ZERO);
            for (a, s_row) in fx_row.iter().zip(&f.s) {
                sum = sum + *a * s_row.get(k).copied().unwrap_or(T::ZERO);
            }
            *value = sum;
        }
    }
    if stuck {
        for (x, s) in out.x.iter_mut().zip(out.s.iter_mut()).take(2) {
            *x = T::ZERO;
            *s = [T::ZERO; P];
        }
    }
    out
}

/// f + c·k.
fn advance<T: Scalar, const P: usize>(f: &Flow<T, P>, k: &Flow<T, P>, c: T) -> Flow<T, P> {
    let mut out = *f;
    for (x, dx) in out.x.iter_mut().zip(&k.x) {
        *x = *x + c * *dx;
    }
    for (row, k_row) in out.s.iter_mut().zip(&k.s) {
        for (s, ds) in row.iter_mut().zip(k_row) {
            *s = *s + c * *ds;
        }
    }
    out
}

/// next += c·(k1 + 2·k2 + 2·k3 + k4).
fn combine<T: Scalar, const P: usize>(next: &mut Flow<T, P>, k: [&Flow<T, P>; 4], c: T) {
    let [k1, k2, k3, k4] = k;
    let two = small::<T>(2);
    let blend = |a: T, b: T, d: T, e: T| a + two * b + two * d + e;
    for (((x, a), (b, d)), e) in next
        .x
        .iter_mut()
        .zip(&k1.x)
        .zip(k2.x.iter().zip(&k3.x))
        .zip(&k4.x)
    {
        *x = *x + c * blend(*a, *b, *d, *e);
    }
    for (((row, a), (b, d)), e) in next
        .s
        .iter_mut()
        .zip(&k1.s)
        .zip(k2.s.iter().zip(&k3.s))
        .zip(&k4.s)
    {
        for (((s, a), (b, d)), e) in row.iter_mut().zip(a).zip(b.iter().zip(d)).zip(e) {
            *s = *s + c * blend(*a, *b, *d, *e);
        }
    }
}

/// An armature past a stop stays at it: z = the stop, v = 0, their
/// sensitivities 0 (an inelastic contact).
fn contact<T: Scalar, const P: usize>(f: &mut Flow<T, P>, settings: &Settings<T, P>) {
    let [z, ..] = f.x;
    let stop = if z <= settings.z_min {
        settings.z_min
    } else if z >= settings.z_max {
        settings.z_max
    } else {
        return;
    };
    let [z, v, _] = &mut f.x;
    *z = stop;
    *v = T::ZERO;
    for row in f.s.iter_mut().take(2) {
        *row = [T::ZERO; P];
    }
}
