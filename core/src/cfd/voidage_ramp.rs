//! The gas's voidage between couplings when it is interpolated in time (case
//! `coupling.gas_voidage = "interpolated"`). Each cell's gas mass ρεV is held when ε changes
//! (solver.rs `set_voidage`), so a voidage set anew at a coupling shows as a pressure step
//! Δp = −p Δε/ε in every cell at once, a step that grows with the interval. Here the gas's ε goes
//! linearly from the previous coupling's field to the new one over the next interval T:
//! ε(t) = ε_{n−1} + (ε_n − ε_{n−1})·min((t − t_n)/T, 1) for t ≥ t_n, the particles' field delayed
//! by one interval and continuous in time, so the gas sees ∂ε/∂t instead of steps.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VoidageRamp {
    from: Vec<f64>,
    to: Vec<f64>,
    /// Time of the coupling that set `to` (t_n) and the interval T.
    start: f64,
    span: f64,
}

impl VoidageRamp {
    /// The ramp from the previous ramp's end (or, for the first, `current`) to `eps`, from
    /// `start` over `span` seconds; it takes over the previous ramp's storage.
    pub fn next(previous: Option<VoidageRamp>, current: &[f64], eps: &[f64], start: f64, span: f64) -> VoidageRamp {
        assert!(span > 0.0, "a ramp needs a positive interval");
        assert_eq!(current.len(), eps.len(), "one voidage per cell");
        let (from, mut to) = match previous {
            Some(p) if p.to.len() == eps.len() => (p.to, p.from),
            _ => (current.to_vec(), Vec::new()),
        };
        to.clear();
        to.extend_from_slice(eps);
        VoidageRamp { from, to, start, span }
    }

    /// The particles' field the ramp ends at (of the last coupling).
    pub fn target(&self) -> &[f64] {
        &self.to
    }

    /// ε at time `t` into `out`.
    pub fn at(&self, t: f64, out: &mut [f64]) {
        let f = ((t - self.start) / self.span).clamp(0.0, 1.0);
        for ((e, a), b) in out.iter_mut().zip(&self.from).zip(&self.to) {
            *e = a + (b - a) * f;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_starts_at_the_previous_field_and_ends_at_the_new_one_one_interval_later() {
        let first = VoidageRamp::next(None, &[1.0, 0.5], &[0.8, 0.4], 0.0, 1e-5);
        let mut e = [0.0; 2];
        first.at(-1.0, &mut e);
        assert_eq!(e, [1.0, 0.5]);
        first.at(0.5e-5, &mut e);
        assert!((e[0] - 0.9).abs() < 1e-15 && (e[1] - 0.45).abs() < 1e-15, "{e:?}");
        first.at(2e-5, &mut e);
        assert_eq!(e, [0.8, 0.4]);
        // The next ramp starts where this one ends, whatever the gas's field is now.
        let second = VoidageRamp::next(Some(first), &[0.9, 0.45], &[0.6, 0.4], 1e-5, 1e-5);
        second.at(1e-5, &mut e);
        assert_eq!(e, [0.8, 0.4]);
        second.at(1.5e-5, &mut e);
        assert!((e[0] - 0.7).abs() < 1e-15 && e[1] == 0.4, "{e:?}");
    }
}
