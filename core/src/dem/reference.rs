//! Reference positions (at the last Verlet-list build and near-list refresh) in single
//! precision, with the bound on their rounding that the displacement checks add. A stored
//! coordinate c is within |c|·2⁻²⁴ of the true one, so a distance measured from a stored position
//! is within √3·max|c|·2⁻²⁴ of the true distance (`RefPositions::err`); the checks compare the
//! measured distance plus that bound with their limits, so no refresh or rebuild comes later than
//! with double-precision references. In a checkpoint they are double (the bytes of earlier builds).

use super::contact::{dist2, V3};
use super::forces::{narrow, widen, PastV3};
use rayon::prelude::*;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A stored position: single precision, as the multistep history's values (`narrow`, `widen`).
pub type RefV3 = PastV3;

/// Positions stored in single precision and the bound on their rounding.
#[derive(Clone, Debug, Default)]
pub struct RefPositions {
    pub x: Vec<RefV3>,
    /// √3·max|c|·2⁻²⁴ (metres) over the stored coordinates, with a margin for its own rounding.
    pub err: f64,
}

impl RefPositions {
    /// Store `x` (reusing the storage).
    pub fn store(&mut self, x: &[V3]) {
        self.x.clear();
        self.x.par_extend(x.par_iter().map(|&p| narrow(p)));
        self.err = rounding_bound(&self.x);
    }
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
    /// Whether any particle may be farther than `reach` from its stored position.
    pub fn any_beyond(&self, x: &[V3], reach: f64) -> bool {
        let r = (reach - self.err).max(0.0);
        x.par_iter().zip(&self.x).any(|(&a, &b)| dist2(a, widen(b)) > r * r)
    }
    /// The largest squared distance of a particle from its stored position, as measured.
    pub fn largest_disp2(&self, x: &[V3]) -> f64 {
        x.par_iter().zip(&self.x).map(|(&a, &b)| dist2(a, widen(b))).reduce(|| 0.0, f64::max)
    }
}

/// From the stored values (so that a checkpoint gives back the same bound): a true coordinate
/// is at most |stored|·(1 + 2⁻²³), which the margin covers.
fn rounding_bound(x: &[RefV3]) -> f64 {
    let max = x.par_iter().map(|p| p.iter().fold(0.0f32, |m, c| m.max(c.abs()))).reduce(|| 0.0, f32::max);
    3f64.sqrt() * f64::from(max) * 2f64.powi(-24) * (1.0 + 1e-6)
}

impl Serialize for RefPositions {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.x.iter().map(|&r| widen(r)))
    }
}

impl<'de> Deserialize<'de> for RefPositions {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<RefPositions, D::Error> {
        let wide = Vec::<V3>::deserialize(d)?;
        let mut r = RefPositions::default();
        r.store(&wide);
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance measured from a stored position is within `err` of the true one, for
    /// coordinates up to 2 m and moves from 0 to 10 µm; a checkpoint gives back the same bits.
    #[test]
    fn a_measured_distance_is_within_the_rounding_bound() {
        let mut k = 7u64;
        let mut uniform = || {
            k = k.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (k >> 11) as f64 / (1u64 << 53) as f64
        };
        let x: Vec<V3> = (0..20_000).map(|_| [0.0; 3].map(|_: f64| 4.0 * uniform() - 2.0)).collect();
        let mut r = RefPositions::default();
        r.store(&x);
        assert!(r.err > 0.0 && r.err < 2.1e-7, "bound {:e}", r.err);
        let mut worst = 0.0f64;
        for (i, p) in x.iter().enumerate() {
            let step = 1e-5 * uniform();
            let moved = [p[0] + step, p[1] - step, p[2]];
            let truth = dist2(moved, *p).sqrt();
            let measured = dist2(moved, widen(r.x[i])).sqrt();
            worst = worst.max((measured - truth).abs());
            if worst > r.err {
                break;
            }
        }
        assert!(worst <= r.err && worst > 0.05 * r.err, "worst {worst:e} against the bound {:e}", r.err);
        let bytes = serde_json::to_vec(&r).expect("serialises");
        let back: RefPositions = serde_json::from_slice(&bytes).expect("reads");
        assert!(back.x == r.x && back.err == r.err);
    }
}
