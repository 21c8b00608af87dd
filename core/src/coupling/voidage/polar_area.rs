//! Exact plane areas on the polar cells of the cylindrical grid: a rectangle (a box of the square
//! grid) and a disk (a horizontal slice of a sphere) intersected with the annular sector
//! {r0 ≤ r ≤ r1, θ0 ≤ θ ≤ θ1}. Both use sector(s) = disk(O, s) ∩ wedge and
//! area(annular sector ∩ X) = area(sector(r1) ∩ X) − area(sector(r0) ∩ X).

use std::f64::consts::PI;

type P = [f64; 2];

#[inline]
fn cross(a: P, b: P) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Keep the part of a convex polygon where cross(e, p) ≥ 0 (left of the line through O along e).
fn clip_left_of(poly: &[P], e: P) -> Vec<P> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (fa, fb) = (cross(e, a), cross(e, b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa > 0.0 && fb < 0.0) || (fa < 0.0 && fb > 0.0) {
            let t = fa / (fa - fb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    out
}

/// Signed area of triangle (O, a, b) ∩ disk(O, s): split the edge where it crosses the circle;
/// pieces inside add a triangle, pieces outside a circular sector.
fn triangle_disk_area(a: P, b: P, s: f64) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (qa, qb, qc) = (d[0] * d[0] + d[1] * d[1], a[0] * d[0] + a[1] * d[1], a[0] * a[0] + a[1] * a[1] - s * s);
    let mut ts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    let disc = qb * qb - qa * qc;
    if qa > 0.0 && disc > 0.0 {
        let sq = disc.sqrt();
        for t in [(-qb - sq) / qa, (-qb + sq) / qa] {
            if t > 0.0 && t < 1.0 {
                ts[n] = t;
                n += 1;
            }
        }
    }
    ts[n] = 1.0;
    let at = |t: f64| [a[0] + t * d[0], a[1] + t * d[1]];
    let mut area = 0.0;
    for k in 0..n {
        let (p0, p1) = (at(ts[k]), at(ts[k + 1]));
        let m = at(0.5 * (ts[k] + ts[k + 1]));
        if m[0] * m[0] + m[1] * m[1] <= s * s {
            area += 0.5 * cross(p0, p1);
        } else {
            area += 0.5 * s * s * cross(p0, p1).atan2(p0[0] * p1[0] + p0[1] * p1[1]);
        }
    }
    area
}

/// Area of a convex polygon (counter-clockwise) ∩ disk(O, s).
fn polygon_disk_area(poly: &[P], s: f64) -> f64 {
    if s <= 0.0 || poly.len() < 3 {
        return 0.0;
    }
    (0..poly.len()).map(|k| triangle_disk_area(poly[k], poly[(k + 1) % poly.len()], s)).sum()
}

/// Area of the rectangle [x0,x1]×[y0,y1] inside the polar cell r0 ≤ r ≤ r1, θ0 ≤ θ ≤ θ1 (exact).
#[allow(clippy::too_many_arguments)]
pub fn rect_cell_area(x0: f64, x1: f64, y0: f64, y1: f64, r0: f64, r1: f64, th0: f64, th1: f64) -> f64 {
    if th1 - th0 > PI {
        // a wedge wider than π is not convex: split it
        let mid = 0.5 * (th0 + th1);
        return rect_cell_area(x0, x1, y0, y1, r0, r1, th0, mid) + rect_cell_area(x0, x1, y0, y1, r0, r1, mid, th1);
    }
    let rect = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    let e0 = [th0.cos(), th0.sin()];
    let e1 = [th1.cos(), th1.sin()];
    let p = clip_left_of(&rect, e0);
    let p = clip_left_of(&p, [-e1[0], -e1[1]]);
    (polygon_disk_area(&p, r1) - polygon_disk_area(&p, r0)).max(0.0)
}

/// Area of disk(c, ρ) ∩ disk(O, s) ∩ wedge[θ0, θ1] (θ1 − θ0 ≤ π), by Green's theorem:
/// ½∮(x dy − y dx) over the pieces of the two circles that lie inside the other sets; the wedge's
/// rays pass through O and add nothing.
fn disk_sector_area(c: P, rho: f64, s: f64, th0: f64, th1: f64) -> f64 {
    if s <= 0.0 || rho <= 0.0 {
        return 0.0;
    }
    let rc = (c[0] * c[0] + c[1] * c[1]).sqrt();
    if rc >= s + rho {
        return 0.0;
    }
    let e0 = [th0.cos(), th0.sin()];
    let e1 = [th1.cos(), th1.sin()];
    let in_wedge = |p: P| cross(e0, p) >= 0.0 && cross(p, e1) >= 0.0;
    let gamma = c[1].atan2(c[0]);
    let mut area = 0.0;

    // Arcs of the slice circle ∂D: p(φ) = c + ρ(cos φ, sin φ).
    let mut phis = [0.0f64; 6];
    let mut n = 0;
    if rc > 0.0 {
        let k = (s * s - rc * rc - rho * rho) / (2.0 * rho * rc);
        if k.abs() < 1.0 {
            let d = k.acos();
            phis[n] = gamma - d;
            phis[n + 1] = gamma + d;
            n += 2;
        }
    }
    for th in [th0, th1] {
        // the line through O along θ: (−sin θ, cos θ)·p = 0
        let m = -(-th.sin() * c[0] + th.cos() * c[1]) / rho;
        if m.abs() < 1.0 {
            let d = m.acos();
            phis[n] = th + PI / 2.0 - d;
            phis[n + 1] = th + PI / 2.0 + d;
            n += 2;
        }
    }
    let arc_d =
        |a: f64, b: f64| 0.5 * (rho * rho * (b - a) + rho * (c[0] * (b.sin() - a.sin()) - c[1] * (b.cos() - a.cos())));
    let inside_all_d = |phi: f64| {
        let p = [c[0] + rho * phi.cos(), c[1] + rho * phi.sin()];
        p[0] * p[0] + p[1] * p[1] < s * s && in_wedge(p)
    };
    if n == 0 {
        if inside_all_d(0.0) {
            area += PI * rho * rho;
        }
    } else {
        let v = &mut phis[..n];
        for x in v.iter_mut() {
            *x = x.rem_euclid(2.0 * PI);
        }
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for k in 0..n {
            let a = v[k];
            let b = if k + 1 < n { v[k + 1] } else { v[0] + 2.0 * PI };
            if b > a && inside_all_d(0.5 * (a + b)) {
                area += arc_d(a, b);
            }
        }
    }

    // Arcs of the circle |p| = s within [θ0, θ1], cut where it crosses ∂D.
    let mut psis = [th0, th1, 0.0, 0.0];
    let mut m = 2;
    if rc > 0.0 {
        let k = (s * s + rc * rc - rho * rho) / (2.0 * s * rc);
        if k.abs() < 1.0 {
            let d = k.acos();
            for psi in [gamma - d, gamma + d] {
                // bring into [θ0, θ0 + 2π)
                let psi = th0 + (psi - th0).rem_euclid(2.0 * PI);
                if psi > th0 && psi < th1 {
                    psis[m] = psi;
                    m += 1;
                }
            }
        }
    }
    let v = &mut psis[..m];
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    for k in 0..m - 1 {
        let (a, b) = (v[k], v[k + 1]);
        let mid = 0.5 * (a + b);
        let p = [s * mid.cos() - c[0], s * mid.sin() - c[1]];
        if b > a && p[0] * p[0] + p[1] * p[1] < rho * rho {
            area += 0.5 * s * s * (b - a);
        }
    }
    area.max(0.0)
}

/// Area of disk(c, ρ) inside the polar cell r0 ≤ r ≤ r1, θ0 ≤ θ ≤ θ1 (exact).
pub fn disk_cell_area(c: P, rho: f64, r0: f64, r1: f64, th0: f64, th1: f64) -> f64 {
    if th1 - th0 > PI {
        let mid = 0.5 * (th0 + th1);
        return disk_cell_area(c, rho, r0, r1, th0, mid) + disk_cell_area(c, rho, r0, r1, mid, th1);
    }
    (disk_sector_area(c, rho, r1, th0, th1) - disk_sector_area(c, rho, r0, th0, th1)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn mc_rect(x0: f64, x1: f64, y0: f64, y1: f64, cell: (f64, f64, f64, f64), n: usize) -> f64 {
        // midpoint lattice sampling
        let mut hit = 0usize;
        for a in 0..n {
            for b in 0..n {
                let x = x0 + (a as f64 + 0.5) / n as f64 * (x1 - x0);
                let y = y0 + (b as f64 + 0.5) / n as f64 * (y1 - y0);
                let r = (x * x + y * y).sqrt();
                let t = y.atan2(x).rem_euclid(2.0 * PI);
                if r >= cell.0 && r < cell.1 && t >= cell.2 && t < cell.3 {
                    hit += 1;
                }
            }
        }
        hit as f64 / (n * n) as f64 * (x1 - x0) * (y1 - y0)
    }

    #[test]
    fn rectangle_area_matches_lattice_sampling() {
        let cells =
            [(0.0, 1.0, 0.0, 2.0 * PI / 3.0), (1.0, 2.0, 0.3, 1.1), (2.0, 3.0, 2.0, 2.5), (0.0, 1.0, 4.0, 2.0 * PI)];
        let rects = [(-0.5, 0.7, -0.2, 0.9), (0.5, 1.9, 0.1, 1.6), (-2.9, -1.0, 1.5, 2.7), (0.1, 0.9, -0.9, 0.2)];
        for cell in cells {
            for r in rects {
                let exact = rect_cell_area(r.0, r.1, r.2, r.3, cell.0, cell.1, cell.2, cell.3);
                let mc = mc_rect(r.0, r.1, r.2, r.3, cell, 1500);
                assert!((exact - mc).abs() < 2e-3 * (r.1 - r.0) * (r.3 - r.2), "{exact} {mc}");
            }
        }
    }

    #[test]
    fn disk_areas_tile_the_disk_and_match_sampling() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        // polar cells: annuli of width 1 with 3(2i+1) cells, out to r = 4
        for _ in 0..60 {
            let c: [f64; 2] = [rng.gen_range(-3.0..3.0), rng.gen_range(-3.0..3.0)];
            let rho = rng.gen_range(0.05..0.9);
            if (c[0] * c[0] + c[1] * c[1]).sqrt() + rho > 4.0 {
                continue;
            }
            let mut total = 0.0;
            for i in 0..4 {
                let n = 3 * (2 * i + 1);
                for j in 0..n {
                    let w = 2.0 * PI / n as f64;
                    let a = disk_cell_area(c, rho, i as f64, i as f64 + 1.0, j as f64 * w, (j + 1) as f64 * w);
                    total += a;
                }
            }
            assert!((total - PI * rho * rho).abs() < 1e-12 * rho * rho, "{} {}", total, PI * rho * rho);
        }
        // one cell against a fine 1D integration of its chord lengths (x-strips of the disk)
        let (c, rho) = ([1.1, 0.35], 0.6);
        let t1 = 2.0 * PI / 9.0;
        let exact = disk_cell_area(c, rho, 1.0, 2.0, 0.0, t1);
        let n = 200_000;
        let dx = 2.0 * rho / n as f64;
        let mut strips = 0.0;
        for k in 0..n {
            let x = c[0] - rho + (k as f64 + 0.5) * dx;
            let h = (rho * rho - (x - c[0]).powi(2)).max(0.0).sqrt();
            let mut lo = (c[1] - h).max(0.0);
            let hi = (c[1] + h).min(x * t1.tan()).min((4.0 - x * x).max(0.0).sqrt());
            if x < 1.0 {
                lo = lo.max((1.0 - x * x).sqrt());
            }
            if hi > lo {
                strips += (hi - lo) * dx;
            }
        }
        assert!((exact - strips).abs() < 1e-8, "{exact} {strips}");
    }
}
