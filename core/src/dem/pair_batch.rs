//! The particle-particle contact law of `contact::contact_force`, evaluated for a batch of
//! touching pairs at a time in short loops over independent lanes (PHYSICS.md 2.2-2.3). The
//! scalar kernel is one long chain of sqrt and division latencies; split into lane loops the
//! CPU overlaps many pairs (and the compiler can use SIMD), which is where the speed comes from.

use super::contact::{ContactLaw, V3};

/// Pairs per batch.
pub const CAP: usize = 64;

/// Touching pairs waiting for evaluation (structure of arrays over lanes).
pub struct Batch {
    pub m: usize,
    /// List slot (for the history), first and second particle.
    pub k: [u32; CAP],
    pub i: [u32; CAP],
    pub j: [u32; CAP],
    /// x_j − x_i and its squared length.
    pub dx: [[f64; CAP]; 3],
    pub r2: [f64; CAP],
    // Results and intermediates.
    n: [[f64; CAP]; 3],
    delta: [f64; CAP],
    sd: [f64; CAP],
    qd: [f64; CAP],
    vn: [f64; CAP],
    vrel: [[f64; CAP]; 3],
    fnorm: [f64; CAP],
    /// Force on i, and n × F_t.
    pub f: [[f64; CAP]; 3],
    pub c: [[f64; CAP]; 3],
}

impl Batch {
    pub fn new() -> Box<Batch> {
        let z = [0.0; CAP];
        Box::new(Batch {
            m: 0,
            k: [0; CAP],
            i: [0; CAP],
            j: [0; CAP],
            dx: [z; 3],
            r2: z,
            n: [z; 3],
            delta: z,
            sd: z,
            qd: z,
            vn: z,
            vrel: [z; 3],
            fnorm: z,
            f: [z; 3],
            c: [z; 3],
        })
    }

    /// Fill lane `l` (the caller counts lanes and sets `m` before `evaluate`).
    #[inline(always)]
    pub fn set(&mut self, l: usize, k: usize, i: usize, j: usize, dx: V3, r2: f64) {
        self.k[l] = k as u32;
        self.i[l] = i as u32;
        self.j[l] = j as u32;
        self.dx[0][l] = dx[0];
        self.dx[1][l] = dx[1];
        self.dx[2][l] = dx[2];
        self.r2[l] = r2;
    }

    /// Evaluate every lane: fills `f` (and `c`, and the history `shear[k − base]` when FR).
    /// Returns (max overlap, max |F_t|² − (μF_n)²).
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate<const FR: bool>(
        &mut self, law: &ContactLaw, r: f64, h: f64, v: &[V3], w: &[V3], shear: &mut [V3], base: usize,
    ) -> (f64, f64) {
        let m = self.m;
        let d = 2.0 * r;
        let mut max_delta: f64 = 0.0;
        for l in 0..m {
            let dist = self.r2[l].sqrt();
            let inv = 1.0 / dist;
            self.n[0][l] = self.dx[0][l] * inv;
            self.n[1][l] = self.dx[1][l] * inv;
            self.n[2][l] = self.dx[2][l] * inv;
            let delta = d - dist;
            self.delta[l] = delta;
            let sd = delta.sqrt();
            self.sd[l] = sd;
            self.qd[l] = sd.sqrt(); // δ^{1/4} without powf
        }
        for l in 0..m {
            let (i, j) = (self.i[l] as usize, self.j[l] as usize);
            for q in 0..3 {
                self.vrel[q][l] = v[i][q] - v[j][q];
            }
        }
        for l in 0..m {
            let vn = self.vrel[0][l] * self.n[0][l] + self.vrel[1][l] * self.n[1][l] + self.vrel[2][l] * self.n[2][l];
            self.vn[l] = vn;
            let (delta, sd, qd) = (self.delta[l], self.sd[l], self.qd[l]);
            // F_n = K_n δ^{3/2} + α_n √(m* K_n) δ^{1/4} dδ/dt (PHYSICS.md 2.2)
            let fnorm = law.kn * delta * sd + law.dn * qd * vn;
            let fnorm = if law.no_tension { fnorm.max(0.0) } else { fnorm };
            self.fnorm[l] = fnorm;
            for q in 0..3 {
                self.f[q][l] = -fnorm * self.n[q][l];
            }
            max_delta = max_delta.max(delta);
        }
        if !FR {
            return (max_delta, f64::NEG_INFINITY);
        }
        let mut max_excess = f64::NEG_INFINITY;
        for l in 0..m {
            let (i, j) = (self.i[l] as usize, self.j[l] as usize);
            let n = [self.n[0][l], self.n[1][l], self.n[2][l]];
            let ws = [r * (w[i][0] + w[j][0]), r * (w[i][1] + w[j][1]), r * (w[i][2] + w[j][2])];
            let vn = self.vn[l];
            // Slip velocity v_ij − (v_ij·n)n + (R_i ω_i + R_j ω_j) × n (PHYSICS.md 2.3)
            let wn = [ws[1] * n[2] - ws[2] * n[1], ws[2] * n[0] - ws[0] * n[2], ws[0] * n[1] - ws[1] * n[0]];
            let vt = [
                self.vrel[0][l] - vn * n[0] + wn[0],
                self.vrel[1][l] - vn * n[1] + wn[1],
                self.vrel[2][l] - vn * n[2] + wn[2],
            ];
            let slot = &mut shear[self.k[l] as usize - base];
            let mut s = [slot[0] + vt[0] * h, slot[1] + vt[1] * h, slot[2] + vt[2] * h];
            let sn = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];
            s = [s[0] - sn * n[0], s[1] - sn * n[1], s[2] - sn * n[2]];
            let kt = law.kt * self.sd[l];
            let et = law.dt * self.qd[l];
            let mut ft = [-kt * s[0] - et * vt[0], -kt * s[1] - et * vt[1], -kt * s[2] - et * vt[2]];
            let ft2 = ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2];
            let lim = law.mu * self.fnorm[l].abs();
            if ft2 > lim * lim {
                // Coulomb: |F_t| = μ F_n, damping dropped, ξ reset to match the spring alone.
                let scale = if ft2 > 0.0 { lim / ft2.sqrt() } else { 0.0 };
                ft = [ft[0] * scale, ft[1] * scale, ft[2] * scale];
                s = [-ft[0] / kt, -ft[1] / kt, -ft[2] / kt];
            }
            *slot = s;
            for q in 0..3 {
                self.f[q][l] += ft[q];
            }
            self.c[0][l] = n[1] * ft[2] - n[2] * ft[1];
            self.c[1][l] = n[2] * ft[0] - n[0] * ft[2];
            self.c[2][l] = n[0] * ft[1] - n[1] * ft[0];
            max_excess = max_excess.max(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2] - lim * lim);
        }
        (max_delta, max_excess)
    }
}
