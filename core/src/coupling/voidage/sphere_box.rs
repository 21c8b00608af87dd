//! Exact volume of a sphere inside an axis-aligned box (PHYSICS.md 3: Baddeley's closed form for
//! the corner volume, reflection rules for negative offsets, inclusion–exclusion over 8 corners).

use std::f64::consts::PI;

/// W(x, y) of PHYSICS.md 3 (normalised radius 1).
fn w(x: f64, y: f64) -> f64 {
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    (x / 2.0 - x * x * x / 6.0) * y.atan2(z) + (y / 2.0 - y * y * y / 6.0) * x.atan2(z)
        - ((x * y).atan2(z) - x * y * z) / 3.0
}

/// U(p, q, s) = volume of {|r| < 1, x > p, y > q, z > s} for p, q, s ≥ 0 (PHYSICS.md 3).
fn u(p: f64, q: f64, s: f64) -> f64 {
    if p * p + q * q + s * s >= 1.0 {
        return 0.0;
    }
    PI / 12.0 * (2.0 - 3.0 * (p + q + s) + p * p * p + q * q * q + s * s * s) + w(p, q) + w(q, s) + w(p, s) - p * q * s
}

/// Unit-sphere volume beyond one plane x > p, any sign of p.
pub fn cap1(p: f64) -> f64 {
    let p = p.clamp(-1.0, 1.0);
    if p >= 0.0 {
        // V₁ = (π/3)(1−p)²(2+p) = 4U(p,0,0)
        PI / 3.0 * (1.0 - p) * (1.0 - p) * (2.0 + p)
    } else {
        4.0 * PI / 3.0 - cap1(-p)
    }
}

/// Unit-sphere volume in the wedge x > p, y > q, any signs.
pub fn wedge2(p: f64, q: f64) -> f64 {
    let (p, q) = (p.clamp(-1.0, 1.0), q.clamp(-1.0, 1.0));
    if p < 0.0 {
        cap1(q) - wedge2(-p, q)
    } else if q < 0.0 {
        cap1(p) - wedge2(p, -q)
    } else {
        2.0 * u(p, q, 0.0)
    }
}

/// Unit-sphere volume in the corner x > p, y > q, z > s, any signs.
pub fn corner3(p: f64, q: f64, s: f64) -> f64 {
    let (p, q, s) = (p.clamp(-1.0, 1.0), q.clamp(-1.0, 1.0), s.clamp(-1.0, 1.0));
    if p < 0.0 {
        wedge2(q, s) - corner3(-p, q, s)
    } else if q < 0.0 {
        wedge2(p, s) - corner3(p, -q, s)
    } else if s < 0.0 {
        wedge2(p, q) - corner3(p, q, -s)
    } else {
        u(p, q, s)
    }
}

/// Volume of the sphere of radius `r` centred at `c` inside the box [lo, hi] (bounds may be ±∞).
/// Inclusion–exclusion over the 8 corners: V = Σ (−1)^(i+j+k) C(x_i, y_j, z_k).
pub fn sphere_box_volume(c: [f64; 3], r: f64, lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let n = |v: f64, k: usize| ((v - c[k]) / r).clamp(-1.0, 1.0);
    let xs = [n(lo[0], 0), n(hi[0], 0)];
    let ys = [n(lo[1], 1), n(hi[1], 1)];
    let zs = [n(lo[2], 2), n(hi[2], 2)];
    if xs[0] >= xs[1] || ys[0] >= ys[1] || zs[0] >= zs[1] {
        return 0.0;
    }
    let mut v = 0.0;
    for (i, &x) in xs.iter().enumerate() {
        for (j, &y) in ys.iter().enumerate() {
            for (k, &z) in zs.iter().enumerate() {
                let sign = if (i + j + k) % 2 == 0 { 1.0 } else { -1.0 };
                v += sign * corner3(x, y, z);
            }
        }
    }
    v * r * r * r
}

/// Volume of the sphere between the planes z = lo and z = hi (1D slab), exact.
pub fn sphere_slab_volume(cz: f64, r: f64, lo: f64, hi: f64) -> f64 {
    let (a, b) = (((lo - cz) / r).clamp(-1.0, 1.0), ((hi - cz) / r).clamp(-1.0, 1.0));
    if a >= b {
        return 0.0;
    }
    // π∫(1 − t²)dt over [a, b]
    PI * ((b - b * b * b / 3.0) - (a - a * a * a / 3.0)) * r * r * r
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    const INF: f64 = f64::INFINITY;

    #[test]
    fn identities_of_physics_item_3() {
        // V₃(0,0,0) = π/6, V₂(0,0) = π/3, V₁(0) = 2π/3 (unit radius)
        assert!((corner3(0.0, 0.0, 0.0) - PI / 6.0).abs() < 1e-15);
        assert!((wedge2(0.0, 0.0) - PI / 3.0).abs() < 1e-15);
        assert!((cap1(0.0) - 2.0 * PI / 3.0).abs() < 1e-15);
        // the general U reduces to the cap and wedge forms
        assert!((4.0 * u(0.3, 0.0, 0.0) - cap1(0.3)).abs() < 1e-14);
        assert!((corner3(0.2, 0.3, -1.0) - wedge2(0.2, 0.3)).abs() < 1e-14);
    }

    #[test]
    fn vertex_gives_one_eighth_in_each_box() {
        let r = 0.6e-3;
        let vp = 4.0 / 3.0 * PI * r * r * r;
        let c: [f64; 3] = [1e-3, 2e-3, 3e-3];
        for ox in [-1.0, 1.0] {
            for oy in [-1.0, 1.0] {
                for oz in [-1.0, 1.0] {
                    let lo = [c[0].min(c[0] + ox), c[1].min(c[1] + oy), c[2].min(c[2] + oz)];
                    let hi = [c[0].max(c[0] + ox), c[1].max(c[1] + oy), c[2].max(c[2] + oz)];
                    let v = sphere_box_volume(c, r, lo, hi);
                    assert!((v / vp - 0.125).abs() < 1e-14, "{}", v / vp);
                }
            }
        }
    }

    #[test]
    fn partition_of_unity_over_random_centres() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (r, h) = (0.6, 1.0);
        let vp = 4.0 / 3.0 * PI * r * r * r;
        for _ in 0..200 {
            let c = [rng.gen_range(0.0..h), rng.gen_range(0.0..h), rng.gen_range(0.0..h)];
            let mut sum = 0.0;
            for i in -1..=2 {
                for j in -1..=2 {
                    for k in -1..=2 {
                        let lo = [i as f64 * h, j as f64 * h, k as f64 * h];
                        sum += sphere_box_volume(c, r, lo, [lo[0] + h, lo[1] + h, lo[2] + h]);
                    }
                }
            }
            assert!((sum / vp - 1.0).abs() < 1e-13, "{}", sum / vp - 1.0);
        }
    }

    #[test]
    fn agrees_with_monte_carlo() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let c = [0.1, -0.25, 0.4];
        let (lo, hi) = ([-0.2, -0.5, 0.0], [0.5, 0.3, INF]);
        let exact = sphere_box_volume(c, 1.0, lo, hi) / (4.0 / 3.0 * PI);
        let (mut hit, mut n) = (0usize, 0usize);
        while n < 400_000 {
            let p = [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0f64)];
            if p[0] * p[0] + p[1] * p[1] + p[2] * p[2] >= 1.0 {
                continue;
            }
            n += 1;
            let q = [p[0] + c[0], p[1] + c[1], p[2] + c[2]];
            if (0..3).all(|k| q[k] > lo[k] && q[k] < hi[k]) {
                hit += 1;
            }
        }
        let mc = hit as f64 / n as f64;
        // binomial standard error ≈ 8e-4; allow 4σ
        assert!((mc - exact).abs() < 3.2e-3, "mc {mc} exact {exact}");
    }

    #[test]
    fn slab_matches_box_with_infinite_sides() {
        let c = [0.0, 0.0, 0.3];
        let a = sphere_slab_volume(c[2], 0.7, 0.1, 0.6);
        let b = sphere_box_volume(c, 0.7, [-INF, -INF, 0.1], [INF, INF, 0.6]);
        assert!((a - b).abs() < 1e-15);
    }
}
