//! The gas's voidage between couplings when it moves in time (case `coupling.gas_voidage`
//! "interpolated" or "extrapolated"). Each cell's gas mass ρεV is held when ε changes (solver.rs
//! `set_voidage`), so a voidage set anew at a coupling shows as a pressure step Δp = −p Δε/ε in
//! every cell at once, a step that grows with the interval T. With s = min((t − t_n)/T, 1), t ≥ t_n:
//! - interpolated: ε(t) = ε_{n−1} + (ε_n − ε_{n−1})·s, from the previous coupling's field to the
//!   new one: continuous, but the particles' field delayed by one interval;
//! - extrapolated: ε(t) = ε_n + (ε_n − ε_{n−1})·s, the new field moved on at the last interval's
//!   rate: no delay, and at the next coupling a step of only the second difference
//!   ε_{n+1} − 2ε_n + ε_{n−1} (the held voidage steps by the first). Kept within [½ε_n, 1].

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VoidageRamp {
    from: Vec<f64>,
    to: Vec<f64>,
    /// Time of the coupling that set `to` (t_n) and the interval T.
    start: f64,
    span: f64,
    /// Extrapolated rather than interpolated: from the case, not the checkpoint (`set_extrapolated`).
    #[serde(skip)]
    extrapolated: bool,
}

impl VoidageRamp {
    /// The ramp from the previous ramp's end (or, for the first, `current`) to `eps`, from
    /// `start` over `span` seconds; it takes over the previous ramp's storage.
    pub fn next(
        previous: Option<VoidageRamp>,
        current: &[f64],
        eps: &[f64],
        start: f64,
        span: f64,
        extrapolated: bool,
    ) -> VoidageRamp {
        assert!(span > 0.0, "a ramp needs a positive interval");
        assert_eq!(current.len(), eps.len(), "one voidage per cell");
        let (from, mut to) = match previous {
            Some(p) if p.to.len() == eps.len() => (p.to, p.from),
            _ => (current.to_vec(), Vec::new()),
        };
        to.clear();
        to.extend_from_slice(eps);
        VoidageRamp { from, to, start, span, extrapolated }
    }

    /// Extrapolate (true) or interpolate between the two fields.
    pub fn set_extrapolated(&mut self, extrapolated: bool) {
        self.extrapolated = extrapolated;
    }

    /// The particles' field the ramp ends at (of the last coupling).
    pub fn target(&self) -> &[f64] {
        &self.to
    }

    /// ε at time `t` into `out`.
    pub fn at(&self, t: f64, out: &mut [f64]) {
        let f = ((t - self.start) / self.span).clamp(0.0, 1.0);
        let pairs = out.iter_mut().zip(&self.from).zip(&self.to);
        if self.extrapolated {
            for ((e, a), b) in pairs {
                *e = (b + (b - a) * f).clamp(0.5 * b, 1.0);
            }
        } else {
            for ((e, a), b) in pairs {
                *e = a + (b - a) * f;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_starts_at_the_previous_field_and_ends_at_the_new_one_one_interval_later() {
        let first = VoidageRamp::next(None, &[1.0, 0.5], &[0.8, 0.4], 0.0, 1e-5, false);
        let mut e = [0.0; 2];
        first.at(-1.0, &mut e);
        assert_eq!(e, [1.0, 0.5]);
        first.at(0.5e-5, &mut e);
        assert!((e[0] - 0.9).abs() < 1e-15 && (e[1] - 0.45).abs() < 1e-15, "{e:?}");
        first.at(2e-5, &mut e);
        assert_eq!(e, [0.8, 0.4]);
        // The next ramp starts where this one ends, whatever the gas's field is now.
        let second = VoidageRamp::next(Some(first), &[0.9, 0.45], &[0.6, 0.4], 1e-5, 1e-5, false);
        second.at(1e-5, &mut e);
        assert_eq!(e, [0.8, 0.4]);
        second.at(1.5e-5, &mut e);
        assert!((e[0] - 0.7).abs() < 1e-15 && e[1] == 0.4, "{e:?}");
    }

    #[test]
    fn the_extrapolated_ramp_moves_the_new_field_on_at_the_last_rate_and_stays_in_range() {
        // Fields of a voidage linear in time, ε = 0.5 − 0.01·t/T: extrapolation is exact.
        let first = VoidageRamp::next(None, &[0.50, 0.98], &[0.49, 0.99], 0.0, 1.0, true);
        let mut e = [0.0; 2];
        first.at(0.5, &mut e);
        assert!((e[0] - 0.485).abs() < 1e-15, "{e:?}");
        // Never past 1 (a cell emptying) and at the interval's end no further than one interval on.
        assert_eq!(e[1], 0.995);
        first.at(3.0, &mut e);
        assert!((e[0] - 0.48).abs() < 1e-15 && e[1] == 1.0, "{e:?}");
        // The next coupling starts from its own field: a step of the second difference only.
        let second = VoidageRamp::next(Some(first), &[0.48, 1.0], &[0.48, 0.995], 1.0, 1.0, true);
        second.at(1.0, &mut e);
        assert_eq!(e, [0.48, 0.995]);
        second.at(1.5, &mut e);
        assert!((e[0] - 0.475).abs() < 1e-15 && (e[1] - 0.9975).abs() < 1e-15, "{e:?}");
    }
}
