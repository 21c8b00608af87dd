//! The simulation: owns the state (particles, gas, coupling buffers), follows the plan, runs the
//! step loop with its watchdog, and produces snapshots and checkpoints.

mod checkpoint;
mod coupled;
pub mod plan;
mod pressure_follow;
mod pressure_mean;
pub mod run_analysis;
pub mod snapshot;
mod watchdog;

pub use plan::Plan;
pub use run_analysis::{AnalysisReport, RunAnalysis};
pub use snapshot::{GridInfo, ParticleSnapshot, Snapshot, SnapshotSink};
pub use watchdog::MAX_OVERLAP_FRACTION;

use crate::case::{Case, Field};
use crate::cfd::GasSolver;
use crate::coupling::{build_voidage, VoidageMethod};
use crate::dem::DemSystem;
use crate::grid::CylGrid;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The checkpoint format this build writes and reads (`checkpoint`: a self-describing header,
/// then named sections).
pub const CHECKPOINT_FORMAT: u32 = checkpoint::FORMAT;

#[derive(Debug, Clone, PartialEq)]
pub enum SimError {
    /// The case cannot be built (bed generation failed, ...).
    Build(String),
    /// The watchdog stopped the run: what, where, when, and which parameter to change.
    Unstable(String),
    /// A checkpoint could not be read.
    Checkpoint(String),
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SimError::Build(m) => write!(f, "cannot build the simulation: {m}"),
            SimError::Unstable(m) => write!(f, "run stopped by the stability watchdog: {m}"),
            SimError::Checkpoint(m) => write!(f, "bad checkpoint: {m}"),
        }
    }
}
impl std::error::Error for SimError {}

/// Everything that evolves; what a checkpoint holds.
#[derive(Serialize, Deserialize)]
struct State {
    /// The case travels as JSON text (its tagged enums are not bincode-friendly).
    #[serde(with = "case_as_json")]
    case: Case,
    plan: Plan,
    steps: u64,
    snapshots_taken: u64,
    dem: DemSystem,
    gas: Option<GasSolver>,
    analysis: RunAnalysis,
    /// The pressure force's state between couplings (`coupling.pressure_force` = "gas_step").
    #[serde(default)]
    follow: pressure_follow::PressureFollow,
    /// The pressure force's sum over the gas steps of an interval (`coupling.pressure_force` =
    /// "interval_mean").
    #[serde(default)]
    mean: pressure_mean::PressureMean,
}

/// Wall time spent per stage (seconds), for progress reports and benchmarks.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageTimers {
    /// Near-list refreshes and Verlet-list rebuilds.
    pub neighbours: f64,
    /// The DEM's fused pass: contact forces, walls, gravity, drag and the AB update (one team pass).
    pub contacts_integration: f64,
    pub voidage: f64,
    /// Gas fields at the cells, drag on the particles and on the gas.
    pub exchange: f64,
    pub gas: f64,
    /// Snapshots: fields, pressure drops.
    pub output: f64,
}

impl StageTimers {
    /// The DEM's share: neighbours, contacts and integration.
    pub fn dem(&self) -> f64 {
        self.neighbours + self.contacts_integration
    }
    pub fn total(&self) -> f64 {
        self.dem() + self.voidage + self.exchange + self.gas + self.output
    }
}

pub struct Simulation {
    st: State,
    timers: StageTimers,
    grid: CylGrid,
    voidage: Box<dyn VoidageMethod>,
    buf: coupled::Buffers,
    steps_per_snapshot: u64,
    end_steps: u64,
    limits: watchdog::Limits,
}

impl Simulation {
    /// Build a run: the settled bed (poured, or loaded from `cache_dir`), the gas, the plan.
    pub fn new(case: Case, cache_dir: Option<&Path>) -> Result<Simulation, SimError> {
        crate::memory::return_freed_memory();
        let (pos, vel) = crate::dem::build_bed(&case, cache_dir).map_err(SimError::Build)?;
        let mut dem = DemSystem::new(&case, pos, vel);
        dem.set_frozen(case.dem.frozen);
        let grid = fluid_grid(&case);
        let gas = case.gas.as_ref().map(|_| GasSolver::new(&case, grid.clone()));
        // The gas step: the stable step of the gas at rest or of the inlet flow, whichever is less.
        let inflow = crate::cfd::case_stable_time_step(&case).unwrap_or(f64::INFINITY);
        let plan = Plan::for_case(&case, dem.len(), gas.as_ref().map(|g| g.stable_dt().min(inflow)));
        let analysis = RunAnalysis::new(&case, &grid);
        let st = State {
            case,
            plan,
            steps: 0,
            snapshots_taken: 0,
            dem,
            gas,
            analysis,
            follow: Default::default(),
            mean: Default::default(),
        };
        let mut sim = Simulation::assemble(st, grid);
        sim.initial_voidage();
        Ok(sim)
    }

    fn assemble(st: State, grid: CylGrid) -> Simulation {
        let sublayers = st.case.coupling.drag_voidage_sublayers.max(1) as usize;
        // With drag-voidage sub-layers the method runs on their grid (coupled.rs).
        let voidage = if sublayers > 1 && st.case.gas.is_some() {
            build_voidage(&st.case, &coupled::sublayer_grid(&grid, sublayers))
        } else {
            build_voidage(&st.case, &grid)
        };
        let dt = st.case.dem.time_step_s;
        let steps_per_snapshot = ((st.case.outputs.snapshot_interval_s / dt).round() as u64).max(1);
        let end_steps = ((st.case.end_time_s / dt).round() as u64).max(1);
        let buf = coupled::Buffers::new(&grid, st.dem.len(), if st.case.gas.is_some() { sublayers } else { 1 });
        let limits = watchdog::Limits::of(&st.case);
        Simulation { st, timers: StageTimers::default(), grid, voidage, buf, steps_per_snapshot, end_steps, limits }
    }

    pub fn case(&self) -> &Case {
        &self.st.case
    }
    pub fn plan(&self) -> &Plan {
        &self.st.plan
    }
    pub fn grid(&self) -> &CylGrid {
        &self.grid
    }
    pub fn dem(&self) -> &DemSystem {
        &self.st.dem
    }
    pub fn gas(&self) -> Option<&GasSolver> {
        self.st.gas.as_ref()
    }
    pub fn steps(&self) -> u64 {
        self.st.steps
    }
    pub fn timers(&self) -> &StageTimers {
        &self.timers
    }
    /// Start the stage timers from zero (benchmarks).
    pub fn reset_timers(&mut self) {
        self.timers = StageTimers::default();
    }
    /// The particles, to step them without the gas (benchmarks: the DEM alone on the same bed).
    pub fn dem_mut(&mut self) -> &mut DemSystem {
        &mut self.st.dem
    }
    /// Change the coupling interval from now on (benchmarks, trade-off studies).
    pub fn set_coupling_interval(&mut self, steps: u32) {
        self.st.case.coupling.interval_steps = steps.max(1);
        self.st.plan.coupling_interval = steps.max(1) as u64;
    }
    /// The gas's time scheme from the next gas step on, with the plan's gas step made the new
    /// scheme's stable step at the inlet flow (benchmarks compare both schemes from one state).
    pub fn set_gas_time_scheme(&mut self, scheme: crate::cfd::TimeScheme) {
        let Some(g) = self.st.case.gas.as_mut() else { return };
        g.time_scheme = scheme;
        let inflow = crate::cfd::case_stable_time_step(&self.st.case).unwrap_or(f64::INFINITY);
        if let Some(gas) = self.st.gas.as_mut() {
            gas.switch_time_scheme(scheme);
            let stable = gas.stable_dt().min(inflow);
            self.st.plan = Plan::for_case(&self.st.case, self.st.dem.len(), Some(stable));
            // `sync_gas` counts gas steps of the plan's length: recount the steps taken in it.
            if let Some(dt_g) = self.st.plan.gas_dt_s {
                let dt = self.st.case.dem.time_step_s;
                gas.set_steps(plan::gas_steps_due(self.st.steps, dt, dt_g));
            }
        }
    }
    /// How the gas's voidage moves between couplings from the next coupling on (the trade-off
    /// bench compares both from one state).
    pub fn set_gas_voidage(&mut self, how: crate::case::GasVoidage) {
        self.st.case.coupling.gas_voidage = how;
    }
    /// The particles' pressure force between couplings from the next coupling on (benchmarks).
    pub fn set_pressure_force(&mut self, how: crate::case::PressureForce) {
        self.st.case.coupling.pressure_force = how;
    }
    /// The drag on the gas between couplings from the next coupling on (`coupling.gas_drag`).
    pub fn set_gas_drag(&mut self, how: crate::case::GasDrag) {
        self.st.case.coupling.gas_drag = how;
    }
    /// Change the set superficial velocity from now on (no new ramp); used by the U_mf sweep.
    pub fn set_superficial_velocity(&mut self, u: f64) {
        if let Some(g) = self.st.case.gas.as_mut() {
            g.superficial_velocity_m_s = u;
        }
        if let Some(gas) = self.st.gas.as_mut() {
            gas.set_superficial_velocity(u);
        }
    }
    pub fn time(&self) -> f64 {
        self.st.steps as f64 * self.st.case.dem.time_step_s
    }
    /// Run to `t` seconds instead of the case's end (a longer run from the same state).
    pub fn set_end_time(&mut self, t: f64) {
        self.st.case.end_time_s = t;
        self.end_steps = ((t / self.st.case.dem.time_step_s).round() as u64).max(1);
    }
    pub fn end_time(&self) -> f64 {
        self.end_steps as f64 * self.st.case.dem.time_step_s
    }
    pub fn is_finished(&self) -> bool {
        self.st.steps >= self.end_steps && self.st.snapshots_taken > self.last_snapshot_index()
    }
    fn last_snapshot_index(&self) -> u64 {
        self.end_steps.div_ceil(self.steps_per_snapshot)
    }

    /// Run at most `max_steps` steps; returns Some(snapshot) when a snapshot time is reached.
    /// Snapshot 0 is the initial state, returned by the first call before any step.
    pub fn advance(&mut self, max_steps: u64) -> Result<Option<Snapshot>, SimError> {
        if self.st.snapshots_taken == 0 {
            return self.take_snapshot().map(Some);
        }
        for _ in 0..max_steps {
            if self.st.steps >= self.end_steps {
                break;
            }
            self.step()?;
            if self.st.analysis.due(self.st.steps, self.st.dem.time()) {
                self.sync_gas()?;
                let t0 = std::time::Instant::now();
                self.sample_analysis();
                self.timers.output += t0.elapsed().as_secs_f64();
            }
            if self.st.steps.is_multiple_of(self.steps_per_snapshot) || self.st.steps == self.end_steps {
                self.sync_gas()?;
                let t0 = std::time::Instant::now();
                let s = self.take_snapshot();
                self.timers.output += t0.elapsed().as_secs_f64();
                return s.map(Some);
            }
        }
        // Whoever reads the state next (a checkpoint, `gas()`) sees the gas at the particles' time.
        self.sync_gas()?;
        Ok(None)
    }

    /// The analysis of the samples so far (case `analysis`).
    pub fn analysis_report(&self) -> AnalysisReport {
        self.st.analysis.report(&self.grid)
    }

    /// The analysis held in a checkpoint (`checkpoint`), read without restoring the run: the
    /// case's grid and the report of its samples (time series from `series_from_s` when given).
    pub fn analysis_of_checkpoint(
        bytes: &[u8],
        series_from_s: Option<f64>,
    ) -> Result<(Case, CylGrid, AnalysisReport), SimError> {
        let (case, analysis) = checkpoint::analysis_of(bytes).map_err(SimError::Checkpoint)?;
        let grid = fluid_grid(&case);
        let report = analysis.report_from(&grid, series_from_s);
        Ok((case, grid, report))
    }

    /// One analysis sample of now (the voidage of the last coupling in a coupled run).
    fn sample_analysis(&mut self) {
        if self.st.plan.voidage_field && !self.st.plan.coupling {
            self.refresh_voidage_field();
        }
        let (pressure, vel) = match &self.st.gas {
            Some(g) => {
                (Some(g.pressure()), Some((0..self.grid.num_cells()).map(|c| g.velocity_cyl(c)).collect::<Vec<_>>()))
            }
            None => (None, None),
        };
        let sample = run_analysis::Sample {
            time_s: self.st.dem.time(),
            voidage: &self.buf.voidage,
            pressure_pa: pressure.as_deref(),
            gas_velocity: vel.as_deref(),
            positions: self.st.dem.positions(),
            velocities: self.st.dem.velocities(),
        };
        self.st.analysis.add(&self.grid, &sample);
    }

    /// Run to the end, handing every snapshot to `sink`.
    pub fn run(&mut self, sink: &mut dyn SnapshotSink) -> Result<(), SimError> {
        while !self.is_finished() {
            if let Some(s) = self.advance(u64::MAX)? {
                sink.snapshot(&s);
            }
        }
        Ok(())
    }

    /// The complete state behind a self-describing header (`checkpoint`); `restore` continues
    /// bit-identically.
    pub fn checkpoint(&self) -> Vec<u8> {
        checkpoint::encode(&self.st)
    }

    pub fn restore(bytes: &[u8]) -> Result<Simulation, SimError> {
        crate::memory::return_freed_memory();
        let st = checkpoint::decode(bytes).map_err(SimError::Checkpoint)?;
        let grid = fluid_grid(&st.case);
        let mut sim = Simulation::assemble(st, grid);
        if let (Some(gas), Some(g)) = (sim.st.gas.as_mut(), sim.st.case.gas.as_ref()) {
            gas.anchor_pressure(g.outlet_pressure_pa);
        }
        // A coupled run holds the voidage of its last coupling, which the gas holds too.
        match (&sim.st.gas, sim.st.plan.coupling) {
            (Some(gas), true) => {
                let held = gas.voidage_ramp().map_or(gas.voidage(), |r| r.target());
                sim.buf.voidage.copy_from_slice(held)
            }
            _ => sim.refresh_voidage_field(),
        }
        Ok(sim)
    }

    /// The snapshot of now; a field holding NaN or ∞ stops the run instead (no stored snapshot
    /// ever holds one: the last good snapshot and checkpoint stay the run's last).
    fn take_snapshot(&mut self) -> Result<Snapshot, SimError> {
        if self.st.plan.voidage_field && !self.st.plan.coupling {
            self.refresh_voidage_field();
        }
        let fields = self.st.case.outputs.fields.clone();
        let want = |f: Field| fields.contains(&f);
        let voidage = (self.st.plan.voidage_field && want(Field::Voidage)).then(|| self.buf.voidage.clone());
        let (mut pressure, mut dp, mut layer_dp, mut vel) = (None, None, None, None);
        if let Some(g) = &self.st.gas {
            let p = g.pressure();
            let layers = crate::analysis::layer_means(&self.grid, &p);
            dp = Some(crate::analysis::bed_pressure_drop(&layers));
            layer_dp = Some(layers.windows(2).map(|w| w[0] - w[1]).collect());
            if want(Field::Pressure) {
                pressure = Some(p);
            }
            if want(Field::GasVelocity) {
                vel = Some((0..self.grid.num_cells()).map(|c| g.velocity_cyl(c)).collect());
            }
        }
        let particles = self.st.plan.particle_field.then(|| self.particle_snapshot());
        let s = Snapshot {
            index: self.st.snapshots_taken,
            time_s: self.time(),
            step: self.st.steps,
            grid: GridInfo::of(&self.grid),
            voidage,
            pressure_pa: pressure,
            gas_velocity_m_s: vel,
            pressure_drop_pa: dp,
            layer_pressure_drop_pa: layer_dp,
            particles,
        };
        if let Some(bad) = s.first_non_finite() {
            return Err(SimError::Unstable(format!(
                "snapshot {} at t = {:.6} s (DEM step {}) would hold {bad}; lower dem.time_step_s or gas.time_step_s",
                s.index, s.time_s, s.step
            )));
        }
        self.st.snapshots_taken += 1;
        Ok(s)
    }

    /// Particle state in the original order.
    pub fn particle_snapshot(&self) -> ParticleSnapshot {
        let d = &self.st.dem;
        let n = d.len();
        let mut pos = vec![[0.0; 3]; n];
        let mut vel = vec![[0.0; 3]; n];
        for (k, &id) in d.ids().iter().enumerate() {
            pos[id as usize] = d.positions()[k];
            vel[id as usize] = d.velocities()[k];
        }
        ParticleSnapshot { radius_m: d.radius(), positions_m: pos, velocities_m_s: vel }
    }

    fn refresh_voidage_field(&mut self) {
        coupled::compute_voidage(&self.grid, self.voidage.as_mut(), &self.st.dem, &mut self.buf);
    }
}

mod case_as_json {
    use crate::case::Case;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};
    pub fn serialize<S: Serializer>(c: &Case, s: S) -> Result<S::Ok, S::Error> {
        serde_json::to_string(c).map_err(serde::ser::Error::custom)?.serialize(s)
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Case, D::Error> {
        let text = String::deserialize(d)?;
        Case::from_stored_json(&text).map_err(serde::de::Error::custom)
    }
}

/// The fluid grid of a case (also used for voidage maps of DEM-only runs).
pub fn fluid_grid(case: &Case) -> CylGrid {
    CylGrid::new(case.column.diameter_m / 2.0, case.column.height_m, case.grid.dr_m, case.grid_dz_m(), case.grid.n0)
}

#[cfg(test)]
mod plan_tests;
#[cfg(test)]
mod resume_tests;
#[cfg(test)]
mod tests;
