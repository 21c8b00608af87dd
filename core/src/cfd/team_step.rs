//! One multistep gas step (solver.rs `step`, AB2/AB3) as one team of threads: a single rayon
//! broadcast in which each thread takes a fixed block of whole layers through the step — save the
//! old state, the four passes of the right-hand side (primitives, gradients, axial faces,
//! residuals), the AB update — with a spin barrier between the passes, and the last thread then
//! updates the outlet layer. As parallel loops, the pool's idle thread had to be woken for every
//! pass (tens of µs on a VM, as much as a pass's work on the shipped grid). Every layer is computed
//! by the same functions in the same order as on the serial path, so the bits do not depend on the
//! thread count or on which path ran.

use super::ab3::combine;
use super::boundary::{outlet_layer, OutletGeometry};
use super::forward_backward::{add_pressure_force, axial_mass_faces, mass_layer, without_pressure_force};
use super::geometry::FaceGeometry;
use super::implicit_drag::{self, ImplicitDrag};
use super::inlet_jet::InletJet;
use super::params::{GasParams, Outlet};
use super::rhs::{PrimView, Primitives, RhsInput};
use super::rhs_layers::{axial_layer, gradients_layer, primitives_layer, residual_layer};
use crate::team::{Raw, SpinBarrier};

/// Everything one step reads besides the state.
pub(super) struct StepInput<'a> {
    pub geo: &'a FaceGeometry,
    pub params: &'a GasParams,
    pub outlet: OutletGeometry,
    pub nz: usize,
    pub eps: &'a [f64],
    pub force: &'a [[f64; 3]],
    /// The drag on the gas stepped implicitly after the momentum's other terms (implicit_drag.rs).
    pub drag: Option<ImplicitDrag<'a>>,
    pub time: f64,
    pub jet: Option<InletJet>,
    pub dt: f64,
    /// The AB weights times the step: of the new right-hand side, then of `past` (one or two).
    /// With `forward_backward` they step the momentum's terms other than the pressure force.
    pub weights: &'a [f64],
    /// The forward–backward step (forward_backward.rs) instead of AB on the whole right-hand side.
    pub forward_backward: bool,
    pub past: &'a [&'a [[f64; 4]]],
    /// Past face right-hand sides, one per past cell right-hand side (none for forward–backward).
    pub past_face: &'a [&'a [f64]],
}

/// What one step writes: the state (cells, then face corrections), the old state, the new
/// right-hand sides and the work arrays of the passes.
pub(super) struct StepState<'a> {
    pub q: &'a mut [[f64; 4]],
    pub face: &'a mut [f64],
    pub q_old: &'a mut [[f64; 4]],
    pub face_old: &'a mut [f64],
    pub rhs: &'a mut [[f64; 4]],
    pub rhs_face: &'a mut [f64],
    pub prim: &'a mut Primitives,
    pub axial: &'a mut [[f64; 7]],
    /// d(ρε)/dt of the forward–backward step's mass pass (one row per cell).
    pub mass_rate: &'a mut [f64],
}

/// Tests only: team steps run (to check that a test took this path).
#[cfg(test)]
pub(super) static TEAM_STEPS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Whether a step of this many layers can run as a team of `threads`: the last thread must hold
/// both layers of the outlet update.
pub(super) fn fits(nz: usize, threads: usize) -> bool {
    threads > 1 && nz >= 2 * threads
}

/// The step on the current pool's threads as one team. The caller holds the pool's `TeamLock`
/// (a team spins while it waits, so two teams on one pool could wait for each other).
pub(super) fn team_step(inp: &StepInput, s: StepState) {
    let (per, nz, nf) = (inp.outlet.per, inp.nz, inp.geo.faces.len());
    let n = per * nz;
    let StepState { q, face, q_old, face_old, rhs, rhs_face, prim, axial, mass_rate } = s;
    let team = rayon::current_num_threads();
    assert!(fits(nz, team), "{nz} layers for a team of {team}");
    let pr = [&mut prim.ux, &mut prim.uy, &mut prim.uz, &mut prim.p, &mut prim.beta, &mut prim.beta_over_eps2];
    let gr = [&mut prim.div, &mut prim.gx, &mut prim.gy, &mut prim.gz];
    let rows = [q.len(), q_old.len(), rhs.len(), axial.len(), inp.eps.len(), inp.force.len()];
    assert!(rows.iter().all(|&r| r == n) && pr.iter().chain(&gr).all(|f| f.len() == n), "one row per cell");
    let nface = n + nz * nf;
    assert!([face.len(), face_old.len(), rhs_face.len()].iter().all(|&r| r == nface), "one row per face");
    let face_past = if inp.forward_backward { 0 } else { inp.past.len() };
    assert!(inp.weights.len() == inp.past.len() + 1 && inp.past_face.len() == face_past);
    assert!(inp.past.iter().all(|f| f.len() == n) && inp.past_face.iter().all(|f| f.len() == nface));
    let [ux, uy, uz, p, beta, bz] = pr.map(|f| Raw::new(f));
    let [div, gx, gy, gz] = gr.map(|f| Raw::new(f));
    // The axial faces of the top layer are never written by the passes.
    rhs_face[(nz - 1) * per..n].fill(0.0);
    let (q, face, q_old, face_old) = (Raw::new(q), Raw::new(face), Raw::new(q_old), Raw::new(face_old));
    let (rhs, rhs_face, axial) = (Raw::new(rhs), Raw::new(rhs_face), Raw::new(axial));
    let mass_rate = Raw::new(mass_rate);
    let barrier = SpinBarrier::new(team);
    #[cfg(test)]
    TEAM_STEPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    rayon::broadcast(|ctx| {
        let (t, nt) = (ctx.index(), ctx.num_threads());
        assert!(nt == team, "broadcast on the pool that was counted");
        let (k0, k1) = (t * nz / nt, (t + 1) * nz / nt);
        let (c0, c1) = (k0 * per, k1 * per);
        // This thread's face rows: the axial faces above its cells, its layers' horizontal faces.
        let (f0, f1) = (n + k0 * nf, n + k1 * nf);
        let layer = |k: usize| (k - k0) * per..(k - k0 + 1) * per;
        let work = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            // SAFETY (every phase): a thread writes only its own rows (cells c0..c1, faces
            // c0..c1 and f0..f1), and reads other threads' rows only of arrays that no thread
            // writes in that phase; the barriers order each phase's writes before the next
            // phase's reads, and no reference outlives its phase.
            {
                // Save the old state and fill the primitives of the own layers.
                let (qs, qo) = unsafe { (q.view(c0, c1), q_old.part(c0, c1)) };
                qo.copy_from_slice(qs);
                let (fs, fo) = unsafe { (face.view(c0, c1), face_old.part(c0, c1)) };
                fo.copy_from_slice(fs);
                let (fs, fo) = unsafe { (face.view(f0, f1), face_old.part(f0, f1)) };
                fo.copy_from_slice(fs);
                let [wx, wy, wz, wp, wb, wbz] = unsafe { [ux, uy, uz, p, beta, bz].map(|f| f.part(c0, c1)) };
                let rhs_in = unsafe { rhs_input(inp, face.view(0, nface)) };
                let qv = unsafe { q.view(0, n) };
                for k in k0..k1 {
                    let r = layer(k);
                    let (a, b, c, d) = (&mut wx[r.clone()], &mut wy[r.clone()], &mut wz[r.clone()], &mut wp[r.clone()]);
                    primitives_layer(&rhs_in, qv, k, a, b, c, d, &mut wb[r.clone()], &mut wbz[r]);
                }
            }
            if !barrier.wait() {
                return;
            }
            {
                let v = unsafe {
                    PrimView {
                        ux: ux.view(0, n),
                        uy: uy.view(0, n),
                        uz: uz.view(0, n),
                        p: p.view(0, n),
                        beta: beta.view(0, n),
                        beta_over_eps2: bz.view(0, n),
                        div: &[],
                        gx: &[],
                        gy: &[],
                        gz: &[],
                    }
                };
                let rhs_in = unsafe { rhs_input(inp, face.view(0, nface)) };
                let [wd, wx, wy, wz] = unsafe { [div, gx, gy, gz].map(|f| f.part(c0, c1)) };
                for k in k0..k1 {
                    let r = layer(k);
                    let (a, b, c) = (&mut wd[r.clone()], &mut wx[r.clone()], &mut wy[r.clone()]);
                    gradients_layer(&rhs_in, &v, k, a, b, c, &mut wz[r]);
                }
            }
            if !barrier.wait() {
                return;
            }
            {
                let v = unsafe { full_view([ux, uy, uz, p, beta, bz, div, gx, gy, gz], n) };
                let (rhs_in, qv) = unsafe { (rhs_input(inp, face.view(0, nface)), q.view(0, n)) };
                // The axial faces above the own layers (none above the top layer).
                let ka = k1.min(nz - 1);
                if k0 < ka {
                    let (wa, wf) = unsafe { (axial.part(c0, ka * per), rhs_face.part(c0, ka * per)) };
                    for k in k0..ka {
                        axial_layer(&rhs_in, qv, &v, k, &mut wa[layer(k)], &mut wf[layer(k)]);
                    }
                }
            }
            if !barrier.wait() {
                return;
            }
            {
                let v = unsafe { full_view([ux, uy, uz, p, beta, bz, div, gx, gy, gz], n) };
                let (rhs_in, qv) = unsafe { (rhs_input(inp, face.view(0, nface)), q.view(0, n)) };
                let ax = unsafe { axial.view(0, n) };
                let (wo, wf) = unsafe { (rhs.part(c0, c1), rhs_face.part(f0, f1)) };
                for k in k0..k1 {
                    let fr = (k - k0) * nf..(k - k0 + 1) * nf;
                    residual_layer(&rhs_in, qv, &v, ax, k, &mut wo[layer(k)], &mut wf[fr]);
                }
            }
            if !barrier.wait() {
                return;
            }
            if inp.forward_backward {
                // SAFETY: as above; the mass passes read the momentum and F of other threads' rows
                // only after the barrier that follows their update.
                let rows = Rows { k: (k0, k1), faces: (f0, f1) };
                let prim = [ux, uy, uz, p, beta, bz, div, gx, gy, gz];
                let arrays = FbArrays { q, q_old, rhs, mass_rate, face, face_old, rhs_face, axial, prim };
                if !unsafe { forward_backward_rows(inp, &arrays, &barrier, rows) } {
                    return;
                }
            } else {
                // The AB update of the own rows: y = y_old + Σ w_i f_i.
                let w = inp.weights;
                unsafe {
                    multistep_cells(inp, [q, q_old, rhs], c0, c1);
                    own_implicit_drag(inp, q.part(c0, c1), c0, c1);
                    for (lo, hi) in [(c0, c1), (f0, f1)] {
                        let (y, y0, f) = (face.part(lo, hi), face_old.view(lo, hi), rhs_face.view(lo, hi));
                        let mut fs: [&[f64]; 3] = [f, &[], &[]];
                        for (i, h) in inp.past_face.iter().enumerate() {
                            fs[i + 1] = &h[lo..hi];
                        }
                        combine(y, y0, &fs[..w.len()], w);
                    }
                }
            }
            if t + 1 == nt && inp.params.outlet == Outlet::Characteristic {
                // The last thread holds the two top layers (`fits`).
                let lo = (nz - 2) * per;
                let (e, qo, qn) = unsafe { (&inp.eps[lo..], q_old.view(lo, n), q.part(lo, n)) };
                outlet_layer(inp.params, inp.outlet, e, qo, qn, inp.dt);
            }
        }));
        if let Err(e) = work {
            barrier.fail();
            std::panic::resume_unwind(e);
        }
    });
}

fn rhs_input<'a>(inp: &StepInput<'a>, face_flux: &'a [f64]) -> RhsInput<'a> {
    RhsInput {
        geo: inp.geo,
        params: inp.params,
        per: inp.outlet.per,
        nz: inp.nz,
        dz: inp.outlet.dz,
        eps: inp.eps,
        force: inp.force,
        face_flux,
        time: inp.time,
        jet: inp.jet,
    }
}

/// # Safety
/// No thread writes any of the fields while the view is live.
unsafe fn full_view<'a>(f: [Raw<f64>; 10], n: usize) -> PrimView<'a> {
    let [ux, uy, uz, p, beta, beta_over_eps2, div, gx, gy, gz] = f.map(|r| r.view(0, n));
    PrimView { ux, uy, uz, p, beta, beta_over_eps2, div, gx, gy, gz }
}

/// The multistep update of the cells c0..c1: q = q_old + Σ w_i f_i over the new right-hand side
/// `rhs` and `inp.past` (`[q, q_old, rhs]`).
///
/// # Safety
/// The rows c0..c1 of q are the calling thread's own, and no thread writes q_old or rhs there.
unsafe fn multistep_cells(inp: &StepInput, [q, q_old, rhs]: [Raw<[f64; 4]>; 3], c0: usize, c1: usize) {
    let w = inp.weights;
    let mut fs: [&[f64]; 3] = [rhs.view(c0, c1).as_flattened(), &[], &[]];
    for (i, h) in inp.past.iter().enumerate() {
        fs[i + 1] = h[c0..c1].as_flattened();
    }
    combine(q.part(c0, c1).as_flattened_mut(), q_old.view(c0, c1).as_flattened(), &fs[..w.len()], w);
}

/// The implicit drag step (implicit_drag.rs) of the cells c0..c1, `q` their rows.
fn own_implicit_drag(inp: &StepInput, q: &mut [[f64; 4]], c0: usize, c1: usize) {
    if let Some(d) = inp.drag {
        implicit_drag::apply(q, d.cells(c0, c1), inp.dt);
    }
}

/// A thread's block: its layers k0..k1 and its horizontal-face rows f0..f1.
struct Rows {
    k: (usize, usize),
    faces: (usize, usize),
}

/// The team's arrays that the forward–backward update reads and writes.
struct FbArrays {
    q: Raw<[f64; 4]>,
    q_old: Raw<[f64; 4]>,
    rhs: Raw<[f64; 4]>,
    mass_rate: Raw<f64>,
    face: Raw<f64>,
    face_old: Raw<f64>,
    rhs_face: Raw<f64>,
    axial: Raw<[f64; 7]>,
    prim: [Raw<f64>; 10],
}

/// The forward–backward update of a thread's rows (forward_backward.rs): the momentum (its other
/// terms by the AB weights, the pressure force forward) and F forward; after a barrier the axial
/// faces' new ṁ above the own layers; after another the own layers' mass. False if the team failed.
///
/// # Safety
/// As `team_step`'s phases: the thread writes only its own rows, and reads other threads' rows of
/// q (momentum), F and the axial ṁ only after the barrier that follows their writes; the
/// primitives are not written.
unsafe fn forward_backward_rows(inp: &StepInput, a: &FbArrays, barrier: &SpinBarrier, rows: Rows) -> bool {
    let (per, nz, nf) = (inp.outlet.per, inp.nz, inp.geo.faces.len());
    let n = per * nz;
    let ((k0, k1), (f0, f1)) = (rows.k, rows.faces);
    let (c0, c1) = (k0 * per, k1 * per);
    let pr = full_view(a.prim, n);
    {
        let (f, e) = (a.rhs.part(c0, c1), &inp.eps[c0..c1]);
        let own = PrimView { gx: &pr.gx[c0..c1], gy: &pr.gy[c0..c1], gz: &pr.gz[c0..c1], ..pr };
        without_pressure_force(f, e, &own);
        multistep_cells(inp, [a.q, a.q_old, a.rhs], c0, c1);
        add_pressure_force(a.q.part(c0, c1), e, &own, inp.dt);
        own_implicit_drag(inp, a.q.part(c0, c1), c0, c1);
        for (lo, hi) in [(c0, c1), (f0, f1)] {
            let (y, y0, f) = (a.face.part(lo, hi), a.face_old.view(lo, hi), a.rhs_face.view(lo, hi));
            combine(y, y0, &[f], &[inp.dt]);
        }
    }

    if !barrier.wait() {
        return false;
    }
    let nface = n + nz * nf;
    {
        let (rhs_in, qv) = (rhs_input(inp, a.face.view(0, nface)), a.q.view(0, n));
        let ka = k1.min(nz - 1);
        for k in k0..ka {
            axial_mass_faces(&rhs_in, qv, &pr, k, a.axial.part(k * per, (k + 1) * per));
        }
    }
    if !barrier.wait() {
        return false;
    }
    {
        // Only the own layers' q is read here: other threads write theirs meanwhile.
        let (rhs_in, ax) = (rhs_input(inp, a.face.view(0, nface)), a.axial.view(0, n));
        for k in k0..k1 {
            let qk = a.q.view(k * per, (k + 1) * per);
            mass_layer(&rhs_in, qk, &pr, ax, k, a.mass_rate.part(k * per, (k + 1) * per));
        }
    }
    let (y, y0, r) = (a.q.part(c0, c1), a.q_old.view(c0, c1), a.mass_rate.view(c0, c1));
    for (s, (s0, r)) in y.iter_mut().zip(y0.iter().zip(r)) {
        s[0] = s0[0] + inp.dt * r;
    }
    true
}
