//! A batch of touching particle pairs waiting for the contact law, as structure of arrays over
//! lanes (`pair_batch` evaluates it, `pair_simd` fills and gathers it eight lanes at a time,
//! `pair_scatter` adds its forces into the chunk buffers), and the per-particle inputs its lanes
//! are gathered from.

use super::contact::{ContactLaw, V3};

/// Pairs per batch.
pub(crate) const CAP: usize = 64;
const _: () = assert!(CAP.is_multiple_of(8), "the vector kernels take lanes eight at a time");

pub(crate) type Lanes = [f32; CAP];

/// Touching pairs waiting for evaluation (structure of arrays over lanes).
#[repr(C, align(64))]
pub(crate) struct Batch {
    pub m: usize,
    /// List slot (for the history), first and second particle.
    pub k: [u32; CAP],
    pub i: [u32; CAP],
    pub j: [u32; CAP],
    /// x_j − x_i, its squared length r² and (2R)² − r² (formed in double, then rounded).
    pub dx: [Lanes; 3],
    pub r2: Lanes,
    pub gap2: Lanes,
    /// 1 when the pair touched in the previous step (its history is live), else 0.
    pub was: [u8; CAP],
    // Gathered inputs and per-lane diagnostics.
    pub vrel: [Lanes; 3],
    pub ws: [Lanes; 3],
    pub s: [Lanes; 3],
    pub delta: Lanes,
    /// (|F_t|² − (μF_n)²)/(μF_n)².
    pub excess: Lanes,
    /// Force on i, and n × F_t.
    pub f: [Lanes; 3],
    pub c: [Lanes; 3],
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
            gap2: z,
            was: [1; CAP],
            vrel: [z; 3],
            ws: [z; 3],
            s: [z; 3],
            delta: z,
            excess: z,
            f: [z; 3],
            c: [z; 3],
        })
    }

    /// Fill lane `l` < CAP with the pair x_j − x_i = `dx`, r² = `r2`, contact at r² = `d2`
    /// (the caller counts lanes and sets `m` before `evaluate`).
    #[inline(always)]
    pub fn set(&mut self, l: usize, entry: Entry, dx: V3, r2: f64, d2: f64) {
        let l = l % CAP; // a no-op for l < CAP that lets the compiler drop the bounds checks
        self.k[l] = entry.k as u32;
        self.i[l] = entry.i as u32;
        self.j[l] = entry.j as u32;
        self.dx[0][l] = dx[0] as f32;
        self.dx[1][l] = dx[1] as f32;
        self.dx[2][l] = dx[2] as f32;
        self.r2[l] = r2 as f32;
        self.gap2[l] = (d2 - r2) as f32;
    }
}

impl Default for Box<Batch> {
    fn default() -> Self {
        Batch::new()
    }
}

/// One list entry as a batch lane holds it: its slot k in the list (for the history) and its
/// two particles i < j (indices into the chunk's window).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    pub k: usize,
    pub i: usize,
    pub j: usize,
}

/// What the lanes of a batch are evaluated with: the pair law, whether to measure the Coulomb
/// excess (`DemParams::audit`), the radius R, the time step h, and the velocities and spins of
/// the chunk's window (the lanes' i and j index them).
#[derive(Clone, Copy)]
pub(crate) struct PairInputs<'a> {
    pub law: &'a ContactLaw,
    pub audit: bool,
    pub r: f64,
    pub h: f64,
    pub v: &'a [V3],
    pub w: &'a [V3],
}

/// The list entries a chunk scans: the row of each entry less the chunk's first row (`owner`,
/// `work_split::MAX_CHUNK_ROWS` bounds it) and its partner (`nbr`) as a particle index, the
/// positions of the chunk's window (particles first..first + x.len()), and contact where r² < d2.
#[derive(Clone, Copy)]
pub(crate) struct Entries<'a> {
    pub owner: &'a [u16],
    pub nbr: &'a [u32],
    pub first: usize,
    pub x: &'a [V3],
    pub d2: f64,
}
